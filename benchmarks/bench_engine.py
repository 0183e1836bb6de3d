"""Engine benchmark: throughput of full shading and the cost of each interactive update.

    python benchmarks/bench_engine.py                # 1M vertices, 8 point lights
    python benchmarks/bench_engine.py --vertices 200000 --lights 4 --repeat 15

The full-shading rows run twice on random points (every vertex-light computed: the kernel's
raw rate) and on a UV sphere mesh with as many vertices, in mesh order and shuffled: the
engine skips a light for runs of vertices that all face away from it (light culling), which
only a mesh whose vertex order keeps neighbours together allows.

Prints the machine, then one row per case: median and best wall time over ``--repeat`` runs (the
first, compiling run is excluded), vertex-lights per second, and ratios. The memory-bandwidth
floor of a recolour (read positions and normals once, write colours once) is measured in the
same run, on the same arrays, so "recolour / floor" is a like-for-like ratio; so are the rows
"geometry preparation" (what a one-shot ``shade()`` does before and between its passes: check
the vertices, find the frame, the plan, then slab by slab (``prepared.SLAB`` vertices) the
geometry in the working precision and its chunk bounds, into the buffers the previous call
handed back, as repeated one-shot calls do) against it.

``--slabs 0,65536,131072,262144`` times only one-shot calls and their geometry preparation at
each slab size (0: one slab of every vertex, as a kept ``Shader`` prepares it), the sizes taking
turns. Two runs on an idle machine (AMD EPYC, 2 cores, load 0.45-0.61, ``--slabs
0,262144,65536 --repeat 15``; medians, ms, run 1 / run 2; the VM moves these by 10 % from run
to run). The 256k slabs made the slowest one-shot float64 call in both runs (by 4-13 %), 64k
the fastest, while the geometry rows are alike; the default stays 256k because beside a busy
process each slab's three parallel regions can wait for a descheduled thread (15 calls beside a
CPU-bound process: one slab 90 ms, 256k 115 ms, 128k 196 ms): worth measuring again.

| slab | one-shot float64 | geometry float64 | one-shot float32 | geometry float32 |
|---:|---:|---:|---:|---:|
| 1,000,000 (whole) | 25.19 / 22.89 | 3.19 / 2.68 | 12.84 / 12.91 | 2.46 / 2.56 |
| 262,144 | 26.17 / 25.16 | 2.32 / 2.28 | 13.69 / 13.08 | 2.15 / 2.30 |
| 65,536 | 24.68 / 22.22 | 2.32 / 2.41 | 12.87 / 12.69 | 2.35 / 2.63 |

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
"""

from __future__ import annotations

import argparse
import os
import platform
import sys

import numba
import numpy as np
from common import cpu_name, load_average, timed, uv_sphere  # benchmarks/common.py

import explorer
from explorer.core.lights import PointLight, SpotLight
from explorer.core.material import Material
from explorer.core.scene import Scene, Viewer
from explorer.shading import kernels as K
from explorer.shading import prepared
from explorer.shading.equation import equation_shade

WIDTH = {True: "16 float32 / 8 float64 lanes (AVX-512)", False: "LLVM default width"}


