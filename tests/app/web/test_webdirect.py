"""The direct socket's rules (:mod:`explorer.app.web.direct`) and its admission
(:func:`explorer.app.web.guard.direct_refusal`), without a server or a browser: the frame's
layout (the whole frame first, then the tiles that changed, read back exactly), what a page's
worker may say, when a view's JPEG is skipped, and when a client goes
back to JPEG; and, with the page's picture path on a real off-screen window
(:class:`explorer.app.web.pictures.Pictures`), what goes raw and what goes as JPEG or PNG. The
page's side: tests/app/web/test_web_direct.py."""

from __future__ import annotations

import asyncio
import struct

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_web_pictures import Publisher, settle

from explorer.app.web import direct as D
from explorer.app.web import guard as G
from explorer.app.web import pictures as P

TOKEN = G.new_token()


@pytest.mark.parametrize("peer", ["127.0.0.1", "127.8.9.1", "::1", "::ffff:127.0.0.1"])
def test_a_loopback_peer_with_the_token_gets_the_socket(peer):
    assert G.loopback(peer)
    assert G.direct_refusal(peer, {"localhost"}, TOKEN, TOKEN) is None


@pytest.mark.parametrize(
    "peer, names, cookie, why",
    [
        ("192.168.1.20", {"localhost"}, TOKEN, "is not this machine"),
        ("::ffff:10.0.0.2", {"localhost"}, TOKEN, "is not this machine"),
        (None, {"localhost"}, TOKEN, "not this machine"),
        ("not an address", {"localhost"}, TOKEN, "is not this machine"),
        ("127.0.0.1", None, TOKEN, "behind a proxy"),
        ("127.0.0.1", {"localhost"}, None, "no token"),
        ("127.0.0.1", {"localhost"}, TOKEN[:-1], "no token"),
    ],
    ids=["lan", "lan-v6-mapped", "no-peer", "garbage", "proxied", "no-cookie", "wrong-token"],
)
def test_the_socket_is_refused_with_a_reason(peer, names, cookie, why):
    assert why in G.direct_refusal(peer, names, cookie, TOKEN)


def decoded(data: bytes, old: np.ndarray | None) -> tuple[list[int], np.ndarray]:
    """A frame's message read as the page's worker reads it (its header; ``old`` with the
    rectangles put in), checking its layout: widths a multiple of 4, inside the frame, the
    blocks filling the message."""
    head = list(struct.unpack_from("<IIIII", data))
    _, _, w, h, n = head
    out = np.zeros((h, w, 3), np.uint8) if old is None else old.copy()
    at = D.HEADER.size + D.RECT.size * n
    for k in range(n):
        x, y, rw, rh = D.RECT.unpack_from(data, D.HEADER.size + D.RECT.size * k)
        assert rw % 4 == 0 and x + rw <= w and y + rh <= h
        out[y : y + rh, x : x + rw] = np.frombuffer(data, np.uint8, rw * rh * 3, at).reshape(
            rh, rw, 3
        )
        at += rw * rh * 3
    assert at == len(data)
    return head, out


def test_a_first_frame_is_whole_in_rows_whose_widths_are_multiples_of_4():
    px = np.arange(6 * 7 * 3, dtype=np.uint8).reshape(6, 7, 3)  # 7 wide: two rectangles
    head, got = decoded(D.message(7, 42, px, None), None)
    assert head == [7, 42, 7, 6, 2] and np.array_equal(got, px)
    head, got = decoded(D.message(1, 1, px[:, :4], None), None)
    assert head[-1] == 1 and np.array_equal(got, px[:, :4])


@settings(max_examples=60, deadline=None)
@given(
    size=st.tuples(st.integers(4, 90), st.integers(4, 90)),
    patches=st.lists(
        st.tuples(st.integers(0, 89), st.integers(0, 89), st.integers(1, 40), st.integers(1, 40)),
        max_size=4,
    ),
    seed=st.integers(0, 2**16),
)
def test_a_later_frame_is_the_tiles_that_changed_and_gives_the_frame_exactly(size, patches, seed):
    rng = np.random.default_rng(seed)
    h, w = size
    old = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
    new = old.copy()
    for y, x, dh, dw in patches:
        new[y : y + dh, x : x + dw] = rng.integers(0, 256, 3, dtype=np.uint8)
    data = D.message(3, 9, new, old)
    head, got = decoded(data, old)
    assert head[:4] == [3, 9, w, h] and np.array_equal(got, new)
    if np.array_equal(old, new):
        assert head[4] == 0  # nothing changed: nothing sent
    # no more bytes than the tiles that changed, each widened by 3 pixels at most, with two
    # rectangles' headers (a whole row of a width not a multiple of 4 is sent as two)
    tiles = int(D.changed_tiles(old, new).sum())
    assert len(data) <= D.HEADER.size + tiles * (2 * D.RECT.size + (D.TILE + 3) * D.TILE * 3)


