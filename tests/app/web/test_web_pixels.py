"""The page's pixels in a real browser (headless Chromium), read from the browser's own
screenshot: ``web --per-pixel`` shows the engine's per-pixel picture
(explorer.render.perpixel.reference, what ``render --per-pixel`` writes) for the page's camera
and size, and per vertex the picture ``render`` writes (explorer.render.offscreen), each within
1 level on every pixel both cover once the view is still (the page's PNG,
explorer.app.web.pictures)."""

from __future__ import annotations

import os

import numpy as np
import pytest
import yaml
from helpers.probes import interior
from test_web import choose, click, open_page, report, shown_picture, view_pixels, wait
from webserver import Server, need_browser, new_browser

from explorer.app import lobeinset as LI
from explorer.app import session as S
from explorer.render.offscreen import BACKGROUND
from explorer.render.perpixel import reference

pytestmark = pytest.mark.web


@pytest.fixture(scope="module")
def pp_server(tmp_path_factory):
    """``phong-explorer web --mesh torus --preset glossy_plastic --per-pixel``."""
    need_browser()
    tmp = tmp_path_factory.mktemp("web_pp")
    env = dict(os.environ, PHONG_EXPLORER_MATERIALS=str(tmp / "presets"))
    args = ["--mesh", "torus", "--preset", "glossy_plastic", "--per-pixel"]
    srv = Server(args, tmp / "server.log", env=env)
    yield srv
    srv.stop()


@pytest.fixture(scope="module")
def pp_browser(pp_server, tmp_path_factory):
    driver = new_browser(tmp_path_factory.mktemp("downloads_pp"))
    yield driver
    driver.quit()


def inset_box(w: int, h: int) -> tuple[int, int, int, int]:
    """The lobe inset's panel (x0, y0, width, height; display pixels, origin bottom-left), as
    explorer.app.lobeinset.LobeInset.layout sizes it."""
    lo, hi = LI.LOBE_SIDE
    side = int(min(max(LI.LOBE_FRACTION * min(w, h), lo), hi, max(w - 2 * LI.LOBE_MARGIN, 40)))
    font = 13 if side >= 170 else 11
    height = side // 2 + 3 * LI.LOBE_PAD + 2 * (font + 4)
    return LI.LOBE_MARGIN, LI.LOBE_MARGIN, side, height


def compared(driver, tmp_path, per_pixel: bool = True):
    """The page's picture beside the engine's picture of the state the server reports (its
    camera, scene, mesh and view size; per pixel: the per-pixel picture, else ``render``'s), or
    None while the picture shown is not of that size: ``(report, got, want, inner, edge)``, the
    browser's pixels of the view, the engine's picture, the interior pixels and the
    silhouette's, what the view draws over the mesh left out."""
    from explorer.render.offscreen import render_image

    rep = report(driver)
    shot, box = view_pixels(driver)
    natural = (shown_picture(driver) or {}).get(
        "size"
    )  # (a picture of another size would be drawn stretched)
    if not [round(box["w"]), round(box["h"])] == rep["size"] == natural:
        return None
    path = tmp_path / "page.yaml"
    path.write_text(yaml.safe_dump(rep["session"]))
    state, mesh = S.load_session(path)
    w, h = rep["size"]
    ref = reference(state.shown_scene(), mesh, (w, h), camera=state.camera)
    if per_pixel:
        want = ref.image()
    else:
        want = render_image(state.shown_scene(), mesh, (w, h), camera=state.camera)
    x0, y0 = round(box["x"]), round(box["y"])
    got = shot[y0 : y0 + h, x0 : x0 + w].astype(int)
    free = np.ones((h, w), bool)
    ix, iy, iw, ih = inset_box(w, h)
    free[h - (iy + ih) - 3 :, : ix + iw + 3] = False
    yy, xx = np.mgrid[0:h, 0:w]
    for px, py in rep["handles_px"]:
        free &= np.hypot(xx - px, yy - py) > 40  # (a handle, its ring)
    inner = interior(ref.mask) & free
    edge = ref.mask & ~interior(ref.mask) & free
    return rep, got, want.astype(int), inner, edge


def exact(driver, tmp_path, per_pixel: bool):
    """Wait until the page's picture is the engine's within 1 level on every interior pixel
    (the picture shown may be an older one on its way out, or the JPEG before the still
    PNG); what :func:`compared` returns then."""
    last = {}

    def agree():
        c = last["c"] = compared(driver, tmp_path, per_pixel)
        return c is not None and np.abs(c[1] - c[2]).max(axis=2)[c[3]].max() <= 1

    try:
        wait("the page's picture to be the engine's", agree)
    finally:
        c = last.get("c")
        if c is not None:
            d = np.abs(c[1] - c[2]).max(axis=2)
            print(
                f"interior pixels {c[3].sum()}: off by > 1: {(d[c[3]] > 1).sum()}, max "
                f"{d[c[3]].max()}; silhouette {c[4].sum()}: off by > 1: "
                f"{(d[c[4]] > 1).sum()}"
            )
    return last["c"]


def test_the_page_shows_the_engines_per_pixel_picture(pp_server, pp_browser, tmp_path):
    open_page(pp_browser, pp_server.url)
    rep, got, want, inner, edge = exact(pp_browser, tmp_path, per_pixel=True)
    assert rep["session"]["scene"]["shading"] == "per-pixel"
    assert inner.sum() > 50000 and edge.sum() > 1000
    # the browser's pixels are the engine's per-pixel picture, within 1 level (no codec error:
    # the JPEG at quality 100 was up to 13 levels off at a highlight's coloured edge)
    d = np.abs(got - want).max(axis=2)
    assert d[inner].max() <= 1
    # the silhouette too, but where the page's G-buffer leaves a pixel to the background that
    # the ray cast hits: the test's servers run the numpy tier, so VTK's picture of triangle
    # indices finds each pixel's triangle, and a pixel centre grazing an edge may fall either
    # side of it (4 of 2396 pixels of the torus framed with its handle at 900x673; the compiled
    # rasteriser agrees with the ray cast on every one there)
    off = edge & (d > 1)
    background = np.round(np.asarray(BACKGROUND) * 255).astype(int)
    assert np.abs(got[off] - background).max(initial=0) <= 1, "a silhouette pixel is off"
    assert off.sum() <= 0.005 * edge.sum(), (off.sum(), edge.sum())
    assert not rep["errors"]


def test_the_page_shows_renders_per_vertex_picture(pp_server, pp_browser, tmp_path):
    """Per vertex, the page's picture is what ``render`` writes for its camera and size."""
    open_page(pp_browser, pp_server.url)
    click(pp_browser, "view tab")
    choose(pp_browser, "shading", "per-vertex")
    scene = lambda: report(pp_browser)["session"]["scene"]  # noqa: E731
    wait("per-vertex shading", lambda: scene().get("shading", "per-vertex") == "per-vertex")
    rep, got, want, inner, edge = exact(pp_browser, tmp_path, per_pixel=False)
    assert inner.sum() > 50000
    d = np.abs(got - want).max(axis=2)
    assert d[inner | edge].max() <= 1
    assert not rep["errors"]
