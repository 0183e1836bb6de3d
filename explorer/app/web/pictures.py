"""The page's pictures: how a frame of the server's off-screen view reaches the browser.

trame's remote view (``VtkRemoteView``) gets its pictures from trame-vtk's image publisher
(``vtkWebPublishImageDelivery``): VTK's ``vtkWebApplication`` renders, reads the frame back and
hands it to ``vtkDataEncoder``, which encodes it in a thread of its own with VTK's JPEG writer
(progressive, 4:2:0 chroma), then as base64 that the publisher decodes again; the publisher
finds the picture still being encoded and sends it half a second later (or when asked again).
:class:`Pictures` replaces that step for every view the publisher serves (pane A and pane B
alike, and every page): the frame is rendered and read back under
:data:`explorer.render.vtk.DRAW_LOCK` and encoded at once, in the server's loop, as a baseline
JPEG with full chroma (4:4:4, Pillow's libjpeg-turbo, :data:`JPEG_QUALITY`), sent as a binary
attachment; once the view has been still for :data:`STILL_S` seconds the same frame follows
as a lossless PNG (:func:`explorer.render.images.encode_png` ``fast``: one row filter, zlib
level 1), encoded in a worker thread (zlib lets go of the GIL while it deflates), so the page's
pixels are then exactly the server's; not for a view no page shows any more. The browser's
decoder reads PNG and JPEG alike (it looks at the bytes, not at the Blob's ``image/jpeg``
type).

What asks for a picture stays trame's: the page (its first picture, a resize, the end of a
camera drag), the camera drag's animation ticks (a picture only when something asked since the
last), and the explorer's own frames (:meth:`WebExplorer.send`, through the view's
``update()``).

In the page, :data:`PAGE_JS` (a script the page runs before its views are made) takes the
picture the rest of its way: wslink's client reads the socket's messages as bytes (it asked for
Blobs and read each back asynchronously, twice a message), and a worker of the page decodes
each picture once (``createImageBitmap``) and draws it into a canvas laid over the view's
``<img>`` (trame's view stream loaded it into a pooled image first, then the ``<img>`` loaded
the same URL again: two loads and decodes a picture; then the ``<img>`` alone, its load event
and its paint waiting for the page's main thread, busy re-rendering Vue's template for the
state the server sends with the picture). The server's socket does not deflate
(:func:`explorer.app.web.wire.bind`): a JPEG or PNG does not shrink, and deflating it cost a
worker thread's round trip and the browser's inflate.

VTK, Pillow and numpy's pictures are imported inside the methods (``import explorer`` stays free
of VTK).
"""

from __future__ import annotations

import io
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from explorer.render.images import encode_png

#: the JPEG's quality (libjpeg's scale, 1-100) while the view changes: at 100 with 4:4:4 chroma
#: the teapot's frame comes back within 1 level of every pixel, the per-pixel torus's within 4
JPEG_QUALITY = 100
#: seconds without a new frame after which the last one is sent again losslessly (PNG): longer
#: than the gap between two frames of a slider drag (about 40-80 ms) so a drag sends JPEGs only
STILL_S = 0.15

#: the page's worker's spread of a raw frame's row (explorer.app.web.direct) into its canvas's
#: pixels: ``spread(s, i, d, j, n)`` writes ``n`` (a multiple of 4) opaque RGBA words into
#: ``d`` (a Uint32Array) from ``j`` on, from ``s`` (a Uint32Array over RGB bytes) from word
#: ``i`` on, 4 pixels from 3 little-endian words (benchmarks/bench_web_transport.py times it)
SPREAD_JS = """
    const spread = (s, i, d, j, n) => {
      for (const end = j + n; j < end; i += 3, j += 4) {
        const a = s[i], b = s[i + 1], c = s[i + 2];
        d[j] = 0xff000000 | a;
        d[j + 1] = 0xff000000 | (a >>> 24) | (b << 8);
        d[j + 2] = 0xff000000 | (b >>> 16) | (c << 16);
        d[j + 3] = 0xff000000 | (c >>> 8);
      }
    };"""

