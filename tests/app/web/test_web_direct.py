"""The direct socket (explorer.app.web.direct) in headless Chromium: a page of this machine
draws the server's frames raw, exactly, and the server makes no JPEG or PNG for it; the socket
is refused without the page's cookie or from another origin; a page that cannot open it (a
page of another machine) still gets every picture beside one that does; a reloaded page gets
its first picture at once (the old page's worker may keep its socket open)."""

from __future__ import annotations

import asyncio
import json

import aiohttp
import numpy as np
import pytest
from test_web import open_page, report, shown_picture, view_pixels, wait
from test_webdirect import decoded
from webserver import new_browser

from explorer.app.web import direct as D
from explorer.app.web import guard

pytestmark = pytest.mark.web

#: Chromium's preferences of a browser that keeps no cookie (the page's socket works: its token
#: comes in the address; the direct socket's request has none)
NO_COOKIES = {"profile.default_content_setting_values.cookies": 2}
#: pixels at the view's edges left out of the exact comparison (the page draws over them)
EDGE = 16

#: counts the pictures that come through trame's socket (a Blob made for each, JPEG or PNG)
COUNT_BLOBS_JS = """
window.blobsMade = 0;
const make = URL.createObjectURL;
URL.createObjectURL = (b) => { window.blobsMade += 1; return make.call(URL, b); };
"""


def shown_raw(driver) -> dict | None:
    """What the view shows once it is a raw frame (its ``url`` is ``direct:<view>:<n>``)."""
    shown = shown_picture(driver)
    return shown if shown and shown.get("direct") else None


def set_kd_step(driver, step: int) -> None:
    driver.execute_script("window.trame.state.set('kd_step', arguments[0]);", step)


def far_step(driver) -> int:
    return 200 if driver.execute_script("return window.trame.state.get('kd_step')") > 500 else 800


def test_a_page_of_this_machine_draws_the_frames_raw_exactly_and_gets_no_jpeg(server, browser):
    browser.execute_cdp_cmd("Page.addScriptToEvaluateOnNewDocument", {"source": COUNT_BLOBS_JS})
    open_page(browser, server.url)
    is_open = "return window.phongPictures.direct === 'open'"
    wait("the direct socket open", lambda: browser.execute_script(is_open))
    before = wait("a raw frame", lambda: shown_raw(browser))
    blobs = browser.execute_script("return window.blobsMade")
    set_kd_step(browser, far_step(browser))

    def changed():
        s = shown_raw(browser)
        return s if s and s["url"] != before["url"] else None

    after = wait("the change's raw frame", changed)
    # the server sends nothing through trame's socket for the view any more: no JPEG, no PNG
    rep = report(browser)
    assert browser.execute_script("return window.blobsMade") == blobs
    assert rep["picture"]["direct"] == 1 and rep["picture"]["encode"] == 0.0
    # what the page shows is the server's frame, exactly (the worker spread the RGB to RGBA):
    # the frame as the socket sends it to a client of our own with the page's cookie
    _, view, number = after["url"].split(":")
    header, frame = asyncio.run(_last_frame(server, view))
    assert header[:2] == [int(view), int(number)] and header[2:] == after["size"]
    shot, box = view_pixels(browser)
    w, h = after["size"]
    assert [round(box["w"]), round(box["h"])] == [w, h]
    x0, y0 = round(box["x"]), round(box["y"])
    got = shot[y0 : y0 + h, x0 : x0 + w]
    m = EDGE  # (the page's toolbar casts its shadow over the view's top rows)
    assert np.array_equal(got[m:-m, m:-m], frame[m:-m, m:-m])


def _headers(server) -> dict:
    """A request of the page's own: its origin and its cookie."""
    return {
        "Origin": server.base.rstrip("/"),
        "Cookie": f"{guard.cookie_name(server.port)}={server.token}",
    }


async def _last_frame(server, view: str):
    """View ``view``'s last frame through a direct socket of our own (the whole frame: a
    client's first of the view): its header (view, number, width, height) and its pixels
    (h, w, 3)."""
    url = server.base.replace("http", "ws", 1) + D.PATH.lstrip("/")
    async with aiohttp.ClientSession() as session:
        async with session.ws_connect(url, headers=_headers(server)) as ws:
            await ws.send_str(json.dumps({"show": view}))
            data = (await ws.receive(timeout=30)).data
    head, pixels = decoded(data, None)
    return head[:4], pixels


async def _handshake(base: str, headers: dict) -> int:
    """The HTTP status of a websocket request for the direct socket (101: open)."""
    url = base.replace("http", "ws", 1) + D.PATH.lstrip("/")
    async with aiohttp.ClientSession() as session:
        try:
            async with session.ws_connect(url, headers=headers) as ws:
                await ws.close()
                return 101
        except aiohttp.WSServerHandshakeError as exc:
            return exc.status


