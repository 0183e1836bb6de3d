"""Web benchmark: a slider change to the browser's new picture, beside the Qt window's slider
to frame, in the same run; and how soon ``phong-explorer web`` is ready.

    python benchmarks/bench_web.py                    # prints the table, writes docs/web_bench.md
    python benchmarks/bench_web.py --repeat 15 --no-write
    python benchmarks/bench_web.py --burners 2 --no-write   # under two CPU burners
    python benchmarks/bench_web.py --per-pixel --repeat 15   # kd change per vertex vs per pixel

- Latency: ``phong-explorer web --mesh teapot --resolution 56`` (100,578 vertices, one point
  light) in its own process, its view sized to 800x600 in headless Chromium (Debian's, driven by
  Selenium): served as it is (the page, of this machine, takes raw frames through its direct
  socket: explorer.app.web.direct), then served ``--no-direct`` (JPEGs through trame's socket, as
  a page of another machine gets them). Each sample sets the kd slider's value in the page (what
  dragging the slider does: the trame state key ``kd_step``) and waits, in the page, for the view
  to show the next picture; the time is the page's own clock (``performance.now()``) from the
  change to the animation frame after the page's worker drew that picture into the view's canvas
  (the worker reads the probe pixel there after each draw: one pixel, its cost printed): the
  message to the server, the engine update, the frame, its way back (raw, or a JPEG), the draw (a
  JPEG decoded first). Median and best over ``--repeat`` samples after two warm-up ones, each
  sample started with the view still (its lossless picture gone). Where the time goes: the
  server's own steps for each sample (``report``'s ``picture``: the change to its frame's end, the
  frame's render, read-back and encode, explorer.app.web.pictures), the picture's arrival to its
  draw, and the browser's decode of the last JPEG and PNG (``createImageBitmap`` on the bytes
  received, in the page, apart); the rest is the two messages (the change to the server, the
  picture back) and trame's work. The CPU a change takes: the server's process and the browser's
  processes (``/proc``), from the change to its picture shown, and the window's process per change
  (bench_gui).
- The Qt window's figure of the same run: :func:`bench_gui.qt_frames` (a number field set, the
  action, the panel, the engine, the upload and the frame; a private Xvfb), its view resized
  to the page's 800x600.
- ``--burners N``: N processes that spin on the CPU for the whole run (the issue's "under two
  CPU burners"), the load printed as usual.
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

import numpy as np
from bench_gui import load, machine, qt_frames  # this script's directory is on sys.path
from common import publish

from explorer.geometry import meshes as M
from explorer.render.vtk import plotter

SIZE = (800, 600)
DOCS = Path(__file__).resolve().parent.parent / "docs" / "web_bench.md"
ROOT = Path(__file__).resolve().parent.parent

#: one sample, in the page: set kd's slider step, resolve when the view shows a new picture
#: whose colour at the probe vertex's pixel is more than 8 levels from the last one's (kd 0.3
#: and 0.7 are far apart, and a still picture's lossless copy differs from its JPEG by a
#: level): the ms from the change to that picture on screen, the change's and the picture's
#: arrival (epoch ms; the arrival: a raw frame's message in the worker's direct socket, or a
#: JPEG's Blob made, KEEP_BLOBS_JS), its draw (epoch ms), the probe's own cost (ms) and whether
#: it came raw. The page's worker (explorer.app.web.pictures.PAGE_JS) draws each picture into
#: the view's canvas (a raw frame as it is; a JPEG or PNG decoded), reads the probe pixel there
#: (one pixel, after the draw: ``phongPictures.probe``) and stamps ``shown`` at its next
#: animation frame, when the drawn frame is composited: the time ends there, in the worker, not
#: when the page's busy main thread hears of it.
SAMPLE_JS = """
const [step, done] = arguments;
const c = document.querySelector('[aria-label="view"] canvas.phong-picture');
const before = c.phong.probe, seq = c.phong.seq;
const t0 = performance.now();
const on = () => {
  const p = c.phong;
  if (p.seq <= seq || !p.probe) return;
  if (before && Math.max(...p.probe.map((v, i) => Math.abs(v - before[i]))) <= 8) return;
  c.removeEventListener('phong-picture', on);
  const shown = p.shown - performance.timeOrigin;  // (the worker's epoch ms, on the page clock)
  const arrived = p.direct ? p.arrived : performance.timeOrigin + window.blobAt;
  done([shown - t0, performance.timeOrigin + t0, arrived, p.drawn, p.probeMs, p.direct]);
};
c.addEventListener('phong-picture', on);
window.trame.state.set('kd_step', step);
setTimeout(() => done(-1), 20000);
"""
#: the page keeps the last pictures' bytes it receives and when (the remote view makes a Blob
#: URL of each as its message arrives)
KEEP_BLOBS_JS = """
if (!window.keptBlobs) {
  window.keptBlobs = [];
  const make = URL.createObjectURL;
  URL.createObjectURL = (b) => {
    window.blobAt = performance.now();
    window.keptBlobs.push(b);
    if (window.keptBlobs.length > 4) window.keptBlobs.shift();
    return make.call(URL, b);
  };
}
"""
#: the browser's decode (ms, median of 7) of the last JPEG and the last PNG kept
DECODE_JS = """
const done = arguments[0];
(async () => {
  const out = {};
  for (const b of window.keptBlobs) {
    const head = new Uint8Array(await b.slice(0, 4).arrayBuffer());
    const kind = head[0] === 0x89 ? 'png' : 'jpeg';
    const ts = [];
    for (let i = 0; i < 7; i++) {
      const t0 = performance.now();
      const bmp = await createImageBitmap(b);
      ts.push(performance.now() - t0);
      bmp.close();
    }
    ts.sort((a, b) => a - b);
    out[kind] = [ts[3], b.size];
  }
  done(out);
})();
"""
#: the view's picture shown: its size and its canvas's box (CSS pixels), null before the first
PICTURE_JS = """
const c = document.querySelector('[aria-label="view"] canvas.phong-picture');
return c && c.phong.shown ? [...c.phong.size, c.getBoundingClientRect().width,
  c.getBoundingClientRect().height] : null;