@pytest.mark.parametrize(
    "text, read",
    [
        ('{"show": "12"}', ("show", "12")),
        ('{"hide": "3"}', ("hide", "3")),
        ('{"drawn": 5}', ("drawn", 5)),
        ('{"show": 12}', None),
        ('{"show": "../x"}', None),
        ('{"show": "12345678901"}', None),
        ('{"drawn": -1}', None),
        ('{"drawn": true}', None),
        ('{"show": "1", "hide": "1"}', None),
        ('["show", "1"]', None),
        ("not json", None),
        ('{"show": "' + "1" * 300 + '"}', None),
        (b"bytes", None),
    ],
)
def test_a_worker_says_show_hide_or_drawn_and_nothing_else(text, read):
    assert D.said(text) == read


class Socket:
    """A direct socket's server side, in memory: what was written, how it closed."""

    def __init__(self):
        self.got: list[bytes] = []
        self.code = None

    async def send_bytes(self, data: bytes) -> None:
        self.got.append(data)

    async def close(self, code: int = 1000, message: bytes = b"") -> None:
        self.code = code


@pytest.fixture
def path():
    """The page's picture path on a real 96x64 off-screen window, with direct sockets: one
    page (``tabs``), whose views a client shows once it says so."""
    import pyvista as pv

    from explorer.render.vtk import plotter

    pl = plotter((96, 64), (0.2, 0.3, 0.4))
    pl.add_mesh(pv.Sphere(), color=(0.9, 0.4, 0.1))
    loop = asyncio.new_event_loop()
    pub = Publisher(pl.render_window)
    pics = P.Pictures(pub, loop, lambda fn, where: fn)
    tabs = [1]
    gone = []

    def resend(view):
        gone.append(view)
        pics.resend(view)

    pics.direct = D.Direct(lambda r: None, lambda: tabs[0], pics.last.get, resend, stall=5.0)
    yield pub, pics, loop, tabs, gone

    async def closed():  # (the clients' writing tasks end before the loop closes)
        for c in pics.direct.clients:
            c.close()
        await asyncio.sleep(0)

    loop.run_until_complete(closed())
    pics.close()
    loop.close()
    pl.close()


def client(loop, direct: D.Direct) -> tuple[D.Client, Socket]:
    ws = Socket()

    async def made():
        c = D.Client(ws, direct._drop, direct.stall)
        direct.clients.add(c)
        return c

    return loop.run_until_complete(made()), ws


def run(loop, seconds: float = 0.05) -> None:
    loop.run_until_complete(asyncio.sleep(seconds))


def say(loop, direct: D.Direct, c: D.Client, key: str, value) -> None:
    """Client ``c``'s worker says ``{key: value}`` (taken in the server's loop, as there)."""

    async def taken():
        direct._take(c, key, value)

    loop.run_until_complete(taken())


def test_a_view_every_page_takes_raw_gets_no_jpeg_and_no_png(path):
    pub, pics, loop, tabs, _ = path
    pub.push_render("1")  # the page's first picture: JPEG (its canvas is made for it)
    assert len(pub.sent) == 1 and pub.sent[0]["data"][:2] == b"\xff\xd8"
    c, ws = client(loop, pics.direct)
    say(loop, pics.direct, c, "show", "1")  # the worker asks: the last frame at once
    run(loop)
    assert len(ws.got) == 1
    head, got = decoded(ws.got[0], None)  # the whole frame
    assert head[:2] == [1, pics.last["1"][0]] and np.array_equal(got, pics.last["1"][1])
    pub.push_render("1")
    run(loop, P.STILL_S + 0.3)
    assert len(pub.sent) == 1  # neither a JPEG nor the still PNG went
    number, pixels = pics.last["1"]
    head, got = decoded(ws.got[-1], decoded(ws.got[0], None)[1])
    assert head[1] == number and np.array_equal(got, pixels)  # the frame itself, exactly
    assert pics.times["encode"] == 0.0 and pics.times["direct"] == 1


