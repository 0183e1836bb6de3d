"""The engine's full pass at two git revisions, in alternating processes.

    python benchmarks/bench_revisions.py 5c40425 HEAD            # before / after a change
    python benchmarks/bench_revisions.py HEAD~3 HEAD --rounds 5
    python benchmarks/bench_revisions.py 7552fa3 HEAD --precision float64

Each revision is checked out in a temporary git worktree (its numba cache is its own, so the
first process of each compiles: not timed) and imported from there; a directory that holds an
``explorer`` package is taken as it is instead (a checkout and its numba cache, kept).
Processes alternate A, B, A, B, ... so that this VM's drift from one minute to the next falls
on both alike. Each process times a light change on a ``Shader`` (float32, or ``--precision``;
1M vertices, 8 point lights, Blinn, local viewer: ``bench_engine.py``'s first row) 25 times, on
random points (every vertex-light computed) and on a UV sphere with as many vertices in mesh
order (light culling skips what faces away), then a one-shot ``explorer.shade`` (10 calls), the
geometry preparation of a one-shot call (11: ``bench_engine.py``'s row, the prepared geometry
handed back as the call does) and a viewer change on a kept ``Shader`` (25), all on the random
points, in the same precision; the table gives the best and the median of the per-process
medians, and the ratios. ``--cpu`` runs each process on one numba thread and times the
process's CPU seconds instead of the wall clock: the work each revision does, unaffected by
other processes taking a core (a parallel pass waits for its slowest thread, so on a busy
machine the wall clock mostly measures the others).

Last results (AMD EPYC, 2 cores, AVX-512, numba 0.68.1; medians of per-process medians):

| case | 6fec099 float64 ms | k10 float64 ms | ratio |
|---|---:|---:|---:|
| random points, wall (load 0.5-1.3) | 28.06 | 22.54 | 1.24x |
| UV sphere, mesh order, wall | 14.74 | 13.22 | 1.12x |
| one-shot shade(), wall | 47.91 | 26.71 | 1.79x |
| viewer change, wall | 26.98 | 22.60 | 1.19x |
| random points, ``--cpu`` (one thread) | 45.08 | 42.51 | 1.06x |
| one-shot shade(), ``--cpu`` | 68.79 | 47.33 | 1.45x |

float32 against cb71986, ``--cpu --rounds 3`` (beside a test run: best of the processes 17.04 /
17.38 ms random points, 12.38 / 12.41 ms UV sphere; medians 0.95x and 0.92x).

What bounds the float64 pass (k10): a standalone copy of the inline point-light Blinn loop,
compiled as the kernel is (512-bit, interleave 2), has 215 vector instructions per 16
vertex-lights (the pow64 loop 123, the L / attenuation / diffuse / base loop 92: 13.4 per
vertex-light) and runs about 1.2 of them per cycle, 11 cycles per vertex-light on one thread;
the engine takes 13.8 (the rest is memory: a kept float64 pass moves about 128 MB), and two
threads give 1.6-1.9x one. Tried on that copy and not kept: float32-seeded reciprocal and square
root with Newton steps (291 instructions instead of 215), Estrin polynomials (no gain),
interleave 4 (3% on top of the split loop, more compile time), cheaper pow polynomials (about
2%), compacting the lanes whose pow is 0 (no vector compress from LLVM 20; scalar costs more).

k11 (952533b -> k11, float64, ``--rounds 3``): the lobe loop packs the lanes with a lobe weight
(``vmath.compress8`` / ``expand8``, AVX-512's vcompresspd / vexpandpd, written as LLVM
intrinsics: the vectoriser does not make them) and takes the power of those only; extent on
integer order keys; the shader prepares the compiled geometry at once and its passes test NaN
and inf (no numpy pass). Tried and not kept: the chunk bounds' sample found by prepare with each
block (0.6 ms more than the separate sampled pass, 0.2-0.3 ms).

| case | 952533b ms | k11 ms | ratio |
|---|---:|---:|---:|
| random points, wall (load 1.3-1.7; best 20.22 / 18.44) | 21.27 | 19.93 | 1.07x |
| UV sphere, mesh order, wall | 12.91 | 12.67 | 1.02x |
| one-shot shade(), wall | 24.97 | 21.38 | 1.17x |
| geometry preparation of a one-shot call, wall | 4.12 | 2.16 | 1.91x |
| viewer change, wall | 21.84 | 19.93 | 1.10x |
| random points, ``--cpu`` (load 1.1-1.3) | 40.36 | 36.34 | 1.11x |
| UV sphere, mesh order, ``--cpu`` | 23.82 | 24.92 | 0.96x |
| one-shot shade(), ``--cpu`` | 45.70 | 42.01 | 1.09x |
| geometry preparation, ``--cpu`` | 6.44 | 4.96 | 1.30x |

An earlier wall run of the packing alone (load 1.0-2.0) gave 26.09 -> 21.00 ms on the random
points (1.24x): the VM moves these figures by 10-20% from run to run. float32, ``--cpu --rounds
3`` (load 1.0): random points 17.09 / 17.44 ms (0.98x), UV sphere 12.85 / 12.67 (1.01x), viewer
change 17.39 / 18.17 (0.96x).

``PACK_SHARE`` 3/4 (the helper's) against 1/2 (lead, after the merge; ``--rounds 3``, load
1.2, wall): random points 21.40 / 19.78 ms (1.08x, 0.40 G), UV sphere in mesh order 14.15 /
13.03 (1.09x; 3/4 had made it 0.87x of 952533b's 12.86 in the run before), one-shot 25.09 /
23.52 (1.07x), viewer change 21.25 / 19.31 (1.10x): 1/2 kept.

What the packing saves, on a standalone copy of the float64 loops (one thread, lanes per light
per block; ``loop2`` is the lobe loop): with 40% of the lanes weighted (random points, a light
at ~5 radii) loop2 1.73 -> 1.12-1.15 ns per lane; with every lane weighted the packing would
cost 0.4 ns more (so it is skipped above ``kernels.PACK_SHARE`` weighted); the L / base
loop 1.8-2.2 ns stays. On the engine, one thread, 1M vertices: 3.87 -> 3.29 ms per light (the
slope from 1 to 8 lights), 41.2 -> 36.1 ms for 8. Measured on that copy and not kept: the
square root and division for 1/|L + V| replaced by a float32-seeded reciprocal square root with
one Newton step (loop1 about 5% faster, but a relative error of 3e-14 in the base, which n up to
128 makes 4e-12 in the lobe: above the 1e-12 the float64 tests hold), a float32 division seeding
pow's (m - 1)/(m + 1) (slower), 8 fewer polynomial terms in pow (loop2 -27%, far looser than the
stated bound).

k12 (632f8d3 -> k12: one-shot calls prepare and shade in slabs, ``prepared.SLAB``; the kernels
unchanged), ``--precision float64``, wall:

| case | run 1 (``--rounds 3``, load 0.9-1.2, VM slow) | run 2 (``--rounds 4``, load 1.3) |
|---|---:|---:|
| random points | 25.34 / 25.09 ms (1.01x) | 20.75 / 19.51 (1.06x: noise, same kernels) |
| one-shot shade() | 28.85 / 26.97 (1.07x) | 23.26 / 22.61 (1.03x) |
| geometry preparation of a one-shot call | 4.63 / 3.45 (1.34x) | 2.99 / 2.87 (1.04x) |

(run 1 with 128k slabs, run 2 with 256k.) Tried and not kept: each task prefetching the next
block's rows of G, sums and colours (``llvm.prefetch``): 0.99x on the full float64 pass
(``--rounds 4``, idle), though the pass's fixed part is bound by reading G (with no light, 3.8 ms
in float64 against 1.7 ms in float32, whose G is half as large).

k13 (97356cc -> k13, ``--precision float64 --rounds 3``, wall, load 1.6-2.1): the float64 light
loops keep base² in the base row, raised to n/2, and the inline point-light loop finds Blinn's
base² as (N·u)²/|u|² with u = l + |l|·V (one square root and two divisions per vertex-light
where there were two of each; ``kernels.lobe_power``); the scratch rows lie
``kernels.ROW = BLOCK + 16`` apart.

| case | 97356cc ms | k13 ms | ratio |
|---|---:|---:|---:|
| random points (best 17.66 / 16.42) | 18.94 | 16.90 | 1.12x |
| UV sphere, mesh order | 12.54 | 11.79 | 1.06x |
| one-shot shade() | 20.89 | 18.61 | 1.12x |
| viewer change | 18.97 | 16.93 | 1.12x |

The row stride alone (k13's square change alone, on 97356cc, -> k13; ``--precision float64 --cpu``,
beside a test run, load 2.6): random points 37.28 / 33.40 ms (1.12x; best 32.60 / 31.90), UV sphere
24.67 / 23.06 (1.07x); again (k13 with the stride reverted -> k13, idle, load 0.6-1.0): 37.58 /
34.06 (1.10x; best 33.65 / 32.73), UV sphere 24.82 / 23.27 (1.07x). In wall time, the stride before
the square change (97356cc -> the stride alone, load 1.0-1.5) gave 18.47 / 19.85 ms (0.93x; best
17.91 / 17.93): within this VM's drift. On a standalone copy of the loops (one thread, one block in
cache, ns per vertex-light): at a 512-lane stride the L / base loop took 1.9-2.8 ns from one process
to the next, at 528 1.9-2.3; the divisions and square roots there are worth 0.8 ns (1.1 with
multiplies in their place), and this square form takes 1.6 (an integer-seeded reciprocal square root
with four Newton steps took 2.7, a float32-seeded one with two 2.3: not kept).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent

#: run in a child process with the revision's package first on sys.path
CHILD = r"""
import statistics, sys, time
sys.path.insert(0, {bench!r})
import numpy as np
from bench_engine import scene_with, sphere_points
from common import uv_sphere
import explorer
assert explorer.__file__.startswith({root!r}), explorer.__file__
if {cpu!r}:  # one thread, timed by the process's CPU time: other processes' load falls out
    import numba
    numba.set_num_threads(1)
    time.perf_counter = time.process_time
