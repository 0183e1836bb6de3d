"""The page's side of the pictures (explorer.app.web.pictures.PAGE_JS, the server's socket)
as a page without the direct socket gets them (a server started ``--no-direct``): in headless
Chromium, each picture is decoded once, by the page's worker, and drawn into the
canvas over the view's ``<img>`` (which loads none), which shows the new frame after a change
and the still frame's PNG after the JPEG; the worker's probe pixel is the screenshot's; a change
the page makes goes to the server before the page redraws; the server's socket does not
deflate."""

from __future__ import annotations

import os

import numpy as np
import pytest
from test_web import open_page, report, shown_picture, view_pixels, wait
from webserver import Server, need_browser

pytestmark = pytest.mark.web

#: kept from the page's start (Chromium runs it in every new document, before the page's own
#: scripts): every ``src`` given to an image (the view's ``<img>``, trame's pooled images), and
#: every picture's Blob made, with its first bytes (JPEG ff d8, PNG 89 50)
WATCH_JS = """
window.watched = {srcs: [], blobs: []};
const d = Object.getOwnPropertyDescriptor(HTMLImageElement.prototype, 'src');
Object.defineProperty(HTMLImageElement.prototype, 'src', {
  get() { return d.get.call(this); },
  set(v) { if (String(v).startsWith('blob:')) window.watched.srcs.push(String(v));
           d.set.call(this, v); },
  configurable: true,
});
const make = URL.createObjectURL;
URL.createObjectURL = (b) => {
  const url = make.call(URL, b);
  const seen = {url, head: null};
  window.watched.blobs.push(seen);
  b.slice(0, 2).arrayBuffer().then((a) => { seen.head = Array.from(new Uint8Array(a)); });
  return url;
};
"""


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    """``phong-explorer web --mesh sphere --no-direct``: the pictures of a page that gets no
    direct socket (a page of another machine), JPEG then PNG through trame's socket (the raw
    frames of a page of this machine: test_web_direct)."""
    need_browser()
    tmp = tmp_path_factory.mktemp("web_jpeg")
    env = dict(os.environ, PHONG_EXPLORER_MATERIALS=str(tmp / "presets"))
    srv = Server(["--mesh", "sphere", "--no-direct"], tmp / "server.log", env=env)
    yield srv
    srv.stop()


@pytest.fixture(scope="module")
def page(server, browser):
    """The page, opened with :data:`WATCH_JS` running from its start."""
    browser.execute_cdp_cmd("Page.addScriptToEvaluateOnNewDocument", {"source": WATCH_JS})
    open_page(browser, server.url)
    return browser


def probe_pixel(driver, rep: dict) -> np.ndarray:
    """The view's pixel under the probe vertex, from the page's screenshot."""
    shot, box = view_pixels(driver)
    x, y = rep["probe"]["px"]
    return shot[round(box["y"] + y), round(box["x"] + x)].astype(int)


def still(driver, count: int = 1):
    """The pictures kept since the last clear once the view shows the last of at least
    ``count``, a PNG (the still frame), else None."""
    w = driver.execute_script("return window.watched")
    heads = [b["head"] for b in w["blobs"]]
    if len(heads) < count or None in heads or heads[-1] != [0x89, 0x50]:
        return None
    shown = shown_picture(driver)
    return w if shown and shown["url"] == w["blobs"][-1]["url"] else None


def test_each_picture_is_decoded_once_by_the_worker_and_drawn_without_an_img_load(page):
    wait("the start's still picture", lambda: still(page))
    rep = report(page)
    before = probe_pixel(page, rep)
    decodes = shown_picture(page)["decodes"]
    page.execute_script("window.watched.srcs = []; window.watched.blobs = [];")
    page.execute_script("window.trame.state.set('kd_step', arguments[0]);", 150)
    # the change's JPEG, then the still frame's PNG, shown by the view
    w = wait("the still picture shown", lambda: still(page, 2))
    heads = [b["head"] for b in w["blobs"]]
    assert heads[0] == [0xFF, 0xD8]  # a JPEG while it changes, then the PNG
    # no image loads a picture (trame's view stream loaded each into a pooled image, then the
    # view's <img> loaded it again; then the <img> alone: one load and decode on the main
    # thread), and the worker decoded each picture once
    assert w["srcs"] == []
    assert shown_picture(page)["decodes"] - decodes == len(w["blobs"])
    assert page.execute_script("return window.phongPictures.shown") > 0

    def moved():  # what a person sees: the new frame (kd 0.15 is far from the start's)
        p = probe_pixel(page, rep)
        return p.tolist() if np.abs(p - before).max() > 8 else None

    wait("the new colour under the probe", moved)