def test_a_page_that_begins_to_show_a_view_gets_its_first_picture_as_jpeg(path):
    """A second page's subscription to the view's pictures while a client shows the
    view, as after a reload whose old page's worker keeps its socket: the next picture goes as
    JPEG too, until a client's next ``show``."""
    pub, pics, loop, tabs, _ = path
    pub.push_render("1")
    c, ws = client(loop, pics.direct)
    say(loop, pics.direct, c, "show", "1")
    pub.push_render("1")
    assert len(pub.sent) == 1
    pics.direct.expect("1")  # (a page's viewport.image.push.observer.add: _bind_direct)
    pub.push_render("1")
    assert len(pub.sent) == 2 and pub.sent[1]["data"][:2] == b"\xff\xd8"
    say(loop, pics.direct, c, "show", "1")
    pub.push_render("1")
    assert len(pub.sent) == 2


def test_with_more_pages_than_clients_the_jpeg_goes_too(path):
    pub, pics, loop, tabs, _ = path
    pub.push_render("1")
    c, ws = client(loop, pics.direct)
    say(loop, pics.direct, c, "show", "1")
    tabs[0] = 2  # a page that has no direct socket
    pub.push_render("1")
    run(loop)
    assert len(pub.sent) == 2 and len(ws.got) == 2  # both ways


def test_slow_frames_send_the_page_back_to_jpeg_with_the_last_frame_as_png(path, monkeypatch):
    pub, pics, loop, tabs, gone = path
    monkeypatch.setattr(D, "SLOW_S", 0.0)  # every frame slow
    pub.push_render("1")
    c, ws = client(loop, pics.direct)
    say(loop, pics.direct, c, "show", "1")
    for _ in range(D.SLOW_FRAMES):
        pub.push_render("1")
        run(loop)
        say(loop, pics.direct, c, "drawn", pics.last["1"][0])
    run(loop)
    assert c.closed and ws.code == D.CLOSE_SLOW and gone == ["1"]
    settle(loop, pub, 2)
    assert pub.sent[-1]["data"][:4] == b"\x89PNG" and pub.sent[-1]["mtime"] == pics.last["1"][0]
    pub.push_render("1")  # the JPEG path again
    assert pub.sent[-1]["data"][:2] == b"\xff\xd8"


def test_frames_drawn_in_time_keep_the_client(path):
    pub, pics, loop, tabs, gone = path
    pub.push_render("1")
    c, ws = client(loop, pics.direct)
    say(loop, pics.direct, c, "show", "1")
    for _ in range(2 * D.SLOW_FRAMES):
        pub.push_render("1")
        run(loop, 0.002)  # (written, and drawn well within SLOW_S)
        say(loop, pics.direct, c, "drawn", pics.last["1"][0])
    assert not c.closed and gone == [] and c.slow == 0


def test_a_frame_never_drawn_ends_its_client(path, monkeypatch):
    """A page gone whose worker's socket stays open (or a page frozen) stops acknowledging:
    its client ends within :data:`~explorer.app.web.direct.ACK_S`."""
    pub, pics, loop, tabs, gone = path
    monkeypatch.setattr(D, "ACK_S", 0.05)
    pub.push_render("1")
    c, ws = client(loop, pics.direct)
    say(loop, pics.direct, c, "show", "1")
    pub.push_render("1")
    run(loop, 0.3)
    assert c.closed and ws.code == D.CLOSE_SLOW and gone == ["1"]
    assert not pics.direct.covers("1")


def test_a_newer_frame_takes_the_place_of_one_not_written_yet(path):
    pub, pics, loop, tabs, _ = path
    pub.push_render("1")
    c, ws = client(loop, pics.direct)
    say(loop, pics.direct, c, "show", "1")
    run(loop)
    assert len(ws.got) == 1  # (the last frame, for the show)
    for _ in range(3):  # (the loop does not run between them: nothing is written)
        pub.push_render("1")
    run(loop)
    assert len(ws.got) == 2
    head, got = decoded(ws.got[1], decoded(ws.got[0], None)[1])
    assert head[1] == pics.last["1"][0] and np.array_equal(got, pics.last["1"][1])
