"""The web explorer's websocket, made to survive its clients (issue 37 §2): wslink's
connection handler, corrected where a tab could make the server allocate what it only claims,
freeze every other tab, or miss (or receive many times) another tab's change.

trame serves the page over wslink's aiohttp backend: one :class:`AioHttpWsHandler` per server
reads each tab's frames (wslink's chunks: a 12-byte header, id, offset and the message's whole
size, then the content), answers its calls and publishes state changes to every tab. Checked
on wslink 2.6.0 and trame-server 4.1.0 (``tests/app/web/test_webwire.py`` pins the private names
used here, so an upgrade that moves them fails loudly); what each part corrects upstream:

- **Claims are not allocations.** ``wslink.chunking.UnChunker.process_chunk`` allocates the
  whole size a chunk's header claims (up to 4 GiB once the hello is done) before any content:
  two 12-byte frames took 2 GiB. :class:`BoundedUnChunker` refuses a claim above
  :data:`MAX_MESSAGE_BYTES`, keeps only what has arrived, in order, and bounds the content of
  unfinished messages (:data:`MAX_PENDING_MESSAGES` per tab, :data:`MAX_PENDING_BYTES` for the
  server). A tab that breaks these rules is closed, with one line in the server's output.
- **A slow tab is dropped, never waited on.** ``WslinkHandler.sendWrappedMessage`` (and
  ``sendWrappedError``) wrote each frame to every tab in turn, awaiting each write's drain under
  one lock shared by all: a tab that stopped reading stopped every answer and every new tab's
  hello. Here each tab has an :class:`Outbox` written by a task of its own; a tab whose writes
  make no progress for :data:`SEND_STALL_S` or whose queue passes :data:`MAX_OUTBOX_BYTES` is
  dropped (its connection aborted).
- **Each change once per tab, and to every other tab.** ``WslinkHandler.publish`` published once
  per tab, and each of those, with ``skip_last_active_client`` (trame-server's
  ``CoreServer.update_state`` re-sending a tab's state change to the others), went to every
  tab but the last active one: N tabs received a change N times. And "the last active tab" was
  read when the scheduled send ran, not when the change came: a tab that spoke in between was
  skipped and the sender got its own change back, so the other tab kept its old value for good
  (trame-server's cache of what was sent said it had been). :meth:`WireHandler.publish` decides
  the tabs when the change is published (all but the sender) and queues each message once per
  tab.
- **A bad call is one line, never a traceback.** ``WslinkHandler.onCompleteMessage`` logged an
  exception raised by a call with its traceback (and sent the traceback to the tab);
  ``onMessage`` let a malformed message (not a mapping, an id that is not text) raise out of
  the connection's loop, and ``onClose`` raised ``KeyError`` for a connection whose handshake
  failed (aiohttp printed both). Here a failed call is one line (:data:`log`) and the tab's
  answer names the error without the server's code; a tab that sends a message that is not a
  wslink call (or text, which wslink's page never sends) is dropped, with one line.

:func:`bind` applies it when trame makes the server (``on_server_bind``): the handler object
wslink made becomes a :class:`WireHandler`.
"""

from __future__ import annotations

import asyncio
import collections
import inspect
import logging
import os
import time

import aiohttp
import msgpack
from wslink.backends.aiohttp import AioHttpWsHandler
from wslink.chunking import HEADER_LENGTH, _decode_header, generate_chunks
from wslink.protocol import AUTHENTICATION_ERROR, EXCEPTION_ERROR, MAX_MSG_SIZE, METHOD_NOT_FOUND

from explorer.core import tolerances as tol

log = logging.getLogger(__name__)

