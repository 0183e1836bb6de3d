"""The term strip's recompose (issue 41): the cached light sums of a Shader made into the five
tiles' colours and the overflow mask, no light pass.

    python benchmarks/bench_strip.py                  # 100k vertices, 31 repeats
    python benchmarks/bench_strip.py --vertices 1000000 --repeat 11

A material change (the colours only, composed by the engine, untimed) then
:func:`explorer.shading.strip.shader_strip_bytes` (timed): the five tiles' bytes and the overflow
mask from the cached sums, as a front end redraws the strip on a slider step; the shader's pass
counters are checked to stay still (no light pass). Prints the median and best wall time and the
thread's CPU time (``time.thread_time``: what a loaded machine's other processes do not add) in
milliseconds per precision and mode, with the machine and its load (the target: <= 2 ms at
100k vertices).
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

from common import cpu_name, load_average, uv_sphere

from explorer.core.presets import find_preset
from explorer.core.scene import Scene
from explorer.shading.shader import Shader
from explorer.shading.strip import MODES, shader_strip_bytes

#: the issue's budget for one recompose at 100k vertices (milliseconds)
TARGET_MS = 2.0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--vertices", type=int, default=100_000, help="about this many (100000)")
    ap.add_argument("--repeat", type=int, default=31, help="timed calls each (31)")
    args = ap.parse_args(argv)
    side = max(4, int(round(math.sqrt(args.vertices))))
    mesh = uv_sphere(side, side - 1)
    scene = Scene(material=find_preset("gold"))
    print(
        f"term strip recompose, {mesh.n_vertices} vertices, gold; {cpu_name()}, "
        f"load {load_average():.2f}"
    )
    heads = ("wall med", "wall best", "CPU med", "CPU best")
    print(f"{'precision':<10} {'mode':<9}" + "".join(f"{h:>10}" for h in heads) + "   (ms)")
    for precision in ("float32", "float64"):
        sh = Shader(scene, mesh.positions, mesh.normals, precision=precision)
        shader_strip_bytes(sh)  # the light pass, once
        passes = sh.stats["pass"] + sh.stats["numpy"]
        for mode in MODES:
            wall, cpu = [], []
            for i in range(args.repeat + 1):  # (the first: warm-up, not counted)
                kd = (0.7 + 0.1 * (i % 2), 0.6, 0.2)  # a kd slider step: the colours only
                sh.set_material(scene.material.replace(diffuse=kd))
                _ = sh.colors
                t0, c0 = time.perf_counter(), time.thread_time()
                shader_strip_bytes(sh, mode)
                cpu.append(time.thread_time() - c0)
                wall.append(time.perf_counter() - t0)
            row = [1e3 * f(t[1:]) for t in (wall, cpu) for f in (statistics.median, min)]
            print(f"{precision:<10} {mode:<9}" + "".join(f"{v:>10.2f}" for v in row))
        assert sh.stats["pass"] + sh.stats["numpy"] == passes, "a light pass ran"
    print(f"target: <= {TARGET_MS:g} ms at 100k vertices (issue 41)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
