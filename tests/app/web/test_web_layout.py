"""The page's finish, in a real browser: pane B of the compare view with the light handles
and the arrows at its edge (dragged there as in pane A), the panel's sliders lined up at
every size, and the lobe inset scaled to a small view."""

from __future__ import annotations

import time

import numpy as np
import pytest
from helpers.insets import panel_extent
from test_web import choose, click, open_page, report, type_value, view_pixels, wait

from explorer.app import lobeinset as LI
from explorer.app.browser import set_viewport

pytestmark = pytest.mark.web

#: a handle's pixels are its light's colour, lit by nothing (a white light's: white); the
#: page's picture is a JPEG, so a level or two off
WHITE = 225


def picture_patch(driver, view: str, px, size) -> np.ndarray:
    """The page's pixels (k, 3) int of view ``view``'s picture around its pixel ``px``
    (the server's picture, origin top-left, ``size`` its width and height): a 3x3 patch."""
    shot, box = view_pixels(driver, view)
    w, h = size
    x = round((box["x"] + (px[0] + 0.5) * box["w"] / w) * box["dpr"] - 0.5)
    y = round((box["y"] + (px[1] + 0.5) * box["h"] / h) * box["dpr"] - 0.5)
    return shot[y - 1 : y + 2, x - 1 : x + 2].reshape(-1, 3).astype(int)