"""


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def browser():
    from explorer.app.browser import new_browser  # the tests' headless Chromium

    return new_browser(downloads=Path(os.environ.get("TMPDIR", "/tmp")), console_log=True)


def start_server(port: int, log, *extra: str) -> subprocess.Popen:
    """``phong-explorer web`` on the 100,578-vertex teapot (``extra``: more options, e.g.
    ``--per-pixel``)."""
    # the server keeps its session when it stops (web --last): not over the user's own
    last = Path(tempfile.gettempdir()) / f"bench-web-{os.getpid()}-last-session.yaml"
    env = dict(os.environ, PYTHONPATH=str(ROOT), PHONG_EXPLORER_LAST_SESSION=str(last))
    return subprocess.Popen(
        [sys.executable, "-m", "explorer.cli", "web", "--mesh", "teapot", "--resolution", "56",
         "--port", str(port), *extra],
        stdout=log, stderr=subprocess.STDOUT, env=env,
    )  # fmt: skip


def stop(proc: subprocess.Popen) -> None:
    """End a server (it keeps its session on the way out: a loaded machine may take a while)."""
    proc.terminate()
    try:
        proc.wait(60)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(10)


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
    """Median seconds from the process start to the URL answering and to the first picture,
    and from the page's request to its first picture."""
    url_s, picture_s, request_s = [], [], []
    for _ in range(starts):
        port = free_port()
        path = Path(tempfile.gettempdir()) / f"bench-web-{os.getpid()}-{port}.log"
        with open(path, "w") as log:
            t0 = time.perf_counter()
            proc = start_server(port, log)
            try:
                url = wait_url(port, path)
                url_s.append(time.perf_counter() - t0)
                t1 = time.perf_counter()
                driver.get(url)
                wait_picture(driver)
                picture_s.append(time.perf_counter() - t0)
                request_s.append(time.perf_counter() - t1)
            finally:
                stop(proc)
        path.unlink()
        driver.get("about:blank")
    return {
        "url": statistics.median(url_s),
        "picture": statistics.median(picture_s),
        "request": statistics.median(request_s),
    }


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


