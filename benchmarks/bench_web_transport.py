"""How a frame best reaches a page's worker on this machine: JPEG against raw pixels, through a
worker's own websocket (the choice behind explorer.app.web.direct).

    python benchmarks/bench_web_transport.py              # 25 frames a way, two rounds
    python benchmarks/bench_web_transport.py --repeat 41 --rounds 3

An aiohttp server (this process) and headless Chromium (Debian's, Selenium) on one machine.
The page's worker opens a websocket to the server and asks for a frame; the server makes its
message (Pillow's JPEG, quality 100, 4:4:4, baseline: what the page's JPEG path sends; or the
frame's raw RGB; or RGBA) and sends it; the worker draws it into an OffscreenCanvas (the JPEG
decoded by ``createImageBitmap``; RGB spread to RGBA 4 pixels from 3 words, as the page's
worker does; RGBA as it is) and answers at its next animation frame. Times, on the page's
clock, medians: ``arrive`` (the request to the message in the worker, the server's making of
it included), ``prep`` (the decode or the spread), ``draw`` and ``total``; the server's own
``make`` and ``send`` (ms, this process's clock). The frame: the teapot as ``render`` draws it
at 800x600 (``--size``). Ways alternate within each round (a change of load falls on all).
"""

from __future__ import annotations

import argparse
import asyncio
import io
import socket
import statistics
import sys
import threading
import time

import numpy as np

from explorer.app.web.pictures import SPREAD_JS  # the page's worker's own spread to RGBA

#: the page: a worker with its canvas and its socket; ``run(kind, n)`` times ``n`` frames
PAGE = (
    """<html><body style="margin:0"><canvas id="a" width="%(w)d" height="%(h)d"></canvas>
<script>
const W = `
let ctx = null, ws = null, t0 = 0, kind = '', rgba = null, image = null;
"""
    + SPREAD_JS
    + """
onmessage = (e) => {
  const m = e.data;
  if (m.canvas) {
    ctx = m.canvas.getContext('2d', {alpha: false});
    ws = new WebSocket(m.url);
    ws.binaryType = 'arraybuffer';
    ws.onopen = () => postMessage('open');
    ws.onmessage = async (ev) => {
      const t1 = performance.now(), w = %(w)d, h = %(h)d, n = w * h;
      let t2;
      if (kind === 'jpeg') {
        const bmp = await createImageBitmap(new Blob([ev.data]),
                                            {colorSpaceConversion: 'none'});
        t2 = performance.now();
        ctx.drawImage(bmp, 0, 0);
        bmp.close();
      } else {
        if (!rgba) {
          rgba = new Uint32Array(4 * Math.ceil(n / 4));
          image = new ImageData(new Uint8ClampedArray(rgba.buffer, 0, 4 * n), w, h);
        }
        if (kind === 'rgb') spread(new Uint32Array(ev.data, 16), 0, rgba, 0, n);
        else rgba.set(new Uint32Array(ev.data, 16, n));
        t2 = performance.now();
        ctx.putImageData(image, 0, 0);
      }
      const t3 = performance.now();
      requestAnimationFrame(() => postMessage({arrive: t1 - t0, prep: t2 - t1, draw: t3 - t2,
                                               total: performance.now() - t0}));
    };
    return;
  }
  kind = m.kind;
  t0 = performance.now();
  ws.send(kind);
};`;
const worker = new Worker(URL.createObjectURL(new Blob([W], {type: 'text/javascript'})));
const off = document.getElementById('a').transferControlToOffscreen();
window.opened = new Promise((r) => { worker.onmessage = (e) => r(e.data); });
worker.postMessage({canvas: off, url: 'ws://' + location.host + '/ws'}, [off]);
window.run = async (kind, n) => {
  await window.opened;
  const out = [];
  for (let i = 0; i < n; i++) {
    out.push(await new Promise((res) => {
      worker.onmessage = (e) => res(e.data);
      worker.postMessage({kind});
    }));
    await new Promise((r) => setTimeout(r, 50));
  }
  return out;
};
</script></body></html>"""
)

WAYS = ("jpeg", "rgb", "rgba")


