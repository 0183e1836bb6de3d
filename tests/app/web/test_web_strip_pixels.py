"""The term strip per pixel in a real browser (headless Chromium, issue 41): ``web --per-pixel``
with the view tab's ``strip`` on draws each tile as a per-pixel picture at the tile's size and
the view's camera; the page's sum tile is ``render --per-pixel``'s picture there (through the
page's JPEG: within a few levels), not the per-vertex tile."""

from __future__ import annotations

import os

import numpy as np
import pytest
import yaml
from helpers.probes import interior
from test_web import click, console_errors, open_page, report, wait
from test_web_litsphere import _picture
from webserver import Server, need_browser, new_browser

from explorer.app import session as S
from explorer.render.live import picture
from explorer.render.offscreen import render_image

pytestmark = pytest.mark.web
#: the rows at a tile's bottom its label may cover (pixels)
LABEL_ROWS = 20
#: the per-pixel and the per-vertex tile are told apart where they differ by more than this
DIFFER = 6


@pytest.fixture(scope="module")
def strip_server(tmp_path_factory):
    """``phong-explorer web --mesh torus --resolution 32 --preset glossy_plastic --per-pixel``
    (a coarse torus: its per-vertex and per-pixel tiles differ on many pixels)."""
    need_browser()
    tmp = tmp_path_factory.mktemp("web_strip_pp")
    env = dict(os.environ, PHONG_EXPLORER_MATERIALS=str(tmp / "presets"))
    args = ["--mesh", "torus", "--resolution", "32", "--preset", "glossy_plastic", "--per-pixel"]
    srv = Server(args, tmp / "server.log", env=env)
    yield srv
    srv.stop()


@pytest.fixture(scope="module")
def strip_browser(strip_server, tmp_path_factory):
    driver = new_browser(tmp_path_factory.mktemp("downloads_strip_pp"))
    yield driver
    driver.quit()


def test_the_pages_sum_tile_is_the_per_pixel_picture(strip_server, strip_browser, tmp_path):
    b = strip_browser
    open_page(b, strip_server.url)
    click(b, "view tab")
    click(b, "strip")
    wait("the per-pixel strip", lambda: (r := report(b))["strip"] and r["strip"]["per_pixel"])
    last = {}

    def agree():  # polled: the picture shown may be an older one on its way out
        rep = report(b)
        img = _picture(b, rep)
        if img is None or not rep["strip"]:
            return False
        path = tmp_path / "page.yaml"
        path.write_text(yaml.safe_dump(rep["session"]))
        state, mesh = S.load_session(path)
        x, y, tw, th = rep["strip"]["boxes"]["sum"]
        ref = picture(state.shown_scene(), mesh, (tw, th), camera=state.camera)  # (its background)
        got = img[y : y + th - LABEL_ROWS, x : x + tw]
        # where the per-pixel picture and the per-vertex one differ by more than DIFFER levels,
        # the page's tile lies nearer the per-pixel one (the page's JPEG moves both alike)
        vertex = render_image(state.shown_scene(), mesh, (tw, th), camera=state.camera)
        rows = slice(0, th - LABEL_ROWS)
        pp, pv = ref.rgb[rows].astype(int), np.asarray(vertex)[rows, :, :3].astype(int)
        where = interior(ref.mask)[rows] & (np.abs(pp - pv).max(axis=2) > DIFFER)
        near_pp = float(np.abs(got - pp).max(axis=2)[where].mean()) if where.any() else 0.0
        near_pv = float(np.abs(got - pv).max(axis=2)[where].mean()) if where.any() else 0.0
        last["d"] = (int(where.sum()), near_pp, near_pv)
        return where.sum() >= 30 and near_pp < 0.5 * near_pv and report(b) == rep

    try:
        wait("the page's sum tile to be the per-pixel picture", agree)
    finally:
        print("sum tile: pixels compared, off the per-pixel, off the per-vertex:", last.get("d"))
    click(b, "strip")
    wait("the strip off", lambda: report(b)["strip"] is None)
    assert not console_errors(b)