REPORT_JS = "const done = arguments[0]; window.trame.trigger('report').then(done);"


def cpu_ms(pids) -> float:
    """The CPU time (ms, user and system) processes ``pids`` have used so far."""
    total = 0
    for pid in pids:
        try:
            with open(f"/proc/{pid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            total += int(fields[11]) + int(fields[12])  # utime, stime (clock ticks)
        except (OSError, IndexError, ValueError):
            pass  # (a process that ended)
    return 1e3 * total / os.sysconf("SC_CLK_TCK")


def descendants(pid: int) -> list[int]:
    """``pid`` and every process under it (the browser's: chromedriver's children)."""
    parent = {}
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                with open(f"/proc/{d}/stat") as f:
                    parent[int(d)] = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                pass
    out, todo = [], [pid]
    while todo:
        p = todo.pop()
        out.append(p)
        todo += [c for c, pp in parent.items() if pp == p]
    return out


def latency(driver, url: str, repeat: int, server_pid: int | None = None) -> dict:
    """Median and best ms from a kd slider change to the new picture on screen in the page
    (``ms``, ``best``), the view's ``size``, the median of each server step (``steps``), the
    browser's decode (``decode``: kind -> (ms, bytes)), the CPU a change takes (``cpu``:
    median ms of the server's process and of the browser's processes, from the change to its
    picture shown) and the probe's own read (``probe_ms``: median ms, in the page's worker)."""
    driver.get(url)
    size = size_view(driver)
    driver.execute_script(KEEP_BLOBS_JS)
    time.sleep(1.0)
    rep = driver.execute_async_script(REPORT_JS)
    driver.execute_script("window.phongPictures.probe = arguments[0];", rep["probe"]["px"])
    ts, steps, cpus, probe_ms, raws = [], [], [], [], []
    browser_pids = descendants(driver.service.process.pid)
    for i in range(repeat + 2):
        step = 300 + 400 * (i % 2)  # kd 0.3 and 0.7
        c0 = cpu_ms([server_pid] if server_pid else []), cpu_ms(browser_pids)
        got = driver.execute_async_script(SAMPLE_JS, step)
        c1 = cpu_ms([server_pid] if server_pid else []), cpu_ms(browser_pids)
        if got == -1:
            raise RuntimeError("the picture did not change within 20 s")
        t, changed, arrived, drawn, probe, direct = got
        if i >= 2:
            raws.append(bool(direct))
            ts.append(float(t))
            probe_ms.append(float(probe))
            cpus.append((c1[0] - c0[0], c1[1] - c0[1]))
            st = driver.execute_async_script(REPORT_JS).get("picture") or {}
            if "at" in st:  # (the page's and the server's clocks: one machine's)
                if st.get("change_at"):
                    st["in"] = st.pop("change_at") - changed  # the change's way to the server
                st["sent"] = st.pop("at") - changed  # the change to the picture sent
                st["back"] = arrived - changed - st["sent"]  # its way to the page
                st["shown"] = t - (arrived - changed)  # its arrival to its frame on screen
                st["drawn"] = drawn - arrived  # its arrival to its draw (decoded, drawn)
            steps.append(st)
        time.sleep(0.3)  # (the view still again: its lossless picture has gone)
    decode = driver.execute_async_script(DECODE_JS)
    size = tuple(int(v) for v in wait_picture(driver)[:2])
    keys = [k for k in steps[0] if all(s.get(k) is not None for s in steps)]  # (none: VTK's path)
    median = {k: statistics.median(float(s[k]) for s in steps) for k in keys}
    return {
        "ms": statistics.median(ts),
        "best": min(ts),
        "size": size,
        "steps": median,
        "decode": decode,
        "cpu": tuple(statistics.median(c[k] for c in cpus) for k in (0, 1)),
        "probe_ms": statistics.median(probe_ms),
        "direct": sum(raws) / len(raws),  # (the share of the samples that came raw)
    }


def burners(n: int) -> list[subprocess.Popen]:
    """``n`` processes that spin on the CPU until terminated."""
    spin = "while True: pass"
    return [subprocess.Popen([sys.executable, "-c", spin]) for _ in range(n)]


def codecs(repeat: int) -> list[str]:
    """The encoders' time (ms, median of ``repeat``), size and largest error (levels) on two
    800x600 frames: the teapot as ``render`` draws it, and the per-pixel torus (glossy plastic;
    sharp coloured highlights); VTK's JPEG writer as VTK's web path used it (progressive) and
    baseline, Pillow's JPEG (4:2:0 and 4:4:4), PNG and WebP (lossless), base64 of the JPEG."""
    import base64
    import io

    from PIL import Image
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkJPEGWriter

    from explorer.core.presets import find_preset
    from explorer.core.scene import Scene
    from explorer.render.images import encode_png
    from explorer.render.offscreen import render_image
    from explorer.render.perpixel import reference

    teapot = M.teapot(56)
    torus = M.get_mesh("torus")
    glossy = Scene(material=find_preset("glossy_plastic"))
    frames = {
        "teapot": render_image(Scene(), teapot, SIZE),
        "per-pixel torus": reference(glossy, torus, SIZE).image(),
    }

    def vtk_jpeg(a, progressive):
        img = vtkImageData()
        img.SetDimensions(a.shape[1], a.shape[0], 1)
        img.GetPointData().SetScalars(numpy_to_vtk(np.ascontiguousarray(a[::-1]).reshape(-1, 3)))
        w = vtkJPEGWriter()
        w.SetInputData(img)
        w.SetQuality(100)
        w.SetProgressive(progressive)
        w.WriteToMemoryOn()
        w.Write()
        return memoryview(w.GetResult()).tobytes()

    def pil(a, fmt, **kw):
        buf = io.BytesIO()
        Image.fromarray(a).save(buf, fmt, **kw)
        return buf.getvalue()

    ways = {
        "VTK JPEG q100, progressive, 4:2:0 (VTK's web path)": lambda a: vtk_jpeg(a, 1),
        "VTK JPEG q100, baseline, 4:2:0": lambda a: vtk_jpeg(a, 0),
        "Pillow JPEG q100, baseline, 4:2:0": lambda a: pil(a, "JPEG", quality=100, subsampling=2),
        "Pillow JPEG q100, baseline, 4:4:4 (the page's)": lambda a: pil(
            a, "JPEG", quality=100, subsampling=0
        ),
        "PNG, zlib level 1, Pillow's filters tried on every row (the still picture before)": (
            lambda a: pil(a, "PNG", compress_level=1)
        ),
        "PNG, zlib level 1, one row filter (Up; the page's still picture)": lambda a: encode_png(
            a, fast=True
        ),
        "PNG, zlib level 6": lambda a: pil(a, "PNG", compress_level=6),
        "WebP lossless, method 0": lambda a: pil(a, "WEBP", lossless=True, quality=0, method=0),
    }
    lines = [
        "| encoder | " + " | ".join(f"{n}: ms, KiB, max error" for n in frames) + " |",
        "|---|" + "---:|" * len(frames),
    ]
    jpeg = {}
    for name, way in ways.items():
        cells = []
        for fname, a in frames.items():
            ms, data = timed_call(lambda: way(a), repeat)  # noqa: B023
            back = np.asarray(Image.open(io.BytesIO(data)).convert("RGB")).astype(int)
            err = int(np.abs(back - a.astype(int)).max())
            cells.append(f"{ms:.1f}, {len(data) / 1024:.0f}, {err}")
            jpeg.setdefault(fname, data)
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    cells = [f"{timed_call(lambda d=d: base64.b64encode(d), repeat)[0]:.2f}" for d in jpeg.values()]
    lines.append(
        "| base64 of VTK's JPEG (VTK's web path; decoded again by the publisher) | "
        + " | ".join(cells)
        + " |"
    )
    return lines


def timed_call(fn, repeat: int):
    """Median ms of ``fn()`` over ``repeat`` calls, and its last result."""
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        ts.append(1000.0 * (time.perf_counter() - t))
    return statistics.median(ts), out


def breakdown(web: dict) -> list[str]:
    """Where the page's time goes (medians of the samples' steps, the decode): the steps of the
    path its pictures took (``web["direct"]``: raw frames through the direct socket, else JPEGs
    through trame's socket)."""
    st, dec = web["steps"], web["decode"]
    raw = web.get("direct", 0) > 0.5
    work = st.get("frame_ms", float("nan")) + st.get("read", 0.0) + st.get("encode", 0.0)

    def row(name, v):
        return f"| {name} | {'n/a' if v is None else f'{v:.1f}'} |"

    sent = st.get("sent")
    lines = ["| step | ms |", "|---|---:|"]
    lines += [
        row(
            "the change set in the page → the picture sent by the server (the machine's clock)",
            sent,
        ),
        row("  the change's way to the server (set in the page → its message read)", st.get("in")),
        row(
            "  trame's handling (the rest of the above)",
            None if sent is None else sent - work - st.get("in", 0.0),
        ),
        row(
            "  the controller, the engine and the frame (the server's clock, from the change "
            "to the frame's end)",
            st.get("frame_ms"),
        ),
        row(
            "    of which the frame's render (VTK, the engine's colours for the viewer)",
            st.get("render"),
        ),
        row("  read-back (the back buffer, GetPixelData)", st.get("read")),
    ]
    if raw:
        return lines + [
            row(
                "the frame's way to the page (sent → its message in the worker's direct socket)",
                st.get("back"),
            ),
            row(
                "its arrival → its frame on screen (the worker spreads the RGB to the canvas's "
                "RGBA and puts it; its next animation frame)",
                st.get("shown"),
            ),
            row("  its arrival → drawn (in the worker)", st.get("drawn")),
            "",
            f"Picture size: {st['bytes'] / 1024:.0f} KiB raw RGB, of which a change's message "
            f"sent {st.get('sent_bytes', 0) / 1024:.0f} KiB (the tiles that changed)"
            if st.get("bytes")
            else "Picture size: the frame's RGB, 3 bytes a pixel.",
        ]
    lines += [
        row("  JPEG encode (Pillow, quality 100, 4:4:4, baseline)", st.get("encode")),
        row("the picture's way to the page (sent → its Blob made in the page)", st.get("back")),
        row(
            "its Blob made → its frame on screen (the page's worker decodes it, draws it into "
            "the view's canvas; its next animation frame)",
            st.get("shown"),
        ),
        row("  its Blob made → drawn (decoded and drawn, in the worker)", st.get("drawn")),
        row(
            "  one JPEG decode, measured apart (createImageBitmap on the same bytes, the page's "
            "main thread)",
            dec.get("jpeg", [None])[0],
        ),
    ]
    size = [f"JPEG {st['bytes'] / 1024:.0f} KiB" if st.get("bytes") else ""]
    if "png" in dec:
        size.append(
            f"the still picture's PNG {dec['png'][1] / 1024:.0f} KiB, decoded in "
            f"{dec['png'][0]:.1f} ms"
        )
    return lines + ["", "Picture sizes: " + "; ".join(x for x in size if x) + "."]


def served(driver, repeat: int, *extra: str, cpu: bool = True) -> dict:
    """:func:`latency` of a server started with ``extra`` options (stopped after; ``cpu``:
    the server's CPU a change measured too)."""
    port = free_port()
    path = Path(tempfile.gettempdir()) / f"bench-web-{os.getpid()}-{port}.log"
    try:
        with open(path, "w") as log:
            proc = start_server(port, log, *extra)
            try:
                return latency(driver, wait_url(port, path), repeat, proc.pid if cpu else None)
            finally:
                stop(proc)
    finally:
        path.unlink(missing_ok=True)


def per_pixel_lines(repeat: int, rounds: int = 2) -> list[str]:
    """The page's kd change to its new picture with the explorer started per vertex and
    started ``--per-pixel`` (issue 39: per pixel within 1.3x per vertex), each a server of its
    own, alternated ``rounds`` times (a change in the load falls on both); each shading's best
    round (by median) kept. Returns the lines (markdown)."""
    driver = browser()
    before = load()
    best: dict = {}
    try:
        for _ in range(rounds):
            for name, extra in (("per-vertex", ()), ("per-pixel", ("--per-pixel",))):
                got = served(driver, repeat, *extra, cpu=False)
                if name not in best or got["ms"] < best[name]["ms"]:
                    best[name] = got
    finally:
        driver.quit()
    v, p = best["per-vertex"], best["per-pixel"]
    w, h = p["size"]
    return [
        f"The page's kd change to its new picture, 100,578-vertex teapot, 1 point light, view "
        f"{w}x{h}: median (best) ms over {repeat} changes, the best of {rounds} alternated "
        f"rounds (load average before / after: {before} / {load()}):",
        "",
        "| shading | ms |",
        "|---|---:|",
        f"| per vertex | {v['ms']:.1f} ({v['best']:.1f}) |",
        f"| per pixel | {p['ms']:.1f} ({p['best']:.1f}) |",
        "",
        f"Per pixel / per vertex: {p['ms'] / v['ms']:.2f}x (issue 39's target: 1.3x or less).",
        "",
        f"Command: `python benchmarks/bench_web.py --per-pixel --repeat {repeat}`",
    ]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=21, help="timed samples per row (21)")
    ap.add_argument("--starts", type=int, default=3, help="server starts timed (3)")
    ap.add_argument(
        "--burners", type=int, default=0, help="processes spinning on the CPU through the run (0)"
    )
    ap.add_argument("--no-write", action="store_true", help="do not write docs/web_bench.md")
    ap.add_argument(
        "--per-pixel",
        action="store_true",
        help="only the page's kd change per vertex and per pixel (prints its lines)",
    )
    args = ap.parse_args(argv)
    spinning = burners(args.burners)
    try:
        if args.per_pixel:
            print("\n".join(per_pixel_lines(args.repeat)))
            return 0
        return measure(args)
    finally:
        for p in spinning:
            p.terminate()
            p.wait(10)


