"""What the plan saves: typical scenes shaded as planned vs with every skip disabled.

    python benchmarks/bench_plan.py                  # default sizes, 7 repeats
    python benchmarks/bench_plan.py --repeat 15 --resolution 256

Each case shades one mesh from scratch (a new :class:`explorer.Shader`, float32, shadows
included) twice: as the plan decides, and with ``force_all=True`` (every term of every light per
vertex, per-vertex halfway vectors, shadow rays from every vertex, facing the light or not). Both
give the same colours (checked); the table prints the median wall time of ``--repeat`` runs
after a warm-up run (compilation excluded), and the ratio forced / planned.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time

import common  # noqa: F401 - the compiled tier (benchmarks/common.py)
import numba
import numpy as np

import explorer
from explorer.geometry import meshes as M


def cases(res: int):
    sphere = M.sphere(res)
    teapot = M.teapot()
    big = M.sphere(4 * res)  # rings of 4 * res vertices: runs of 32 span a few degrees
    return [
        (
            "matte preset (opengl_default): specular skipped",
            {"material": "opengl_default", "viewer": {"eye": [0, 1, 4]},
             "lights": [{"type": "point", "position": [2, 2, 2]},
                        {"type": "directional", "to_light": [-1, 1, 1]}]},
            teapot,
        ),
        (
            "sphere, shadows: true: rays from lit vertices only",
            {"material": "gold",
             "lights": [{"type": "directional", "to_light": [1, 1, 1], "shadows": True}]},
            sphere,
        ),
        (
            "directional + infinite viewer (Blinn): constant H",
            {"material": "gold", "model": "blinn", "viewer": {"to_viewer": [0, 0, 1]},
             "lights": [{"type": "directional", "to_light": [1, 1, 1]},
                        {"type": "directional", "to_light": [-1, 0.5, 1]}]},
            sphere,
        ),
        (
            "point lights without attenuation, no ambient",
            {"material": "jade", "viewer": {"eye": [0, 1, 4]},
             "lights": [{"type": "point", "position": [2, 2, 2]},
                        {"type": "point", "position": [-2, 1, 2], "attenuation": [2, 0, 0]}]},
            teapot,
        ),
        (
            "4 point lights around a sphere: light culling",
            {"material": "gold", "viewer": {"eye": [0, 1, 4]},
             "lights": [{"type": "point", "position": p, "attenuation": [1, 0.1, 0.01]}
                        for p in ([3, 1, 1], [-2, 2, -2], [0, -3, 1], [1, 0, -3])]},
            big,
        ),
    ]  # fmt: skip


def time_one(scene, mesh, force_all: bool, repeat: int) -> tuple[float, np.ndarray]:
    def run():
        sh = explorer.Shader(
            scene, mesh.positions, mesh.normals, faces=mesh.faces, keep=False,
            force_all=force_all,
        )  # fmt: skip
        return np.asarray(sh.colors)

    colors = run()  # warm-up: compilation
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        run()
        times.append(time.perf_counter() - t)
    return statistics.median(times), colors


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--resolution", type=int, default=128, help="sphere segments (default 128)")
    args = ap.parse_args(argv)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(
        f"machine: {platform.machine()} {platform.processor() or ''} {os.cpu_count()} cores, "
        f"python {sys.version.split()[0]}, numpy {np.__version__}, numba {numba.__version__}, "
        f"numba threads {numba.get_num_threads()}, load {load:.2f}"
    )
    print(f"{'case':<52} {'vertices':>8} {'planned ms':>11} {'forced ms':>10} {'ratio':>6}")
    for name, mapping, mesh in cases(args.resolution):
        scene = explorer.load_scene(mapping)
        tp, cp = time_one(scene, mesh, False, args.repeat)
        tf, cf = time_one(scene, mesh, True, args.repeat)
        diff = float(np.abs(cp - cf).max())
        assert diff <= 1.0 / 255.0, f"{name}: forced colours differ by {diff}"
        print(
            f"{name:<52} {mesh.n_vertices:>8} {tp * 1e3:>11.2f} {tf * 1e3:>10.2f} {tf / tp:>6.1f}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