def test_the_socket_is_the_pages_only(server):
    """Refused (403) without the page's cookie, with a wrong token in it, or from a page of
    another origin; opened with the cookie from the page's own origin."""
    origin = server.base.rstrip("/")
    cookie = guard.cookie_name(server.port)

    def status(headers):
        return asyncio.run(_handshake(server.base, headers))

    assert status(_headers(server)) == 101
    assert status({"Origin": origin}) == 403
    assert status({"Origin": origin, "Cookie": f"{cookie}=not-the-token"}) == 403
    assert status({"Origin": "http://evil.example", "Cookie": f"{cookie}={server.token}"}) == 403


def test_a_page_without_the_socket_gets_every_picture_beside_one_with_it(server, browser, tmp_path):
    """Two pages of one server: one opens the direct socket, one cannot (a browser that keeps
    no cookie: refused for want of the token, as a page of another machine is refused for its
    address): a change reaches both, raw and as JPEG (the server made the JPEG because not
    every page took the frame raw), and once the JPEG page has the still PNG both show the
    same pixels."""
    open_page(browser, server.url)
    wait("a raw frame", lambda: shown_raw(browser))
    other = new_browser(tmp_path / "downloads", prefs=NO_COOKIES)
    try:
        other.get(server.url)  # (its console says the socket was refused: 403)
        wait("the cookie-less page's first picture", lambda: shown_picture(other))
        closed = "return window.phongPictures.direct === 'closed'"
        wait("the blocked page's try", lambda: other.execute_script(closed))
        seen = shown_picture(other)["url"], shown_picture(browser)["url"]
        set_kd_step(browser, far_step(browser))

        def new(driver, old):
            s = shown_picture(driver)
            return s if s and s["url"] != old else None

        raw = wait("the new raw frame", lambda: new(browser, seen[1]))
        jpeg = wait("the new picture as JPEG", lambda: new(other, seen[0]))
        assert raw["direct"] and raw["url"].startswith("direct:")
        assert not jpeg["direct"] and jpeg["url"].startswith("blob:")
        # then the other page's still PNG: both show the same frame exactly
        wait("the still PNG after the JPEG", lambda: new(other, jpeg["url"]))
        a, box_a = view_pixels(browser)
        b, box_b = view_pixels(other)
        w, h = raw["size"]
        crop_a = a[round(box_a["y"]) :, round(box_a["x"]) :][:h, :w]
        crop_b = b[round(box_b["y"]) :, round(box_b["x"]) :][:h, :w]
        m = EDGE
        assert np.array_equal(crop_a[m:-m, m:-m], crop_b[m:-m, m:-m])
    finally:
        other.quit()


def test_a_reloaded_page_gets_its_first_picture_then_raw_frames(server, browser):
    """The page left by a reload may keep its worker's socket open (Chromium does): counted as
    showing the view, it took the new page's first picture, which never came."""
    open_page(browser, server.url)
    wait("a raw frame", lambda: shown_raw(browser))
    open_page(browser, server.url)  # (waits for the first picture: STEP_TIMEOUT)
    set_kd_step(browser, far_step(browser))
    wait("a raw frame after the reload", lambda: shown_raw(browser))


def test_pane_b_shown_again_takes_raw_frames_of_each_change(server, browser):
    """Compare A | B on, off and on again: pane B's view gets a new canvas, whose raw frames
    the worker asks for; the old canvas, let go, must not take them away (its drop said
    ``hide`` for the server's view the new canvas shows, and pane B kept its last frame)."""
    from test_web import click

    open_page(browser, server.url)
    click(browser, "view tab")
    for _ in range(2):
        click(browser, "compare")
        wait("side B", lambda: report(browser)["compare"])
        wait(
            "pane B's first raw frame",
            lambda: (s := shown_picture(browser, "view_b")) and s.get("direct"),
        )
        click(browser, "compare")
        wait("side B gone", lambda: report(browser)["compare"] is None)
    click(browser, "compare")
    wait("side B", lambda: report(browser)["compare"])
    before = wait(
        "pane B's raw frame",
        lambda: (s := shown_picture(browser, "view_b")) and s.get("direct") and s,
    )
    set_kd_step(browser, far_step(browser))

    def changed():
        s = shown_picture(browser, "view_b")
        return s if s and s.get("direct") and s["url"] != before["url"] else None

    wait("pane B's raw frame of the change", changed)
    click(browser, "compare")
    wait("side B gone", lambda: report(browser)["compare"] is None)
    click(browser, "material tab")
