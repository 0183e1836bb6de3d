"""The direct socket: the page's pictures as raw pixels, straight to its picture worker.

A JPEG costs the server its encode (1.7 ms for the teapot's 800x600 frame), then its way
through the page's main thread (wslink's message, trame's view stream, a Blob handed to the
page's worker) and its decode in the worker (2-4 ms). On this machine's loopback the same
frame's raw bytes (1.4 MiB of RGB) reach a worker's own socket in about 2.5 ms idle and are
drawn in under 1 (``benchmarks/bench_web_transport.py``; docs/web.md, "The direct socket"). So
a page on the server's own machine gets its pictures raw, lossless while the view moves:

- **The socket.** The page's picture worker (:data:`explorer.app.web.pictures.PAGE_JS`) opens
  a websocket of its own at :data:`PATH` (beside wslink's ``ws``) and says which of the
  server's views it draws: ``{"show": "<view id>"}`` once a view's canvas has its first
  picture (which came the usual way, as JPEG), ``{"hide": ...}`` when the canvas goes. The
  server answers a ``show`` with the view's last frame, then sends each new frame of the view
  as one binary message (:func:`message`): :data:`HEADER` (view id, picture number, width,
  height, rectangles), each rectangle's :data:`RECT` (x, y, width, height; widths a multiple
  of 4), then each rectangle's rows, RGB (the worker reads 4 pixels from 3 32-bit words). The
  rectangles cover the :data:`TILE`-pixel tiles that differ from the frame the client was
  sent last (:func:`changed_tiles`; all of them for a client's first frame of the view or a
  new size): a kd change on the teapot alters a third of them, a camera drag every one. The
  worker acknowledges each frame it draws: ``{"drawn": n}``.
- **Who gets one.** A page of this machine only (:func:`explorer.app.web.guard.direct_refusal`):
  the connection comes from a loopback address, the server is not behind a proxy (through
  jupyter-server-proxy its browser may be anywhere), the request passed the guard's Host and
  Origin checks (its middleware) and carries the page's cookie (the token). Anything else is
  refused (403) and the page keeps the JPEG path. ``phong-explorer web --pictures jpeg`` never
  offers the socket.
- **A slow link goes back to JPEG.** The end of an SSH tunnel or of an editor's port forward
  is a loopback address too, with the browser far away: a client whose frames take more than
  :data:`SLOW_S` from written to drawn, :data:`SLOW_FRAMES` times in a row, is closed (code
  :data:`CLOSE_SLOW`) and its page goes back to the JPEG path; the views it showed get their
  last frame again that way (the ``gone`` callback).
- **Latest wins.** A client holds at most one frame per view not yet written; a newer frame
  replaces it (a drag never queues a backlog). A write that makes no progress for
  :data:`explorer.app.web.wire.SEND_STALL_S` drops the client.
- **The JPEG only where needed.** :meth:`Direct.covers`: when as many direct clients show a
  view as there are tabs (wslink's authenticated connections), the view's JPEG and still PNG
  are not made (:class:`explorer.app.web.pictures.Pictures`).

aiohttp is imported inside the methods that use it (``import explorer`` stays free of it).
"""

from __future__ import annotations

import asyncio
import collections
import json
import logging
import struct
import time

import numpy as np

log = logging.getLogger(__name__)

