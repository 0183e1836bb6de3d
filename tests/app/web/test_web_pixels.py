"""The page's per-pixel mode in a real browser (headless Chromium): ``web --per-pixel`` shows
the engine's per-pixel picture (explorer.render.perpixel.reference, what ``render --per-pixel``
writes) for the page's camera and size, read from the browser's own pixels."""

from __future__ import annotations

import io
import os

import numpy as np
import pytest
import yaml
from helpers.probes import interior
from test_web import open_page, report, view_pixels, wait
from webserver import Server, need_browser, new_browser

from explorer.app import lobeinset as LI
from explorer.app import session as S
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


def as_the_page_sends(picture: np.ndarray) -> np.ndarray:
    """``picture`` through the page's picture codec: VTK's remote view sends JPEG at quality 100
    (``still_quality=100``), libjpeg's default 4:2:0 chroma subsampling."""
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(picture).save(buf, "JPEG", quality=100, subsampling=2)
    return np.asarray(Image.open(buf).convert("RGB")).astype(int)


def compared(driver, tmp_path):
    """The page's picture beside the engine's per-pixel picture of the state the server
    reports (its camera, scene, mesh and view size), or None while the picture shown is not
    of that size: ``(report, got, want, sent, inner, edge)``, the browser's pixels of the view,
    the per-pixel picture, that picture through the page's codec, the interior pixels and the
    silhouette's, what the view draws over the mesh left out."""
    rep = report(driver)
    shot, box = view_pixels(driver)
    natural = driver.execute_script(
        "const i = document.querySelector('[aria-label=\"view\"] img');"
        "return [i.naturalWidth, i.naturalHeight];"
    )  # (a picture of another size would be drawn stretched)
    if not [round(box["w"]), round(box["h"])] == rep["size"] == natural:
        return None
    path = tmp_path / "page.yaml"
    path.write_text(yaml.safe_dump(rep["session"]))
    state, mesh = S.load_session(path)
    w, h = rep["size"]
    ref = reference(state.shown_scene(), mesh, (w, h), camera=state.camera)
    want = ref.image()
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
    return rep, got, want, as_the_page_sends(want), inner, edge


def test_the_page_shows_the_engines_per_pixel_picture(pp_server, pp_browser, tmp_path):
    open_page(pp_browser, pp_server.url)
    last = {}

    def agree():  # polled: the picture shown may be an older one on its way out
        c = last["c"] = compared(pp_browser, tmp_path)
        return c is not None and np.abs(c[1] - c[3]).max(axis=2)[c[4]].max() <= 1

    try:
        wait("the page's picture to be the engine's per-pixel picture", agree)
    finally:
        c = last.get("c")
        if c is not None:
            d = np.abs(c[1] - c[3]).max(axis=2)[c[4]]
            print(f"interior pixels {d.size}: off by > 1: {(d > 1).sum()}, max {d.max()}")
    rep, got, want, sent, inner, edge = last["c"]
    assert rep["session"]["scene"]["shading"] == "per-pixel"
    assert inner.sum() > 50000 and edge.sum() > 1000
    # the browser's pixels are the engine's per-pixel picture as the page's codec sends it
    d = np.abs(got - sent).max(axis=2)
    assert d[inner].max() <= 1
    assert (d[edge] > 1).sum() <= 0.05 * edge.sum()  # silhouette pixels, counted
    # against the picture itself: no more than the codec's own error (JPEG at quality 100;
    # 99% within 3 levels with the torus framed for the page's own 900x673 view, within 2 when
    # it was framed for the server's 800x600)
    raw = np.abs(got - want.astype(int)).max(axis=2)[inner]
    codec = np.abs(sent - want.astype(int)).max(axis=2)[inner]
    assert (raw <= codec + 1).all() and np.percentile(raw, 99) <= 3
    assert not rep["errors"]
