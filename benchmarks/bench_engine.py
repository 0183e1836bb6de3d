"""Engine benchmark: throughput of full shading and the cost of each interactive update.

    python benchmarks/bench_engine.py                # 1M vertices, 8 point lights
    python benchmarks/bench_engine.py --vertices 200000 --lights 4 --repeat 15
    python benchmarks/bench_engine.py --flows        # the one-shot pass against slabs
    python benchmarks/bench_engine.py --geometry     # the geometry rows and the floor alone
    python benchmarks/bench_engine.py --isa both --alternate 3 --cpu   # AVX2 beside AVX-512

The full-shading rows run on random points (every vertex-light computed: the kernel's raw
rate; float32 vertices, and in float64 also float64 ones: the pass reads the same prepared
copy of either) and on a UV sphere mesh with as many vertices, in mesh order and shuffled: the
engine skips a light for runs of vertices that all face away from it (light culling), which
only a mesh whose vertex order keeps neighbours together allows.

Prints the machine, then one row per case: median and best wall time over ``--repeat`` runs (the
first, compiling run is excluded), vertex-lights per second, and ratios. The memory-bandwidth
floor of a recolour (read positions and normals once, write colours once) is measured in the
same run, on the same arrays, so "recolour / floor" is a like-for-like ratio. "geometry
preparation" is what a one-shot ``shade()`` does before its pass (:func:`one_shot_geometry`:
check the vertices, find the frame and its extent, the plan, and the chunk bounds light
culling would use); its pass then prepares each block of vertices as it shades it (a
``kernels.Source`` of vertices), so that share is inside the one-shot rows, and the row "one-shot -
full shading" gives what a one-shot call costs beyond a kept shader's pass over the same
lights. "a kept shader's" geometry is what new vertices cost a kept ``Shader``
(:func:`kept_geometry`: the frame, the prepared copy G and the chunk bounds), G in the memory
the shader keeps from one geometry to the next, and beside it in new memory (as before the
shader kept any: page faults at a million float64 vertices). The geometry rows and the floor
are timed in turns, call after call, so the ratio between them sees the same machine (the floor
moves by 2x between runs, with what of the arrays the cache still holds); ``--geometry`` times
those alone.

The float64 full-shading row (the issue's target: 0.4 G vertex-lights/s, <= 20 ms), four runs
of this script at 97356cc and at k13 (the float64 lobe from base², see
``benchmarks/bench_revisions.py``) taking turns, load 1.0-1.3 (medians, ms):

| run | 97356cc float64 | k13 float64 | 97356cc one-shot float64 | k13 one-shot float64 |
|---:|---:|---:|---:|---:|
| 1 | 20.63 | 17.14 | 23.37 | 21.52 |
| 2 | 19.36 | 19.88 | 21.89 | 18.59 |
| 3 | 19.50 | 17.04 | 22.04 | 18.94 |
| 4 | 20.61 | 16.97 | 23.73 | 18.15 |

(float32 row in the same runs: 11.21 / 10.43, 10.14 / 10.97, 9.54 / 9.56, 8.70 / 8.87.)

Timings are wall-clock and vary with machine load: the load average is printed with the table.
``--cpu`` runs on one numba thread and times the process's CPU seconds instead (the work,
whatever else the machine runs; ``benchmarks/bench_revisions.py --cpu`` does the same).

``--isa native|avx2|both`` measures in child processes compiled for the host's ISA, for AVX2
(a Zen 3 target on any x86-64 host with AVX2, its numba cache kept in ``--cache-dir``) or for
both, ``--alternate N`` processes each taking turns, and ends with the figures side by side
(``benchmarks/isa.py``); the machine line names the ISA each child measured and what numba
compiled for it.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time

import common  # benchmarks/common.py
import isa  # benchmarks/isa.py
import numba
import numpy as np
from common import cpu_name, load_average, timed, uv_sphere

import explorer
from explorer.core.lights import PointLight, SpotLight
from explorer.core.material import Material
from explorer.core.scene import Scene, Viewer
from explorer.shading import codegen, prepared
from explorer.shading import kernels as K
from explorer.shading.equation import equation_shade


def width() -> str:
    """The vector width the kernels are compiled with (``codegen.VECTOR_BITS``)."""
    bits = codegen.VECTOR_BITS
    if not bits:
        return "LLVM default width"
    return f"{codegen.lanes(4)} float32 / {codegen.lanes(8)} float64 lanes ({bits} bits)"


def machine() -> str:
    return (
        f"{cpu_name()}; {os.cpu_count()} cores, numba threads {numba.get_num_threads()}; "
        f"Python {platform.python_version()}, numpy {np.__version__}, numba {numba.__version__}; "
        f"vectors: {width()}; {isa.isa_line()}; "
        f"load average {load_average():.2f}"
    )


def sphere_points(n: int, rng) -> tuple[np.ndarray, np.ndarray]:
    N = rng.normal(size=(n, 3))
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    return N.astype(np.float32), N.astype(np.float32)


def scene_with(lights: int, rng) -> Scene:
    return Scene(
        material=Material(
            ambient=(0.2, 0.1, 0.05),
            diffuse=(0.7, 0.4, 0.2),
            specular=(0.4, 0.3, 0.2),
            shininess=25.6,
        ),
        viewer=Viewer(eye=(0.0, 0.0, 5.0)),
        lights=tuple(
            PointLight(position=tuple(rng.normal(size=3) * 3), attenuation=(1.0, 0.1, 0.01))
            for _ in range(lights)
        ),
    )


def spot_lights(lights: int, rng) -> tuple:
    """Spot lights around the mesh, each aimed at the centre (cone 40°, exponent 8)."""
    out = []
    for _ in range(lights):
        p = rng.normal(size=3) * 3
        out.append(
            SpotLight(
                position=tuple(p),
                aim=tuple(-p / np.linalg.norm(p)),
                cutoff=40.0,
                exponent=8.0,
                attenuation=(1.0, 0.1, 0.01),
            )
        )
    return tuple(out)


def one_shot_geometry(scene, P, N, precision: str) -> None:
    """What a one-shot ``shade()`` does before its pass: the shader's checks, the frame (one
    compiled pass over the positions, their finiteness test too), the plan, and the chunk bounds
    for light culling (a sample first; every chunk when the sample says culling pays)."""
    sh = explorer.Shader(scene, P, N, precision=precision, keep=False)
    sh._compiled_geometry()  # (the frame: found by the constructor when kernels serve)
    src = prepared.vertices(sh._P, sh._N, sh._centre, sh._scale, sh._k.dtype)
    prepared.chunk_bounds(src, sh._k)


#: the memory of :func:`kept_geometry`'s rows, per precision (as a kept shader keeps its own)
_ROWS: dict = {}


def kept_geometry(P, N, precision: str, memory: bool = True) -> None:
    """What a kept ``Shader`` does to new vertices (:func:`prepared.prepared_geometry`): the
    frame, the prepared copy G (``kernels.prepare``) and the chunk bounds; G in the memory the
    shader keeps from one geometry to the next (:class:`prepared.RowMemory`), or (``memory``
    False) new memory, as before it kept any: fresh pages from the kernel when G is larger
    than glibc's 32 MB threshold (float64 from 700k vertices, float32 from 1.4M)."""
    rows = _ROWS.setdefault(precision, prepared.RowMemory()) if memory else None
    dtype = np.dtype(precision)
    prepared.prepared_geometry(P, N, dtype, K.constants(dtype), memory=rows)