def machine() -> str:
    return (
        f"{cpu_name()}; {os.cpu_count()} cores, numba threads {numba.get_num_threads()}; "
        f"Python {platform.python_version()}, numpy {np.__version__}, numba {numba.__version__}; "
        f"vectors: {WIDTH[K.WIDE_VECTORS]}; "
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


def slab_sizes(scene, P, N, sizes, R) -> int:
    """One-shot calls (and their geometry preparation alone) at each slab size: the sizes
    take turns, ``R`` rounds, so drift spreads over all of them; prints the medians."""
    n = len(P)
    times: dict = {}
    for _ in range(R):
        for size in sizes:
            prepared.SLAB = size or n
            for precision in ("float64", "float32"):

                def prep(precision=precision):
                    sh = explorer.Shader(scene, P, N, precision=precision, keep=False)
                    for _ in sh._slabs():
                        pass

                one = timed(lambda p=precision: explorer.shade(scene, P, N, precision=p), 3)[0]
                times.setdefault((size, precision, "one-shot"), []).append(one)
                times.setdefault((size, precision, "geometry"), []).append(timed(prep, 3)[0])
    print(f"machine: {machine()}")
    print(f"mesh: {n} vertices, {len(scene.lights)} point lights; medians of {R} rounds\n")
    print("| slab (vertices) | one-shot float64 ms | geometry float64 ms "
          "| one-shot float32 ms | geometry float32 ms |")  # fmt: skip
    print("|---:|---:|---:|---:|---:|")
    for size in sizes:
        cells = [
            f"{np.median(times[(size, p, what)]) * 1e3:.2f}"
            for p in ("float64", "float32")
            for what in ("one-shot", "geometry")
        ]
        print(f"| {size or n} | " + " | ".join(cells) + " |")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--vertices", type=int, default=1_000_000)
    ap.add_argument("--lights", type=int, default=8)
    ap.add_argument("--repeat", type=int, default=11)
    ap.add_argument(
        "--slabs",
        default="",
        help="only time one-shot calls with these slab sizes (comma-separated vertex counts, "
        "multiples of kernels.BLOCK; 0: one slab of every vertex; see prepared.SLAB)",
    )
    args = ap.parse_args(argv)
    n, L, R = args.vertices, args.lights, args.repeat
    rng = np.random.default_rng(0)
    P, N = sphere_points(n, rng)
    scene = scene_with(L, rng)
    if args.slabs:
        return slab_sizes(scene, P, N, [int(v) for v in args.slabs.split(",")], R)
    other = scene_with(L, np.random.default_rng(1)).lights

    rows = []

    def row(name, med, best, work=None, note=""):
        rate = f"{work / med / 1e9:.2f}" if work else ""
        rows.append((name, med * 1e3, best * 1e3, rate, note))

    # full shading after a light change (geometry prepared once, as in the explorer)
    for precision in ("float32", "float64"):
        sh = explorer.Shader(scene, P, N, precision=precision)
        flip = [scene.lights, other]

        def relight(sh=sh, flip=flip):
            flip.reverse()
            sh.set_lights(flip[0])
            return sh.colors

        med, best = timed(relight, R)
        row(
            f"full shading, {precision} ({L} point lights, Blinn, local viewer)",
            med,
            best,
            n * L,
            "light change: every term recomputed",
        )
        if precision == "float32":
            full32 = med

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

    one_shot = timed(lambda: explorer.shade(scene, P, N, precision="float32"), R)
    row("one-shot `shade()` float32, incl. preparing the geometry", *one_shot, n * L)
    one_shot = timed(lambda: explorer.shade(scene, P, N), R)
    row("one-shot `shade()` float64 (the default), incl. preparing the geometry", *one_shot, n * L)
    # what a one-shot call does before and between its passes: check the vertices, find the
    # frame, the plan, and slab by slab the geometry in the working precision and its chunk
    # bounds (into the buffers the previous call left)
    geometry = {}
    for precision in ("float32", "float64"):

        def prep(precision=precision):
            sh = explorer.Shader(scene, P, N, precision=precision, keep=False)
            sh._compiled_geometry()  # (the frame: found by the constructor when kernels serve)
            for _ in sh._slabs():
                pass

        geometry[precision] = timed(prep, R)
        row(f"geometry preparation, {precision} (of a one-shot call)", *geometry[precision])

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

    out = np.empty((n, 3), np.float32)
    # the floor: the faster of a compiled parallel pass and numpy's add over the same arrays
    floor = min(timed(lambda: K.stream(P, N, out), R), timed(lambda: np.add(P, N, out=out), R))
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

    print(f"machine: {machine()}")
    print(f"mesh: {n} vertices, {L} point lights; median and best of {R} runs\n")
    print("| case | median ms | best ms | G vertex-lights/s | note |")
    print("|---|---:|---:|---:|---|")
    for name, med, best, rate, note in rows:
        print(f"| {name} | {med:.2f} | {best:.2f} | {rate} | {note} |")
    print()
    print(
        f"recolour / bandwidth floor: {recol[0] / floor[0]:.2f}x (median), "
        f"{recol[1] / floor[1]:.2f}x (best)"
    )
    for precision, (med, best) in geometry.items():
        print(
            f"geometry preparation {precision} / bandwidth floor: {med / floor[0]:.2f}x (median), "
            f"{best / floor[1]:.2f}x (best)"
        )
    print(f"full float32 shading vs plain numpy reference: {ref[0] * n / sub / full32:.1f}x faster")
    print(
        f"UV sphere, mesh order vs shuffled (light culling): {shuffled32 / mesh32:.2f}x faster "
        f"({culled['mesh order']:.0%} of the vertex-lights skipped)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
