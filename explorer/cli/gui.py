"""``phong-explorer gui`` (also plain ``phong-explorer``): the interactive explorer window.

::

    phong-explorer                                   # gold on the teapot under one point light
    phong-explorer gui --preset jade --mesh torus
    phong-explorer gui scene.yaml --mesh bunny.obj
    phong-explorer gui --session my.yaml             # a saved session, exactly
    phong-explorer gui --last                        # the session kept when the window closed

A SCENE file gives the start (material, lights, viewer, mesh); the options are the ``render``
command's and override their part of it. The window needs a display: without one the command
prints one line saying why and what to run instead, and exits with status 3; so it does when Qt's
xcb platform lacks system libraries (:mod:`explorer.app.qtlibs`: the line names them and the apt
command).
"""

from __future__ import annotations

import argparse
import logging
import math
import os
import sys

from explorer.app import qtlibs
from explorer.app import start as gui
from explorer.cli.explorerstart import add_preset_option, add_shading_option
from explorer.cli.explorerstart import start as shared_start
from explorer.cli.explorerstart import start_state as shared_start_state
from explorer.cli.options import add_scene_arguments, background_from_options
from explorer.core.atomic import UnwritableFile, check_target
from explorer.core.errors import ExplorerError
from explorer.core.text import printable, say
from explorer.render.images import parse_size


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_preset_option(p)
    add_shading_option(p)
    p.add_argument(
        "--size", default="{}x{}".format(*gui.WINDOW_SIZE), metavar="WxH",
        help="window size in pixels (default %(default)s)",
    )  # fmt: skip
    p.add_argument(
        "--screenshot-dir", metavar="DIR", default=None,
        help="where key i saves screenshots (default: the current directory)",
    )  # fmt: skip
    p.add_argument(
        "--state-file", metavar="FILE.json", default=None,
        help="write the explorer's state as JSON to this file after every frame (for scripts "
        "and tests; written atomically)",
    )  # fmt: skip
    p.add_argument(
        "--exit-after", type=float, metavar="SECONDS", default=None,
        help="close the window after this many seconds (a safety net for scripts and tests)",
    )  # fmt: skip
    p.add_argument(
        "--force", action="store_true", help="replace the --state-file if it exists already",
    )  # fmt: skip
    p.add_argument(
        "--session", metavar="FILE", default=None,
        help="open a saved session (File > Save session, or a --state-file) exactly as it was",
    )  # fmt: skip
    p.add_argument(
        "--last", action="store_true",
        help="reopen the session the window kept when it was last closed",
    )  # fmt: skip
    add_scene_arguments(p, force=False, mesh_default=gui.DEFAULT_MESH)


def check_options(args) -> None:
    """Refuse options that cannot work before anything opens: ``--exit-after`` must be a
    finite number of seconds > 0; an existing ``--state-file`` is replaced only with
    ``--force``."""
    t = args.exit_after
    if t is not None and not (math.isfinite(t) and t > 0):
        raise ExplorerError(f"--exit-after must be a finite number of seconds > 0, got {t}")
    f = args.state_file
    if f is not None:
        check_state_file(f, args.force)
    if args.session is not None and args.last:
        raise ExplorerError("--session and --last both name a session: give one")


def check_state_file(f, force: bool) -> None:
    """Refuse a ``--state-file`` the window could not write after every frame: a directory
    (even with ``--force``), a file in a directory that does not exist, an existing file
    without ``--force``. (Before, the window ran and logged one error per frame.)"""
    shown = printable(repr(os.fspath(f)))
    try:  # what no --force replaces: a folder, a FIFO, a device; a name too long...
        check_target(os.path.abspath(f), overwrite=True)
    except UnwritableFile as exc:
        raise ExplorerError(f"--state-file {shown}: {printable(exc.reason)}") from None
    if os.path.lexists(f) and not force:
        raise ExplorerError(f"--state-file {shown}: already exists; use --force to replace it")


def start(args):
    """The explorer's start from the command line: see
    :func:`explorer.cli.explorerstart.start` (the options are checked first)."""
    check_options(args)
    return shared_start(args)


def start_state(args, warnings: list | None = None):
    """``(state, mesh)``: see :func:`explorer.cli.explorerstart.start_state` (the options are
    checked first)."""
    check_options(args)
    return shared_start_state(args, warnings)


def run(args) -> int:

    check_options(args)
    reason = gui.no_display_reason()
    if reason:
        say(gui.no_display_message(reason), file=sys.stderr)
        return gui.NO_DISPLAY_STATUS
    missing = qtlibs.missing_libraries()  # before Qt is asked: it would abort (status 134)
    if missing:
        say(qtlibs.missing_message(missing), file=sys.stderr)
        return gui.NO_DISPLAY_STATUS
    if not logging.getLogger().handlers:
        logging.basicConfig(
            level=logging.WARNING, format="phong-explorer: %(levelname)s: %(message)s"
        )
    size = parse_size(args.size)
    if args.screenshot_dir is not None and not os.path.isdir(args.screenshot_dir):
        raise ExplorerError(f"--screenshot-dir: {args.screenshot_dir!r} is not a directory")
    warnings: list[str] = []
    state, mesh = start_state(args, warnings)
    # Qt is loaded only when a window opens (every other command starts without it)
    from explorer.app.qtmain import run_window

    try:
        return run_window(
            state, mesh, materials_dirs=tuple(args.materials_dirs), size=size,
            state_file=args.state_file, output_dir=args.screenshot_dir,
            background=background_from_options(args), exit_after=args.exit_after,
            start_warnings=tuple(warnings),
        )  # fmt: skip
    except gui.NoDisplayError as exc:
        say(gui.no_display_message(str(exc)), file=sys.stderr)
        return gui.NO_DISPLAY_STATUS
