"""The term strip in the explorer's view (explorer.app.termstrip), on an off-screen plotter as
both front ends draw it: the tiles under the main view, each the engine's term at its pixels."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.probes import in_ring, one_ring
from helpers.views import sphere_view

from explorer.app import panelmodel as PM
from explorer.app.termstrip import band_height, set_strip, set_strip_mode
from explorer.render.strip import COLUMNS
from explorer.shading.strip import shader_strip

SIZE = (900, 600)


@pytest.fixture
def view():
    v = sphere_view("gold", SIZE)
    yield v
    v.plotter.close()


def _picture(view):
    view.before_frame(view.state.camera) if view.state.camera else None
    view.plotter.render()
    return view.plotter.screenshot(return_img=True)[:, :, :3].astype(int)


@pytest.mark.parametrize("mode", ["weighted", "raw"])
def test_each_tile_shows_the_engines_term_at_the_probe_vertex(view, mode):
    before = _picture(view)
    state = set_strip_mode(set_strip(view.state, True), mode)
    view.show_state(state)
    img = _picture(view)
    strip = view.strip
    assert strip.on and len(strip.renderers) == len(COLUMNS)
    top = SIZE[1] - band_height(SIZE[1])  # (the tiles' and the overflow caption's band)
    assert view.plotter.renderer.GetViewport() == pytest.approx((0, 1 - top / SIZE[1], 1, 1))
    band = img[top + 1 :]
    assert not np.array_equal(band, before[-len(band) :])  # the tiles are drawn there
    i = view.probe_vertex()
    ring = one_ring(view.mesh, i)
    point = view.to_view(view.mesh.positions[i])
    terms = shader_strip(view.drawings[0].shader, mode)
    for k, column in enumerate(COLUMNS):
        x, y = strip.tile_pixel(column, point)
        assert top <= y < SIZE[1]  # in the band under the view
        want = strip.tiles[k][i].astype(int)
        if column in terms.tiles:  # (the float term's bytes: the tile is the engine's term)
            assert np.abs(want - np.rint(terms.tiles[column][i] * 255)).max() <= 1
        assert in_ring(img[y, x], strip.tiles[k], ring), column
    assert strip.labels[-1].GetInput().startswith("overflow ")


def test_the_strip_turns_off_and_its_rows_are_panel_rows(view):
    view.show_state(set_strip(view.state, True))
    _picture(view)
    view.show_state(set_strip(view.state, False))
    assert not view.strip.on
    assert view.plotter.renderer.GetViewport() == pytest.approx((0, 0, 1, 1))
    assert PM.row("strip").tab == "view" and PM.row("strip_mode").choices == ("weighted", "raw")
    action, args, _ = PM.edit(view.state, "strip_mode", "raw")
    assert action(view.state, *args).strip_mode == "raw"
    with pytest.raises(ValueError, match="strip_mode must be one of"):
        set_strip_mode(view.state, "linear")


def _label_boxes(strip, height: int) -> dict:
    """Each label's box (x, y, w, h) in window pixels (origin top-left), measured here from
    the label's position and its text's size as drawn."""
    out = {}
    for column, r, label in zip(COLUMNS, strip.renderers, strip.labels, strict=True):
        extent = [0.0, 0.0]
        label.GetSize(r, extent)
        x, y = r.GetOrigin()
        lx, ly = label.GetPosition()
        out[column] = (x + lx, height - (y + ly + extent[1]), extent[0], extent[1])
    return out


@pytest.mark.parametrize("width", [330, 900])
def test_the_tile_labels_fit_their_tiles_and_do_not_touch(width):
    """A narrow view (tiles 55 pixels wide) draws its labels smaller, or shorter (``sum`` for
    ``sum (weighted)``; initials at the narrowest), so that each lies inside its tile with room
    to spare: no label box reaches its tile's right edge or the next label, and the tiles'
    rightmost columns under the labels hold no text's pixels (a label cut by the tile's edge
    left its letters there). A wide one keeps the full names."""
    from explorer.app.termstrip import LABEL_COLOUR

    v = sphere_view("gold", (width, 400))
    try:
        v.show_state(set_strip(v.state, True))
        img = _picture(v)
        strip = v.strip
        boxes = _label_boxes(strip, 400)
        light = np.rint(np.multiply(LABEL_COLOUR, 255)).astype(int)
        ends = []
        for column in COLUMNS:
            x, y, w, h = strip.tile_box(column)
            lx, ly, lw, lh = boxes[column]
            assert x < lx and lx + lw <= x + w - 2, (column, strip.labels[0].GetInput())
            assert y <= ly and ly + lh <= y + h
            edge = img[int(ly) : int(ly + lh) + 1, x + w - 2 : x + w].reshape(-1, 3)
            assert not (np.abs(edge - light).max(axis=1) <= 60).any(), column
            ends.append((lx, lx + lw))
        assert all(a[1] < b[0] for a, b in zip(ends, ends[1:], strict=False))
        texts = [t.GetInput() for t in strip.labels]
        if width == 900:
            assert texts[:5] == ["emission", "ambient", "diffuse", "specular", "sum (weighted)"]
        else:
            assert texts[4] in ("sum", "+")  # (shortened: "sum (weighted)" did not fit)
    finally:
        v.plotter.close()


def test_tiles_too_small_for_a_picture_draw_per_vertex():
    """A pane so narrow that the tiles are under 16 pixels wide (a picture's least side, the
    page's compare pane as it opens): the per-pixel view's strip draws its tiles per vertex,
    and says nothing (it said 'image size must be ... got (10, 12)' in the page's log)."""
    v = sphere_view("gold", (80, 300))
    try:
        state = set_strip(v.state, True)
        state = state.replace(scene=state.scene.replace(shading="per-pixel"))
        v.show_state(state)
        _picture(v)
        assert v.strip.on and v.strip.renderers[0].GetSize()[0] < 16
        v.strip.before_pixels(state, True, v.mesh)
        assert v.strip.pixel_tiles is None and not v.strip.report((0, 0, 0))["per_pixel"]
    finally:
        v.plotter.close()


def test_the_selected_handles_ring_stays_around_its_handle_above_the_strip(view):
    """The ring is drawn in the main renderer's own pixels: with the strip's band under the
    view it stays around the handle's sphere (it was drawn the band's height above it)."""
    import math

    from explorer.app import view as V
    from explorer.app.model import handle_point

    view.add_handles(lambda i: None, lambda i: None, lambda i: None)
    view.show_state(set_strip(view.state, True))
    s = view.state
    view.before_frame(V.view_camera(view.plotter.camera, s.centre, s.radius))  # (places the ring)
    img = _picture(view)
    point = handle_point(s, s.light)
    x, y = view.world_to_window(point)
    band = view.viewport_pixels()[1]  # (the strip's band under the main renderer)
    assert band > 0 and 0 <= x < SIZE[0] and 0 <= y < SIZE[1] - band  # (the test's premise)
    size = V.HANDLE_RADIUS * V.SELECTED_SCALE * s.radius / view.frame[1]
    r = view._pixel_radius(view.to_view(point), size) + V.RING_GAP
    t = np.linspace(0, 2 * math.pi, 72, endpoint=False)
    xs, ys = (x + r * np.cos(t)).round().astype(int), (y - r * np.sin(t)).round().astype(int)
    inside = (ys >= 0) & (ys < SIZE[1]) & (xs >= 0) & (xs < SIZE[0])
    on_ring = img[ys[inside], xs[inside]].min(axis=1) > 235
    assert inside.mean() > 0.9 and on_ring.mean() > 0.5


@pytest.mark.parametrize("preset", ["gold", "black_rubber"])
def test_the_overflow_caption_says_what_the_mask_is_under_the_tiles(preset):
    """Where the overflow tile shows a share > 0 (gold's saturated highlight), a caption on the
    line under the tiles says what the mask is, its share the overflow tile's: its text's pixels
    drawn there, inside the strip's band and under every tile. Where nothing is clamped the line
    is empty (the band's background)."""
    from explorer.app.termstrip import LABEL_COLOUR

    v = sphere_view(preset, (900, 600))
    try:
        v.show_state(set_strip(v.state, True))
        img = _picture(v)
        rep = v.strip.report((0, 0, 0))
        share = 100.0 * rep["overflow"]
        bottom = max(y + h for _, y, _, h in rep["boxes"].values())  # (the tiles' lowest row)
        line = img[bottom:600]
        light = np.rint(np.multiply(LABEL_COLOUR, 255)).astype(int)
        text = (np.abs(line - light).max(axis=2) <= 60).sum()  # (the caption's letters)
        if preset == "gold":
            assert share > 0.0
            want = f"overflow (magenta): {share:.1f}% of the vertices clamped"
            assert rep["overflow_caption"].startswith(want)
            x, y, w, h = rep["overflow_box"]
            assert 0 <= x and x + w <= 900 and bottom <= y and y + h <= 600
            assert text > 50
        else:
            assert share == 0.0 and rep["overflow_caption"] == "" and text == 0
            assert (line == line[0, 0]).all()  # (the band's background, nothing drawn)
    finally:
        v.plotter.close()


def _two_lights(state):
    """``state`` with a second light (a red directional one from the left, some ambient)."""
    from explorer.core.lights import DirectionalLight

    red = DirectionalLight(
        ambient=(0.1, 0.0, 0.0), diffuse=(0.8, 0.1, 0.1), specular=(1, 1, 1), to_light=(-1, 0, 1)
    )
    return state.replace(scene=state.scene.replace(lights=(*state.scene.lights, red)))


def test_a_row_per_light_each_the_engines_strip_of_that_light_alone():
    """``strip_lights`` adds a row of tiles per light under the strip: each tile at the probe
    vertex shows that light's term alone as ``render --strip --strip-lights`` computes it (its
    rows after the scene's), named at the row's first tile; the rows go with the switch."""
    from explorer.app.termstrip import set_strip_lights
    from explorer.render.strip import render_strip
    from explorer.shading.display import to_bytes

    v = sphere_view("gold", (900, 700))
    try:
        state = set_strip_lights(set_strip(_two_lights(v.state), True), True)
        v.show_state(state)
        img = _picture(v)
        strip = v.strip
        i = v.probe_vertex()
        ring = one_ring(v.mesh, i)
        point = v.to_view(v.mesh.positions[i])
        rep = strip.report(point)
        assert [r["name"] for r in rep["lights"]] == ["light 1: point", "light 2: directional"]
        want = render_strip(v.drawings[0].shader.scene, v.mesh, lights=True, tile=(32, 32))
        top = min(y for _, y, _, _ in rep["boxes"].values())
        for k, (row, light) in enumerate(zip(strip.lights.rows, rep["lights"], strict=True)):
            engine = want.strips[k + 1]  # (render --strip-lights: the scene's row first)
            for t, column in enumerate(COLUMNS[:5]):
                assert np.array_equal(row.tiles[t], to_bytes(engine.tiles[column]))
                x, y = light["px"][column]
                assert rep["boxes"][column][1] + rep["boxes"][column][3] <= y  # under the strip
                assert in_ring(img[y, x], row.tiles[t], ring), (k, column)
        assert not np.array_equal(strip.lights.rows[0].tiles[4], strip.lights.rows[1].tiles[4])
        assert top < 700 * 0.6  # (the strip grew: three rows)
        v.show_state(set_strip_lights(state, False))
        assert not strip.lights.rows and strip.report(point)["lights"] == []
    finally:
        v.plotter.close()
