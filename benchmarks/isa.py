"""``--isa native|avx2|both``: a benchmark measured for an instruction set, in child processes.

numba compiles for the CPU it runs on (its "host"); ``NUMBA_CPU_NAME`` and
``NUMBA_CPU_FEATURES`` make it compile for another one. ``avx2`` sets :data:`AVX2`, a Zen 3
(AVX2 + FMA, 256-bit vectors, no AVX-512), so that on an AVX-512 host the benchmark times AVX2
code as a laptop, a desktop or a Zen 3 cloud machine runs it (the same instructions, on this
host's cores and memory: compare ISAs in one run on one machine). ``native`` is the host's own
target, whatever the calling environment said.

The parent (:func:`run`) starts the same script with the same arguments once per ISA and per
round (``--alternate N``: N processes per ISA, taking turns, so that a VM's drift from one
minute to the next falls on both alike), each child with its ISA's environment and
:data:`CHILD` set (the child then measures in its own process, as without ``--isa``), and
prints each child's output as it comes. The avx2 children compile into their own numba cache, a
persistent folder (``--cache-dir``, default :func:`default_cache`): the first run compiles
every kernel for AVX2 (minutes of CPU), later runs load them. With two ISAs or more than one
round the parent ends with the figures each child recorded (:func:`record`), side by side: the
median over the processes of each ISA, and AVX2's ratio to native.

A child's machine line names its ISA (:func:`isa_line`): what numba targets (CPU name and
feature string) and which registers a float32 loop compiled as the kernels are compiled
(``explorer.shading.codegen.wide``) uses: ``zmm`` (512 bits) or ``ymm`` (256 bits), and how the
float64 lobe packs its lanes (``explorer.shading.vmath.PACK``).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: the environment of ``--isa avx2``: numba compiles for AMD Zen 3 (AVX2, FMA; no AVX-512),
#: AVX-512F switched off as well (a feature string is added to the CPU's own)
AVX2 = {"NUMBA_CPU_NAME": "znver3", "NUMBA_CPU_FEATURES": "-avx512f"}
ISAS = {"native": {}, "avx2": AVX2}
CHOICES = ("native", "avx2", "both")
#: set in a child process: its ISA (the child measures in its own process)
CHILD = "PHONG_EXPLORER_BENCH_ISA"
#: set in a child process: the file it writes its recorded figures to (JSON)
RESULTS = "PHONG_EXPLORER_BENCH_RESULTS"

_figures: list[list] = []


def add_arguments(ap: argparse.ArgumentParser) -> None:
    """The ``--isa``, ``--cache-dir`` and ``--alternate`` options."""
    ap.add_argument(
        "--isa",
        choices=CHOICES,
        help="measure in child processes compiled for this ISA: native (the host's), avx2 "
        "(Zen 3: NUMBA_CPU_NAME=znver3 NUMBA_CPU_FEATURES=-avx512f) or both",
    )
    ap.add_argument(
        "--cache-dir",
        type=Path,
        help=f"numba's cache for the avx2 build (default {default_cache()}; kept between runs)",
    )
    ap.add_argument(
        "--alternate",
        type=int,
        default=1,
        metavar="ROUNDS",
        help="with --isa: this many processes per ISA, taking turns (default 1)",
    )


def default_cache() -> Path:
    """Where the avx2 children keep numba's cache: ``$XDG_CACHE_HOME`` (else ``~/.cache``)
    ``/phong-explorer/bench-numba-avx2``."""
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "phong-explorer" / "bench-numba-avx2"


def in_child() -> bool:
    """Whether this process is a child of :func:`run` (it measures; it starts no children)."""
    return bool(os.environ.get(CHILD))


def isas(choice: str) -> tuple[str, ...]:
    """The ISAs of a ``--isa`` choice, in the order their children run."""
    return ("native", "avx2") if choice == "both" else (choice,)


def child_env(isa: str, cache_dir: Path | None, results: str) -> dict[str, str]:
    """The environment of ``isa``'s child: the caller's, less any target it set, plus the ISA's
    (:data:`ISAS`), its own numba cache for a foreign target, :data:`CHILD`, :data:`RESULTS`,
    and this tree first on ``PYTHONPATH``."""
    env = dict(os.environ)
    for key in AVX2:
        env.pop(key, None)
    env.update(ISAS[isa])
    if ISAS[isa]:
        env["NUMBA_CACHE_DIR"] = str(cache_dir or default_cache())
    env[CHILD] = isa
    env[RESULTS] = results
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH")) if p)
    return env


def host_has(feature: str) -> bool:
    import llvmlite.binding as llvm

    try:
        return bool(llvm.get_host_cpu_features().get(feature, False))
    except RuntimeError:  # llvmlite cannot read this host's features
        return False


def run(script: str, argv: list[str], args: argparse.Namespace) -> int:
    """Run ``script`` with ``argv`` in a child per ISA of ``args.isa`` and round of
    ``args.alternate``, print their output, then (two ISAs or several rounds) the side-by-side
    figures. Returns the exit status."""
    order = isas(args.isa)
    if "avx2" in order and not (host_has("avx2") and host_has("fma")):
        print("error: --isa avx2: this CPU has no AVX2 and FMA to run its code", file=sys.stderr)
        return 2
    if args.alternate < 1:
        print("error: --alternate: at least 1 process per ISA", file=sys.stderr)
        return 2
    figures: dict[str, list[list]] = {isa: [] for isa in order}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.alternate):
            for isa in order:
                results = os.path.join(tmp, f"{isa}-{r}.json")
                print(f"\n### ISA {isa}, process {r + 1} of {args.alternate}\n", flush=True)
                env = child_env(isa, args.cache_dir, results)
                code = subprocess.run([sys.executable, script, *argv], env=env).returncode
                if code:
                    print(f"error: the {isa} child exited with status {code}", file=sys.stderr)
                    return code
                if os.path.exists(results):  # (a mode that records nothing writes nothing)
                    with open(results, encoding="utf-8") as f:
                        figures[isa].append(json.load(f))
    if len(order) > 1 or args.alternate > 1:
        print("\n" + side_by_side(figures))
    return 0


def record(case: str, value: float, unit: str = "ms") -> None:
    """Keep a figure for the parent's side-by-side table (``unit``: a rate such as "M rays/s",
    larger is faster; "x", a ratio; "", no speed (the load); any other, a time such as "ms",
    smaller is faster)."""
    _figures.append([case, float(value), unit])


def write_results() -> None:
    """Write the recorded figures to the parent's file (in a child; else nothing)."""
    path = os.environ.get(RESULTS)
    if path:
        with open(path, "w", encoding="utf-8") as f:
            json.dump(_figures, f)


