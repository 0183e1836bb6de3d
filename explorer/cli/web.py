"""``phong-explorer web``: the explorer served to a browser (trame; the view rendered here).

::

    phong-explorer web                               # gold on the teapot, http://127.0.0.1:8080/?secret=
    phong-explorer web --preset jade --mesh torus --port 9000 --open
    phong-explorer web scene.yaml
    phong-explorer web --session my.yaml             # a saved session, exactly
    phong-explorer web --last                        # the session kept when it last stopped

It prints its URL, with the page's token (only that address opens the page:
:mod:`explorer.app.web.guard`), and serves until Ctrl-C (or SIGTERM); then it keeps the session
where the desktop's window keeps it on closing, and ``--last`` (either command's) reopens it.
It listens on 127.0.0.1 (this machine only) unless ``--host`` says otherwise, and then warns
that anyone who can reach the port and has that address can use it. One explorer per server:
every tab shows and edits the same state. Needs the ``web`` extra (``pip install
"phong-explorer[web]"``); without it the command says so in one line.
"""

from __future__ import annotations

import argparse
import importlib.util
import logging
import sys

from explorer.app import start as gui
from explorer.cli.explorerstart import add_preset_option, add_shading_option, start_state
from explorer.cli.options import add_scene_arguments, background_from_options
from explorer.core.errors import ExplorerError
from explorer.core.text import say

#: the port served unless --port says otherwise
DEFAULT_PORT = 8080
#: what the web front end needs (the ``web`` extra)
NEEDS = ("trame", "trame_vuetify", "trame_vtk")


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_preset_option(p)
    add_shading_option(p)
    p.add_argument(
        "--port", type=int, default=DEFAULT_PORT, metavar="N",
        help="port to listen on (default %(default)s; 0: any free port)",
    )  # fmt: skip
    p.add_argument(
        "--host", default=None, metavar="ADDR",
        help="address to listen on (default 127.0.0.1: this machine only; any other address "
        "lets whoever reaches the port use the explorer)",
    )  # fmt: skip
    p.add_argument("--open", action="store_true", help="open the page in the default browser")
    p.add_argument(
        "--no-direct",
        dest="direct",
        action="store_false",
        help="send every picture as JPEG (then PNG once the view is still), never raw through "
        "the direct socket a page of this machine gets: for a slow link that arrives on a "
        "loopback address, such as an SSH tunnel (four slow frames send it back anyway)",
    )
    p.add_argument(
        "--session", metavar="FILE", default=None,
        help="open a saved session (Save session, or the desktop's) exactly as it was",
    )  # fmt: skip
    p.add_argument(
        "--last", action="store_true",
        help="reopen the session kept when the explorer (this server, or the desktop's "
        "window) last closed",
    )  # fmt: skip
    add_scene_arguments(p, force=False, mesh_default=gui.DEFAULT_MESH)


def missing() -> list[str]:
    """The web extra's modules that are not installed."""
    return [m for m in NEEDS if importlib.util.find_spec(m) is None]


def run(args) -> int:
    from explorer.app import web  # noqa: I001 - the server's module (VTK, trame) only here

    if not 0 <= args.port <= 65535:
        raise ExplorerError(f"--port must be 0 to 65535, got {args.port}")
    if args.session is not None and args.last:
        raise ExplorerError("--session and --last both name a session: give one")
    lack = missing()
    if lack:
        raise ExplorerError(
            f'the web explorer needs {", ".join(lack)}: pip install "phong-explorer[web]"'
        )
    if not logging.getLogger().handlers:
        logging.basicConfig(
            level=logging.WARNING, format="phong-explorer: %(levelname)s: %(message)s"
        )
    host = args.host or web.DEFAULT_HOST
    if args.host is not None and host not in ("127.0.0.1", "localhost", "::1"):
        say(web.OPEN_HOST_WARNING.format(host=host, port=args.port), file=sys.stderr)
    web.check_listen(host, args.port)  # a taken port said at once, before the explorer loads
    warnings: list[str] = []
    state, mesh = start_state(args, warnings)
    app = web.WebExplorer(state, mesh, materials_dirs=tuple(args.materials_dirs),
                          background=background_from_options(args), last_session=True,
                          start_warnings=tuple(warnings), direct=args.direct)  # fmt: skip
    web.serve(app, port=args.port, host=host, open_browser=args.open)
    return 0