def geometry_turns(scene, P, N, R: int) -> dict:
    """(median, best) seconds of the geometry rows and the bandwidth floor's two loops, timed in
    turns (:func:`in_turns`): "stream" and "add" (the floor), "float32" and "float64" (a one-shot
    call's, :func:`one_shot_geometry`), "kept ..." and "new ..." (:func:`kept_geometry` in
    kept and in new memory)."""
    out = np.empty((len(P), 3), np.float32)
    return in_turns(
        {
            "stream": lambda: K.stream(P, N, out),
            "add": lambda: np.add(P, N, out=out),
            "float32": lambda: one_shot_geometry(scene, P, N, "float32"),
            "float64": lambda: one_shot_geometry(scene, P, N, "float64"),
            "kept float32": lambda: kept_geometry(P, N, "float32"),
            "kept float64": lambda: kept_geometry(P, N, "float64"),
            "new float32": lambda: kept_geometry(P, N, "float32", memory=False),
            "new float64": lambda: kept_geometry(P, N, "float64", memory=False),
        },
        R,
    )


def geometry_only(scene, P, N, R: int) -> int:
    """``--geometry``: the geometry rows alone (:func:`geometry_turns`), each with its ratio to
    the bandwidth floor of the same run."""
    turns = geometry_turns(scene, P, N, R)
    floor = min(turns["stream"], turns["add"])
    names = {
        "float32": "geometry preparation float32 (of a one-shot call)",
        "float64": "geometry preparation float64 (of a one-shot call)",
        "kept float32": "kept shader's geometry float32",
        "kept float64": "kept shader's geometry float64",
        "new float32": "kept shader's geometry float32, G in new memory",
        "new float64": "kept shader's geometry float64, G in new memory",
    }
    print("| case | median ms | best ms | median / floor's median |")
    print("|---|---:|---:|---:|")
    print(f"| bandwidth floor | {floor[0] * 1e3:.2f} | {floor[1] * 1e3:.2f} | 1.00x |")
    isa.record("bandwidth floor", floor[0] * 1e3)
    for key, name in names.items():
        med, best = turns[key]
        print(f"| {name} | {med * 1e3:.2f} | {best * 1e3:.2f} | {med / floor[0]:.2f}x |")
        isa.record(name, med * 1e3)
        isa.record(f"{name} / bandwidth floor", med / floor[0], "x")
    isa.record("load average at the end", load_average(), "")
    isa.write_results()
    return 0