def test_the_workers_probe_pixel_is_the_screenshots(page):
    """The benchmark's probe (``phongPictures.probe``: the pixel read in the worker after each
    draw) reads what the screenshot shows there: the still frame's PNG, exactly."""
    wait("the start's still picture", lambda: still(page))
    rep = report(page)
    x, y = rep["probe"]["px"]
    page.execute_script("window.phongPictures.probe = arguments[0];", [x, y])
    page.execute_script("window.watched.blobs = [];")
    step = 200 if page.execute_script("return window.trame.state.get('kd_step')") > 500 else 800
    page.execute_script("window.trame.state.set('kd_step', arguments[0]);", step)
    wait("the still picture shown", lambda: still(page, 2))
    read = shown_picture(page)["probe"]
    page.execute_script("window.phongPictures.probe = null;")
    assert read == probe_pixel(page, rep).tolist()


def test_a_change_leaves_for_the_server_before_the_page_redraws(page):
    """The kd slider's change is on the socket when ``state.set`` returns: trame awaited its
    value decorators first, and Vue redrew the page's whole template in between."""
    rep = report(page)
    old = rep["session"]["scene"]["material"]["diffuse"]
    sent = page.execute_script(
        """
        const ws = WebSocket.prototype, send = ws.send;
        let n = 0;
        ws.send = function (d) { n += 1; return send.call(this, d); };
        window.trame.state.set('kd_step', arguments[0]);
        ws.send = send;
        return n;
        """,
        850,
    )
    assert sent >= 1
    wait(
        "the server's new kd",
        lambda: report(page)["session"]["scene"]["material"]["diffuse"] != old,
    )


#: every CSS transition and animation that starts in the page, kept (kind, property or
#: animation, the element's class)
MOVES_JS = """
window.moves = [];
for (const t of ['transitionrun', 'animationstart']) {
  document.addEventListener(t, (e) => window.moves.push([t, e.propertyName || e.animationName,
    String(e.target.className.baseVal ?? e.target.className)]), true);
}
"""


def test_a_change_animates_nothing_in_the_page(page):
    """A kd change moves the slider, the field and the busy mark without a CSS transition or
    animation (Vuetify's slider slid its thumb and fill for 0.2 s and trame's busy circle
    spun: a style recalculation and a layout of the page every frame, about 20 a change, on the
    cores the server's frame needs): the page's style recalculations (Chromium's own count)
    stay few; the slider's thumb and the busy mark show the new state."""
    wait("the start's still picture", lambda: still(page))
    page.execute_script(MOVES_JS)
    page.execute_cdp_cmd("Performance.enable", {})

    def recalcs() -> float:
        got = page.execute_cdp_cmd("Performance.getMetrics", {})["metrics"]
        return next(m["value"] for m in got if m["name"] == "RecalcStyleCount")

    thumb = (
        "return document.querySelector('[aria-label=\"kd_slider\"]').closest('.v-slider')"
        ".querySelector('.v-slider-thumb').getBoundingClientRect().left"
    )
    left = page.execute_script(thumb)
    page.execute_script("window.watched.srcs = []; window.watched.blobs = [];")
    step = 100 if page.execute_script("return window.trame.state.get('kd_step')") > 500 else 900
    r0 = recalcs()
    page.execute_script("window.trame.state.set('kd_step', arguments[0]);", step)
    wait("the still picture shown", lambda: still(page, 2))
    r1 = recalcs()
    assert page.execute_script("return window.moves") == []
    # Vue's patch of the slider, the field and the busy mark (and the <img>'s load, before the
    # page's worker drew the pictures): 3 here (15-28 with the transitions and the spinning
    # circle)
    assert r1 - r0 <= 6
    moved = page.execute_script(thumb)
    assert abs(moved - left) > 20  # (kd 0.1 or 0.9: the thumb far from where it was)
    mark = page.execute_script("return document.querySelector('[aria-label=\"busy\"]').className")
    assert mark.split() == ["phong-busy"]  # (the server done: the dot empty)


def test_the_servers_socket_does_not_deflate(server):
    """Offered permessage-deflate (as Chromium offers it), the server does not take it: a
    JPEG or PNG does not shrink, and deflating each picture cost a worker thread's round trip
    and the browser's inflate."""
    import websocket

    url = server.base.replace("http://", "ws://", 1) + "ws"
    ws = websocket.create_connection(
        url,
        timeout=30,
        origin=server.base.rstrip("/"),
        header=["Sec-WebSocket-Extensions: permessage-deflate; client_max_window_bits"],
    )
    try:
        headers = {k.lower(): v for k, v in (ws.getheaders() or {}).items()}
    finally:
        ws.close()
    assert ws.getstatus() == 101
    assert "permessage-deflate" not in headers.get("sec-websocket-extensions", "")