#: the page's side of the pictures (run by the page before its views are made, again harmless):
#: (1) each trame view stream hands its picture's Blob URL on at once (no pooled image decoding
#: it first: ``decodeImage`` off, and the event's ``image`` is the URL and size, which is what
#: trame-vtk's canvas view and the view's first-picture listener read of it), for the streams
#: made before and after this script; (2) the socket's binary messages arrive as ArrayBuffers,
#: handed to wslink's client as the Blob-like object it reads (``slice``, ``arrayBuffer``):
#: the socket is found at its next ``send``; (3) a change of a plain value (a number, text, a
#: switch) goes to the server at once: trame's ``state.flush`` first awaits its value
#: decorators, a few microtasks during which Vue re-renders the page's whole template for the
#: change (about 10 ms: the change's message waited for it); any other value, a busy or
#: unconnected client, a flush of named keys keep trame's own path; (4) the picture is drawn by
#: a worker, not loaded by the view's ``<img>``: when the canvas view gives its ``<img>`` a
#: picture's URL, the picture's Blob goes to a worker that decodes it (``createImageBitmap``,
#: once) and draws it into an OffscreenCanvas, whose ``<canvas class="phong-picture">`` lies
#: over the ``<img>`` (same box, ``pointer-events: none``: the mouse still reaches the view);
#: the page's main thread, busy re-rendering Vue's template for the server's state of the same
#: change, is not on the way (a browser without OffscreenCanvas keeps the ``<img>`` loading).
#: Each canvas's ``phong`` says what it shows (``seq``, ``url``, ``size``; ``drawn``: epoch ms
#: of the draw, ``shown``: of the worker's next animation frame after it, when the drawn frame
#: is composited; ``probe``: the pixel at ``phongPictures.probe`` = [x, y] if set, read in the
#: worker after the draw, and ``probeMs`` its cost; ``decodes``: the worker's decodes so far),
#: and the canvas gets a ``phong-picture`` event each time.
#: ``window.phongPictures`` counts the pictures handed on (``shown``), drawn (``drawn``) and
#: the changes sent at once (``sent``).
PAGE_JS = (
    """
(() => {
  if (window.phongPictures) return;
  const P = window.phongPictures = {shown: 0, streams: 0, bytes: false, sent: 0, drawn: 0,
                                     direct: null};
  // the Blob of each picture URL handed on (the stream makes the URL, then its event: the last
  // Blob made is the event's), until a view's <img> is given it (a few kept)
  const pictures = new Map();
  let made = null;
  const make = URL.createObjectURL;
  URL.createObjectURL = function (b) {
    const url = make.call(URL, b);
    made = {url, blob: b};
    return url;
  };
  // (1) trame's objects are frozen: each view stream is told not to decode, and a listener of
  // its own (priority 1: before the canvas view's and the view's first-picture listeners)
  // gives the event the URL as its image
  const patched = new WeakSet();
  const give = (ev) => {
    if (ev && ev.url && !ev.image) {
      const [w, h] = ev.metadata.size;
      ev.image = {src: ev.url, width: w, height: h};
      P.shown += 1;
      if (made && made.url === ev.url) {
        pictures.set(ev.url, {blob: made.blob, view: String(ev.metadata.id)});
        if (pictures.size > 8) pictures.delete(pictures.keys().next().value);
      }
    }
  };
  const streams = () => {
    const client = window.trame && window.trame.client;
    const is = client && client.getImageStream && client.getImageStream();
    for (const vs of (is && is.get('viewStreams').viewStreams) || []) {
      if (patched.has(vs)) continue;
      patched.add(vs);
      vs.onImageReady(give, 1);
      vs.setDecodeImage(false);
      P.streams += 1;
    }
  };
  streams();
  // (4) the worker: one OffscreenCanvas a view; a picture is decoded, then drawn unless a newer
  // one of the view is drawn already (decodes may end out of order); the report goes back at
  // the worker's next animation frame (the drawn frame is then composited). (5) Its direct
  // socket (explorer.app.web.direct): the raw frames of the views it shows, drawn as they
  // come; while they come, the view's JPEGs and PNGs (the same frames, later) are not drawn
  const WORKER = `
    const views = new Map();  // the page's id of a view -> its canvas and what it showed
    const byView = new Map();  // the server's id of a view -> the page's
    let decodes = 0, shows = 0, probe = null, sock = null;
    const frame = self.requestAnimationFrame ? (f) => requestAnimationFrame(f)
      : (f) => setTimeout(f, 0);
    // the drawing and its report (both paths): the canvas sized, painted, the probe read
    const show = (id, v, m, size, paint) => {
      if (v.canvas.width !== size[0] || v.canvas.height !== size[1]) {
        v.canvas.width = size[0];
        v.canvas.height = size[1];
      }
      v.ctx = v.ctx || v.canvas.getContext('2d', {alpha: false});
      paint(v.ctx);
      const drawn = performance.timeOrigin + performance.now(), seq = ++shows;
      let read = null, probeMs = 0;
      if (probe) {
        const t = performance.now();
        read = Array.from(v.ctx.getImageData(probe[0], probe[1], 1, 1).data.slice(0, 3));
        probeMs = performance.now() - t;
      }
      frame(() => postMessage({id, seq, url: m.url, size, drawn, probe: read, probeMs, decodes,
                               direct: !!m.direct, arrived: m.arrived || null,
                               shown: performance.timeOrigin + performance.now()}));
    };
    const say = (m) => { if (sock && sock.readyState === 1) sock.send(JSON.stringify(m)); };
"""
    + SPREAD_JS
    + """
    // a raw frame: the rectangles that changed, spread into the view's RGBA copy of what it
    // shows, then put into its canvas (the rectangles' box)
    const raw = (buf, arrived) => {
      if (!(buf instanceof ArrayBuffer) || buf.byteLength < 20) return;
      const [view, count, w, h, n] = new Uint32Array(buf, 0, 5);
      const id = byView.get(String(view)), v = views.get(id);
      if (v && buf.byteLength >= 20 + 16 * n) {
        if (!v.image || v.image.width !== w || v.image.height !== h) {
          v.rgba = new Uint32Array(w * h);
          v.image = new ImageData(new Uint8ClampedArray(v.rgba.buffer), w, h);
        }
        const rects = new Uint32Array(buf, 20, 4 * n);
        let at = 20 + 16 * n, x0 = w, y0 = h, x1 = 0, y1 = 0;
        for (let k = 0; k < 4 * n; k += 4) {
          const x = rects[k], y = rects[k + 1], rw = rects[k + 2], rh = rects[k + 3];
          if (at + rw * rh * 3 > buf.byteLength) break;
          const s = new Uint32Array(buf, at, rw * rh * 3 / 4);
          for (let r = 0; r < rh; r++) spread(s, r * rw * 3 / 4, v.rgba, (y + r) * w + x, rw);
          at += rw * rh * 3;
          x0 = Math.min(x0, x); y0 = Math.min(y0, y);
          x1 = Math.max(x1, x + rw); y1 = Math.max(y1, y + rh);
        }
        if (v.canvas.width !== w || v.canvas.height !== h) [x0, y0, x1, y1] = [0, 0, w, h];
        v.direct = true;  // (a new size clears the canvas: all of it put then)
        show(id, v, {url: 'direct:' + view + ':' + count, direct: true, arrived}, [w, h],
             (ctx) => { if (x1 > x0) ctx.putImageData(v.image, 0, 0, x0, y0, x1 - x0, y1 - y0); });
      }
      say({drawn: count});
    };
    const connect = (url) => {
      try {
        sock = new WebSocket(url);
      } catch (err) {
        postMessage({direct: 'refused', why: String(err)});
        return;
      }
      sock.binaryType = 'arraybuffer';
      sock.onopen = () => {
        postMessage({direct: 'open'});
        for (const g of byView.keys()) say({show: g});
      };
      sock.onclose = (e) => {
        sock = null;
        for (const v of views.values()) v.direct = false;  // (the JPEG path again)
        postMessage({direct: 'closed', code: e.code, why: e.reason});
      };
      sock.onmessage = (e) => raw(e.data, performance.timeOrigin + performance.now());
    };
    onmessage = async (e) => {
      const m = e.data;
      if (m.direct) return connect(m.direct);
      if (m.close) { if (sock) sock.close(1000, 'the page went'); return; }
      if ('probe' in m) { probe = m.probe; return; }
      if (m.canvas) {  // (its context made at its first draw: an opaque canvas is black
        views.set(m.id, {canvas: m.canvas, ctx: null, drawn: 0});  // until then)
        return;
      }
      if (m.drop) {  // (the server's view may have a newer canvas of the page by now)
        const v = views.get(m.id);
        if (v && v.view && byView.get(v.view) === m.id) {
          byView.delete(v.view);
          say({hide: v.view});
        }
        views.delete(m.id);
        return;
      }
      const v = views.get(m.id);
      if (!v) return;
      if (m.view && v.view !== m.view) {  // the server's view this canvas shows: asked for raw
        v.view = m.view;
        byView.set(m.view, m.id);
        say({show: m.view});
      }
      if (v.direct) return;  // (its raw frames come: this one was sent before, or as well)
      let bmp;
      try {
        decodes += 1;
        bmp = await createImageBitmap(m.blob, {colorSpaceConversion: 'none',
                                               premultiplyAlpha: 'none'});
      } catch (err) {
        postMessage({id: m.id, seq: m.seq, error: String(err)});
        return;
      }
      if (m.seq < v.drawn || v.direct) { bmp.close(); return; }
      v.drawn = m.seq;
      show(m.id, v, m, [bmp.width, bmp.height], (ctx) => ctx.drawImage(bmp, 0, 0));
      bmp.close();
    };`;
  let worker = null;
  try {
    if (window.Worker && window.createImageBitmap && window.OffscreenCanvas
        && HTMLCanvasElement.prototype.transferControlToOffscreen) {
      worker = new Worker(make.call(URL, new Blob([WORKER], {type: 'text/javascript'})));
    }
  } catch (err) {
    worker = null;  // (the <img> loads the pictures, as trame's view does)
  }
  if (worker) {  // (the page goes: its raw frames end now, not when the browser lets go)
    window.addEventListener('pagehide', () => worker.postMessage({close: true}));
  }
  let probe = null;  // (the probe is the worker's: it reads the pixel after each draw)
  Object.defineProperty(P, 'probe', {
    get() { return probe; },
    set(v) { probe = v; if (worker) worker.postMessage({probe: v}); },
  });
  const views = new WeakMap();  // a view's <img> -> its canvas's side
  const byId = new Map();
  let ids = 0, seq = 0;
  const canvasFor = (img, view) => {
    for (const [id, v] of byId) {  // the canvases of views gone (pane B closed): let go
      if (!v.canvas.isConnected) { byId.delete(id); worker.postMessage({id, drop: true}); }
    }
    const canvas = view.canvas = document.createElement('canvas');
    canvas.className = 'phong-picture';
    canvas.style.cssText = 'position: absolute; left: 0; top: 0; width: 100%; height: 100%; '
      + 'z-index: -1; pointer-events: none';
    img.after(canvas);  // (after the <img>, at its z-index: drawn over it)
    const off = canvas.transferControlToOffscreen();
    canvas.phong = {seq: 0, url: null, size: null, drawn: null, shown: null, probe: null};
    worker.postMessage({id: view.id, canvas: off}, [off]);
    byId.set(view.id, view);
    const state = window.trame && window.trame.state;
    const here = /^(localhost|127\\.\\d+\\.\\d+\\.\\d+|\\[::1\\])$/.test(location.hostname);
    if (P.direct === null && here && state && state.get('direct')) {  // (offered; this machine)
      const url = new URL('pictures', location.href);
      url.protocol = url.protocol === 'https:' ? 'wss:' : 'ws:';
      P.direct = 'connecting';
      worker.postMessage({direct: url.href});
    }
  };
  // a view's first picture may come before its <img> is in the page (trame's canvas view adds
  // it with its container): the canvas is made and the picture drawn once it is, looked for
  // at each animation frame (10 s at most: then the <img> loads its picture itself)
  const place = (img, view, frames = 600) => {
    if (!view.pending) return;
    if (img.parentNode) {
      canvasFor(img, view);
      worker.postMessage(view.pending);
      view.pending = null;
    } else if (frames > 0) {
      requestAnimationFrame(() => place(img, view, frames - 1));
    } else {
      src.set.call(img, view.pending.url);
      view.pending = null;
      view.url = null;
    }
  };
  const src = Object.getOwnPropertyDescriptor(HTMLImageElement.prototype, 'src');
  if (worker) {
    worker.onmessage = (e) => {
      const m = e.data, view = byId.get(m.id);
      if (typeof m.direct === 'string') {  // the direct socket's news
        P.direct = m.direct;
        if (m.direct === 'closed' && m.why) console.log('The raw pictures ended:', m.why);
        return;
      }
      if (m.error) console.log('The picture could not be decoded', m.error);
      if (!view || m.error) return;
      Object.assign(view.canvas.phong, m);
      P.drawn += 1;
      view.canvas.dispatchEvent(new Event('phong-picture'));  // (the benchmark's probe waits)
    };
    Object.defineProperty(HTMLImageElement.prototype, 'src', {
      get() { return src.get.call(this); },
      set(v) {
        const got = pictures.get(v);
        if (!got) return src.set.call(this, v);
        let view = views.get(this);
        if (!view) views.set(this, view = {id: ++ids, url: null, canvas: null, pending: null});
        if (view.url === v) return;  // (the same picture again: the first-picture listener's)
        view.url = v;
        seq += 1;
        const picture = {id: view.id, seq, blob: got.blob, url: v, view: got.view};
        if (view.canvas) return worker.postMessage(picture);
        const waiting = view.pending;
        view.pending = picture;  // (the newest picture waits for the <img> to be in the page)
        if (!waiting) place(this, view);
      },
      configurable: true,
    });
  }
  class Bytes {
    constructor(b) { this.b = b; }
    get size() { return this.b.byteLength; }
    slice(s, e) { return new Bytes(this.b.slice(s, e)); }
    arrayBuffer() { return Promise.resolve(this.b); }
  }
  const send = WebSocket.prototype.send;
  WebSocket.prototype.send = function (data) {
    const on = this.onmessage;
    if (!this.phongBytes && on) {
      this.phongBytes = true;
      this.binaryType = 'arraybuffer';
      this.onmessage = (e) => {
        streams();  // (a view made since: patched before its first picture)
        return on.call(this, e.data instanceof ArrayBuffer ? {data: new Bytes(e.data)} : e);
      };
      P.bytes = true;
    }
    return send.call(this, data);
  };
  const plain = (v) => v === null || ['number', 'string', 'boolean'].includes(typeof v);
  const state = window.trame && window.trame.state;
  if (state && state.flush && state.dirtyKeys) {
    // trame's own decorators pass a number, a text or a switch as it is (they read files and
    // objects); one registered since may not: then every change takes trame's path
    let decorated = false;
    if (state.registerDecorator) {
      const register = state.registerDecorator;
      state.registerDecorator = function (...a) {
        decorated = true;
        return register.apply(this, a);
      };
    }
    const flush = state.flush;
    state.flush = function (...keys) {
      const client = this.client;
      const dirty = [...this.dirtyKeys];
      if (decorated || keys.length || !dirty.length || client.isBusy() || !client.isConnected()
          || !dirty.every((k) => plain(this.state[k]))) {
        return flush.apply(this, keys);
      }
      this.dirtyKeys.clear();
      P.sent += 1;
      const change = dirty.map((k) => ({key: k, value: this.state[k]}));
      return client.getRemote().Trame.updateState(change).then(() => {
        this.pushFailed = false;
        return this.dirtyKeys.size ? this.flush() : undefined;
      }, (err) => {
        dirty.forEach((k) => this.dirtyKeys.add(k));
        if (!this.pushFailed) console.log('Could not push state, keys stay dirty', dirty, err);
        this.pushFailed = true;
      });
    };
  }
})();
"""
)