#: the largest message a tab may send (bytes, msgpack-encoded): the largest upload, a mesh at its
#: cap with its .mtl libraries (each capped at MAX_MTL_FILE_BYTES; four of them at the cap fit),
#: and the message's own few bytes of framing. Any other message the page sends is a few KiB.
MAX_MESSAGE_BYTES = tol.MAX_MESH_FILE_BYTES + 4 * tol.MAX_MTL_FILE_BYTES
#: a tab's messages under way (chunks received, not complete): wslink's page sends one message's
#: chunks in order and few messages at a time; more means a client that only claims
MAX_PENDING_MESSAGES = 8
#: the content of unfinished messages, all tabs together (bytes): the largest message and a
#: half more, so one upload under way never blocks another tab's small calls
MAX_PENDING_BYTES = MAX_MESSAGE_BYTES + MAX_MESSAGE_BYTES // 2
#: how long one frame may wait for a tab's socket to take it (seconds): a frame is at most
#: wslink's 4 MiB, which a tab reading at 300 KB/s takes in this time; a tab slower than that,
#: or one that stopped reading, is dropped
SEND_STALL_S = 15.0
#: what may wait in one tab's queue (bytes): the largest message (an upload re-sent to the
#: other tabs) and 64 MiB of pictures and state behind it. The frames are shared between the
#: tabs' queues, so N tabs do not hold N copies.
MAX_OUTBOX_BYTES = MAX_MESSAGE_BYTES + (64 << 20)
#: the size a tab may claim before its hello (wslink's own default, 512 bytes, or its setting)
AUTH_MESSAGE_BYTES = int(os.environ.get("WSLINK_AUTH_MSG_SIZE", "512"))
#: the calls no tab may make: wslink's ``application.exit`` and ``application.exit.later``
#: stop the server for every tab (trame's page calls the second when it is destroyed)
REFUSED_METHODS = frozenset({"application.exit", "application.exit.later"})


#: when each call last arrived (its method -> epoch ms): the benchmark's split of a change's
#: time (bench_web: the page's clock is the same machine's)
ARRIVED: dict[str, float] = {}


class WireError(ValueError):
    """A tab broke the wire's rules (a message too large, chunks out of order, not wslink's)."""


def _size(n: int) -> str:
    return f"{n} bytes ({n / (1 << 20):.1f} MiB)"


class BoundedUnChunker:
    """A tab's messages put together from wslink's chunks, as ``wslink.chunking.UnChunker``
    does, but never holding more than has arrived: a message's claimed size is checked against
    the tab's limit (:data:`AUTH_MESSAGE_BYTES` before the hello, then
    :data:`MAX_MESSAGE_BYTES`), its chunks must come in order, and the content of unfinished
    messages is bounded (``budget()``: what every tab holds; :data:`MAX_PENDING_BYTES`).
    :meth:`process_chunk` raises :class:`WireError` for a chunk that breaks a rule."""

    def __init__(self, budget=None):
        self.pending: dict[int, tuple[int, bytearray]] = {}  # id -> (claimed size, content)
        self.max_message_size = AUTH_MESSAGE_BYTES
        self._budget = budget if budget is not None else self.pending_bytes

    def set_max_message_size(self, size: int) -> None:
        """wslink's hello raises the limit (to 4 GiB): never above :data:`MAX_MESSAGE_BYTES`."""
        self.max_message_size = min(int(size), MAX_MESSAGE_BYTES)

    def release_pending_messages(self) -> None:
        self.pending = {}

    def pending_bytes(self) -> int:
        return sum(len(part) for _, part in self.pending.values())

    def process_chunk(self, chunk: bytes):
        """The whole message (unpacked) once its last chunk has come, else None."""
        if len(chunk) < HEADER_LENGTH:
            raise WireError(f"a frame of {len(chunk)} bytes: shorter than wslink's header")
        mid, offset, total = _decode_header(chunk[:HEADER_LENGTH])
        content = memoryview(chunk)[HEADER_LENGTH:]
        if not 0 < total <= self.max_message_size:
            raise WireError(
                f"a message of {_size(total)}: the limit is {_size(self.max_message_size)}"
            )
        if mid not in self.pending:
            if len(self.pending) >= MAX_PENDING_MESSAGES:
                raise WireError(f"more than {MAX_PENDING_MESSAGES} messages under way")
            self.pending[mid] = (total, bytearray())
        claimed, part = self.pending[mid]
        if claimed != total or offset != len(part) or len(part) + len(content) > total:
            del self.pending[mid]
            raise WireError(
                f"a chunk at {offset} of {total} bytes, after {len(part)} of "
                f"{claimed}: wslink's chunks come in order"
            )
        if self._budget() + len(content) > MAX_PENDING_BYTES:
            del self.pending[mid]
            raise WireError(f"the messages under way pass {_size(MAX_PENDING_BYTES)}")
        part += content
        if len(part) < total:
            return None
        del self.pending[mid]
        try:
            return msgpack.unpackb(part)
        except Exception as exc:  # noqa: BLE001 - msgpack raises several kinds for bad bytes
            raise WireError(f"a message that is not msgpack ({type(exc).__name__})") from None