def drag_in(driver, view: str, size, start, moves) -> None:
    """Press at pixel ``start`` of view ``view``'s picture (``size`` its width and height,
    origin top-left), move by each ``(dx, dy)`` of ``moves`` (CSS pixels) and release."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    img = driver.find_element(By.CSS_SELECTOR, f'[aria-label="{view}"] img')
    w, h = size
    r = driver.execute_script("return arguments[0].getBoundingClientRect().toJSON()", img)
    ox = start[0] * r["width"] / w - r["width"] / 2
    oy = start[1] * r["height"] / h - r["height"] / 2
    chain = ActionChains(driver).move_to_element_with_offset(img, round(ox), round(oy))
    chain.click_and_hold()
    for dx, dy in moves:
        chain.move_by_offset(dx, dy)
    chain.release().perform()


#: the pause between two moves of :func:`steady_drag` (seconds): the remote view sends a move
#: to the server only while the pointer keeps moving (vtk.js starts a new "mouse move" after
#: 200 ms still, and sends none for its start; Selenium's moves, 250 ms each, were never sent)
MOVE_PAUSE = 0.08


def steady_drag(driver, view: str, start, moves) -> None:
    """A drag as a hand makes it: press at CSS pixel ``start`` of view ``view``'s picture
    (from its top left), move by each ``(dx, dy)`` of ``moves`` every :data:`MOVE_PAUSE`
    seconds, release (Chromium's own input events, through the DevTools protocol)."""
    box = driver.execute_script(
        f"return document.querySelector('[aria-label=\"{view}\"] img')"
        ".getBoundingClientRect().toJSON()"
    )
    x, y = box["x"] + start[0], box["y"] + start[1]

    def mouse(kind: str, **kw) -> None:
        driver.execute_cdp_cmd("Input.dispatchMouseEvent", {"type": kind, "x": x, "y": y, **kw})

    mouse("mouseMoved")
    mouse("mousePressed", button="left", buttons=1, clickCount=1)
    for dx, dy in moves:
        time.sleep(MOVE_PAUSE)
        x, y = x + dx, y + dy
        mouse("mouseMoved", button="left", buttons=1)
    mouse("mouseReleased", button="left", buttons=0, clickCount=1)


def shows(driver, view: str, px, size) -> bool:
    """Whether view ``view``'s picture is white (a white light's handle or arrow) at ``px``."""
    return bool((picture_patch(driver, view, px, size).mean(axis=0) >= WHITE).all())


def test_pane_b_draws_the_handles_and_a_drag_there_moves_the_light(server, browser):
    """Compare A | B: pane B draws the arrow at its edge toward a handle out of it and the
    handle where the light projects (its pixels white, a white light's), and a drag on B's
    handle moves the light in both panes, ending under the pointer (issue 42: pane B had
    neither handles nor arrows)."""
    open_page(browser, server.url)
    click(browser, "view tab")
    click(browser, "compare")
    rep = wait("side B's arrow", lambda: (r := report(browser))["compare"] and r)
    rep = wait("side B's arrow", lambda: (r := report(browser))["compare"]["arrows_px"] and r)
    light = rep["session"]["light"] - 1
    size = rep["compare"]["size"]
    arrow = np.asarray(rep["compare"]["arrows_px"][str(light)]).mean(axis=0)
    wait("B's arrow in its picture", lambda: shows(browser, "view_b", arrow, size))
    click(browser, "lights tab")
    type_value(browser, "azimuth", "10")  # the handle in B's half-width view
    w, h = size

    def inside(r):
        x, y = r["compare"]["handles_px"][light]
        return 20 <= x < w - 20 and 20 <= y < h - 20 and r

    rep = wait("B's handle in its view", lambda: inside(report(browser)))
    hx, hy = rep["compare"]["handles_px"][light]
    wait("B's handle in its picture", lambda: shows(browser, "view_b", (hx, hy), size))
    before = rep["placement"]
    a_before = rep["handles_px"][light]
    sx, sy = (-1 if hx > w / 2 else 1), (1 if hy < h / 2 else -1)  # toward the middle
    drag_in(browser, "view_b", size, (hx, hy), [(8 * sx, 5 * sy)] * 10)
    target = (hx + 80 * sx, hy + 50 * sy)

    def moved(r):
        x, y = r["compare"]["handles_px"][light]
        near = abs(x - target[0]) <= 3 and abs(y - target[1]) <= 3
        return near and r["placement"] != before and not r["errors"] and r

    end = time.monotonic() + 10
    while not (rep := moved(report(browser))) and time.monotonic() < end:
        time.sleep(0.05)
    assert rep, ("B's handle ended away from the pointer", target, report(browser))
    assert rep["handles_px"][light] != a_before  # the light moved in pane A too
    wait("B's handle where it was put", lambda: shows(browser, "view_b", target, size))
    click(browser, "undo")
    click(browser, "undo")
    wait("undo", lambda: report(browser)["placement"] != rep["placement"])
    click(browser, "view tab")
    click(browser, "compare")
    wait("side B gone", lambda: report(browser)["compare"] is None)
    click(browser, "material tab")


#: every slider of the tab shown: its track and its number field, as (left, right) in CSS
#: pixels (a tab shown before stays in the page, moved aside)
SLIDERS_JS = """
const box = e => { const r = e.getBoundingClientRect(); return [r.left, r.right]; };
return [...document.querySelectorAll('[aria-label$="_slider"]')]
  .filter(e => e.closest('.v-window-item--active') && e.getClientRects().length)
  .map(e => { const key = e.getAttribute('aria-label').replace(/_slider$/, '');
              const field = document.querySelector(`input[aria-label="${key}"]`);
              const label = e.closest('.v-slider').querySelector('.v-label');
              return {key: key, track: box(e.closest('.v-slider').querySelector('.v-slider-track')),
                      cut: label.scrollWidth > label.clientWidth,
                      field: box(field.closest('.v-field'))}; });
"""


#: the panel's tab bar: its content's width and the width it has (CSS pixels)
TABS_JS = """
const g = document.querySelector('.v-navigation-drawer .v-slide-group__container');
return [g.firstElementChild.scrollWidth, g.clientWidth];
"""


def settled(driver, script: str):
    """What ``script`` returns once the page stands still: the same in two reads 0.2 s apart
    (the drawer slides in as a page opens), or None."""
    first = driver.execute_script(script)
    time.sleep(0.2)
    return first if first and driver.execute_script(script) == first else None


@pytest.mark.parametrize("size", [(1280, 900), (900, 720), (640, 480)])
def test_every_slider_starts_and_ends_at_the_same_x(server, browser, size):
    """Every slider of every tab (the material's, the light's, the view's exposure) starts and
    ends at the same x, and so does every number field beside them: the labels are a column of
    one width (issue 42: shininess's and opacity's sliders started further right than ka's,
    their labels being longer). Every label is whole ("shinine..." was cut in the first
    column), and the panel's tabs fit their bar (at 640x480 it scrolled, "MATERIAL" cut)."""
    try:
        browser.get("about:blank")
        browser.set_window_size(*size)
        open_page(browser, server.url)
        click(browser, "view tab")
        click(browser, "hdr")  # (the exposure's slider is shown with hdr on)
        wait("hdr", lambda: report(browser)["session"]["scene"].get("hdr"))
        rows = []
        for tab in ("material", "lights", "view"):
            click(browser, f"{tab} tab")
            got = wait(f"the {tab} tab's sliders", lambda: settled(browser, SLIDERS_JS))
            rows += [{**r, "tab": tab} for r in got]
        want = {"ka", "shininess", "opacity", "intensity", "elevation", "exposure"}
        assert {r["key"] for r in rows} >= want, rows
        for part in ("track", "field"):
            for side in (0, 1):
                xs = [r[part][side] for r in rows]
                assert max(xs) - min(xs) <= 1, (part, side, rows)
        assert min(r["track"][1] - r["track"][0] for r in rows) >= 60, rows  # still a slider
        assert not [r["key"] for r in rows if r["cut"]], rows  # every label whole
        tabs = browser.execute_script(TABS_JS)
        assert tabs[0] <= tabs[1], f"the panel's tabs scroll sideways: {tabs}"
    finally:
        click(browser, "view tab")
        click(browser, "hdr")
        wait("hdr off", lambda: not report(browser)["session"]["scene"].get("hdr"))
        browser.get("about:blank")
        browser.set_window_size(1280, 900)


def view_picture(driver, view: str, size) -> np.ndarray:
    """View ``view``'s picture as the page shows it (h, w, 3), at the server's size."""
    from PIL import Image

    shot, box = view_pixels(driver, view)
    d = box["dpr"]
    x, y, w, h = (round(v * d) for v in (box["x"], box["y"], box["w"], box["h"]))
    img = Image.fromarray(np.ascontiguousarray(shot[y : y + h, x : x + w]))
    return np.asarray(img.resize(tuple(size), Image.NEAREST))


def test_the_lobe_inset_covers_at_most_a_fifth_of_a_small_view(server, browser):
    """At 640x480, compare on: in each pane (183x251 pixels) the inset's panel, read from the
    page's pixels, covers at most LOBE_AREA of the pane and is still there (issue 42: the
    130-pixel inset covered 32% of each pane, 40% of the view before the drawer narrowed)."""
    try:
        browser.get("about:blank")
        browser.set_window_size(640, 480)
        open_page(browser, server.url)
        click(browser, "view tab")
        click(browser, "compare")
        rep = wait("side B", lambda: (r := report(browser))["compare"] and r)
        for view, size in (("view", rep["size"]), ("view_b", rep["compare"]["size"])):
            w, h = size

            def fits(view=view, size=size, w=w, h=h):
                side, height = panel_extent(view_picture(browser, view, size))
                small = side * height <= LI.LOBE_AREA * w * h + 2 * (side + height)
                return small and side >= LI.LOBE_MIN_SIDE - 2 and (side, height)

            wait(f"{view}'s inset at most {LI.LOBE_AREA:.0%} of {w}x{h}", fits)
    finally:
        click(browser, "compare")
        wait("side B gone", lambda: report(browser)["compare"] is None)
        click(browser, "material tab")
        browser.get("about:blank")
        browser.set_window_size(1280, 900)


def test_a_camera_drag_in_per_pixel_mode_draws_per_vertex_when_per_pixel_costs_twice(
    server, browser
):
    """Issue 39 item 4 in the page: in per-pixel mode, a camera drag (the page's pointer on
    the view) draws per vertex while a per-pixel picture costs more than FALLBACK_RATIO
    per-vertex frames, the page says so, and the release draws per pixel again; a per-pixel
    picture that costs less is drawn through the drag. Frames counted on the server (the
    page's remote view did not report its drags: every frame of a drag was per pixel).

    Which of the two the drag is, is what the server decided at the drag's first camera frame,
    on the times it had measured then (the report's ``pixels.drag``), not a guess from times
    read before the drag: under load another picture can come between, and the two times are
    the machine's. The frames drawn per vertex are counted as such (``vertex_frames``): the
    press's and the release's frames keep the camera and make no picture, so "frames less
    per-pixel pictures" was 2 in every drag drawn per pixel (a run at load 16 measured per
    pixel cheaper and failed on it). The test checks that the decision follows the rule on its
    own figures and that the frames follow the decision."""
    from explorer.app.pixellayer import FALLBACK_RATIO

    open_page(browser, server.url)
    click(browser, "view tab")
    choose(browser, "shading", "per-pixel")
    try:

        def timed():
            r = report(browser)
            return r["pixels"]["ms"] and r["pixels"]["vertex_ms"] is not None and r

        rep = wait("per-pixel frames timed", timed)
        p0 = rep["pixels"]
        w, h = rep["size"]
        eye = rep["session"]["scene"]["viewer"]
        steady_drag(browser, "view", (w // 2, h // 2 + 40), [(5, 0)] * 20)

        def released():  # the drag decided, turned the camera and ended; a per-pixel picture
            r = report(browser)
            p = r["pixels"]
            turned = r["session"]["scene"]["viewer"] != eye
            done = p["drags"] == p0["drags"] + 1 and not r["dragging"] and not p["fallback"]
            return turned and done and p["frames"] > p0["frames"] and r

        after = wait("the camera to turn and the drag to end", released)
        decided = after["pixels"]["drag"]  # the server's: the times it compared, its choice
        assert decided["fallback"] is (
            decided["ms"] > FALLBACK_RATIO * max(decided["vertex_ms"], 0.0)
        ), decided
        per_vertex = after["pixels"]["vertex_frames"] - p0["vertex_frames"]
        per_pixel = after["pixels"]["frames"] - p0["frames"]

        def status() -> str:
            return browser.find_element("css selector", '[role="status"]').text

        if decided["fallback"]:
            said = f"a per-pixel frame takes {decided['ms']:.0f} ms"
            wait("the page to say the drag is drawn per vertex", lambda: said in status())
            assert "camera drag drawn per vertex" in status()
            assert per_vertex >= 3 and per_pixel <= 2, (decided, per_vertex, per_pixel)
        else:
            assert per_vertex == 0 and per_pixel >= 1, (decided, per_vertex, per_pixel)
            assert "camera drag drawn per vertex" not in status()
    finally:
        choose(browser, "shading", "per-vertex")
        click(browser, "material tab")


#: the least distance (pixels) of a handle's centre from its view's edge that counts as inside
EDGE = 12


def test_the_handle_stays_inside_the_view_until_the_camera_is_moved(tmp_path):
    """The start is framed for the page's view at each size it takes until the camera is
    moved: a page opened at 1280x900, then made 760x900 (a 490x816 view: taller than wide)
    and 900x720, shows the selected light's handle inside the view at each, white in the
    page's pixels (issue 42: the start was framed once, at the view's first size, a 30x30
    placeholder's square; a view taller than wide showed the handle out of it). Once the
    camera is turned by a drag, a resize keeps it where the drag left it. (The handle's centre
    at least :data:`EDGE` pixels from the view's edge: its sphere's radius on the screen, about
    10 pixels here.)"""
    from webserver import Server, need_browser, new_browser

    need_browser()
    srv = Server(["--mesh", "teapot"], tmp_path / "server.log")
    driver = new_browser(tmp_path)
    try:
        driver.get("about:blank")
        for i, (w, h) in enumerate(((1280, 900), (760, 900), (900, 720))):
            set_viewport(driver, w, h)
            if i == 0:
                open_page(driver, srv.url)

            def inside(w=w):
                r = report(driver)
                (vw, vh), light = r["size"], r["session"]["light"] - 1
                x, y = r["handles_px"][light]
                laid = vw < w - 200  # the drawer is beside the view
                return laid and EDGE <= x < vw - EDGE and EDGE <= y < vh - EDGE and r

            rep = wait(f"the handle inside the view of a {w}x{h} page", inside)
            px = rep["handles_px"][rep["session"]["light"] - 1]
            size = rep["size"]
            wait("the handle in its pixels", lambda p=px, s=size: shows(driver, "view", p, s))
        vw, vh = rep["size"]
        eye = rep["session"]["scene"]["viewer"]
        steady_drag(driver, "view", (vw // 2, vh // 2 + 40), [(5, 0)] * 12)
        turned = wait(
            "the camera turned",
            lambda: (r := report(driver))["session"]["scene"]["viewer"] != eye and r,
        )
        time.sleep(0.5)  # the drag's last frames
        turned = report(driver)["session"]["scene"]["viewer"]
        set_viewport(driver, 760, 900)
        wait("the view resized", lambda: report(driver)["size"] != [vw, vh])
        time.sleep(0.5)
        assert report(driver)["session"]["scene"]["viewer"] == turned
    finally:
        driver.quit()
        srv.stop()
