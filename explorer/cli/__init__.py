"""The ``phong-explorer`` command: argument parsing and messages, one module per command.

May import every other part of the package; nothing imports it. Each subcommand lives in its
own module (``explorer.cli.<name>``) exposing ``add_arguments(parser)`` and
``run(args) -> int``; VTK and trimesh load only when a command draws or reads a mesh file.
User mistakes raise :class:`~explorer.core.errors.ExplorerError`: printed as one ``error: ...``
block on stderr, exit status 2, no traceback (so is an ``OSError`` naming a file that no
check turned into one: a folder that cannot be searched, a name too long); text a terminal
would act on (from file names, keys, descriptions) is shown escaped
(:func:`explorer.core.text.say`). SIGTERM (every command but ``gui``, whose window loop would
hold it back) raises :class:`Terminated`, so that the writer's cleanup runs: the command
stops with one ``error:`` line, exit status 143, and leaves no temporary file. Ctrl-C does
the same with exit status 130: long ray work runs in chunks (:mod:`explorer.geometry.bvh`)
and stops at the end of the current one, well within a second, with one ``error:
interrupted ...`` line.
"""

from __future__ import annotations

import argparse
import importlib
import os
import signal
import sys
import threading
import warnings
from contextlib import contextmanager

from explorer.core.errors import Cancelled, ExplorerError, Notice
from explorer.core.text import printable, say
from explorer.core.version import __version__

#: subcommand -> one-line help; each is the module ``explorer.cli.<name>``, with
#: ``add_arguments`` and ``run``
COMMANDS = {
    "plan": "print the work plan for a scene and why each term is in or out",
    "presets": "list, show, validate, import (.mtl) and export material presets",
    "render": "render a scene off-screen to PNG, PLY, GLB, OBJ or a GIF/MP4 turntable",
    "sheet": "render every preset in one labelled grid",
    "gui": "open the interactive explorer window",
    "web": "serve the interactive explorer to a browser (trame)",
    "bench": "measure what accuracy costs in time",
}


#: the command run when none is given; its options (and a SCENE file) are taken without it
DEFAULT_COMMAND = "gui"
#: the top-level options (they do not mean the default command)
TOP_OPTIONS = ("-h", "--help", "--version")


def with_default_command(argv: list[str]) -> list[str]:
    """``argv`` with :data:`DEFAULT_COMMAND` put first when no command is named: nothing at all,
    a ``gui`` option (``phong-explorer --preset jade``) or an existing SCENE file. A word that
    is neither a command nor a file is left for the parser to refuse (a mistyped command)."""
    if not argv:
        return [DEFAULT_COMMAND]
    first = argv[0]
    if first in COMMANDS or first in TOP_OPTIONS:
        return list(argv)
    if first.startswith("-") or os.path.isfile(first):
        return [DEFAULT_COMMAND, *argv]
    return list(argv)


def build_parser() -> argparse.ArgumentParser:
    """The command's parser. Imports every subcommand's module (and with them numpy and the
    engine: about half a second), which this module itself does not, so that :func:`main`
    starts inside its own Ctrl-C handling."""
    parser = argparse.ArgumentParser(
        prog="phong-explorer",
        description="Explore materials under the Phong / Blinn-Phong illumination model.",
        epilog=f"Without a COMMAND, '{DEFAULT_COMMAND}' runs and takes its options and SCENE "
        f"(phong-explorer --preset jade); 'phong-explorer {DEFAULT_COMMAND} --help' lists them.",
    )
    parser.add_argument("--version", action="version", version=f"phong-explorer {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, help_ in COMMANDS.items():
        mod = importlib.import_module(f"explorer.cli.{name}")
        p = sub.add_parser(name, help=help_, description=help_)
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run)
    return parser


@contextmanager
def _notices_as_lines():
    """While a command runs, every :class:`~explorer.core.errors.Notice` (a preset hiding
    another, an old key name) shown is one ``notice: ...`` line on stderr, not a Python
    warning. Only the form changes (``warnings.formatwarning``), and only for the command's
    time: the warning filters decide as ever, and a caller recording warnings
    (``pytest.warns``, ``warnings.catch_warnings(record=True)``) receives them."""
    original = warnings.formatwarning

    def form(message, category, filename, lineno, line=None):
        if issubclass(category, Notice):
            return f"notice: {printable(message, keep=chr(10))}\n"
        return original(message, category, filename, lineno, line)

    warnings.formatwarning = form
    try:
        yield
    finally:
        warnings.formatwarning = original


#: exit status after SIGTERM (the shell's 128 + signal number)
TERMINATED_STATUS = 128 + signal.SIGTERM
#: exit status after Ctrl-C (SIGINT)
INTERRUPTED_STATUS = 128 + signal.SIGINT


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread like Ctrl-C so that every ``finally`` runs (the
    atomic writer removes its temporary files)."""


def _raise_terminated(signum, frame):
    raise Terminated()


@contextmanager
def _sigterm_raises(enabled: bool = True):
    """While inside, SIGTERM raises :class:`Terminated` (main thread only; the previous handler
    is restored on the way out)."""
    if not enabled or threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def main(argv: list[str] | None = None) -> int:
    with _notices_as_lines():
        return _main(argv)


def _main(argv: list[str] | None) -> int:
    try:
        parser = build_parser()
    except KeyboardInterrupt:  # Ctrl-C while the engine loads: nothing was started
        print("error: interrupted (Ctrl-C)", file=sys.stderr)
        return INTERRUPTED_STATUS
    args = parser.parse_args(with_default_command(sys.argv[1:] if argv is None else argv))
    try:
        with _sigterm_raises(enabled=args.command != "gui"):
            status = int(args._run(args) or 0)
            sys.stdout.flush()  # here, so a reader that went away is met below, not at exit
        return status
    except ExplorerError as exc:
        say(f"error: {exc}", file=sys.stderr)
        return 2
    except Terminated:
        print("error: terminated (SIGTERM); no unfinished file was left", file=sys.stderr)
        return TERMINATED_STATUS
    except (KeyboardInterrupt, Cancelled):
        print("error: interrupted (Ctrl-C); no unfinished file was left", file=sys.stderr)
        return INTERRUPTED_STATUS
    except BrokenPipeError:  # the reader went away (``| head``): stop quietly, as cat does
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # so the interpreter's final flush cannot fail
        return 141
    except OSError as exc:  # a file the system refused that no check named: still one line
        if exc.filename is None:
            raise
        say(f"error: {exc.filename}: {exc.strerror or exc}", file=sys.stderr)
        return 2
