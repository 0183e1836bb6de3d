"""Web benchmark: a slider change to the browser's new picture, beside the Qt window's slider
to frame, in the same run; and how soon ``phong-explorer web`` is ready.

    python benchmarks/bench_web.py                    # prints the table, writes docs/web_bench.md
    python benchmarks/bench_web.py --repeat 15 --no-write

- Latency: ``phong-explorer web --mesh teapot --resolution 56`` (100,578 vertices, one point
  light) in its own process, its view sized to 800x600 in headless Chromium (Debian's, driven
  by Selenium). Each sample sets the kd slider's value in the page (what dragging the slider
  does: the trame state key ``kd_step``) and waits, in the page, for the view's ``<img>`` to load
  the next picture; the time is the page's own clock (``performance.now()``) from the change to
  that load: the message to the server, the engine update, the frame, the JPEG and its way back,
  the decode. Median and best over ``--repeat`` samples after two warm-up ones.
- The Qt window's figure of the same run: :func:`bench_gui.qt_frames` (a number field set, the
  action, the panel, the engine, the upload and the frame; a private Xvfb).
- Ready: from starting the process (numba's cache warm) to the URL answering, and to the first
  picture in a browser already running; median of ``--starts`` starts.

Wall times vary with load: the load average before and after is printed with the table.
"""

from __future__ import annotations

import argparse
import os
import re
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

from bench_gui import load, machine, qt_frames  # this script's directory is on sys.path
from common import publish

from explorer.geometry import meshes as M
from explorer.render.vtk import plotter

SIZE = (800, 600)
DOCS = Path(__file__).resolve().parent.parent / "docs" / "web_bench.md"
ROOT = Path(__file__).resolve().parent.parent

#: one sample, in the page: set kd's slider step, resolve when the view's picture shows a new
#: colour at the probe vertex's pixel (a picture still being encoded arrives first unchanged)
SAMPLE_JS = """
const [step, x, y, done] = arguments;
const img = document.querySelector('[aria-label="view"] img');
const canvas = document.createElement('canvas');
const ctx = canvas.getContext('2d', {willReadFrequently: true});
const pixel = () => {
  canvas.width = img.naturalWidth; canvas.height = img.naturalHeight;
  ctx.drawImage(img, 0, 0);
  return Array.from(ctx.getImageData(x, y, 1, 1).data.slice(0, 3)).join(',');
};
const before = pixel();
const t0 = performance.now();
const on = () => {
  if (pixel() !== before) { img.removeEventListener('load', on); done(performance.now() - t0); }
};
img.addEventListener('load', on);
window.trame.state.set('kd_step', step);
setTimeout(() => done(-1), 20000);
"""
PICTURE_JS = """
const i = document.querySelector('[aria-label="view"] img');
return i && i.complete && i.naturalWidth > 0 ? [i.naturalWidth, i.naturalHeight,
  i.getBoundingClientRect().width, i.getBoundingClientRect().height] : null;
"""


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def browser():
    sys.path.insert(0, str(ROOT / "tests" / "web"))
    from webserver import new_browser  # the tests' headless Chromium

    return new_browser(Path(os.environ.get("TMPDIR", "/tmp")))


def start_server(port: int, log) -> subprocess.Popen:
    # the server keeps its session when it stops (web --last): not over the user's own
    last = Path(tempfile.gettempdir()) / f"bench-web-{os.getpid()}-last-session.yaml"
    env = dict(os.environ, PYTHONPATH=str(ROOT), PHONG_EXPLORER_LAST_SESSION=str(last))
    return subprocess.Popen(
        [sys.executable, "-m", "explorer.cli", "web", "--mesh", "teapot", "--resolution", "56",
         "--port", str(port)],
        stdout=log, stderr=subprocess.STDOUT, env=env,
    )  # fmt: skip


def wait_url(port: int, log: Path, timeout: float = 120.0) -> str:
    """The page's address the server on ``port`` printed into ``log`` (with its token), once
    it answers."""
    printed = re.compile(rf"http://127\.0\.0\.1:{port}/\?secret=[A-Za-z0-9_-]+")
    end = time.monotonic() + timeout
    while True:
        found = printed.search(log.read_text(errors="replace"))
        try:
            if found:
                with urllib.request.urlopen(found.group(0), timeout=2) as r:
                    if r.status == 200:
                        return found.group(0)
        except OSError:
            pass
        if time.monotonic() > end:
            raise RuntimeError(f"port {port} did not answer within {timeout} s")
        time.sleep(0.02)


def wait_picture(driver, timeout: float = 60.0):
    end = time.monotonic() + timeout
    while True:
        got = driver.execute_script(PICTURE_JS)
        if got:
            return got
        if time.monotonic() > end:
            raise RuntimeError("no picture")
        time.sleep(0.02)