def one_shot_flows(scene, P, N, R: int) -> int:
    """``--flows``: a one-shot pass as the engine runs it (the kernel prepares each block of
    the vertices as it shades it, a ``kernels.Source``) against the flow it replaced (slabs of
    256k vertices prepared into a reused buffer, each then shaded), the same kernels and
    arguments in one process, in turns; both give the same colours (checked). Prints wall-clock
    medians with every thread and CPU medians with one."""
    import numba

    for precision in ("float64", "float32"):
        flows = _flows(scene, P, N, precision)
        for threads in (numba.config.NUMBA_NUM_THREADS, 1):
            numba.set_num_threads(threads)
            clock = time.perf_counter if threads > 1 else time.process_time
            ts = in_turns(flows, R, clock)
            v, sl = (ts[x][0] * 1e3 for x in ("vertices", "slabs"))
            what = f"wall, {threads} threads" if threads > 1 else "CPU, 1 thread"
            print(f"{precision} one-shot pass ({what}): vertices {v:.2f} ms, slabs {sl:.2f} ms")
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    return 0


def _flows(scene, P, N, precision: str) -> dict:
    """The two one-shot flows of :func:`one_shot_flows` for ``precision``, as functions."""
    slab, seen, real = 256 * 1024, {}, K.shade

    def spy(*args):
        seen["args"] = args
        return real(*args)

    K.shade = spy
    try:
        _ = explorer.Shader(scene, P, N, precision=precision, keep=False).colors
    finally:
        K.shade = real
    src, lights, opts, surface, k, sums, lobes, vis, marks, out, culling = seen["args"]
    n = len(P)
    bufs = {size: np.empty((6, size), precision) for size in (slab, n % slab)}
    inputs = (lights, opts, surface, k, sums, lobes, vis)

    def vertices():
        b = prepared.chunk_bounds(src, k)
        real(src, *inputs, marks, out, K.Culling(b, culling.culled))

    def slabs():
        for s in range(0, n, slab):
            e = min(n, s + slab)
            G = bufs[e - s]
            P_, N_ = (src.P, src.N) if len(src.P) else (src.P32, src.N32)
            K.prepare(P_[s:e], N_[s:e], src.centre, src.inv_scale, k, G)
            b = prepared.chunk_bounds(prepared.rows(G), k)
            b0, b1 = s // K.BLOCK, -(-e // K.BLOCK)
            m = K.Marks(marks.redo[s:e] if len(marks.redo) else marks.redo, marks.count[b0:b1])
            real(prepared.rows(G), *inputs, m, out[s:e], K.Culling(b, culling.culled[b0:b1]))

    vertices()
    first = out.copy()
    slabs()
    assert np.array_equal(first, out), "the two flows' colours differ"
    return {"vertices": vertices, "slabs": slabs}