def _pane_picture(browser, size, view: str) -> np.ndarray | None:
    """Pane ``view``'s picture as the page shows it (h, w, 3) int, in the server's pixels;
    None while the picture shown is not of the reported ``size``."""
    from test_web import shown_picture, view_pixels

    shot, box = view_pixels(browser, view)
    w, h = size
    natural = (shown_picture(browser, view) or {}).get("size")
    if not [round(box["w"]), round(box["h"])] == list(size) == natural:
        return None
    xs = np.round((box["x"] + (np.arange(w) + 0.5) * box["w"] / w) * box["dpr"] - 0.5).astype(int)
    ys = np.round((box["y"] + (np.arange(h) + 0.5) * box["h"] / h) * box["dpr"] - 0.5).astype(int)
    return shot[ys][:, xs].astype(int)


def test_side_bs_strip_in_the_page_is_per_pixel_and_named(strip_server, strip_browser, tmp_path):
    """The compare view with the strip on, both sides lit per pixel: pane B's strip is side B's
    per-pixel strip (its sum tile, read from the page's picture once it is still, a PNG: ``render
    --per-pixel``'s picture of B's scene at the tile's size, bit for bit), under the caption
    ``side B``; pane A's is named ``side A``."""
    from explorer.app import model as M

    b = strip_browser
    open_page(b, strip_server.url)
    click(b, "view tab")
    click(b, "strip")
    click(b, "compare")

    def ready():
        side = (r := report(b))["compare"]
        return side and side["strip"] and side["strip"]["per_pixel"] and r

    rep = wait("side B's per-pixel strip", ready)
    assert rep["strip"]["caption"] == "side A" and rep["compare"]["strip"]["caption"] == "side B"
    last = {}

    def agree():  # polled: the picture shown may be an older one, or the JPEG of a change
        rep = report(b)
        side = rep["compare"]
        if not side or not side["strip"]:
            return False
        img = _pane_picture(b, side["size"], "view_b")
        if img is None:
            return False
        path = tmp_path / "page.yaml"
        path.write_text(yaml.safe_dump(rep["session"]))
        state, mesh = S.load_session(path)
        scene = M.side_b(state).shown_scene()
        x, y, tw, th = side["strip"]["boxes"]["sum"]
        ref = picture(scene, mesh, (tw, th), camera=state.camera)  # (the view's background)
        got = img[y : y + th - LABEL_ROWS, x : x + tw]
        d = np.abs(got - ref.rgb[: th - LABEL_ROWS].astype(int)).max(axis=2)
        last["d"] = (int(d.max()), int((d > 0).sum()), int(ref.mask.sum()))
        return ref.mask.sum() > 200 and not d.any() and report(b) == rep

    try:
        wait("pane B's sum tile to be B's per-pixel picture", agree)
    finally:
        print("B's sum tile: largest difference, pixels off, the mesh's:", last.get("d"))
    click(b, "compare")
    wait("side B gone", lambda: report(b)["compare"] is None)
    click(b, "strip")
    wait("the strip off", lambda: report(b)["strip"] is None)
    assert not console_errors(b)


def test_the_page_shows_a_row_per_light_under_the_strip(strip_server, strip_browser, tmp_path):
    """The view tab's ``strip_lights`` check box adds a row of tiles per light under the strip
    in the page: the report names each row, and in the page's picture the row's sum tile holds
    the light's lit torus (pixels away from the background), under the strip's own tiles."""
    b = strip_browser
    open_page(b, strip_server.url)
    click(b, "view tab")
    click(b, "strip")
    click(b, "strip_lights")
    rep = wait("a row per light", lambda: (r := report(b))["strip"] and r["strip"]["lights"] and r)
    assert [r["name"] for r in rep["strip"]["lights"]] == ["light 1: point"]

    def drawn():  # polled: the picture shown may be one from before the rows
        rep = report(b)
        img = _picture(b, rep)
        if img is None or not rep["strip"]["lights"]:
            return False
        x, y, tw, th = rep["strip"]["lights"][0]["boxes"]["sum"]
        sx, sy, _, sh = rep["strip"]["boxes"]["sum"]
        tile = img[y + 2 : y + th - 2, x + 2 : x + tw - 2]
        background = img[y + 2, x + 2]
        lit = (np.abs(tile - background).max(axis=2) > 30).sum()
        return y >= sy + sh and lit > 50 and report(b) == rep

    wait("the light row's sum tile drawn in the page", drawn)
    b.save_screenshot(str(tmp_path / "page_light_rows.png"))
    click(b, "strip_lights")
    wait("the light rows gone", lambda: report(b)["strip"]["lights"] == [])
    click(b, "strip")
    wait("the strip off", lambda: report(b)["strip"] is None)
    assert not console_errors(b)
