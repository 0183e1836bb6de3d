"""The material tab's texture maps in the page, in headless Chromium: an uploaded PNG worn by the
mesh (the view's pixels) with its thumbnail (the ``<img>``'s pixels in the screenshot), turned off
and on, a bad upload said in one line, cleared, and undone."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image
from test_web import by_name, click, open_page, report, view_pixels, wait
from test_web_parity import status

pytestmark = pytest.mark.web

RED = (255, 0, 0)


def box_pixels(driver, name: str) -> np.ndarray:
    """(h, w, 3) int: the screenshot's pixels inside the element named ``name``."""
    shot, _ = view_pixels(driver)
    r = driver.execute_script(
        "const r = arguments[0].getBoundingClientRect();"
        "return {x: r.left, y: r.top, w: r.width, h: r.height, dpr: window.devicePixelRatio};",
        by_name(driver, name),
    )
    d = r["dpr"]
    y0, x0 = round(r["y"] * d), round(r["x"] * d)
    return shot[y0 : y0 + round(r["h"] * d), x0 : x0 + round(r["w"] * d)].astype(int)


def mesh_picture(driver) -> np.ndarray:
    shot, b = view_pixels(driver)
    d = b["dpr"]
    y0, x0 = round(b["y"] * d), round(b["x"] * d)
    return shot[y0 : y0 + round(b["h"] * d), x0 : x0 + round(b["w"] * d)].astype(int)


def settled(driver, what: str, check):
    """The view's picture once ``check(picture)`` holds (the server draws after a change)."""
    return wait(what, lambda: (p := mesh_picture(driver)) is not None and check(p) and p)


def map_of(rep) -> dict | None:
    return rep["session"]["scene"]["material"].get("diffuse_map")


def test_an_uploaded_map_is_worn_shown_turned_off_and_on_and_undone(server, browser, tmp_path):
    open_page(browser, server.url)

    plain = mesh_picture(browser)
    red = tmp_path / "red.png"
    Image.fromarray(np.full((8, 8, 3), RED, np.uint8)).save(red)
    by_name(browser, "diffuse_map_choose").send_keys(str(red))
    wait("the map set", lambda: map_of(report(browser)) is not None)
    assert map_of(report(browser)).endswith("red.png")
    # the mesh wears it: where it was drawn, no pixel keeps green or blue above its red
    covered = np.abs(plain - plain[2, 2]).max(axis=2) > 30
    assert covered.sum() > 500
    worn = settled(browser, "the red mesh",
                   lambda p: (p[covered][:, 1:] <= p[covered][:, :1] + 3).all())  # fmt: skip
    # the thumbnail: 48 px of red
    browser.execute_script("arguments[0].scrollIntoView()", by_name(browser, "diffuse_map"))
    thumb = wait("the thumbnail", lambda: (t := box_pixels(browser, "diffuse_map_thumbnail"))
                 .size and np.abs(t.reshape(-1, 3).mean(0) - RED).max() < 6 and t)  # fmt: skip
    assert thumb.shape[0] >= 48
    assert "red.png" in by_name(browser, "diffuse_map_file").text
    # off: the untextured picture; on again: the red one
    click(browser, "diffuse_map_on")
    settled(browser, "the map off", lambda p: np.abs(p - plain).mean() < 1.5)
    assert "diffuse_map" in report(browser)["session"]["hidden"]
    click(browser, "diffuse_map_on")
    settled(browser, "the map on", lambda p: np.abs(p - worn).mean() < 1.5)
    # a bad file: one line, nothing changed
    bad = tmp_path / "notes.png"
    bad.write_text("not an image\n")
    before = report(browser)["session"]
    by_name(browser, "diffuse_map_choose").send_keys(str(bad))
    line = wait("the refusal", lambda: "not a PNG or JPEG" in (t := status(browser)) and t)
    assert "notes.png" in line and "\n" not in line.strip()
    assert report(browser)["session"] == before
    # clear, then undo gives it back
    click(browser, "diffuse_map_clear")
    wait("the map cleared", lambda: map_of(report(browser)) is None)
    settled(browser, "the cleared mesh", lambda p: np.abs(p - plain).mean() < 1.5)
    click(browser, "undo")
    wait("the map back", lambda: map_of(report(browser)) is not None)
    settled(browser, "the red mesh again", lambda p: np.abs(p - worn).mean() < 1.5)
