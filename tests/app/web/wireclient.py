"""A raw wslink client for the wire tests (tests/app/web/test_web_wire.py): what trame's page says
over its websocket, frame by frame, without a browser. The connect step is :func:`connect`
alone (the page's ``Origin`` header and wslink's hello with its secret), so a change in how a
tab must introduce itself is a change here only."""

from __future__ import annotations

import asyncio
import contextlib
import itertools

import aiohttp
import msgpack
from wslink.chunking import HEADER_LENGTH, _decode_header, generate_chunks

#: the largest frame the raw client sends (wslink's page sends 4 MiB at most)
FRAME = 4 << 20
#: the tabs of each open :func:`session` (by the session's id), closed as it ends
_TABS: dict[int, list] = {}


@contextlib.asynccontextmanager
async def session(**kw):
    """An aiohttp client session (``kw``: its options) whose tabs (:func:`connect`) are all
    closed before it is: a tab's websocket left open went to the garbage collector with its
    connection, and aiohttp's "Unclosed connection" warning then failed whichever test was
    running (test_each_tab_receives_a_change_once, in CI's two-worker run)."""
    async with aiohttp.ClientSession(**kw) as s:
        _TABS[id(s)] = tabs = []
        try:
            yield s
        finally:
            del _TABS[id(s)]
            for tab in tabs:
                await tab.close()


async def connect(session: aiohttp.ClientSession, server, *, hello: bool = True) -> Tab:
    """A tab's websocket to ``server`` (a :class:`webserver.Server`: its ``port`` and
    ``token``), introduced as trame's page introduces itself (the page's ``Origin``, wslink's
    hello with the server's token as its secret)."""
    port = server.port
    ws = await session.ws_connect(
        f"ws://127.0.0.1:{port}/ws",
        max_msg_size=0,
        compress=0,
        headers={"Origin": f"http://127.0.0.1:{port}"},
    )
    tab = Tab(ws)
    _TABS.get(id(session), []).append(tab)
    if hello:
        reply = await tab.call("wslink.hello", [{"secret": server.token}], system=True)
        assert "result" in reply, reply
    return tab


class Tab:
    """One websocket: rpc calls, state updates, and the messages received (unchunked)."""

    _ids = itertools.count(1)

    def __init__(self, ws):
        self.ws = ws
        self.received: list[dict] = []  # every whole message, in order
        self._parts: dict[int, bytearray] = {}
        self._waiting: dict[str, asyncio.Future] = {}
        self._reader = asyncio.ensure_future(self._read())

    async def send(self, message: dict) -> None:
        for chunk in generate_chunks(msgpack.packb(message), FRAME):
            await self.ws.send_bytes(chunk)

    async def call(self, method: str, args=(), *, system: bool = False, timeout: float = 30):
        """An rpc call, and its reply (``result`` or ``error``)."""
        rpcid = f"{'system' if system else 'rpc'}:c0:{next(self._ids)}"
        fut = asyncio.get_running_loop().create_future()
        self._waiting[rpcid] = fut
        await self.send(
            {"wslink": "1.0", "id": rpcid, "method": method, "args": list(args), "kwargs": {}}
        )
        return await asyncio.wait_for(fut, timeout)

    async def set_state(self, **values) -> dict:
        """What the page sends when its controls change state keys."""
        changes = [{"key": k, "value": v} for k, v in values.items()]
        return await self.call("trame.state.update", [changes])

    def state_updates(self, key: str) -> list:
        """The values of ``key`` in the server's state messages received, in order."""
        return [
            m["result"][key]
            for m in self.received
            if str(m.get("id", "")).startswith("publish:trame.state.topic")
            and isinstance(m.get("result"), dict)
            and key in m["result"]
        ]

    async def _read(self) -> None:
        async for msg in self.ws:
            if msg.type != aiohttp.WSMsgType.BINARY:
                break
            rid, offset, size = _decode_header(msg.data[:HEADER_LENGTH])
            part = self._parts.setdefault(rid, bytearray())
            part += msg.data[HEADER_LENGTH:]
            if len(part) >= size:
                del self._parts[rid]
                whole = msgpack.unpackb(bytes(part))
                self.received.append(whole)
                fut = self._waiting.pop(str(whole.get("id")), None)
                if fut is not None and not fut.done():
                    fut.set_result(whole)

    async def close(self) -> None:
        self._reader.cancel()
        await self.ws.close()
