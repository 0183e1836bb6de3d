"""``phong-explorer bench accuracy``: measure what accuracy costs in time.

::

    phong-explorer bench accuracy                      # full run, in a source checkout
    phong-explorer bench accuracy --out-dir results/   # anywhere: results/accuracy.{md,png,json}
    phong-explorer bench accuracy --quick --out-dir /tmp/q

Per-vertex shading of sphere tessellations against the per-pixel reference (see
:mod:`explorer.analysis.accuracy`). Outputs:

- by default, in the source checkout the package runs from: ``docs/accuracy.md``,
  ``docs/accuracy.png`` and ``explorer/data/accuracy.json`` (the table
  :func:`explorer.analysis.accuracy.mesh_for_error` reads). These files belong to the command: it
  replaces them without ``--force``.
- with ``--out-dir DIR``: ``DIR/accuracy.md``, ``DIR/accuracy.png``, ``DIR/accuracy.json``;
  existing files there are user files and are replaced only with ``--force``.

Every file is written atomically. The plot needs matplotlib (``pip install
'phong-explorer[bench]'``); without it the plot is skipped with a message.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from explorer.analysis import accuracy as A
from explorer.analysis.accuracy import data_path
from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError

#: bench -> one-line help
BENCHES = {"accuracy": "per-vertex shading against the per-pixel reference: error and time"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="bench", metavar="BENCH")
    p = sub.add_parser(
        "accuracy",
        help=BENCHES["accuracy"],
        description=BENCHES["accuracy"],
        epilog="Without --out-dir (in a source checkout) it replaces docs/accuracy.md, "
        "docs/accuracy.png and explorer/data/accuracy.json: those files belong to this command. "
        "In --out-dir it never replaces an existing file without --force. A progress bar is "
        "shown on a terminal. The plot needs matplotlib (pip install 'phong-explorer[bench]').",
    )
    p.add_argument(
        "--quick",
        action="store_true",
        help="a small run (2 materials, 7 meshes, 96x96, one repeat) for tests; needs --out-dir",
    )
    p.add_argument(
        "--out-dir",
        metavar="DIR",
        help="write DIR/accuracy.md, .png and .json (default: the checkout's docs/ and "
        "explorer/data/)",
    )
    p.add_argument(
        "--repeats", type=int, metavar="N", help="timed runs per median (default 5; quick 1)"
    )
    p.add_argument("--force", action="store_true", help="replace existing files in --out-dir")


def checkout_root() -> Path | None:
    """The source checkout the package runs from (it has pyproject.toml and docs/), or None
    for an installed package."""
    import explorer

    root = Path(explorer.__file__).resolve().parent.parent
    if (root / "pyproject.toml").is_file() and (root / "docs").is_dir():
        return root
    return None


def outputs(args) -> tuple[dict[str, Path], bool]:
    """Where the three files go, and whether existing ones may be replaced."""
    if args.out_dir is not None:
        d = Path(args.out_dir)
        if not d.is_dir():
            raise ExplorerError(f"--out-dir {args.out_dir!r}: not a directory")
        paths = {k: d / f"accuracy.{k}" for k in ("md", "png", "json")}
        if not args.force:
            for p in paths.values():
                if p.exists():
                    raise ExplorerError(f"{p}: already exists; use --force to replace it")
        return paths, bool(args.force)
    if args.quick:
        raise ExplorerError(
            "--quick measures a small table for tests; give --out-dir so it does not replace "
            "the project's measured table"
        )
    root = checkout_root()
    if root is None:
        raise ExplorerError(
            "not running from a source checkout: give --out-dir DIR for the results"
        )

    return {
        "md": root / "docs" / "accuracy.md",
        "png": root / "docs" / "accuracy.png",
        "json": data_path(),
    }, True


def run(args) -> int:
    if getattr(args, "bench", None) != "accuracy":
        raise ExplorerError("which bench? phong-explorer bench accuracy (see --help)")
    return run_accuracy(args)


def run_accuracy(args) -> int:
    import os

    paths, overwrite = outputs(args)
    config = A.BenchConfig.quick_run() if args.quick else A.BenchConfig()
    if args.repeats is not None:
        if args.repeats < 1:
            raise ExplorerError(f"--repeats must be at least 1, got {args.repeats}")
        config = A.BenchConfig(**{**config.__dict__, "repeats": args.repeats})
    command = "phong-explorer bench accuracy" + (" --quick" if args.quick else "")
    table = A.run_bench(config, progress=A.Progress())
    table["command"] = command
    write_atomic(paths["json"], A.table_bytes(table), overwrite=overwrite)
    print(f"wrote {paths['json']}: {len(table['rows'])} rows")
    drawn = A.plot(table, paths["png"], overwrite=overwrite)
    if drawn:
        print(f"wrote {paths['png']}")
    else:
        print(
            "plot skipped: matplotlib is not installed (pip install 'phong-explorer[bench]')",
            file=sys.stderr,
        )
    rel = os.path.relpath(paths["png"], paths["md"].parent) if drawn else None
    text = A.markdown(table, plot=rel, command=command)
    write_atomic(paths["md"], text.encode("utf-8"), overwrite=overwrite)
    print(f"wrote {paths['md']}")
    return 0
