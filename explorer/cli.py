"""The ``phong-explorer`` command.

Each subcommand lives in its own module (``explorer.cli_<name>``) exposing
``add_arguments(parser)`` and ``run(args) -> int``; heavy imports (VTK, trimesh) happen inside
``run``. User mistakes raise :class:`~explorer.errors.ExplorerError`: printed as one
``error: ...`` block on stderr, exit status 2, no traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from .errors import ExplorerError

#: subcommand -> (module, one-line help)
COMMANDS: dict[str, tuple[str, str]] = {
    "plan": ("explorer.cli_plan", "print the work plan for a scene and why each term is in or out"),
    "presets": ("explorer.cli_presets", "list, show and validate material presets"),
    "render": ("explorer.cli_render", "render a scene off-screen to PNG, PLY or GLB"),
    "sheet": ("explorer.cli_render", "render every preset in one labelled grid"),
    "gui": ("explorer.cli_gui", "open the interactive explorer window"),
    "bench": ("explorer.cli_bench", "measure what accuracy costs in time"),
}


def _available():
    for name, (module, help_) in COMMANDS.items():
        try:
            mod = importlib.import_module(module)
        except ModuleNotFoundError as exc:  # a subcommand not shipped yet
            if exc.name == module:
                continue
            raise
        yield name, mod, help_


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="phong-explorer",
        description="Explore materials under the Phong / Blinn-Phong illumination model.",
    )
    parser.add_argument("--version", action="version", version=_version())
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, mod, help_ in _available():
        p = sub.add_parser(name, help=help_, description=help_)
        adder = getattr(mod, f"add_{name}_arguments", None) or mod.add_arguments
        adder(p)
        p.set_defaults(_run=getattr(mod, f"run_{name}", None) or mod.run)
    return parser


def _version() -> str:
    from . import __version__

    return f"phong-explorer {__version__}"


def _show_notices() -> None:
    """Print preset notices as one ``notice: ...`` line on stderr, not as Python warnings."""
    import warnings

    from .presets import PresetNotice

    original = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, PresetNotice):
            print(f"notice: {message}", file=sys.stderr)
        else:
            original(message, category, filename, lineno, file, line)

    warnings.showwarning = show


def main(argv: list[str] | None = None) -> int:
    _show_notices()
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        if "gui" in {n for n, _, _ in _available()}:
            args = parser.parse_args(["gui"])
        else:
            parser.print_help()
            return 0
    try:
        return int(args._run(args) or 0)
    except ExplorerError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