class Outbox:
    """One tab's outgoing frames, in order, written by a task of its own: nothing waits for
    the tab. ``drop(reason)`` is called once when the tab must go: a frame not taken within
    ``stall`` seconds, more than ``cap`` bytes waiting, or a write that failed."""

    def __init__(self, ws, drop, *, stall: float = SEND_STALL_S, cap: int = MAX_OUTBOX_BYTES):
        self.ws, self._drop, self.stall, self.cap = ws, drop, stall, cap
        self.frames: collections.deque = collections.deque()
        self.bytes = 0
        self.closed = False
        self._wake = asyncio.Event()
        self._task = asyncio.ensure_future(self._write())

    def put(self, frames) -> bool:
        """Queue ``frames`` (bytes each): False when the tab is gone or dropped for it."""
        if self.closed:
            return False
        n = sum(len(f) for f in frames)
        if self.bytes + n > self.cap:
            self.drop(f"{_size(self.bytes + n)} waiting to be sent, more than {_size(self.cap)}")
            return False
        self.frames.extend(frames)
        self.bytes += n
        self._wake.set()
        return True

    async def _write(self) -> None:
        while not self.closed:
            if not self.frames:
                self._wake.clear()
                await self._wake.wait()
                continue
            frame = self.frames.popleft()
            self.bytes -= len(frame)
            try:
                await asyncio.wait_for(self.ws.send_bytes(frame), self.stall)
            except (TimeoutError, asyncio.TimeoutError):
                self.drop(f"a frame not taken in {self.stall:g} s (it stopped reading)")
            except Exception as exc:  # noqa: BLE001 - a socket going away raises several kinds
                self.drop(f"its connection failed ({type(exc).__name__})", quiet=True)

    def drop(self, reason: str, quiet: bool = False) -> None:
        if self.closed:
            return
        self.close()
        self._drop(reason, quiet)

    def close(self) -> None:
        """No more frames; the writing task ends (a frame being written is abandoned)."""
        self.closed = True
        self.frames.clear()
        self.bytes = 0
        if self._task is not asyncio.current_task():
            self._task.cancel()
        self._wake.set()


def abort(ws) -> None:
    """``ws``'s connection cut at once (a close would wait for the tab to read what is
    queued): aiohttp's ``WebSocketResponse._req.transport``."""
    req = getattr(ws, "_req", None)
    transport = getattr(req, "transport", None)
    if transport is not None:
        transport.abort()


def _well_formed(rpc) -> bool:
    """A wslink call or notification: a mapping whose ``id`` (when there is one) and
    ``method`` are text (``WslinkHandler.onCompleteMessage`` indexes and splits them)."""
    return isinstance(rpc, dict) and (
        "id" not in rpc or (isinstance(rpc["id"], str) and isinstance(rpc.get("method"), str))
    )


#: a connection never made (:meth:`WireHandler.onClose`)
_MISSING = object()


