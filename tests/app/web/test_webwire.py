"""explorer/app/web/wire.py without a server: the bounded un-chunker, a tab's outbox, the
publish that decides its tabs when called, and the private wslink / trame-server / aiohttp
names the module relies on (an upgrade that moves them fails here, loudly)."""

from __future__ import annotations

import asyncio
import inspect
import struct
import tracemalloc

import pytest

pytest.importorskip("wslink")
msgpack = pytest.importorskip("msgpack")

from wslink.chunking import generate_chunks  # noqa: E402

from explorer.app.web import wire as W  # noqa: E402


def frames(message, size=64, mid=None):
    out = list(generate_chunks(msgpack.packb(message), size))
    if mid is not None:
        out = [struct.pack("<I", mid) + f[4:] for f in out]
    return out


def hello_done() -> W.BoundedUnChunker:
    u = W.BoundedUnChunker()
    u.set_max_message_size(4 << 30)  # what wslink's hello asks
    return u


# -- the private API relied on --------------------------------------------------------------------
def test_the_private_api_relied_on_is_there():
    """Checked on wslink 2.6.0, trame-server 4.1.0, aiohttp 3.14: an upgrade that renames or
    reshapes these fails here rather than silently undoing the module's corrections."""
    import aiohttp.web_response
    import wslink.backends.aiohttp as backend
    import wslink.chunking as chunking
    import wslink.protocol as protocol
    from trame_server.protocol import CoreServer

    assert chunking.HEADER_LENGTH == 12
    assert chunking._decode_header(struct.pack("<III", 1, 2, 3)) == (1, 2, 3)
    handler = backend.AioHttpWsHandler
    for name in (
        "onConnect",
        "onClose",
        "onMessage",
        "onCompleteMessage",
        "handleSystemMessage",
        "sendWrappedMessage",
        "sendWrappedError",
        "publish",
        "isClientAuthenticated",
        "getServerProtocol",
    ):
        assert callable(getattr(handler, name)), name
    src = inspect.getsource(protocol.WslinkHandler)
    for text in (
        "self.unchunkers[client_id] = UnChunker()",
        "self.connections = {}",
        "self.functionMap[uri] = (protocolObject, proc)",
        "set_max_message_size",
        "self.web_app.last_active_client_id = client_id",
        "protocolObject.init(\n                    self.publish,",
    ):
        assert text in src, text
    src = inspect.getsource(backend.AioHttpWsHandler.handleWsRequest)
    assert "self.connections[client_id] = current_ws" in src
    assert "await self.onMessage(is_binary(msg), msg, client_id)" in src
    assert "self._ws_handlers.append(protocol_handler)" in inspect.getsource(backend.WebAppServer)
    src = inspect.getsource(CoreServer)
    assert "self.push_state_change(client_state, skip_last_active_client=True)" in src
    assert "self.server.controller.on_server_bind(_server)" in src
    assert "self._req = request" in inspect.getsource(aiohttp.web_response.StreamResponse)


def test_abort_cuts_a_websocket_at_once():
    """:func:`webwire.abort` on a real aiohttp websocket (the private ``_req.transport``): the
    tab sees its connection end, with no close handshake awaited."""
    import aiohttp
    from aiohttp import web

    async def go():
        done = asyncio.Event()

        async def handler(request):
            ws = web.WebSocketResponse()
            await ws.prepare(request)
            W.abort(ws)
            async for _ in ws:
                pass
            done.set()
            return ws

        app = web.Application()
        app.router.add_get("/ws", handler)
        runner = web.AppRunner(app)
        await runner.setup()
        site = web.TCPSite(runner, "127.0.0.1", 0)
        await site.start()
        port = runner.addresses[0][1]
        try:
            async with aiohttp.ClientSession() as s, s.ws_connect(f"ws://127.0.0.1:{port}/ws") as c:
                msg = await asyncio.wait_for(c.receive(), 10)
                await asyncio.wait_for(done.wait(), 10)
                return msg.type
        finally:
            await runner.cleanup()

    assert asyncio.run(go()) in (aiohttp.WSMsgType.CLOSED, aiohttp.WSMsgType.ERROR)


# -- the un-chunker -------------------------------------------------------------------------------
def test_a_claim_allocates_nothing_and_one_above_the_cap_is_refused():
    u = hello_done()
    assert u.max_message_size == W.MAX_MESSAGE_BYTES
    tracemalloc.start()
    try:
        assert u.process_chunk(struct.pack("<III", 1, 0, W.MAX_MESSAGE_BYTES)) is None
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 1 << 20 and u.pending_bytes() == 0
    with pytest.raises(W.WireError, match=r"a message of 335544321 bytes .*the limit is"):
        u.process_chunk(struct.pack("<III", 2, 0, W.MAX_MESSAGE_BYTES + 1))


def test_before_the_hello_a_message_is_small():
    u = W.BoundedUnChunker()
    with pytest.raises(W.WireError, match="the limit is 512 bytes"):
        u.process_chunk(struct.pack("<III", 1, 0, 513))


