"""The material tab's texture maps in the page, in headless Chromium: an uploaded PNG worn by the
mesh (the view's pixels) with its thumbnail (the ``<img>``'s pixels in the screenshot), turned off
and on, a bad upload said in one line, cleared, and undone."""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from test_web import by_name, click, open_page, report, view_pixels, wait
from test_web_parity import status
from webserver import Server, need_browser, new_browser

pytestmark = pytest.mark.web

RED = (255, 0, 0)
TILES = Path(__file__).resolve().parents[3] / "docs" / "examples" / "tiles.png"


@pytest.fixture(scope="module")
def maps_server(tmp_path_factory):
    """``phong-explorer web --mesh sphere --diffuse-map tiles.png``: the sphere with its (u, v)."""
    need_browser()
    tmp = tmp_path_factory.mktemp("web_maps")
    env = dict(os.environ, PHONG_EXPLORER_MATERIALS=str(tmp / "presets"))
    srv = Server(["--mesh", "sphere", "--diffuse-map", str(TILES)], tmp / "server.log", env=env)
    yield srv
    srv.stop()


@pytest.fixture(scope="module")
def maps_browser(maps_server, tmp_path_factory):
    driver = new_browser(tmp_path_factory.mktemp("downloads_maps"))
    yield driver
    driver.quit()


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
    """The view's picture once ``check(picture)`` holds (the server draws after a change); the
    page's screenshot is kept in the server's folder when it does not."""
    try:
        return wait(what, lambda: [p] if check(p := mesh_picture(driver)) else None)[0]
    except BaseException:
        driver.save_screenshot(os.environ.get("W40_SHOT", "/dev/null"))
        raise


def still(driver):
    """The view's picture once two taken 0.3 s apart are the same (the page's start is drawn)."""

    def same():
        a = mesh_picture(driver)
        time.sleep(0.3)
        b = mesh_picture(driver)
        return [b] if a.shape == b.shape and np.abs(a - b).max() == 0 else None

    return wait("the start's picture to settle", same)[0]


def moved(p, q) -> int:
    """How many pixels of picture ``p`` differ from ``q`` by more than 30 levels in a channel."""
    return int((np.abs(p - q).max(axis=2) > 30).sum())


def map_of(rep):
    """The diffuse map's file the server's session names (None: none)."""
    m = rep["session"]["scene"]["material"].get("diffuse_map")
    return m["file"] if isinstance(m, dict) else m


def test_an_uploaded_map_is_worn_shown_turned_off_and_on_and_undone(
    maps_server, maps_browser, tmp_path
):
    """The tiles at the start; a red PNG uploaded as the diffuse map turns the mesh red and its
    thumbnail red; off draws the untextured mesh (the same picture as after a clear), on the
    red one again; a file that is not an image is one line and changes nothing; undo after the
    clear gives the red map back."""
    browser, server = maps_browser, maps_server
    open_page(browser, server.url)
    assert map_of(report(browser)) == str(TILES)
    tiled = still(browser)  # (the start is framed again for the page's view: after that)
    red = tmp_path / "red.png"
    Image.fromarray(np.full((8, 8, 3), RED, np.uint8)).save(red)
    by_name(browser, "diffuse_map_choose").send_keys(str(red))
    wait("the map set", lambda: (m := map_of(report(browser))) and m.endswith("red.png"))

    # the mesh wears it: where it changed, the pixels keep (almost) no green or blue above their
    # red (the handles and the inset do not change; the page's JPEG blurs the dark rim)
    def red_mesh(p):
        changed = np.abs(p - tiled).max(axis=2) > 30
        ok = (p[changed][:, 1:] <= p[changed][:, :1] + 3).all(axis=1)
        return changed.sum() > 500 and ok.mean() > 0.97

    worn = settled(browser, "the red mesh", red_mesh)
    # the thumbnail: the red image grown to 48 px (8 px times 6)
    browser.execute_script("arguments[0].scrollIntoView()", by_name(browser, "diffuse_map"))
    browser.save_screenshot(str(server.log.parent / "maps.png"))

    def red_thumbnail():
        t = box_pixels(browser, "diffuse_map_thumbnail")
        return [t] if t.size and np.abs(t.reshape(-1, 3).mean(0) - RED).max() < 6 else None

    thumb = wait("the thumbnail", red_thumbnail)[0]
    assert min(thumb.shape[:2]) >= 48
    assert "red.png" in by_name(browser, "diffuse_map_file").text
    # off: the untextured picture; on again: the red one
    click(browser, "diffuse_map_on")
    wait("the map off", lambda: "diffuse_map" in report(browser)["session"].get("hidden", []))
    off = settled(
        browser,
        "the mesh without its map",
        lambda p: min(moved(p, worn), moved(p, tiled)) > 500,
    )
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
    # clear: the untextured picture again; undo gives the map back
    click(browser, "diffuse_map_clear")
    wait("the map cleared", lambda: map_of(report(browser)) is None)
    settled(browser, "the cleared mesh", lambda p: np.abs(p - off).mean() < 1.5)
    click(browser, "undo")
    wait("the map back", lambda: map_of(report(browser)) is not None)
    settled(browser, "the red mesh again", lambda p: np.abs(p - worn).mean() < 1.5)
