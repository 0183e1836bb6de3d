"""``phong-explorer bench accuracy``: measure what accuracy costs in time.

::

    phong-explorer bench accuracy                      # ./accuracy.md, .png, .json
    phong-explorer bench accuracy --out-dir results/   # results/accuracy.{md,png,json}
    phong-explorer bench accuracy --quick --out-dir /tmp/q

Per-vertex shading of sphere tessellations against the per-pixel reference
(:mod:`explorer.analysis.benchmark`). It writes three files into the current directory, or into
``--out-dir DIR`` (which must exist): ``accuracy.json`` (the measured table),
``accuracy.png`` (the plot) and ``accuracy.md`` (the report, linking the plot). It checks
before measuring that none of them exists, and replaces existing ones only with ``--force``;
the three are written all-or-nothing (if one cannot be written, none of the new files is
left and the old ones stay), so a failed run can be re-run as it was. It never writes
anywhere else: not into the installed package, not into a source checkout it runs from.

The copies published with the project are made by the maintainer in a source checkout::

    phong-explorer bench accuracy --out-dir docs --force
    mv docs/accuracy.json explorer/data/accuracy.json

(``docs/accuracy.md`` and ``docs/accuracy.png``, and the table the package ships, which
:func:`explorer.analysis.advice.mesh_for_error` reads). The plot needs matplotlib
(``pip install 'phong-explorer[bench]'``); without it the plot is skipped with a message.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
from pathlib import Path

from explorer.analysis.benchmark import BenchConfig, run_bench
from explorer.analysis.report import markdown, plot_png, table_bytes
from explorer.core.atomic import write_all_atomic
from explorer.core.errors import ExplorerError
from explorer.core.progress import Progress
from explorer.core.text import say

#: bench -> one-line help
BENCHES = {"accuracy": "per-vertex shading against the per-pixel reference: error and time"}
#: the files a run writes, by kind
OUTPUTS = ("json", "png", "md")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="bench", metavar="BENCH")
    p = sub.add_parser(
        "accuracy",
        help=BENCHES["accuracy"],
        description=BENCHES["accuracy"],
        epilog="Writes accuracy.md, accuracy.png and accuracy.json into the current directory "
        "(or --out-dir DIR) and never replaces an existing file without --force. A progress "
        "bar is shown on a terminal. The plot needs matplotlib (pip install "
        "'phong-explorer[bench]'). To update the project's published copies, in a source "
        "checkout: --out-dir docs --force, then move docs/accuracy.json to "
        "explorer/data/accuracy.json.",
    )
    p.add_argument(
        "--quick",
        action="store_true",
        help="a small run (2 materials, 7 meshes, 96x96, one repeat) for tests",
    )
    p.add_argument(
        "--out-dir",
        metavar="DIR",
        default=".",
        help="write DIR/accuracy.md, .png and .json (default: the current directory)",
    )
    p.add_argument(
        "--repeats", type=int, metavar="N", help="timed runs per median (default 5; quick 1)"
    )
    p.add_argument("--force", action="store_true", help="replace existing files")


def outputs(out_dir, force: bool) -> dict[str, Path]:
    """Where the files go (``json``, ``png``, ``md`` -> path in ``out_dir``); an ExplorerError
    when ``out_dir`` is not a directory or, without ``force``, when one of them exists."""
    d = Path(out_dir)
    if not d.is_dir():
        raise ExplorerError(f"--out-dir {str(out_dir)!r}: not a directory")
    paths = {k: d / f"accuracy.{k}" for k in OUTPUTS}
    if not force:
        for p in paths.values():
            if p.exists():
                raise ExplorerError(f"{p}: already exists; use --force to replace it")
    return paths


def run(args) -> int:
    if getattr(args, "bench", None) != "accuracy":
        raise ExplorerError("which bench? phong-explorer bench accuracy (see --help)")
    return run_accuracy(args)


def run_accuracy(args) -> int:
    paths = outputs(args.out_dir, args.force)
    config = BenchConfig.quick_run() if args.quick else BenchConfig()
    if args.repeats is not None:
        if args.repeats < 1:
            raise ExplorerError(f"--repeats must be at least 1, got {args.repeats}")
        config = dataclasses.replace(config, repeats=args.repeats)
    command = "phong-explorer bench accuracy" + (" --quick" if args.quick else "")
    table = run_bench(config, progress=Progress("accuracy"))
    table["command"] = command
    files = {paths["json"]: table_bytes(table)}
    png = plot_png(table)
    if png is not None:
        files[paths["png"]] = png
    rel = os.path.relpath(paths["png"], paths["md"].parent) if png is not None else None
    files[paths["md"]] = markdown(table, plot=rel, command=command).encode("utf-8")
    # all-or-nothing: a failure leaves none of the new files and the old ones as they were
    write_all_atomic(files, overwrite=args.force)
    say(f"wrote {paths['json']}: {len(table['rows'])} rows")
    if png is not None:
        say(f"wrote {paths['png']}")
    else:
        say(
            "plot skipped: matplotlib is not installed (pip install 'phong-explorer[bench]')",
            file=sys.stderr,
        )
    say(f"wrote {paths['md']}")
    return 0