def measure(args) -> int:
    driver = browser()
    before = load()
    try:
        ready = ready_times(driver, args.starts)
        pages = {}  # the direct socket's raw frames (a page of this machine), and the JPEGs
        for name, extra in (("direct", ()), ("jpeg", ("--no-direct",))):
            pages[name] = served(driver, args.repeat, *extra)
        web, jpeg = pages["direct"], pages["jpeg"]
        version = driver.capabilities.get("browserVersion", "?")
    finally:
        driver.quit()
    teapot = M.teapot(56)
    qt = qt_frames(teapot, args.repeat, view=SIZE)
    codec_rows = codecs(args.repeat)
    after = load()
    pl = plotter(SIZE, (0.0, 0.0, 0.0))
    pl.render()  # the renderer's name is known once it has drawn
    info = machine(pl)
    pl.close()

    vw, vh = qt["view"]
    ww, wh = web["size"]
    ratio = web["ms"] / qt["kd"][0]
    burning = f", {args.burners} CPU burners running" if args.burners else ""
    lines = ["# Web benchmark", "", "Machine:", ""]
    lines += [f"- {x}" for x in info]
    lines += [
        f"- browser: headless Chromium {version} (Selenium), on the same machine",
        f"- load average before / after: {before} / {after}{burning}",
        "",
    ]
    lines += [
        f"A kd change to the new picture, {teapot.n_vertices:,}-vertex teapot, 1 point light; "
        f"median (best) ms over {args.repeat} changes:",
        "",
        "| front end | view | ms |",
        "|---|---|---:|",
        f"| web page: slider value set in the page → the view's next picture on screen (page "
        f"clock); raw frames through the direct socket (a page on the server's machine; "
        f"{web['direct']:.0%} of the samples came raw) | {ww}x{wh} | {web['ms']:.1f} "
        f"({web['best']:.1f}) |",
        f"| the same page served `--no-direct`: JPEGs through trame's socket (as a page on "
        f"another machine gets them) | {jpeg['size'][0]}x{jpeg['size'][1]} | {jpeg['ms']:.1f} "
        f"({jpeg['best']:.1f}) |",
        f"| Qt window: number field set → frame done (glFinish) | {vw}x{vh} | "
        f"{qt['kd'][0]:.1f} ({qt['kd'][1]:.1f}) |",
        "",
        f"The page takes {web['ms'] - qt['kd'][0]:+.1f} ms ({ratio:.2f}x) the window's time; "
        f"served `--no-direct`, {jpeg['ms'] - qt['kd'][0]:+.1f} ms "
        f"({jpeg['ms'] / qt['kd'][0]:.2f}x).",
        "",
        f"CPU a change takes (median ms, user and system, from the change to its picture "
        f"shown; the clock ticks are 10 ms): the page's server process {web['cpu'][0]:.0f}, "
        f"the browser's processes {web['cpu'][1]:.0f} (the probe's own read of one pixel "
        f"included: {web['probe_ms']:.2f} ms median, in the page's worker); the window's "
        f"process {qt.get('cpu', {}).get('kd', float('nan')):.0f} (mean over its changes).",
        "",
        "Where the page's time goes (medians over the same changes), raw frames through the "
        "direct socket:",
        "",
        *breakdown(web),
        "",
        f"The same served `--no-direct` (JPEGs; the server's process {jpeg['cpu'][0]:.0f} ms "
        f"CPU a change, the browser's {jpeg['cpu'][1]:.0f}):",
        "",
        *breakdown(jpeg),
        "",
        f"Encoding one {SIZE[0]}x{SIZE[1]} frame (median of {args.repeat}; size; largest "
        f"error in 8-bit levels):",
        "",
        *codec_rows,
        "",
        f"Ready (numba's cache warm), median of {args.starts} starts: the URL answers "
        f"{ready['url']:.2f} s after the process starts; the first picture is in the page "
        f"{ready['picture']:.2f} s after it, {ready['request']:.2f} s after the page's request.",
        "",
        f"Command: `python benchmarks/bench_web.py --repeat {args.repeat} --starts {args.starts}"
        f"{f' --burners {args.burners}' if args.burners else ''}`",
    ]  # fmt: skip
    text = "\n".join(lines) + "\n"
    kept = kept_sections(DOCS.read_text()) if DOCS.exists() else ""
    publish(text + ("\n" + kept if kept else ""), DOCS, write=not args.no_write)
    return 0


def kept_sections(page: str) -> str:
    """The sections of ``page`` (a docs/web_bench.md) this script does not write: from its
    first ``## `` heading on (the run's own text has none), kept as they are by a new run."""
    at = page.find("\n## ")
    return page[at + 1 :] if at >= 0 else ""


if __name__ == "__main__":
    sys.exit(main())