def encode(pixels: np.ndarray, lossless: bool) -> bytes:
    """``pixels`` (h, w, 3 uint8, rows top to bottom) as PNG (``lossless``: the fast writer of
    :func:`explorer.render.images.encode_png`, one row filter and zlib level 1, half the time
    of Pillow's five filters tried on every row) or as a baseline JPEG with 4:4:4 chroma at
    :data:`JPEG_QUALITY`."""
    if lossless:
        return encode_png(pixels, fast=True)
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(pixels).save(buf, "JPEG", quality=JPEG_QUALITY, subsampling=0)
    return buf.getvalue()


def read_back(window) -> np.ndarray:
    """The frame ``window`` drew last (h, w, 3 uint8, rows top to bottom), read from its back
    buffer (``GetPixelData``, as ``vtkWindowToImageFilter`` reads it for ``vtkWebApplication``,
    without the filter: its pipeline and image data took 1.0 ms of CPU a picture against 0.6,
    the same pixels)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkCommonCore import vtkUnsignedCharArray

    w, h = (int(v) for v in window.GetSize()[:2])
    rgb = vtkUnsignedCharArray()
    window.GetPixelData(0, 0, w - 1, h - 1, 0, rgb, 0)  # (the back buffer; rows bottom first)
    return np.ascontiguousarray(vtk_to_numpy(rgb).reshape(h, w, 3)[::-1])


class Pictures:
    """The picture path of ``publisher`` (trame-vtk's ``vtkWebPublishImageDelivery``, found
    once the server runs) in ``loop`` (the server's asyncio loop); ``guard(fn, where)`` makes a
    callback safe (an error is said on the page). :attr:`times` keeps the last picture's steps
    (ms: render, read, encode; bytes; ``at``: when it was made and ``change_at`` when the last
    change arrived, epoch ms) for the benchmark."""

    def __init__(self, publisher, loop, guard, direct=None):
        self.pub = publisher
        self.loop = loop
        self.guard = guard
        self.direct = direct  # the pages' direct sockets (web.direct.Direct), or None
        self.asked: set[str] = set()  # views asked for a picture since their last one
        self.last: dict[str, tuple[int, np.ndarray]] = {}  # view -> (picture number, pixels)
        self.count = 0  # pictures made (every view's)
        self.times: dict[str, float] = {}
        self._pool = ThreadPoolExecutor(1, thread_name_prefix="page-png")
        publisher.decode = False  # (bytes, no base64)
        publisher.push_render = self.push_render
        publisher.still_render = self.still_render

    def close(self) -> None:
        self._pool.shutdown(wait=False, cancel_futures=True)

    def resend(self, v_id: str) -> None:
        """View ``v_id``'s last frame again, losslessly (PNG), to the pages that take the JPEG
        path: a page whose direct socket ended had its last frames through it only
        (:class:`explorer.app.web.direct.Direct`'s ``gone``)."""
        last = self.last.get(v_id)
        if last is not None:
            self._still(v_id, last[0])

    # -- trame-vtk's publisher, replaced ---------------------------------------------------------
    def push_render(self, v_id, ignore_animation=False, stale_count=0) -> None:
        """The publisher's ``push_render``: a picture of view ``v_id`` is sent when anything but
        an animation tick asked for one (a tick sends what was asked during a camera drag)."""
        info = self.pub.tracking_views.get(v_id)
        if info is None or not info["enabled"]:
            return
        if not ignore_animation:
            self.asked.add(v_id)
            if self.pub.views_in_animations:
                return  # the drag's next tick sends it
        if v_id not in self.asked:
            return
        self.asked.discard(v_id)
        if "originalSize" not in info:
            info["originalSize"] = list(self.pub.get_view(v_id).GetSize())
        ratio = info.get("ratio", 1)
        size = [int(s * ratio + 0.5) for s in info["originalSize"]]
        if self.direct is not None and self.direct.covers(str(v_id)):
            info["mtime"] = self._frame({"view": v_id, "size": size})[1]
            return  # every page got it raw, through its direct socket: no JPEG, no PNG
        reply = self.still_render({"view": v_id, "size": size})
        info["mtime"] = reply["mtime"]
        self._publish(reply)
        self.loop.call_later(STILL_S, self.guard(self._still, "picture"), v_id, reply["mtime"])

    def _frame(self, options: dict) -> tuple[str, int, np.ndarray, float]:
        """View ``options["view"]`` rendered at ``options["size"]`` and read back; the frame
        sent to the direct sockets that show the view. Returns the view's id, the picture's
        number, its pixels ((h, w, 3) uint8, rows top to bottom) and when it began
        (``time.perf_counter``); :attr:`times` says its steps."""
        from explorer.app.web.wire import ARRIVED  # (wslink's, imported with the server)
        from explorer.render.vtk import DRAW_LOCK  # (VTK only once a page asks)

        t0 = time.perf_counter()
        view = self.pub.get_view(options["view"])
        v_id = str(self.pub.get_global_id(view))
        size = list(options.get("size", view.GetSize()[:2]))
        with DRAW_LOCK:  # (VTK draws one thread at a time; the read-back is of this frame)
            if size != list(view.GetSize()[:2]) and size[0] > 10 and size[1] > 10:
                view.SetSize(size)
            view.Render()
            t1 = time.perf_counter()
            pixels = read_back(view)
        t2 = time.perf_counter()
        self.count += 1
        self.last[v_id] = (self.count, pixels)
        direct = self.direct.send(v_id, self.count, pixels) if self.direct is not None else 0
        self.times = {
            "render": 1e3 * (t1 - t0),
            "read": 1e3 * (t2 - t1),
            "encode": 0.0,
            "bytes": pixels.nbytes if direct else 0,
            "direct": direct,  # (the direct sockets the frame went to)
            "at": 1e3 * time.time(),  # (epoch ms: the page's clock is the same machine's)
            "change_at": ARRIVED.get("trame.state.update"),  # (the last change's arrival)
        }
        return v_id, self.count, pixels, t0

    def still_render(self, options: dict) -> dict:
        """The publisher's ``still_render``: view ``options["view"]`` rendered at
        ``options["size"]``, read back (:meth:`_frame`) and encoded as JPEG (its reply,
        ``image`` as bytes)."""
        v_id, count, pixels, t0 = self._frame(options)
        t2 = time.perf_counter()
        image = encode(pixels, lossless=False)
        t3 = time.perf_counter()
        self.times.update(encode=1e3 * (t3 - t2), bytes=len(image), at=1e3 * time.time())
        h, w = pixels.shape[:2]
        return {
            "image": image,
            "format": "jpeg",
            "stale": False,
            "mtime": count,
            "size": [w, h],
            "memsize": len(image),
            "global_id": v_id,
            "localTime": options.get("localTime", 0),
            "workTime": round(1e3 * (t3 - t0)),
        }

    # -- the still picture -----------------------------------------------------------------------
    def _publish(self, reply: dict) -> None:
        reply = dict(reply, id=reply["global_id"], image=self.pub.addAttachment(reply["image"]))
        self.pub.publish("viewport.image.push.subscription", reply)

    def _shown(self, v_id: str) -> bool:
        """Whether a page still shows view ``v_id``: the publisher still tracks it, enabled (the
        last page showing it removed its observer, or turned its pictures off, since)."""
        info = self.pub.tracking_views.get(v_id)
        return info is not None and bool(info.get("enabled"))

    def _still(self, v_id: str, count: int) -> None:
        """View ``v_id``'s picture number ``count`` again as PNG, if it is still the last
        picture sent and a page still shows the view (encoded in the worker thread, sent from
        the loop)."""
        n, pixels = self.last.get(v_id, (None, None))
        if n != count:
            return  # a newer picture of the view went since: it is not still
        if not self._shown(v_id):
            return  # nobody would see it
        if self.direct is not None and self.direct.covers(v_id):
            return  # every page has it exactly (raw, through its direct socket)

        def sent(future) -> None:
            if future.cancelled() or self.last.get(v_id, (None,))[0] != count:
                return  # (a newer picture went while this one was encoded)
            png = future.result()  # (an encoder's error is said, by the guard)
            h, w = pixels.shape[:2]
            self._publish(
                {
                    "image": png,
                    "format": "png",
                    "stale": False,
                    "mtime": count,
                    "size": [w, h],
                    "memsize": len(png),
                    "global_id": v_id,
                    "localTime": 0,
                    "workTime": 0,
                }
            )

        job = self._pool.submit(encode, pixels, True)

        def back(future) -> None:  # (in the worker thread)
            try:
                self.loop.call_soon_threadsafe(self.guard(sent, "picture"), future)
            except RuntimeError:  # the loop closed since (the server stopped): nothing to send
                pass

        job.add_done_callback(back)