def side_by_side(figures: dict[str, list[list]]) -> str:
    """A table of each recorded case: per ISA the median over its processes, and (avx2 beside
    native) AVX2's time over native's (> 1: AVX2 is slower; a rate: native's over AVX2's; a
    ratio such as "recolour / floor": AVX2's over native's)."""
    order = list(figures)
    runs = {isa: len(v) for isa, v in figures.items()}
    cases: dict[str, str] = {}
    values: dict[tuple[str, str], list[float]] = {}
    for isa, processes in figures.items():
        for fig in processes:
            for case, value, unit in fig:
                cases.setdefault(case, unit)
                values.setdefault((case, isa), []).append(value)
    both = "native" in figures and "avx2" in figures
    head = " | ".join(f"{isa} ({runs[isa]} processes)" for isa in order)
    lines = [f"| case | unit | {head} |" + (" avx2 / native (time) |" if both else "")]
    lines.append("|---|---|" + "---:|" * (len(order) + both))
    for case, unit in cases.items():
        med = {isa: statistics.median(values.get((case, isa), [float("nan")])) for isa in order}
        cells = " | ".join(f"{med[isa]:.4g}" for isa in order)
        line = f"| {case} | {unit} | {cells} |"
        if both:
            a, n = med["avx2"], med["native"]
            if unit.endswith("/s"):  # a rate: larger is faster
                line += f" {n / a:.2f}x |" if a else " |"
            elif unit == "x":
                line += f" {a / n:.2f}x |" if n else " |"
            elif not unit:  # (a figure that is no speed: the load)
                line += " |"
            else:  # a time (ms, ns per ray): smaller is faster
                line += f" {a / n:.2f}x |" if n else " |"
        lines.append(line)
    return "\n".join(lines)


def registers(asm: str) -> dict[str, int]:
    """How often the assembly ``asm`` names 512-bit (zmm), 256-bit (ymm) and 128-bit (xmm)
    vector registers."""
    return {w: len(re.findall(rf"%{w}\d+", asm)) for w in ("zmm", "ymm", "xmm")}


def widest(asm: str) -> str:
    """The widest vector registers ``asm`` uses: "zmm (512-bit)", "ymm (256-bit)", "xmm
    (128-bit)" or "no vector registers"."""
    regs = registers(asm)
    for w, bits in (("zmm", 512), ("ymm", 256), ("xmm", 128)):
        if regs[w]:
            return f"{w} ({bits}-bit)"
    return "no vector registers"


def probe_asm() -> str:
    """The assembly of a float32 streaming loop (``kernels._add``, the bandwidth floor's)
    compiled now as the kernels are (their options, their vector width: ``codegen.wide``),
    not loaded from a cache (numba cannot show cached code)."""
    import numba as nb
    import numpy as np

    from explorer.shading import codegen
    from explorer.shading import kernels as K

    fn = nb.njit(fastmath=K._FASTMATH, error_model="numpy", boundscheck=False)(K._add.py_func)
    a = np.zeros(64, np.float32)
    with codegen.wide_vectors():
        fn(a, a, a)
    return fn.inspect_asm(fn.signatures[0])


def isa_line() -> str:
    """The ISA this process measures: its name (``--isa``, or "in process"), what numba
    targets, the vector registers its kernels' code uses, and whether the float64 lobe packs."""
    import llvmlite.binding as llvm
    from numba.core import config

    from explorer.shading import kernels as K
    from explorer.shading import vmath

    isa = os.environ.get(CHILD) or "in process (no --isa)"
    cpu = config.CPU_NAME or llvm.get_host_cpu_name()
    feats = "host features" if config.CPU_FEATURES is None else f"features {config.CPU_FEATURES}"
    pack = {"compress": "AVX-512 compress", "permute": "AVX2 permute"}.get(vmath.PACK, "no packing")
    return (
        f"ISA {isa}: numba targets {cpu} ({feats}); kernel code in {widest(probe_asm())} "
        f"registers; float64 lobe: {pack} (PACK_SHARE {K.PACK_SHARE})"
    )