class WireHandler(AioHttpWsHandler):
    """wslink's aiohttp connection handler with the corrections this module describes (it
    becomes the class of the handler object wslink made: :func:`bind`; no state of its own
    beyond ``outboxes`` and ``publish_count``, made there)."""

    outboxes: dict
    publish_count: int

    # -- connections ------------------------------------------------------------------------------
    async def onConnect(self, request, client_id):
        await super().onConnect(request, client_id)
        self.unchunkers[client_id] = BoundedUnChunker(self._pending_bytes)

    async def onClose(self, client_id):
        """Upstream's, without its ``KeyError`` for a connection whose handshake failed."""
        box = self.outboxes.pop(client_id, None)
        if box is not None:
            box.close()
        if self.unchunkers.pop(client_id, _MISSING) is _MISSING or not self.serverProtocol:
            return  # its handshake failed: it never connected
        if hasattr(self.serverProtocol, "onClose"):
            self.serverProtocol.onClose(client_id)
        for link in self.serverProtocol.getLinkProtocols():
            if hasattr(link, "onClose"):
                link.onClose(client_id)

    def _pending_bytes(self) -> int:
        return sum(
            u.pending_bytes() for u in self.unchunkers.values() if isinstance(u, BoundedUnChunker)
        )

    def _outbox(self, client_id) -> Outbox | None:
        box = self.outboxes.get(client_id)
        ws = self.connections.get(client_id)
        if box is None and ws is not None and not ws.closed:
            box = self.outboxes[client_id] = Outbox(
                ws, lambda why, quiet: self._drop(client_id, why, quiet)
            )
        return box

    def _drop(self, client_id, why: str, quiet: bool = False) -> None:
        """Tab ``client_id`` is cut off (its connection aborted; its loop then closes it)."""
        if client_id in self.unchunkers:
            self.unchunkers[client_id] = None  # what it sends from now on is not read
        if not quiet:
            log.warning("web: a tab was dropped: %s", why)
        ws = self.connections.get(client_id)
        if ws is not None:
            abort(ws)

    # -- what comes in ------------------------------------------------------------------------
    async def onMessage(self, is_binary, msg, client_id):
        if not is_binary:
            if msg.type == aiohttp.WSMsgType.TEXT:
                self._drop(client_id, "it sent text (wslink's page sends binary frames only)")
            return
        unchunker = self.unchunkers.get(client_id)
        if unchunker is None:
            return
        try:
            whole = unchunker.process_chunk(msg.data)
        except WireError as exc:
            self._drop(client_id, str(exc))
            return
        if whole is None:
            return
        if not _well_formed(whole):
            self._drop(client_id, "a message that is not a wslink call")
            return
        with self.network_monitor:
            await self.onCompleteMessage(whole, client_id)

    async def onCompleteMessage(self, rpc, client_id):
        """Upstream's (wslink 2.6.0), but a call's error is one line in the server's output
        and one line to the tab (no traceback either side), the calls that stop the server
        are refused (:data:`REFUSED_METHODS`), and ``args`` / ``kwargs`` of a wrong type are
        an error, not silently dropped."""
        if "id" not in rpc:
            return
        rpcid, method = rpc["id"], rpc["method"]
        ARRIVED[method] = 1e3 * time.time()
        args, kwargs = rpc.get("args", []), rpc.get("kwargs", {})
        if (
            not isinstance(args, list)
            or not isinstance(kwargs, dict)
            or not all(isinstance(k, str) for k in kwargs)
        ):
            await self.sendWrappedError(
                rpcid,
                EXCEPTION_ERROR,
                "args must be a list and kwargs a mapping",
                client_id=client_id,
            )
            return
        if await self.handleSystemMessage(rpcid, method, args, client_id):
            return
        if not self.isClientAuthenticated(client_id):
            await self.sendWrappedError(
                rpcid,
                AUTHENTICATION_ERROR,
                "Unauthorized: Skip message processing",
                client_id=client_id,
            )
            return
        if method not in self.functionMap or method in REFUSED_METHODS:
            await self.sendWrappedError(
                rpcid, METHOD_NOT_FOUND, "Unregistered method called", method, client_id=client_id
            )
            return
        obj, func = self.functionMap[method]
        try:
            self.web_app.last_active_client_id = client_id
            result = func(obj, *args, **kwargs)
            if inspect.isawaitable(result):
                result = await result
        except Exception as exc:  # noqa: BLE001 - any call's failure is the tab's answer
            text = f"{type(exc).__name__}: {exc}"[:300]
            log.warning("web: call %s failed: %s", method[:80], text)
            await self.sendWrappedError(
                rpcid,
                EXCEPTION_ERROR,
                "Exception raised",
                {"method": method, "exception": text},
                client_id=client_id,
            )
            return
        ws = self.connections.get(client_id)
        if ws is not None and not ws.closed:
            await self.sendWrappedMessage(rpcid, result, method=method, client_id=client_id)

    # -- what goes out ------------------------------------------------------------------------
    def _targets(self, client_id=None, skip_last_active_client=False) -> list:
        if client_id:
            return [client_id] if self.isClientAuthenticated(client_id) else []
        skip = self.web_app.last_active_client_id if skip_last_active_client else None
        return [c for c in self.connections if self.isClientAuthenticated(c) and c != skip]

    def _queue(self, packed: bytes, targets) -> None:
        frames = list(generate_chunks(packed, MAX_MSG_SIZE))  # one copy for every tab
        for c in targets:
            box = self._outbox(c)
            if box is not None:
                box.put(frames)
        self.network_monitor.network_call_completed()

    def _pack(self, message: dict) -> bytes | None:
        try:
            return msgpack.packb(message)
        except Exception as exc:  # noqa: BLE001 - the content is not msgpack's
            log.warning("web: a message was not sent: %s", f"{type(exc).__name__}: {exc}"[:200])
            return None

    async def sendWrappedMessage(
        self, rpcid, content, method="", client_id=None, skip_last_active_client=False
    ):
        packed = self._pack({"wslink": "1.0", "id": rpcid, "result": content})
        if packed is None:
            await self.sendWrappedError(
                rpcid, -32002, "Method result cannot be serialized", method, client_id=client_id
            )
            return
        self._queue(packed, self._targets(client_id, skip_last_active_client))

    async def sendWrappedError(self, rpcid, code, message, data=None, client_id=None):
        error = {"code": code, "message": message}
        if data:
            error["data"] = data
        packed = self._pack({"wslink": "1.0", "id": rpcid, "error": error})
        if packed is None:
            packed = msgpack.packb(
                {"wslink": "1.0", "id": rpcid, "error": {"code": code, "message": message}}
            )
        self._queue(packed, [client_id] if client_id else list(self.connections))

    def publish(self, topic, data, client_id=None, skip_last_active_client=False):
        """``data`` to tab ``client_id``, or to every tab (but the one whose call is being
        answered, with ``skip_last_active_client``: decided now), once each."""
        self.publish_count += 1
        targets = self._targets(client_id, skip_last_active_client)
        if not targets:
            return
        packed = self._pack(
            {"wslink": "1.0", "id": f"publish:{topic}:{self.publish_count}", "result": data}
        )
        if packed is not None:
            self._queue(packed, targets)


