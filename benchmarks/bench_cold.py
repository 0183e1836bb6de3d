"""What a fresh install costs: the quick start, the window and first calls, cold against warm.

    python benchmarks/bench_cold.py                 # everything (several minutes: it waits for
                                                    # the background compile to finish)
    python benchmarks/bench_cold.py --no-window     # without Xvfb
    python benchmarks/bench_cold.py --no-compiled   # skip the old behaviour's cold row

Cold means an empty numba cache (a fresh ``NUMBA_CACHE_DIR``), as on a machine that has never
run the product; every cold measurement is a new process in that state. Rows:

1. README's quick start, ``phong-explorer render --preset bronze --mesh teapot --out ...``: cold
   (mode auto: the numpy tier serves, the background compile starts), then, once the background
   compile has written its ready marker (its duration is reported), warm (median of 3).
2. ``phong-explorer gui`` until its first frame on a private Xvfb server, cold and warm
   (``benchmarks/bench_gui_start.py``'s measure).
3. The first ``explorer.shade`` call for each kind of scene on a 20k-vertex mesh in a process
   on a cold cache (float32 and float64), and the first relight of a float32 Shader (the
   window's path) to each light type and model; then the window's difference view of the
   default teapot as its worker makes it (from the rasteriser's triangles while the compiled
   rays are not loaded; the first opens its off-screen windows), and with the numpy tier's rays
   for comparison.
4. With ``PHONG_EXPLORER_KERNELS=compiled`` (the behaviour before the tiers: the first call
   compiles in the foreground), the quick start on a cold cache, for comparison in the same run.

The machine line and every figure are printed as a Markdown table.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

from bench_engine import machine
from bench_gui_start import start_once

from explorer.app.start import start_xvfb
from explorer.shading import tiers

QUICK = ["-m", "explorer.cli", "render", "--preset", "bronze", "--mesh", "teapot", "--out"]

#: first calls in a cold process: each kind of scene, then the window's relights
FIRST_CALLS = textwrap.dedent(
    """
    import json, time, warnings
    warnings.simplefilter("ignore")
    import numpy as np
    import explorer
    from explorer.geometry.meshes import teapot
    mesh = teapot(24)  # about 18k vertices
    P, N, F = mesh.positions, mesh.normals, mesh.faces
    kinds = {
        "point": {"lights": [{"type": "point", "position": [2, 2, 3]}]},
        "spot": {"lights": [{"type": "spot", "position": [0, 3, 1], "aim": [0, -1, -0.3],
                             "cutoff": 30, "exponent": 4}]},
        "directional": {"lights": [{"type": "directional", "to_light": [1, 1, 1]}]},
        "phong": {"model": "phong"},
        "two-sided, infinite viewer": {"two_sided": True, "viewer": {"to_viewer": [0, 0, 1]}},
        "local viewer, attenuation": {"viewer": {"eye": [0, 1, 4]}, "lights": [
            {"type": "point", "position": [2, 2, 3], "attenuation": [1, 0.2, 0.05]}]},
        "fresnel + energy": {"material": {"fresnel": 0.04, "energy_conserving": True}},
        "hdr": {"hdr": True},
        "shadows (2 lights)": {"lights": [
            {"type": "point", "position": [2, 3, 2], "shadows": True},
            {"type": "directional", "to_light": [-1, 2, 0.5], "shadows": True}]},
        "8 point lights": {"lights": [{"type": "point", "position": [float(i), 2, 3]}
                                      for i in range(8)]},
    }
    out = {"vertices": len(P)}
    for name, scene in kinds.items():
        for precision in ("float32", "float64"):
            faces = F if "shadows" in name else None
            t = time.perf_counter()
            explorer.shade(scene, P, N, precision=precision, faces=faces)
            out[f"{name} ({precision})"] = time.perf_counter() - t
    s = explorer.Shader({}, P, N, precision="float32")
    _ = s.colors
    for name, change in (
        ("relight: spot", lambda: s.set_lights(kinds["spot"]["lights"])),
        ("relight: directional", lambda: s.set_lights(kinds["directional"]["lights"])),
        ("model: phong", lambda: s.set_model("phong")),
        ("model: blinn", lambda: s.set_model("blinn")),
        ("shininess", lambda: s.set_material(s.scene.material.replace(shininess=77.0))),
    ):
        t = time.perf_counter()
        change()
        _ = s.colors
        out[name] = time.perf_counter() - t
    # the window's difference view, default teapot at 1100x720, as its worker makes it: the
    # rasteriser's triangles while the compiled rays are not loaded; the numpy tier's rays
    from explorer.analysis.comparison import ViewComparer
    from explorer.app.difference import Job, run_job
    from explorer.core.scene import load_scene
    from explorer.render.camera import camera_for
    from explorer.shading.display import vertex_colors
    view, size = teapot(), (1100, 720)
    scene = load_scene({"material": "gold"})
    job = Job(0, scene, view, vertex_colors(scene, view), camera_for(scene, view, 1100 / 720),
              size, (0.32, 0.32, 0.32))
    with ViewComparer(size) as v:
        for name, method in (("difference view, first (rasteriser's triangles)", "auto"),
                             ("difference view, again (rasteriser's triangles)", "auto"),
                             ("difference view (the numpy tier's rays)", "raycast")):
            t = time.perf_counter()
            if method == "auto":
                run_job(job, comparer=v)
            else:
                v.compare(scene, view, camera=job.camera, colors=job.colors, method=method)
            out[name] = time.perf_counter() - t
    print(json.dumps(out))
    """
)


#: in a warm process: what loading the compiled kernels from numba's cache costs, against the
#: numpy tier's time per vertex-light (tiers.LOAD_WORTH is the break-even between the two)
LOAD = textwrap.dedent(
    """
    import json, time
    import numpy as np
    import explorer
    from explorer.geometry.meshes import sphere
    from explorer.shading.display import to_bytes
    small = sphere(8)
    t = time.perf_counter()
    for precision in ("float64", "float32"):
        to_bytes(explorer.shade({}, small.positions, small.normals, precision=precision,
                                tier="compiled"))
    load = time.perf_counter() - t
    big = sphere(400)
    scene = {"lights": [{"type": "point", "position": [2.0, 1.0 + i, 3.0]} for i in range(4)]}
    explorer.shade(scene, big.positions, big.normals, tier="numpy")
    t = time.perf_counter()
    explorer.shade(scene, big.positions, big.normals, tier="numpy")
    per = (time.perf_counter() - t) / (len(big.positions) * 4)
    print(json.dumps({"load": load, "numpy_per_vertex_light": per}))
    """
)


def cold_env(root: Path, mode: str = "auto") -> dict:
    """The environment of a process on a cold cache under ``root`` (made empty)."""
    shutil.rmtree(root, ignore_errors=True)
    root.mkdir(parents=True)
    return dict(os.environ, NUMBA_CACHE_DIR=str(root), PHONG_EXPLORER_KERNELS=mode)


def timed_run(args, env, cwd) -> float:
    t = time.perf_counter()
    out = subprocess.run([sys.executable, *args], env=env, cwd=cwd, capture_output=True,
                         text=True)  # fmt: skip
    if out.returncode != 0:
        raise SystemExit(f"{' '.join(args)} failed:\n{out.stderr}")
    return time.perf_counter() - t


def marker_ready(env) -> Path:
    probe = "from explorer.shading import tiers; print(tiers.marker_path())"
    out = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True)
    return Path(out.stdout.strip())


def wait_for(path: Path, timeout: float) -> float:
    t = time.perf_counter()
    while not path.exists():
        if time.perf_counter() - t > timeout:
            raise SystemExit(f"the background compile wrote no marker in {timeout:.0f} s")
        time.sleep(0.5)
    return time.perf_counter() - t


def quick_start(out_dir: Path, env, name: str) -> float:
    target = out_dir / f"{name}.png"
    target.unlink(missing_ok=True)
    return timed_run([*QUICK, str(target)], env, out_dir)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--no-window", action="store_true", help="skip the window rows")
    ap.add_argument("--no-compiled", action="store_true", help="skip the old cold row")
    ap.add_argument("--timeout", type=float, default=900.0, help="wait for the background fill")
    args = ap.parse_args(argv)
    window = not args.no_window and shutil.which("Xvfb")
    work = Path(tempfile.mkdtemp(prefix="bench_cold_"))
    rows: list[tuple[str, str, str, str]] = []
    print(f"machine: {machine()}")

    # 3. first calls on a cold cache (the background compile runs meanwhile, as for a user)
    env = cold_env(work / "first")
    out = subprocess.run([sys.executable, "-c", FIRST_CALLS], env=env, cwd=work,
                         capture_output=True, text=True)  # fmt: skip
    first = json.loads(out.stdout.strip().splitlines()[-1])
    subprocess.run(["pkill", "-f", "explorer.shading.warm"], capture_output=True)

    # 1 and 2: cold, then wait for the background fill, then warm
    env = cold_env(work / "cache")
    cold = quick_start(work, env, "cold")
    display = None
    if window:
        server, display = start_xvfb()
        cache = {"NUMBA_CACHE_DIR": env["NUMBA_CACHE_DIR"], "PHONG_EXPLORER_KERNELS": "auto"}
        cold_window = start_once(display, cache, args.timeout)
    fill = wait_for(marker_ready(env), args.timeout)
    warm = statistics.median(quick_start(work, env, f"warm{i}") for i in range(3))
    out = subprocess.run([sys.executable, "-c", LOAD], env=env, cwd=work, capture_output=True,
                         text=True)  # fmt: skip
    load = json.loads(out.stdout.strip().splitlines()[-1])
    rows.append(("quick start render", f"{cold:.2f} s", f"{warm:.2f} s", f"{cold / warm:.2f}x"))
    if window:
        warm_window = statistics.median(start_once(display, cache, args.timeout) for _ in range(3))
        rows.append(("window's first frame", f"{cold_window:.2f} s", f"{warm_window:.2f} s",
                     f"{cold_window / warm_window:.2f}x"))  # fmt: skip
        server.terminate()
    if not args.no_compiled:
        old = quick_start(work, cold_env(work / "old", "compiled"), "old")
        rows.append(("quick start, compiling in the foreground (before)", f"{old:.2f} s",
                     f"{warm:.2f} s", f"{old / warm:.2f}x"))  # fmt: skip

    print("\n| what | cold (fresh install) | warm | ratio |\n|---|---:|---:|---:|")
    for r in rows:
        print(f"| {' | '.join(r)} |")
    print(f"\nbackground compile until the ready marker: {fill:.1f} s after the cold render ended")
    per = load["numpy_per_vertex_light"]
    print(f"loading the compiled kernels from the cache (both precisions): {load['load']:.2f} s; "
          f"the numpy tier: {per * 1e9:.0f} ns per vertex-light, so the load is worth "
          f"{load['load'] / per / 1e6:.1f} M vertex-lights (tiers.LOAD_WORTH: "
          f"{tiers.LOAD_WORTH / 1e6:.1f} M)")  # fmt: skip
    n = first.pop("vertices")
    print(f"\nfirst calls in a process on a cold cache ({n:,} vertices):\n")
    print("| call | seconds |\n|---|---:|")
    for name, t in first.items():
        print(f"| {name} | {t:.3f} |")
    calls = [t for name, t in first.items() if not name.startswith("difference view")]
    print(f"\nslowest first call (the difference view's rows aside): {max(calls):.3f} s")
    shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