P, N = sphere_points({n}, np.random.default_rng(0))
around = max(8, int(round(np.sqrt({n}))))
Pm = uv_sphere(around, max(2, {n} // around - 1)).positions.astype(np.float32)
scene = scene_with(8, np.random.default_rng(0))
for P_, N_ in ((P, N), (Pm, Pm)):
    flip = [scene.lights, scene_with(8, np.random.default_rng(1)).lights]
    sh = explorer.Shader(scene, P_, N_, precision={precision!r})
    def relight():
        flip.reverse()
        sh.set_lights(flip[0])
        return sh.colors
    relight(); relight()  # compile (or load from the cache), warm up
    ts = []
    for _ in range(25):
        t = time.perf_counter(); relight(); ts.append(time.perf_counter() - t)
    print(min(ts) * 1e3, statistics.median(ts) * 1e3)
    del sh, relight
ts = []  # one-shot shade(): geometry preparation and one pass that keeps no sums
for _ in range(11):
    t = time.perf_counter(); explorer.shade(scene, P, N, precision={precision!r})
    ts.append(time.perf_counter() - t)
print(min(ts[1:]) * 1e3, statistics.median(ts[1:]) * 1e3)
ts = []  # what a one-shot call does before its pass (bench_engine's geometry row; older
for _ in range(12 if hasattr(explorer.Shader, "_compiled_geometry") else 0):  # revisions
    t = time.perf_counter()  # prepared the geometry here too: slab by slab, or whole)
    sh = explorer.Shader(scene, P, N, precision={precision!r}, keep=False)
    sh._compiled_geometry()
    if hasattr(sh, "_one_shot"):
        from explorer.shading import prepared
        import inspect  # (a Source per precision since w38: vertices takes the dtype)
        more = [sh._k.dtype] if "dtype" in inspect.signature(prepared.vertices).parameters else []
        src = prepared.vertices(sh._P, sh._N, sh._centre, sh._scale, *more)
        prepared.chunk_bounds(src, sh._k)
    for _ in getattr(sh, "_slabs", lambda: ())():
        pass
    ts.append(time.perf_counter() - t)
print(min(ts[1:]) * 1e3 if ts else "nan", statistics.median(ts[1:]) * 1e3 if ts else "nan")
sh = explorer.Shader(scene, P, N, precision={precision!r})
sh.colors
from bench_engine import Viewer  # (the revision's own Viewer class)
eyes = [Viewer(eye=(0.0, 0.0, 5.0)), Viewer(eye=(1.0, 2.0, 5.0))]
ts = []  # a viewer change: the specular sum alone is recomputed
for _ in range(26):
    eyes.reverse(); t = time.perf_counter(); sh.set_viewer(eyes[0]); sh.colors
    ts.append(time.perf_counter() - t)
print(min(ts[1:]) * 1e3, statistics.median(ts[1:]) * 1e3)
"""

CASES = (
    "random points (every vertex-light)",
    "UV sphere, mesh order (light culling)",
    "one-shot shade(), random points (incl. geometry)",
    "geometry preparation of a one-shot call",
    "viewer change, random points (specular only)",
)
#: cases that shade no vertex-light (no rate)
NO_RATE = {"geometry preparation of a one-shot call"}


def run(root: Path, n: int, precision: str = "float32", cpu=False) -> list[tuple[float, float]]:
    env = dict(os.environ, PYTHONPATH=str(root))
    # the revision's own bench_engine helpers: they build scenes with that revision's classes
    own = Path(root) / "benchmarks"
    code = CHILD.format(
        bench=str(own if (own / "bench_engine.py").exists() else HERE),
        root=str(root),
        n=n,
        precision=precision,
        cpu=cpu,
    )
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=root, env=env, capture_output=True, text=True
    )
    if out.returncode != 0:
        sys.exit(f"{root}: the benchmark failed:\n{out.stderr[-3000:]}")
    values = list(map(float, out.stdout.split()))
    return [(values[i], values[i + 1]) for i in range(0, len(values), 2)]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a", help="a git revision (the baseline), or a checkout's directory")
    ap.add_argument("b", help="another git revision, or a checkout's directory")
    ap.add_argument("--rounds", type=int, default=3, help="processes per revision")
    ap.add_argument("--vertices", type=int, default=1_000_000)
    ap.add_argument("--precision", choices=("float32", "float64"), default="float32")
    ap.add_argument(
        "--cpu",
        action="store_true",
        help="one numba thread, CPU seconds of the process: the work, whatever else runs",
    )
    args = ap.parse_args(argv)
    repo = subprocess.run(
        ["git", "rev-parse", "--show-toplevel"], cwd=HERE, capture_output=True, text=True
    ).stdout.strip()
    with tempfile.TemporaryDirectory() as tmp:
        roots = {}
        for rev in (args.a, args.b):
            if Path(rev, "explorer").is_dir():  # a checkout as it is, with its own numba cache
                roots[rev] = Path(rev).resolve()
                continue
            root = Path(tmp) / f"rev{len(roots)}"
            subprocess.run(
                ["git", "-C", repo, "worktree", "add", "--detach", "-f", str(root), rev],
                check=True,
                capture_output=True,
            )
            roots[rev] = root
        try:
            for root in roots.values():
                run(root, 1000, args.precision)  # compile each revision's kernels, untimed
            res: dict[str, list] = {rev: [] for rev in roots}
            for _ in range(args.rounds):
                for rev, root in roots.items():
                    res[rev].append(run(root, args.vertices, args.precision, args.cpu))
        finally:
            for root in roots.values():
                if not root.is_relative_to(tmp):  # (a checkout given as a directory: kept)
                    continue
                subprocess.run(
                    ["git", "-C", repo, "worktree", "remove", "--force", str(root)],
                    capture_output=True,
                )
    sys.path[:0] = [str(HERE.parent), str(HERE)]  # this tree's package, then the benchmarks
    from bench_engine import machine

    print(f"machine: {machine()}")
    clock = "CPU time of one thread" if args.cpu else "wall time, all threads"
    print(
        f"full {args.precision} pass, {args.vertices} vertices x 8 point lights; {args.rounds} "
        f"alternating processes per revision, 25 light changes each; {clock}\n"
    )
    print("| case | revision | best ms | median of medians ms | G vertex-lights/s (median) |")
    print("|---|---|---:|---:|---:|")
    ratios = []
    for c, case in enumerate(CASES):
        med = {}
        for rev, rows in res.items():
            best = min(r[c][0] for r in rows)
            med[rev] = statistics.median(r[c][1] for r in rows)
            rate = "" if case in NO_RATE else f"{args.vertices * 8 / med[rev] / 1e6:.2f}"
            print(f"| {case} | {rev} | {best:.2f} | {med[rev]:.2f} | {rate} |")
        ratios.append(f"{case}: {args.a} / {args.b} (median) {med[args.a] / med[args.b]:.2f}x")
    print("\n" + "\n".join(ratios))
    return 0


if __name__ == "__main__":
    sys.exit(main())
