"""How long the explorer window takes to appear: from starting ``phong-explorer gui`` to its
first drawn frame (the ``--state-file`` is written after each frame), on a private Xvfb.

    python benchmarks/bench_gui_start.py                 # warm: numba's cache as it is
    python benchmarks/bench_gui_start.py --cold          # also cold: an empty numba cache

``--cold`` points ``NUMBA_CACHE_DIR`` at a new empty directory for each start, as on a fresh
install: the numpy tier draws while a background process compiles the kernels
(:mod:`explorer.shading.tiers`; stopped after each cold start, its cache being thrown away);
the ratio cold / warm is what the window issue asks to keep within 3x. Needs Xvfb.
``benchmarks/bench_cold.py`` measures the same with the background compile left to finish.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from explorer.app.start import start_xvfb


def start_once(display: str, env_extra: dict, timeout: float) -> float:
    """Seconds from launching the window to its first frame."""
    with tempfile.TemporaryDirectory() as tmp:
        state = Path(tmp) / "state.json"
        env = {k: v for k, v in os.environ.items() if k != "VTK_DEFAULT_OPENGL_WINDOW"}
        env.update(DISPLAY=display, QT_QPA_PLATFORM="xcb", **env_extra,
                   PHONG_EXPLORER_LAST_SESSION=str(Path(tmp) / "last.yaml"))  # fmt: skip
        t0 = time.perf_counter()
        with open(Path(tmp) / "log", "wb") as log:
            proc = subprocess.Popen(
                [sys.executable, "-m", "explorer.cli", "gui", "--state-file", str(state),
                 "--exit-after", str(timeout)], env=env, stdout=log, stderr=log,
            )  # fmt: skip
        try:
            while time.perf_counter() - t0 < timeout:
                try:
                    if json.loads(state.read_text())["window"]["frame"] >= 1:
                        return time.perf_counter() - t0
                except (OSError, ValueError, KeyError):
                    pass
                if proc.poll() is not None:
                    raise RuntimeError((Path(tmp) / "log").read_text(errors="replace"))
                time.sleep(0.02)
            raise RuntimeError(f"no frame within {timeout} s")
        finally:
            proc.kill()
            proc.wait()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3, help="starts per row (3)")
    ap.add_argument("--cold", action="store_true", help="also start with an empty numba cache")
    ap.add_argument("--timeout", type=float, default=900.0)
    args = ap.parse_args(argv)
    proc, display = start_xvfb()
    try:
        start_once(display, {}, args.timeout)  # warms the cache the warm rows use
        rows = {"warm": [start_once(display, {}, args.timeout) for _ in range(args.repeat)]}
        if args.cold:
            cold = []
            for _ in range(args.repeat):
                with tempfile.TemporaryDirectory() as cache:
                    cold.append(start_once(display, {"NUMBA_CACHE_DIR": cache}, args.timeout))
                    # the background compile the cold start began (explorer.shading.tiers)
                    # would fill a cache about to be deleted: stop it
                    subprocess.run(["pkill", "-f", "explorer.shading.warm"], check=False)
            rows["cold (empty numba cache)"] = cold
    finally:
        proc.terminate()
        proc.wait()
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    print(f"window start to first frame, default start, {args.repeat} starts; load {load}")
    print("| start | median s | best s | / warm |")
    print("|---|---:|---:|---:|")
    warm = statistics.median(rows["warm"])
    for name, ts in rows.items():
        m = statistics.median(ts)
        print(f"| {name} | {m:.2f} | {min(ts):.2f} | {m / warm:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