def test_a_message_is_put_together_from_its_chunks_in_order():
    u = hello_done()
    message = {"id": "rpc:c0:1", "method": "m", "args": ["x" * 300]}
    parts = frames(message)
    assert len(parts) > 3
    assert [u.process_chunk(f) for f in parts[:-1]] == [None] * (len(parts) - 1)
    assert u.process_chunk(parts[-1]) == message
    assert u.pending == {}
    parts = frames(message)
    u.process_chunk(parts[0])
    with pytest.raises(W.WireError, match="wslink's chunks come in order"):
        u.process_chunk(parts[2])


@pytest.mark.parametrize("chunk", [b"", b"short", struct.pack("<III", 1, 0, 0)])
def test_a_frame_that_is_not_a_chunk_is_refused(chunk):
    with pytest.raises(W.WireError):
        hello_done().process_chunk(chunk)


def test_content_that_is_not_msgpack_is_refused():
    with pytest.raises(W.WireError, match="not msgpack"):
        hello_done().process_chunk(struct.pack("<III", 1, 0, 1) + b"\xc1")


def test_messages_under_way_are_bounded():
    u = hello_done()
    for mid in range(W.MAX_PENDING_MESSAGES):
        u.process_chunk(struct.pack("<III", mid, 0, 100) + b"x")
    with pytest.raises(W.WireError, match="messages under way"):
        u.process_chunk(struct.pack("<III", 99, 0, 100) + b"x")
    full = W.BoundedUnChunker(budget=lambda: W.MAX_PENDING_BYTES)
    full.set_max_message_size(1 << 20)
    with pytest.raises(W.WireError, match="the messages under way pass"):
        full.process_chunk(struct.pack("<III", 1, 0, 100) + b"x")


# -- a tab's outbox -------------------------------------------------------------------------------
class FakeWs:
    def __init__(self, stuck_after=None):
        self.sent = []
        self.stuck_after = stuck_after
        self.closed = False

    async def send_bytes(self, data):
        if self.stuck_after is not None and len(self.sent) >= self.stuck_after:
            await asyncio.sleep(3600)
        self.sent.append(bytes(data))


def test_an_outbox_sends_in_order_and_drops_a_tab_that_stops_reading():
    async def go():
        dropped = []
        ws = FakeWs(stuck_after=2)
        box = W.Outbox(ws, lambda why, quiet: dropped.append(why), stall=0.05, cap=1000)
        assert box.put([b"a", b"b"]) and box.put([b"c"])
        for _ in range(100):
            if dropped:
                break
            await asyncio.sleep(0.01)
        return ws.sent, dropped, box.closed, box.put([b"d"])

    sent, dropped, closed, put = asyncio.run(go())
    assert sent == [b"a", b"b"]
    assert dropped == ["a frame not taken in 0.05 s (it stopped reading)"]
    assert closed and not put


def test_an_outbox_over_its_cap_drops_the_tab():
    async def go():
        dropped = []
        box = W.Outbox(FakeWs(stuck_after=0), lambda why, quiet: dropped.append(why), cap=10)
        assert box.put([b"x" * 6])
        assert not box.put([b"y" * 6])
        box.close()
        return dropped

    assert asyncio.run(go()) == [
        "12 bytes (0.0 MiB) waiting to be sent, more than 10 bytes (0.0 MiB)"
    ]


# -- publish ----------------------------------------------------------------------------------
class Web:
    last_active_client_id = None


def wired(clients):
    """A WireHandler over fake connections (all authenticated), its outboxes recording."""
    h = W.WireHandler.__new__(W.WireHandler)
    h.connections = {c: FakeWs() for c in clients}
    h.authentified_client_ids = set(clients)
    h.unchunkers, h.outboxes, h.publish_count = {}, {}, 0
    h.web_app = Web()
    h.network_monitor = type("M", (), {"network_call_completed": lambda self: None})()
    queued = {c: [] for c in clients}
    h._outbox = lambda c: type("B", (), {"put": lambda self, f: queued[c].append(f)})()
    return h, queued


def test_a_change_goes_once_to_each_tab_but_its_sender_decided_when_published():
    h, queued = wired(["a", "b", "c"])
    h.web_app.last_active_client_id = "a"
    h.publish("trame.state.topic", {"preset": "jade"}, skip_last_active_client=True)
    h.web_app.last_active_client_id = "b"  # b speaks before anything is written: no matter
    assert {c: len(q) for c, q in queued.items()} == {"a": 0, "b": 1, "c": 1}
    h.publish("topic", 1)
    assert {c: len(q) for c, q in queued.items()} == {"a": 1, "b": 2, "c": 2}
    h.publish("topic", 2, client_id="c")
    assert {c: len(q) for c, q in queued.items()} == {"a": 1, "b": 2, "c": 3}
    assert queued["b"][0] is queued["c"][0]  # one copy of the frames for every tab


# -- the page's values (explorer/app/web/panel.page_value) -----------------------------------------
@pytest.mark.parametrize(
    ("value", "like"),
    [({"x": 1}, 0), ("1", 0), (True, 0), (1, True), (float("nan"), None), ([1], None)],
)
def test_a_page_value_of_the_wrong_kind_is_one_line_naming_the_key(value, like):
    from explorer.app.web.panel import page_value
    from explorer.core.errors import ExplorerError

    with pytest.raises(ExplorerError, match=r"^light: the page sent .*, not a value of light$"):
        page_value("light", int, value, like=like)
    assert page_value("light", int, 2, like=0) == 2
    assert page_value("light", int, 2.0, like=1) == 2
