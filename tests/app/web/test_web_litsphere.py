"""The lobe inset's lit sphere in a real browser (headless Chromium, issue 41): its pixels are
the engine's colours, and a drag on it through the page's pointer events sets the lobe plot's
incidence; the plot's pixels follow (its lobe peaks where the engine's does). The page's
picture comes as a JPEG: the sphere's pixels are the engine's within a few levels, and the
lobe's pixels are told by the colour they lie nearest."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from helpers.peaks import engine_peak
from test_web import (
    STEP_TIMEOUT,
    click,
    console_errors,
    drag,
    open_page,
    report,
    shown_picture,
    view_pixels,
    wait,
)

import explorer
from explorer.analysis import litsphere as LS
from explorer.app import lobeinset as LI
from explorer.shading.display import to_bytes

pytestmark = pytest.mark.web
#: how far (pixels) the page's picture is searched around the box the server reports
SHIFT = 4


def _picture(browser, rep) -> np.ndarray | None:
    """The view's picture as the page shows it (h, w, 3) int, in the server's pixels; None
    while the picture shown is not of the reported size (it would be drawn stretched)."""
    shot, box = view_pixels(browser)
    w, h = rep["size"]
    natural = (shown_picture(browser) or {}).get("size")
    if not [round(box["w"]), round(box["h"])] == rep["size"] == natural:
        return None
    xs = np.round((box["x"] + (np.arange(w) + 0.5) * box["w"] / w) * box["dpr"] - 0.5).astype(int)
    ys = np.round((box["y"] + (np.arange(h) + 0.5) * box["h"] / h) * box["dpr"] - 0.5).astype(int)
    return shot[ys][:, xs].astype(int)


def _sphere_error(img, rep, scene) -> tuple[float, int, int]:
    """The mean difference (levels) between the page's sphere and the engine's, over the disc
    away from its rim and the light's mark, at the offset (up to 4 pixels each way) where the
    page's picture matches best, and that offset (dx, dy): the page's first picture showed the
    sphere 3 pixels left and 1 up of the box the server reports (0, 0 after a change: not
    understood yet, see the report of issue 41's helper)."""
    s = rep["sphere"]
    x, y, size = s["box"]
    want = LS.sphere_picture(scene, math.radians(s["theta"]), size).astype(int)
    c = (np.arange(size) + 0.5) * 2 / size - 1
    u, v = np.meshgrid(c, c)
    mx, my = s["mark"]
    yy, xx = np.mgrid[0:size, 0:size]
    keep = (u * u + v * v < 0.8) & (np.hypot(xx + x - mx, yy + y - my) > 8)
    found = []
    for dy in range(-SHIFT, SHIFT + 1):
        for dx in range(-SHIFT, SHIFT + 1):
            got = img[y + dy : y + dy + size, x + dx : x + dx + size]
            found.append((float(np.abs(got - want)[keep].mean()), dx, dy))
    return min(found)


def _plot_peak(img, rep, dx: int = 0, dy: int = 0) -> float:
    """The angle from the plot's normal (degrees) of the pixel farthest from the plot's origin
    whose colour lies nearest the lobe's of the inset's colours (the picture read at offset
    ``dx``, ``dy``)."""
    s = rep["sphere"]
    img = img[max(dy, 0) :, max(dx, 0) :]
    img = np.pad(img, ((max(-dy, 0), 0), (max(-dx, 0), 0), (0, 0)))
    ox, oy = s["origin"]
    x, y, size = s["box"]
    left = int(2 * ox - x)
    part = img[int(y - 2) : int(oy) + 1, left : x - 4]
    classes = to_bytes(
        [
            LI.LOBE_COLOR,
            LI.LOBE_PANEL_COLOR,
            LI.LOBE_FRAME_COLOR,
            LI.LOBE_DIFFUSE_COLOR,
            LI.LOBE_INCIDENT_COLOR,
            LI.LOBE_MIRROR_COLOR,
        ]
    ).astype(int)
    nearest = np.argmin(np.abs(part[:, :, None, :] - classes).sum(axis=3), axis=2)
    rows, cols = np.nonzero(nearest == 0)
    assert len(rows) > 10
    dx, dy = cols + left - ox, oy - (rows + y - 2)
    k = int(np.argmax(np.hypot(dx, dy)))
    return math.degrees(math.atan2(dx[k], dy[k]))


def _settled(browser, check):
    """Poll the report and the page's pixels until ``check(img, rep)`` (a tuple: whether the
    page shows it, then what was measured) holds on a picture of that report (the report
    unchanged around the screenshot)."""
    end = time.monotonic() + STEP_TIMEOUT
    while True:
        rep = report(browser)
        img = _picture(browser, rep)
        got = (False, "a picture of another size") if img is None else check(img, rep)
        if got[0] and report(browser) == rep:
            return rep
        if time.monotonic() > end:
            pytest.fail(f"the page's pixels did not show it: {got}")
        time.sleep(0.1)


def test_a_drag_on_the_lit_sphere_sets_the_incidence_and_the_lobe_follows(
    server, browser, tmp_path
):
    rep = open_page(browser, server.url)
    assert rep["session"]["lobes"]["incidence"] is None
    t0 = rep["sphere"]["theta"]

    def shows(img, r):
        scene = explorer.load_scene(r["session"]["scene"])
        err, dx, dy = _sphere_error(img, r, scene)
        peak = _plot_peak(img, r, dx, dy)
        want = engine_peak(scene, math.radians(r["sphere"]["theta"]))
        return (err <= 4.0 and abs(peak - want) <= 3.0, err, peak, want, dx, dy)

    rep = _settled(browser, shows)
    camera = rep["session"]["camera"]
    x, y, size = rep["sphere"]["box"]
    cx, cy = x + size // 2, y + size // 2
    # press near the sphere's middle, drag 5 right and 6 up (about 10°), let go
    drag(browser, (cx, cy), [(2, -2), (2, -2), (1, -2)])
    ex, ey = cx + 5, cy - 6
    rep = wait(
        "the incidence", lambda: (q := report(browser))["session"]["lobes"]["incidence"] and q
    )
    rep = _settled(
        browser,
        lambda img, q: (
            q["session"]["lobes"]["incidence"] == q["sphere"]["theta"] and shows(img, q)[0],
            q["sphere"]["theta"],
            *shows(img, q),
        ),
    )
    theta = rep["session"]["lobes"]["incidence"]
    # the pointer's pixel asks for asin(its distance / the radius): within 2 pixels of it
    near = [
        LS.incidence_at((ex + 0.5 + i - x) * 2 / size - 1, (y + size - ey - 0.5 + j) * 2 / size - 1)
        for i in (-2, 0, 2)
        for j in (-2, 0, 2)
    ]
    assert min(near) <= theta <= max(near) and abs(theta - t0) > 20
    assert rep["session"]["camera"] == camera  # the press was the sphere's
    browser.save_screenshot(str(tmp_path / "web_litsphere.png"))
    click(browser, "undo")
    wait("undo", lambda: report(browser)["session"]["lobes"]["incidence"] is None)
    assert not console_errors(browser)


def _curve_hits(img, rep, index: int) -> int:
    """How many of curve ``index``'s points (as reported while it was drawn) have, within one
    pixel, a pixel whose colour lies nearest its colour of the curves' and the panel's."""
    from explorer.app.lobeinset import LOBE_FRAME_COLOR, LOBE_PANEL_COLOR

    curves = rep["lobes"]["curves"]
    classes = np.array(
        [c["colour"] for c in curves] + to_bytes([LOBE_PANEL_COLOR, LOBE_FRAME_COLOR]).tolist()
    )
    n = 0
    for px, py in curves[index]["px"]:
        patch = img[max(py - 1, 0) : py + 2, max(px - 1, 0) : px + 2].reshape(-1, 3)
        nearest = np.argmin(np.abs(patch[:, None, :] - classes[None]).sum(axis=2), axis=1)
        n += bool((nearest == index).any())
    return n


def test_a_lobe_is_hidden_from_its_row_and_shown_again_by_a_click_on_its_legend(server, browser):
    """The three models' lobes: the page's ``show_lobe_3`` check box off, three.js's curve
    leaves the page's pixels; a click on its legend entry in the view draws it again."""
    from test_web import choose

    open_page(browser, server.url)
    click(browser, "view tab")
    choose(browser, "lobes", "models")
    drawn = wait("three lobes", lambda: (r := report(browser))["lobes"] and r)
    k = len(drawn["lobes"]["curves"][2]["px"])

    def hits(img, q):
        return (True, _curve_hits(img, drawn, 2))

    def shown(img, q):
        n = hits(img, q)[1]
        return (n >= 0.8 * k and q["session"]["lobes"]["hidden"] == [], n)

    _settled(browser, shown)
    click(browser, "show_lobe_3")

    def hidden(img, q):
        n = hits(img, q)[1]
        return (n <= 0.2 * k and q["session"]["lobes"]["hidden"] == [3], n)

    rep = _settled(browser, hidden)
    assert rep["lobes"]["shown"] == [True, True, False]
    x, y, bw, bh = rep["lobes"]["legend"][2]
    camera = rep["session"]["camera"]
    drag(browser, (x + bw // 2, y + bh // 2), [])  # (a press and a release: a click)
    rep = _settled(browser, shown)
    assert rep["session"]["camera"] == camera  # the click was the legend's
    choose(browser, "lobes", "selected")
    wait("one lobe", lambda: report(browser)["lobes"] is None)
    assert not console_errors(browser)
