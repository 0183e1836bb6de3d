"""Memory of explorer windows opened and closed in one process: RSS after each, and whether the
closed window and its controller were freed.

    python benchmarks/bench_window_memory.py              # 10 windows, compare view and all
    python benchmarks/bench_window_memory.py --windows 20 --plain

Each window (icosphere, resolution 3, 1000x700, on a private Xvfb) is shown and drawn; unless
``--plain`` it then turns on the compare view (side B's pane), the difference view (its worker)
and per-pixel shading, and draws again. It is closed, deleted (``deleteLater``, Qt's events
processed) and the garbage collected; the line says which of the window, its controller, its
view port and its scene are still alive, and the process's RSS. The last lines give the RSS
growth per window from the first window to the last, and from the middle one to the last.
"""

from __future__ import annotations

import argparse
import gc
import os
import tempfile
import weakref


def rss_mb() -> float:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS"):
                return int(line.split()[1]) / 1024
    return float("nan")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--windows", type=int, default=10)
    ap.add_argument("--plain", action="store_true", help="no compare, difference or per pixel")
    args = ap.parse_args()

    from explorer.app.start import start_xvfb

    _server, display = start_xvfb(size=(1920, 1200))  # (ends with this process)
    os.environ.update(DISPLAY=display, QT_QPA_PLATFORM="xcb")
    os.environ.pop("VTK_DEFAULT_OPENGL_WINDOW", None)
    tmp = tempfile.mkdtemp(prefix="phong-explorer-memory-")
    os.environ["PHONG_EXPLORER_MATERIALS"] = os.path.join(tmp, "presets")
    from PySide6 import QtCore, QtWidgets

    app = QtWidgets.QApplication(["bench_window_memory"])

    from explorer.app.qt.window import ExplorerWindow
    from explorer.cli import build_parser
    from explorer.cli.gui import start_state

    def process(n: int = 20) -> None:
        for _ in range(n):
            app.processEvents(QtCore.QEventLoop.ProcessEventsFlag.AllEvents, 50)
            QtCore.QCoreApplication.sendPostedEvents(None, QtCore.QEvent.Type.DeferredDelete)

    def one() -> dict:
        argv = ["gui", "--mesh", "icosphere", "--resolution", "3"]
        state, mesh = start_state(build_parser().parse_args(argv), [])
        w = ExplorerWindow(
            state, mesh, output_dir=tmp, last_session=os.path.join(tmp, "l.yaml"), size=(1000, 700)
        )
        w.show()
        process()
        w.render()
        if not args.plain:
            for key, v in (("compare", True), ("difference", True), ("shading", "per-pixel")):
                w.controller.set_value(key, v, merge=False)
                w.render()
                process(5)
        refs = {"window": w, "controller": w.controller, "viewport": w.viewport, "view": w.view}
        refs = {k: weakref.ref(v) for k, v in refs.items()}
        w.close()
        w.deleteLater()
        del w
        process()
        gc.collect()
        return refs

    rss = []
    for i in range(args.windows):
        refs = one()
        alive = [k for k, r in refs.items() if r() is not None]
        rss.append(rss_mb())
        print(
            f"window {i + 1}: RSS {rss[-1]:.1f} MB, alive after close: {alive or 'none'}",
            flush=True,
        )
    half = len(rss) // 2  # (the first windows also warm caches: GL, numba, fonts)
    for a in (0, half):
        n = max(len(rss) - 1 - a, 1)
        print(
            f"RSS {rss[a]:.1f} MB after window {a + 1}, {rss[-1]:.1f} MB after the last: "
            f"{(rss[-1] - rss[a]) / n:+.2f} MB a window"
        )


if __name__ == "__main__":
    main()