def message(kind: str, rgb: np.ndarray) -> bytes:
    """The frame ``rgb`` ((h, w, 3) uint8) as the server would send it."""
    if kind == "jpeg":
        from PIL import Image

        buf = io.BytesIO()
        Image.fromarray(rgb).save(buf, "JPEG", quality=100, subsampling=0)
        return buf.getvalue()
    h, w = rgb.shape[:2]
    head = np.array([1, 1, w, h], "<u4").tobytes()
    if kind == "rgb":
        body = rgb.tobytes()
        return head + body + bytes(-len(body) % 12)
    rgba = np.empty((h, w, 4), np.uint8)
    rgba[..., :3] = rgb
    rgba[..., 3] = 255
    return head + rgba.tobytes()


def serve(rgb: np.ndarray, port: int, made: dict) -> None:
    """The frames' server, in a thread of its own, until the process ends."""
    from aiohttp import WSMsgType, web

    h, w = rgb.shape[:2]

    async def page(request):
        return web.Response(text=PAGE % {"w": w, "h": h}, content_type="text/html")

    async def ws(request):
        sock = web.WebSocketResponse(compress=False)
        await sock.prepare(request)
        async for m in sock:
            if m.type != WSMsgType.TEXT:
                break
            t0 = time.perf_counter()
            data = message(m.data, rgb)
            t1 = time.perf_counter()
            await sock.send_bytes(data)
            made.setdefault(m.data, []).append((1e3 * (t1 - t0), 1e3 * (time.perf_counter() - t1)))
        return sock

    app = web.Application()
    app.router.add_get("/", page)
    app.router.add_get("/ws", ws)
    loop = asyncio.new_event_loop()
    runner = web.AppRunner(app)
    loop.run_until_complete(runner.setup())
    loop.run_until_complete(web.TCPSite(runner, "127.0.0.1", port).start())
    loop.run_forever()


def main(argv=None) -> int:
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parent))
    from bench_gui import load  # (this script's directory)
    from bench_web import browser

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=25, help="frames a way and round (25)")
    ap.add_argument("--rounds", type=int, default=2, help="rounds of the ways alternating (2)")
    ap.add_argument("--size", default="800x600", help="the frame's size (800x600)")
    args = ap.parse_args(argv)
    w, h = (int(v) for v in args.size.split("x"))

    from explorer.core.scene import Scene
    from explorer.geometry import meshes as M
    from explorer.render.offscreen import render_image

    rgb = np.ascontiguousarray(render_image(Scene(), M.teapot(56), (w, h)))
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    made: dict = {}
    threading.Thread(target=serve, args=(rgb, port, made), daemon=True).start()
    time.sleep(0.5)
    before = load()
    driver = browser()
    got: dict = {k: [] for k in WAYS}
    try:
        driver.get(f"http://127.0.0.1:{port}/")
        driver.set_script_timeout(300)
        for _ in range(args.rounds):
            for kind in WAYS:
                got[kind] += driver.execute_async_script(
                    "const [k, n, done] = arguments; run(k, n).then(done);", kind, args.repeat
                )
        version = driver.capabilities.get("browserVersion", "?")
    finally:
        driver.quit()
    print(
        f"A {w}x{h} frame to a page's worker through its websocket, headless Chromium "
        f"{version} and the server on one machine; medians of {args.rounds} x "
        f"{args.repeat} frames a way, alternating (load average before / after: {before} / "
        f"{load()}):\n"
    )
    print("| way | bytes | server: make, send | arrive | prep | draw | total |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for kind in WAYS:
        med = {k: statistics.median(r[k] for r in got[kind]) for k in got[kind][0]}
        mk = statistics.median(m for m, _ in made[kind])
        sd = statistics.median(s for _, s in made[kind])
        size = len(message(kind, rgb))
        cells = [f"{med[k]:.1f}" for k in ("arrive", "prep", "draw", "total")]
        print(
            f"| {kind} | {size / 1024:.0f} KiB | {mk:.2f}, {sd:.2f} | " + " | ".join(cells) + " |"
        )
    command = f"python benchmarks/bench_web_transport.py --repeat {args.repeat}"
    print(f"\nCommand: `{command} --rounds {args.rounds}`")
    return 0


if __name__ == "__main__":
    sys.exit(main())
