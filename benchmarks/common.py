"""Meshes and helpers the benchmarks share (no GUI imports: bench_engine runs without VTK).

Importing it puts the engine on its compiled tier (compiled in the process when numba's cache
lacks it): the benchmarks measure the kernels, never the numpy tier that serves while the cache
is filled (explorer.shading.tiers).
"""

from __future__ import annotations

import os
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("PHONG_EXPLORER_KERNELS", "compiled")

from explorer.geometry import meshes as M


def uv_sphere(around: int, rings: int) -> M.Mesh:
    """A UV sphere with ``around * (rings + 1)`` vertices (seam duplicated), in the order a
    mesh generator writes them: ring after ring, ``around`` vertices each."""
    theta = np.linspace(0.0, np.pi, rings + 1)
    phi = np.linspace(0.0, 2.0 * np.pi, around, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    pos = np.stack([np.sin(t) * np.sin(p), np.cos(t), np.sin(t) * np.cos(p)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(rings), np.arange(around), indexing="ij")
    a = i * around + j
    b = i * around + (j + 1) % around
    c, d = a + around, b + around
    faces = np.concatenate([np.stack([a, c, b], -1), np.stack([b, c, d], -1)]).reshape(-1, 3)
    return M.Mesh(pos, pos.copy(), faces, "uv_sphere")


def cpu_name() -> str:
    """The processor's model name (``/proc/cpuinfo``), else what ``platform`` says."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def load_average() -> float:
    return os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")


#: the clock :func:`timed` reads: the wall clock, or ``time.process_time`` (a benchmark's
#: ``--cpu``: the process's CPU seconds, every thread's)
clock = time.perf_counter


def timed(fn, repeat: int) -> tuple[float, float]:
    """(median, best) seconds of ``repeat`` calls of ``fn`` after one warm-up call, by
    :data:`clock`."""
    fn()  # compile / warm up
    ts = []
    for _ in range(repeat):
        t = clock()
        fn()
        ts.append(clock() - t)
    return statistics.median(ts), min(ts)


def publish(text: str, path: Path, write: bool = True) -> None:
    """Print a benchmark's table and, unless ``write`` is False, write it to ``path``."""
    print(text)
    if write:
        path.write_text(text)
        print(f"wrote {path}", file=sys.stderr)
