"""The page's side of a picture, two versions of the page alternating in one run: a kd change
to its picture on screen, and the CPU the browser spends on it.

    python benchmarks/bench_web_client.py --old /path/to/old/checkout --repeat 15

Two ``phong-explorer web`` servers on the teapot (100,578 vertices), one from this checkout and
one from ``--old`` (another checkout of the project, e.g. a ``git worktree`` of main), each in
a headless Chromium of its own with its view at 800x600; the samples alternate between them,
so a change in the machine's load falls on both. Each sample sets the kd slider's step in the
page and takes, on the page's clock, the change's picture (the first picture after it: each
sample starts with the view still) at each mark the page has:

- ``blob``: its Blob made (the message read; both pages); ``free``: a task posted then runs
  (the page's main thread is free again);
- a page whose worker draws the pictures (explorer.app.web.pictures.PAGE_JS, a
  ``canvas.phong-picture`` in the view): ``drawn`` (decoded and drawn, in the worker) and
  ``shown`` (the worker's next animation frame after the draw, when it is composited);
- a page whose ``<img>`` loads them: ``load`` (its load event), ``raf`` (the page's next
  animation frame after it: the image is then decoded and rastered for that frame) and
  ``painted`` (Element Timing's ``renderTime`` of the ``<img>``'s new picture: the frame that
  shows it presented).

No pixel is read. The CPU: the browser's processes (``/proc``, user and system) from the change
to 0.25 s after it, the change's picture and the still PNG after it included.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import bench_web as B  # this script's directory is on sys.path
from bench_gui import load

#: the marks, kept in the page from its start (after PAGE_JS): every Blob URL made, the view's
#: <img>'s load events and its next animation frames, its Element Timing entries, and the
#: canvas's reports (the worker's)
MARKS_JS = """
if (!window.marks) {
  const M = window.marks = {blob: [], free: [], load: [], raf: [], painted: [], canvas: []};
  const make = URL.createObjectURL;
  URL.createObjectURL = (b) => {
    const url = make.call(URL, b);
    M.blob.push([performance.now(), url]);
    const ch = new MessageChannel();  // (a task posted now runs when the main thread is free)
    ch.port1.onmessage = () => M.free.push([performance.now(), url]);
    ch.port2.postMessage(0);
    return url;
  };
  const img = document.querySelector('[aria-label="view"] img');
  img.setAttribute('elementtiming', 'view');
  img.addEventListener('load', () => {
    M.load.push([performance.now(), img.src]);
    requestAnimationFrame(() => M.raf.push([performance.now(), img.src]));
  });
  new PerformanceObserver((l) => {
    for (const e of l.getEntries()) M.painted.push([e.renderTime, e.url]);
  }).observe({type: 'element', buffered: false});
  const c = document.querySelector('[aria-label="view"] canvas.phong-picture');
  if (c) c.addEventListener('phong-picture', () => M.canvas.push([
    c.phong.drawn - performance.timeOrigin, c.phong.shown - performance.timeOrigin, c.phong.url]));
}
"""
#: one sample: the change at t0; after ``wait`` ms, each mark of its picture (ms after t0)
SAMPLE_JS = """
const [step, wait, done] = arguments;
const M = window.marks;
for (const k of Object.keys(M)) M[k] = [];
const t0 = performance.now();
window.trame.state.set('kd_step', step);
setTimeout(() => {
  const [tb, url] = M.blob[0] || [null, null];
  const of = (list, i = 0) => {
    const e = list.find((m) => m[m.length - 1] === url);
    return e ? e[i] - t0 : null;
  };
  done({blob: tb === null ? null : tb - t0, free: of(M.free), load: of(M.load), raf: of(M.raf),
        painted: of(M.painted), drawn: of(M.canvas), shown: of(M.canvas, 1),
        pictures: M.blob.length});
}, wait);
"""


def open_page(root: Path, log_dir: Path):
    """A server from checkout ``root`` and a browser showing its page at 800x600; returns
    (server process, driver, the browser's processes, log path)."""
    port = B.free_port()
    path = log_dir / f"bench-web-client-{os.getpid()}-{port}.log"
    last = log_dir / f"bench-web-client-{os.getpid()}-{port}-last-session.yaml"
    env = dict(os.environ, PYTHONPATH=str(root), PHONG_EXPLORER_LAST_SESSION=str(last))
    log = open(path, "w")
    proc = B.subprocess.Popen(
        [
            sys.executable,
            "-m",
            "explorer.cli",
            "web",
            "--mesh",
            "teapot",
            "--resolution",
            "56",
            "--port",
            str(port),
        ],
        stdout=log,
        stderr=B.subprocess.STDOUT,
        env=env,
        cwd=str(root),
    )
    driver = B.browser()
    driver.get(B.wait_url(port, path))
    size_img_view(driver)
    driver.execute_script(MARKS_JS)
    return proc, driver, B.descendants(driver.service.process.pid), path


def size_img_view(driver) -> None:
    """Resize the browser so the view's box is :data:`bench_web.SIZE` CSS pixels (either page)."""
    box = 'return document.querySelector(`[aria-label="view"] img`).getBoundingClientRect()'
    time.sleep(3.0)
    for _ in range(4):
        r = driver.execute_script(box)
        w, h = round(r["width"]), round(r["height"])
        if (w, h) == B.SIZE:
            break
        ww, wh = driver.get_window_size().values()
        driver.set_window_size(ww + B.SIZE[0] - w, wh + B.SIZE[1] - h)
        time.sleep(1.5)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--old", type=Path, required=True, help="the other checkout (the old page)")
    ap.add_argument("--repeat", type=int, default=15, help="samples per page (15)")
    args = ap.parse_args(argv)
    here = Path(__file__).resolve().parent.parent
    pages = {"old": args.old.resolve(), "new": here}
    log_dir = Path(tempfile.gettempdir())
    before = load()
    opened = {}
    try:
        for name, root in pages.items():
            opened[name] = open_page(root, log_dir)
        rows: dict[str, list[dict]] = {n: [] for n in pages}
        for i in range(args.repeat + 2):
            for name, (_, driver, pids, _) in opened.items():
                step = 300 + 400 * (i % 2)
                c0 = B.cpu_ms(pids)
                got = driver.execute_async_script(SAMPLE_JS, step, 250)
                got["cpu"] = B.cpu_ms(pids) - c0
                if i >= 2:
                    rows[name].append(got)
                time.sleep(0.3)  # (the view still again: its lossless picture has gone)
    finally:
        for proc, driver, _, path in opened.values():
            driver.quit()
            B.stop(proc)
            path.unlink(missing_ok=True)
    after = load()
    print(
        f"load average before / after: {before} / {after}; {args.repeat} samples a page, "
        "alternating; ms after the change (median, and the median of each mark minus the "
        "Blob's), the browser's CPU ms per change (median)"
    )
    marks = ("blob", "free", "drawn", "shown", "load", "raf", "painted")
    for name, got in rows.items():
        cells = []
        for k in marks:
            v = [g[k] for g in got if g[k] is not None]
            d = [g[k] - g["blob"] for g in got if g[k] is not None and g["blob"] is not None]
            if v:
                cells.append(f"{k} {statistics.median(v):.1f} (+{statistics.median(d):.1f})")
        cpu = statistics.median(g["cpu"] for g in got)
        print(f"{name} ({pages[name]}): " + ", ".join(cells) + f"; CPU {cpu:.0f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