def ready_times(driver, starts: int) -> dict:
    """Median seconds from the process start to the URL answering and to the first picture."""
    url_s, picture_s = [], []
    for _ in range(starts):
        port = free_port()
        path = Path(tempfile.gettempdir()) / f"bench-web-{os.getpid()}-{port}.log"
        with open(path, "w") as log:
            t0 = time.perf_counter()
            proc = start_server(port, log)
            try:
                url = wait_url(port, path)
                url_s.append(time.perf_counter() - t0)
                driver.get(url)
                wait_picture(driver)
                picture_s.append(time.perf_counter() - t0)
            finally:
                proc.terminate()
                proc.wait(10)
        path.unlink()
        driver.get("about:blank")
    return {"url": statistics.median(url_s), "picture": statistics.median(picture_s)}


def size_view(driver) -> tuple[int, int]:
    """Resize the browser so the view's picture is :data:`SIZE` CSS pixels; its size."""
    for _ in range(4):
        _, _, w, h = wait_picture(driver)
        if (round(w), round(h)) == SIZE:
            break
        ww, wh = driver.get_window_size().values()
        driver.set_window_size(ww + SIZE[0] - round(w), wh + SIZE[1] - round(h))
        time.sleep(1.0)
    nw, nh, _, _ = wait_picture(driver)
    return int(nw), int(nh)


def latency(driver, url: str, repeat: int) -> tuple[float, float, tuple[int, int]]:
    """Median and best ms from a kd slider change to the new picture loaded in the page."""
    driver.get(url)
    size = size_view(driver)
    time.sleep(1.0)
    rep = driver.execute_async_script(
        "const done = arguments[0]; window.trame.trigger('report').then(done);"
    )
    x, y = rep["probe"]["px"]
    ts = []
    for i in range(repeat + 2):
        step = 300 + 400 * (i % 2)  # kd 0.3 and 0.7
        t = driver.execute_async_script(SAMPLE_JS, step, x, y)
        if t < 0:
            raise RuntimeError("the picture did not change within 20 s")
        if i >= 2:
            ts.append(float(t))
        time.sleep(0.05)
    size = tuple(int(v) for v in wait_picture(driver)[:2])
    return statistics.median(ts), min(ts), size


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=21, help="timed samples per row (21)")
    ap.add_argument("--starts", type=int, default=3, help="server starts timed (3)")
    ap.add_argument("--no-write", action="store_true", help="do not write docs/web_bench.md")
    args = ap.parse_args(argv)
    driver = browser()
    before = load()
    try:
        ready = ready_times(driver, args.starts)
        port = free_port()
        path = Path(tempfile.gettempdir()) / f"bench-web-{os.getpid()}-{port}.log"
        with open(path, "w") as log:
            proc = start_server(port, log)
            try:
                web = latency(driver, wait_url(port, path), args.repeat)
            finally:
                proc.terminate()
                proc.wait(10)
        path.unlink()
        version = driver.capabilities.get("browserVersion", "?")
    finally:
        driver.quit()
    teapot = M.teapot(56)
    qt = qt_frames(teapot, args.repeat)
    after = load()
    pl = plotter(SIZE, (0.0, 0.0, 0.0))
    pl.render()  # the renderer's name is known once it has drawn
    info = machine(pl)
    pl.close()

    vw, vh = qt["view"]
    lines = ["# Web benchmark", "", "Machine:", ""]
    lines += [f"- {x}" for x in info]
    lines += [f"- browser: headless Chromium {version} (Selenium), on the same machine",
              f"- load average before / after: {before} / {after}", ""]  # fmt: skip
    lines += [
        f"A kd change to the new picture, {teapot.n_vertices:,}-vertex teapot, 1 point light; "
        f"median (best) ms over {args.repeat} changes:",
        "",
        "| front end | view | ms |",
        "|---|---|---:|",
        f"| web page: slider value set in the page → the view's next picture loaded (page "
        f"clock) | {web[2][0]}x{web[2][1]} | {web[0]:.1f} ({web[1]:.1f}) |",
        f"| Qt window: number field set → frame done (glFinish) | {vw}x{vh} | "
        f"{qt['kd'][0]:.1f} ({qt['kd'][1]:.1f}) |",
        "",
        f"Ready (numba's cache warm), median of {args.starts} starts: the URL answers "
        f"{ready['url']:.2f} s after the process starts; the first picture is in the page "
        f"{ready['picture']:.2f} s after it.",
        "",
        f"Command: `python benchmarks/bench_web.py --repeat {args.repeat} --starts {args.starts}`",
    ]  # fmt: skip
    text = "\n".join(lines) + "\n"
    publish(text, DOCS, write=not args.no_write)
    return 0


if __name__ == "__main__":
    sys.exit(main())