#: the socket's path, beside wslink's ``/ws`` (the page opens ``<page folder>/pictures``)
PATH = "/pictures"
#: a frame's header: the view's id, the picture's number, its width and height, the number of
#: rectangles that follow (little-endian 32-bit words)
HEADER = struct.Struct("<IIIII")
#: a rectangle of a frame: x, y, width (a multiple of 4), height (pixels); its rows follow the
#: rectangles' headers, in their order, RGB
RECT = struct.Struct("<IIII")
#: the side of the square tiles a frame is compared in with the client's last (pixels): a kd
#: change on the teapot at 800x600 alters 30 % of its pixels, 34 % of its 16-pixel tiles (and
#: 56 % of their bounding box); comparing costs 0.5 ms for 900x673
TILE = 16
#: the longest message a page's worker may send (a ``show``, ``hide`` or ``drawn``)
MAX_TEXT = 256
#: seconds from a frame written to its acknowledgement above which the frame was slow: this
#: machine's loopback takes 2-6 ms idle for an 800x600 frame, and a busy machine's page may
#: stall tens of ms now and then; a 100 Mbit/s link takes 120 ms (the JPEG is 20-25x
#: smaller there), a 1 Gbit/s one 12 ms (raw frames still pay)
SLOW_S = 0.1
#: slow frames in a row after which the client goes back to JPEG (a stall of a busy machine
#: is seldom four frames long; a slow link's every frame is slow)
SLOW_FRAMES = 4
#: the close code that tells the page its link is too slow for raw frames (4000-4999: an
#: application's own)
CLOSE_SLOW = 4000
#: the frames whose write time a client keeps for their acknowledgement
KEEP_SENT = 8
#: seconds within which a frame written must be acknowledged, or the client is gone: a page
#: left (a reload, a closed tab) whose worker's socket the browser kept open
ACK_S = 1.0