def in_turns(fns: dict, R: int, clock=None) -> dict:
    """(median, best) seconds of each of ``fns`` (name -> function) by ``clock`` (default
    :data:`common.clock`), timed in turns: one call of each per round, ``R`` rounds after a
    warm-up round."""
    clock = clock or common.clock
    for fn in fns.values():
        fn()
    ts: dict = {name: [] for name in fns}
    for _ in range(R):
        for name, fn in fns.items():
            t = clock()
            fn()
            ts[name].append(clock() - t)
    return {name: (statistics.median(v), min(v)) for name, v in ts.items()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--vertices", type=int, default=1_000_000)
    ap.add_argument("--lights", type=int, default=8)
    ap.add_argument("--repeat", type=int, default=11)
    ap.add_argument(
        "--flows",
        action="store_true",
        help="only the one-shot pass over the vertices against slabs prepared first",
    )
    ap.add_argument(
        "--geometry",
        action="store_true",
        help="only the geometry preparation rows and the bandwidth floor, timed in turns",
    )
    ap.add_argument(
        "--cpu",
        action="store_true",
        help="one numba thread, timed by the process's CPU seconds (not the wall clock)",
    )
    isa.add_arguments(ap)
    args = ap.parse_args(argv)
    if args.isa and not isa.in_child():
        return isa.run(__file__, sys.argv[1:] if argv is None else list(argv), args)
    if args.cpu:  # the work of one thread, whatever else the machine runs
        numba.set_num_threads(1)
        common.clock = time.process_time
    n, L, R = args.vertices, args.lights, args.repeat
    rng = np.random.default_rng(0)
    P, N = sphere_points(n, rng)  # float32, as GPU-bound meshes (glTF, PLY) mostly come
    scene = scene_with(L, rng)
    if args.flows:
        print(f"machine: {machine()}\nmesh: {n} vertices, {L} point lights; medians of {R}")
        return one_shot_flows(scene, P, N, R)
    if args.geometry:
        clock = "CPU seconds of one numba thread" if args.cpu else "wall clock"
        print(f"machine: {machine()}\nmesh: {n} vertices, {L} point lights; {R} turns; {clock}")
        return geometry_only(scene, P, N, R)
    other = scene_with(L, np.random.default_rng(1)).lights

    rows = []
    full = {}  # (median, best) full shading per precision (float32 vertices)

    def row(name, med, best, work=None, note=""):
        rate = f"{work / med / 1e9:.2f}" if work else ""
        rows.append((name, med * 1e3, best * 1e3, rate, note))

    # full shading after a light change (geometry prepared once, as in the explorer), of float32
    # vertices and of float64 ones (the pass reads the same prepared copy G of either)
    P64, N64 = P.astype(np.float64), N.astype(np.float64)
    for precision, vertices in (
        ("float32", "float32"),
        ("float64", "float32"),
        ("float64", "float64"),
    ):
        sh = explorer.Shader(
            scene, *((P, N) if vertices == "float32" else (P64, N64)), precision=precision
        )
        flip = [scene.lights, other]

        def relight(sh=sh, flip=flip):
            flip.reverse()
            sh.set_lights(flip[0])
            return sh.colors

        med, best = timed(relight, R)
        given = "" if vertices == "float32" else ", float64 vertices"
        row(
            f"full shading, {precision}{given} ({L} point lights, Blinn, local viewer)",
            med,
            best,
            n * L,
            "light change: every term recomputed",
        )
        full.setdefault(precision, (med, best))
        del sh, relight

    # the same lights on a mesh: a UV sphere with as many vertices, in the order it was made
    # (ring after ring), and the same vertices shuffled. In mesh order neighbours sit
    # together, and a run of 32 that all face away from a light skips it (light culling);
    # shuffled, no run has a narrow cone of normals, so nothing is culled and every
    # vertex-light is computed
    around = max(8, int(round(np.sqrt(n))))
    mesh = uv_sphere(around, max(2, n // around - 1))
    Pm = mesh.positions.astype(np.float32)
    order = np.random.default_rng(2).permutation(len(Pm))
    m = len(Pm)
    culled = {}
    for label, P_ in (("mesh order", Pm), ("shuffled", Pm[order])):
        sh = explorer.Shader(scene, P_, P_, precision="float32")
        flip = [scene.lights, other]

        def relight(sh=sh, flip=flip):
            flip.reverse()
            sh.set_lights(flip[0])
            return sh.colors

        before = sh.stats["culled"], sh.stats["pass"]
        med, best = timed(relight, R)
        done = sh.stats["pass"] - before[1]
        culled[label] = (sh.stats["culled"] - before[0]) / max(done, 1) / (m * L)
        row(
            f"full shading, float32, {m:,}-vertex UV sphere, {label} ({L} point lights)",
            med,
            best,
            m * L,
            f"light culling skips {culled[label]:.0%} of the vertex-lights",
        )
        if label == "mesh order":
            mesh32 = med
        else:
            shuffled32 = med
        del sh, relight  # (1M-vertex shaders left alive slowed the recolour row below 1.4x)

    # the same with spot lights (cone and exponent: the engine's row path, not the inline one)
    spots = [spot_lights(L, np.random.default_rng(s)) for s in (0, 1)]
    sh = explorer.Shader(scene.replace(lights=spots[0]), P, N, precision="float32")

    def respot(sh=sh, flip=spots):
        flip.reverse()
        sh.set_lights(flip[0])
        return sh.colors

    row(f"full shading, float32 ({L} spot lights, Blinn, local viewer)", *timed(respot, R), n * L)

    one_shot = {}
    for precision in ("float32", "float64"):
        one_shot[precision] = timed(lambda p=precision: explorer.shade(scene, P, N, precision=p), R)
        what = "float64 (the default)" if precision == "float64" else precision
        row(f"one-shot `shade()` {what}, incl. preparing the geometry", *one_shot[precision], n * L)
    # what a one-shot call does before its pass, in turns with the bandwidth floor (below)
    turns = geometry_turns(scene, P, N, R)
    geometry = {p: turns[p] for p in ("float32", "float64")}
    for precision, (med, best) in geometry.items():
        row(f"geometry preparation, {precision} (of a one-shot call, before its pass)", med, best)
    for precision in ("float32", "float64"):
        row(
            f"geometry preparation, {precision} (a kept shader's: frame, prepare, chunk bounds)",
            *turns[f"kept {precision}"],
            note="G in the memory the shader keeps",
        )
        row(
            f"geometry preparation, {precision} (a kept shader's, G in new memory)",
            *turns[f"new {precision}"],
            note="as before prepared.RowMemory",
        )
    for precision in ("float32", "float64"):
        # (bests: the first rows' medians carry the VM's warm-up, by 10-50 %)
        extra = one_shot[precision][1] - full[precision][1]
        row(f"one-shot - full shading, {precision} (bests: beyond a kept pass)", extra, extra)

    # interactive updates, float32 Shader
    sh = explorer.Shader(scene, P, N, precision="float32")
    _ = sh.colors
    mats = [scene.material, scene.material.replace(diffuse=(0.3, 0.6, 0.2))]

    def recolour():
        mats.reverse()
        sh.set_material(mats[0])
        return sh.colors

    recol = timed(recolour, R)
    row("material colour change (recompose only)", *recol)
    shin = [25.6, 80.0]

    def reshine():
        shin.reverse()
        sh.set_material(sh.scene.material.replace(shininess=shin[0]))
        return sh.colors

    row("shininess change (lobe only)", *timed(reshine, R), n * L)
    eyes = [Viewer(eye=(0.0, 0.0, 5.0)), Viewer(eye=(1.0, 2.0, 5.0))]

    def review():
        eyes.reverse()
        sh.set_viewer(eyes[0])
        return sh.colors

    row("viewer change (specular only)", *timed(review, R), n * L)

    # the floor: the faster of a compiled parallel pass and numpy's add over the same arrays
    floor = min(turns["stream"], turns["add"])
    row(
        "bandwidth floor: read P, N once + write colours once",
        *floor,
        note="faster of numba `stream` and `np.add(P, N, out)`",
    )

    sub = max(n // 20, 1)
    ref = timed(lambda: equation_shade(scene, P[:sub], N[:sub]), max(3, R // 3))
    row(
        f"plain numpy float64 reference (full generality; on {sub} vertices, scaled)",
        ref[0] * n / sub,
        ref[1] * n / sub,
        n * L,
    )

    clock = "CPU seconds of one numba thread" if args.cpu else "wall clock"
    print(f"machine: {machine()}")
    print(f"mesh: {n} vertices, {L} point lights; median and best of {R} runs; {clock}\n")
    print("| case | median ms | best ms | G vertex-lights/s | note |")
    print("|---|---:|---:|---:|---|")
    for name, med, best, rate, note in rows:
        print(f"| {name} | {med:.2f} | {best:.2f} | {rate} | {note} |")
        isa.record(name, med)
    print()
    isa.record("recolour / bandwidth floor", recol[0] / floor[0], "x")
    for precision, (med, _) in geometry.items():
        isa.record(f"geometry preparation {precision} / bandwidth floor", med / floor[0], "x")
    for precision in ("float32", "float64"):
        kept = turns[f"kept {precision}"][0]
        isa.record(f"kept shader's geometry {precision} / bandwidth floor", kept / floor[0], "x")
    isa.record("load average at the end", load_average(), "")
    isa.write_results()
    print(
        f"recolour / bandwidth floor: {recol[0] / floor[0]:.2f}x (median), "
        f"{recol[1] / floor[1]:.2f}x (best)"
    )
    for precision, (med, best) in geometry.items():
        print(
            f"geometry preparation {precision} / bandwidth floor: {med / floor[0]:.2f}x (median), "
            f"{best / floor[1]:.2f}x (best)"
        )
    print(
        "full float32 shading vs plain numpy reference: "
        f"{ref[0] * n / sub / full['float32'][0]:.1f}x faster"
    )
    print(
        f"UV sphere, mesh order vs shuffled (light culling): {shuffled32 / mesh32:.2f}x faster "
        f"({culled['mesh order']:.0%} of the vertex-lights skipped)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