def wire(handler) -> WireHandler:
    """``handler`` (wslink's :class:`AioHttpWsHandler`, made by the server) becomes a
    :class:`WireHandler`, and the protocols publish through it."""
    if not isinstance(handler, AioHttpWsHandler):
        raise TypeError(f"not wslink's aiohttp handler: {type(handler).__name__}")
    if not isinstance(handler, WireHandler):
        handler.__class__ = WireHandler
        handler.outboxes = {}
        handler.publish_count = 0
    proto = handler.getServerProtocol()
    if proto is not None:
        for p in {id(x): x for x in (proto, *proto.getLinkProtocols())}.values():
            p.publish = handler.publish
    return handler


def bind(ws_server) -> None:
    """trame's ``on_server_bind``: every websocket handler of wslink's server ``ws_server``
    wired (:func:`wire`), and its sockets made without permessage-deflate (wslink's
    ``ws_compress``, on by default: aiohttp deflated every frame above 16 KiB in a worker
    thread, the page's JPEGs and PNGs that do not shrink, and the browser inflated them again:
    about 10 ms a picture here; the page's state messages are a few KiB)."""
    config = getattr(ws_server, "config", None)
    if isinstance(config, dict):
        config["ws_compress"] = False
    for handler in getattr(ws_server, "_ws_handlers", ()):
        wire(handler)