def changed_tiles(old: np.ndarray, new: np.ndarray) -> np.ndarray:
    """(H, W) bool: which :data:`TILE` x :data:`TILE` tiles of ``new`` differ from ``old``
    (both (h, w, 3) uint8; H, W the tile rows and columns, the last ones partial)."""
    h, w = new.shape[:2]
    rows, cols = -(-h // TILE), -(-w // TILE)
    x = np.bitwise_xor(old.reshape(h, w * 3), new.reshape(h, w * 3))
    per_row = np.maximum.reduceat(x, np.arange(0, w * 3, TILE * 3), axis=1)  # (h, W)
    tiles = np.zeros((rows * TILE, cols), np.uint8)
    tiles[:h] = per_row
    return tiles.reshape(rows, TILE, cols).any(axis=1)


def rectangles(tiles: np.ndarray, w: int, h: int) -> list[tuple[int, int, int, int]]:
    """The rectangles (x, y, width, height) that cover the true ``tiles`` of a ``w`` x ``h``
    frame: each tile row's runs, a run kept on as long as the next tile rows have it too; each
    width made a multiple of 4 by taking in pixels to its left (unchanged pixels sent again),
    a whole row of a width that is not in two (frames are at least 4 pixels wide)."""
    out: list[tuple[int, int, int, int]] = []
    open_: dict[tuple[int, int], int] = {}  # (x0, x1) -> the y its rectangle began at
    for i in range(tiles.shape[0] + 1):
        runs = set()
        if i < tiles.shape[0]:
            t = np.flatnonzero(np.diff(np.concatenate(([0], tiles[i].astype(np.int8), [0]))))
            runs = {(a * TILE, min(b * TILE, w)) for a, b in zip(t[::2], t[1::2], strict=True)}
        for run in [r for r in open_ if r not in runs]:
            y0 = open_.pop(run)
            out += _four(run[0], run[1], y0, min(i * TILE, h), w)
        for run in runs:
            open_.setdefault(run, i * TILE)
    return out


def _four(x0: int, x1: int, y0: int, y1: int, w: int) -> list[tuple[int, int, int, int]]:
    width = -(-(x1 - x0) // 4) * 4
    if x1 - width >= 0:
        return [(x1 - width, y0, width, y1 - y0)]
    whole = w // 4 * 4  # (a whole row of a width that is not a multiple of 4)
    return [(0, y0, whole, y1 - y0), (w - 4, y0, 4, y1 - y0)]


def message(view: int, number: int, pixels: np.ndarray, old: np.ndarray | None) -> bytearray:
    """One message of the socket: frame ``number`` of ``view`` (``pixels``: (h, w, 3) uint8,
    rows top to bottom) as the rectangles that differ from ``old`` (the frame the client has:
    None, or another size, for the whole frame)."""
    h, w = pixels.shape[:2]
    if w < 4:
        rects = []  # (never a view's size: the page's smallest is 30x30)
    elif old is None or old.shape != pixels.shape:
        rects = _four(0, w, 0, h, w)
    else:
        rects = rectangles(changed_tiles(old, pixels), w, h)
    size = HEADER.size + RECT.size * len(rects) + sum(rw * rh * 3 for _, _, rw, rh in rects)
    data = bytearray(size)
    HEADER.pack_into(data, 0, view, number, w, h, len(rects))
    at = HEADER.size + RECT.size * len(rects)
    for k, (x, y, rw, rh) in enumerate(rects):
        RECT.pack_into(data, HEADER.size + RECT.size * k, x, y, rw, rh)
        n = rw * rh * 3
        block = np.frombuffer(data, np.uint8, n, at).reshape(rh, rw, 3)
        block[:] = pixels[y : y + rh, x : x + rw]
        at += n
    return data


def said(text) -> tuple[str, str | int] | None:
    """A worker's message ``text`` read: ``("show" | "hide", view id)`` or ``("drawn", n)``;
    None for anything else (the client is then closed)."""
    if not isinstance(text, str) or len(text) > MAX_TEXT:
        return None
    try:
        msg = json.loads(text)
    except ValueError:
        return None
    if not isinstance(msg, dict) or len(msg) != 1:
        return None
    ((key, value),) = msg.items()
    if key in ("show", "hide") and isinstance(value, str) and value.isdigit() and len(value) < 11:
        return key, value
    if key == "drawn" and isinstance(value, int) and not isinstance(value, bool) and value >= 0:
        return key, value
    return None


class Client:
    """One page's direct socket ``ws``: the views it shows, its frames waiting to be written
    (one a view, the newest), when each was written (for its acknowledgement) and its slow
    frames in a row. ``drop(client, code, why)`` ends it."""

    def __init__(self, ws, drop, stall: float):
        self.ws, self._drop, self.stall = ws, drop, stall
        self.views: set[str] = set()
        self.waiting: dict[str, tuple[int, np.ndarray]] = {}  # view -> (number, pixels)
        self.has: dict[str, np.ndarray] = {}  # view -> the pixels of the frame written last
        self.last_bytes = 0  # the size of the last message written
        self.sent: collections.OrderedDict[int, float] = collections.OrderedDict()
        self.slow = 0
        self.closed = False
        self._wake = asyncio.Event()
        self._task = asyncio.ensure_future(self._write())

    def put(self, view: str, number: int, pixels: np.ndarray) -> None:
        if not self.closed:
            self.waiting[view] = (number, pixels)  # (a frame not written yet is replaced)
            self._wake.set()

    async def _write(self) -> None:
        while not self.closed:
            if not self.waiting:
                self._wake.clear()
                await self._wake.wait()
                continue
            view = next(iter(self.waiting))
            number, pixels = self.waiting.pop(view)
            data = message(int(view), number, pixels, self.has.get(view))
            self.has[view] = pixels  # (a frame's arrays are never written again)
            self.last_bytes = len(data)
            try:
                await asyncio.wait_for(self.ws.send_bytes(data), self.stall)
            except (TimeoutError, asyncio.TimeoutError):
                self._drop(self, None, f"a frame not taken in {self.stall:g} s")
                return
            except Exception:  # noqa: BLE001 - a socket going away raises several kinds
                self._drop(self, None, "")
                return
            self.sent[number] = time.monotonic()
            while len(self.sent) > KEEP_SENT:
                self.sent.popitem(last=False)
            asyncio.get_running_loop().call_later(ACK_S, self._overdue, number)

    def _overdue(self, number: int) -> None:
        if number in self.sent and not self.closed:
            self._drop(self, CLOSE_SLOW, f"a frame not drawn within {ACK_S:g} s")

    def drawn(self, number: int) -> bool:
        """Frame ``number`` acknowledged: False once :data:`SLOW_FRAMES` in a row were slow."""
        at = self.sent.pop(number, None)
        if at is None:
            return True
        self.slow = self.slow + 1 if time.monotonic() - at > SLOW_S else 0
        return self.slow < SLOW_FRAMES

    def close(self) -> None:
        self.closed = True
        self.waiting.clear()
        if self._task is not asyncio.current_task():
            self._task.cancel()
        self._wake.set()


class Direct:
    """The direct sockets of a server's pages. ``refusal(request)`` says why a request may not
    have one (None: it may); ``tabs()`` counts the pages (wslink's authenticated connections);
    ``last(view)`` is a view's last frame ``(number, pixels)`` or None; ``gone(view)`` is
    called for each view a closed client showed, once it is closed (its page takes the JPEG
    path again and needs the last frame that way)."""

    def __init__(self, refusal, tabs, last, gone, *, stall: float):
        self.refusal, self.tabs, self.last, self.gone = refusal, tabs, last, gone
        self.stall = stall
        self.clients: set[Client] = set()
        self.fresh: set[str] = set()  # views a page began to show since the last show

    def showing(self, view: str) -> int:
        return sum(1 for c in self.clients if view in c.views and not c.closed)

    def last_bytes(self) -> int:
        """The size of the last message written to a client (the largest of the clients')."""
        return max((c.last_bytes for c in self.clients), default=0)

    def covers(self, view: str) -> bool:
        """Whether every tab gets ``view``'s frames here (then no JPEG is made for it): as
        many clients show it as there are tabs, and no page began to show it since the last
        ``show`` (:meth:`expect`)."""
        n = self.showing(view)
        return n > 0 and n >= self.tabs() and view not in self.fresh

    def expect(self, view: str) -> None:
        """A page began to show ``view`` (it asked for the view's pictures: trame-vtk's
        ``viewport.image.push.observer.add``): its next picture goes as JPEG (its canvas is
        made for it, and only then does its worker ask for raw frames), until a client's next
        ``show``. A reloaded page's old worker may keep its socket open a while (it counts as
        showing the view until its frames go unacknowledged for :data:`ACK_S`)."""
        self.fresh.add(view)

    def send(self, view: str, number: int, pixels: np.ndarray) -> int:
        """Frame ``number`` of ``view`` (pixels: (h, w, 3) uint8) to each client showing it:
        how many."""
        to = [c for c in self.clients if view in c.views and not c.closed]
        for c in to:
            c.put(view, number, pixels)
        return len(to)

    async def handle(self, request):
        """aiohttp's handler of :data:`PATH`."""
        from aiohttp import WSMsgType, web

        why = self.refusal(request)
        ws = web.WebSocketResponse(compress=False, max_msg_size=MAX_TEXT)
        if why is None and not ws.can_prepare(request).ok:
            why = "not a websocket request"
        if why is not None:
            log.info("web: the direct picture socket was refused: %s", why)
            return web.Response(status=403, text=f"phong-explorer: {why}\n")
        await ws.prepare(request)
        client = Client(ws, self._drop, self.stall)
        self.clients.add(client)
        try:
            async for msg in ws:
                said_ = said(msg.data) if msg.type == WSMsgType.TEXT else None
                if said_ is None:
                    self._drop(client, 1008, "it sent what the page's worker never sends")
                    break
                self._take(client, *said_)
                if client.closed:
                    break
        finally:
            self._forget(client)
        return ws

    def _take(self, client: Client, key: str, value) -> None:
        if key == "show":
            client.views.add(value)
            client.has.pop(value, None)  # (its canvas has a JPEG: the whole frame next)
            self.fresh.discard(value)
            last = self.last(value)
            if last is not None:  # (the frames made before the show went as JPEG only)
                client.put(value, *last)
        elif key == "hide":
            client.views.discard(value)
            client.waiting.pop(value, None)
            client.has.pop(value, None)
        elif not client.drawn(value):
            self._drop(client, CLOSE_SLOW, f"frames took over {SLOW_S * 1e3:g} ms to be drawn")

    def _drop(self, client: Client, code: int | None, why: str) -> None:
        """``client`` ended: closed with ``code`` (None: its connection is cut), ``why`` said in
        one line (nothing for a socket that went away)."""
        if client.closed:
            return
        views = set(client.views)
        client.close()
        if why:
            log.info("web: a page's direct pictures ended: %s", why)
        if code is None:
            from explorer.app.web.wire import abort  # (wslink and aiohttp: with the server)

            abort(client.ws)
        else:
            asyncio.ensure_future(client.ws.close(code=code, message=why.encode()[:120]))
        self._forget(client, views)

    def _forget(self, client: Client, views=None) -> None:
        views = set(client.views) if views is None else views
        client.close()
        if client in self.clients:
            self.clients.discard(client)
            for view in views:
                self.gone(view)
