"""The term strip in the real window (pytest-qt on a private Xvfb, issue 41): the panel's
``strip`` check box and ``strip_mode`` radios, and the tiles under the view read from the
window's pixels at the probe vertex, each the engine's term."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.probes import in_ring, one_ring
from PySide6 import QtWidgets

from explorer.app.termstrip import LABEL_COLOUR
from explorer.render.strip import COLUMNS
from explorer.shading.strip import shader_strip

pytestmark = pytest.mark.usefixtures("xdisplay")


def _pixels(pl) -> np.ndarray:
    pl.render()
    return np.asarray(pl.screenshot(return_img=True)[:, :, :3]).astype(int)


def _tab_with(w, widget) -> None:
    """Show the panel tab that holds ``widget`` (a click reaches shown widgets only)."""
    tabs = w.findChild(QtWidgets.QTabWidget)
    for i in range(tabs.count()):
        if tabs.widget(i).isAncestorOf(widget):
            tabs.setCurrentIndex(i)


def test_the_strip_is_drawn_under_the_view_from_the_panel(open_window, qtbot, tmp_path):
    w = open_window("--mesh", "sphere", "--preset", "gold")
    box = w.findChild(QtWidgets.QCheckBox, "strip")
    _tab_with(w, box)
    box.click()  # (the widget's own click: it may lie below the panel's scrolled part)
    assert w.controller.state.strip and w.view.strip.on
    for mode in ("raw", "weighted"):
        radio = w.findChild(QtWidgets.QRadioButton, mode)
        radio.click()
        assert w.controller.state.strip_mode == mode
        img = _pixels(w.plotter)
        view = w.view
        strip = view.strip
        i = view.probe_vertex()
        ring = one_ring(view.mesh, i)
        point = view.to_view(view.mesh.positions[i])
        terms = shader_strip(view.drawings[0].shader, mode)
        for k, column in enumerate(COLUMNS):
            x, y = strip.tile_pixel(column, point)
            want = strip.tiles[k][i].astype(int)
            if column in terms.tiles:
                assert np.abs(want - np.rint(terms.tiles[column][i] * 255)).max() <= 1
            assert in_ring(img[y, x], strip.tiles[k], ring), column
    # gold clamps its highlight: the caption under the tiles says so, its letters drawn there
    rep = strip.report((0, 0, 0))
    share = 100.0 * rep["overflow"]
    assert rep["overflow_caption"].startswith(f"overflow (magenta): {share:.1f}% of the vertices")
    x, y, cw, ch = rep["overflow_box"]
    assert y >= max(by + bh for _, by, _, bh in rep["boxes"].values())  # (under the tiles)
    letters = img[y : y + ch, x : x + cw]
    assert (np.abs(letters - np.rint(np.multiply(LABEL_COLOUR, 255))).max(axis=2) <= 60).sum() > 50
    w.grab().save(str(tmp_path / "window_strip.png"))
    box.click()
    assert not w.view.strip.on


def test_the_inset_plots_the_three_models_lobes_from_the_panel(open_window, tmp_path):
    w = open_window("--mesh", "sphere", "--preset", "chrome")
    combo = w.findChild(QtWidgets.QComboBox, "lobes")
    _tab_with(w, combo)
    combo.setCurrentIndex(combo.findText("models"))
    combo.activated.emit(combo.currentIndex())  # (what a pick in the list sends)
    assert w.controller.state.lobes == "models"
    rep = w.view.lobe.report()
    assert [c["label"].split()[0] for c in rep["curves"]] == ["Phong", "Blinn", "three.js"]
    img = _pixels(w.plotter)
    last = rep["curves"][-1]  # (drawn last: nothing over it)
    hits = 0
    for x, y in last["px"]:
        patch = img[max(y - 1, 0) : y + 2, max(x - 1, 0) : x + 2].reshape(-1, 3)
        hits += bool((np.abs(patch - last["colour"]) <= 1).all(axis=1).any())
    assert hits >= 0.9 * len(last["px"])
    w.grab().save(str(tmp_path / "window_lobes.png"))


#: the rows at a tile's bottom its label may cover (pixels)
LABEL_ROWS = 20


def test_per_pixel_the_tiles_are_the_per_pixel_terms_and_the_sum_tile_the_picture(
    open_window, tmp_path
):
    """With the view lit per pixel, each tile is a per-pixel picture at the tile's size and
    the view's camera: the window's sum tile is ``render --per-pixel``'s picture there bit for
    bit, and the diffuse tile the per-pixel shader's diffuse term (its kept sums recomposed)."""
    from explorer.app import model as M
    from explorer.app.view import view_camera
    from explorer.render.live import LivePixels, picture
    from explorer.shading.display import to_bytes
    from explorer.shading.strip import compose_strip

    w = open_window("--mesh", "torus", "--preset", "glossy_plastic", "--per-pixel")
    box = w.findChild(QtWidgets.QCheckBox, "strip")
    _tab_with(w, box)
    box.click()
    img = _pixels(w.plotter)
    strip = w.view.strip
    assert strip.pixel_tiles is not None and strip.report((0, 0, 0))["per_pixel"]
    state = w.controller.state
    camera = view_camera(w.plotter.camera, state.centre, state.radius)
    scene = M.set_camera(state, camera).shown_scene()
    bg = tuple(w.plotter.renderer.GetBackground())
    x, y, tw, th = strip.tile_box("sum")
    ref = picture(scene, w.view.mesh, (tw, th), camera=camera, background=bg).rgb
    rows = slice(0, th - LABEL_ROWS)
    assert (ref != to_bytes([bg])[0]).any(axis=2).mean() > 0.1  # the mesh fills the tile
    assert np.array_equal(img[y : y + th, x : x + tw][rows], ref[rows])
    with LivePixels(w.view.mesh) as live:
        live.frame(scene, camera, (tw, th), background=bg)
        g, _ = live.gbuffer(camera, (tw, th))
        terms = compose_strip(scene, live.shader.terms, live.shader.colors, "weighted")
        want = np.array(ref)
        want.reshape(-1, 3)[g.pixels] = to_bytes(terms.tiles["diffuse"])
    x, y, tw, th = strip.tile_box("diffuse")
    assert np.array_equal(img[y : y + th, x : x + tw][rows], want[rows])
    # the overflow caption gives the per-pixel tile's share, of the pixels (its label's)
    rep = strip.report((0, 0, 0))
    share = rep["texts"]["overflow"].split()[-1]
    assert rep["overflow_caption"].startswith(f"overflow (magenta): {share} of the pixels")
    # the main view above the strip: the per-pixel picture of its own part of the window
    from helpers.probes import interior
    from test_window_pixels import rings

    from explorer.render.perpixel import reference

    x0, y0 = (int(v) for v in w.plotter.renderer.GetOrigin())
    vw, vh = (int(v) for v in w.plotter.renderer.GetSize())
    assert y0 > 0 and vh < w.plotter.window_size[1]  # (the strip under it)
    ref = reference(scene, w.view.mesh, (vw, vh), camera=camera)
    H = w.plotter.window_size[1]
    got = img[H - y0 - vh : H - y0, x0 : x0 + vw]
    d = np.abs(got - ref.image(bg).astype(int)).max(axis=2)
    W = w.plotter.window_size[0]
    free = interior(ref.mask) & ~rings(w.view, (W, H))[H - y0 - vh : H - y0, x0 : x0 + vw]
    lx, ly, lw, lh = w.view.lobe.box  # (the inset: in the main renderer's own pixels)
    free[vh - (ly + lh) - 2 :, : lx + lw + 3] = False
    assert free.sum() > 5000 and d[free].max() <= 1
    w.grab().save(str(tmp_path / "window_strip_per_pixel.png"))
    # per vertex again: the tiles draw the mesh, the pictures gone
    w.controller.set_value("shading", "per-vertex")
    _pixels(w.plotter)
    assert strip.pixel_tiles is None and not strip.report((0, 0, 0))["per_pixel"]


def test_a_mesh_files_groups_each_in_its_material_in_the_strip(open_window, tmp_path):
    """An OBJ of two groups in two materials drawn in them: the sum tile is the view's own
    colours on every vertex, and each group's tiles recompose its own material (the window's
    pixel at a vertex of each group within its one-ring's colours)."""
    from helpers.files import write_two_groups

    from explorer.shading.shader import Shader

    w = open_window("--mesh", str(write_two_groups(tmp_path)))
    state = w.controller.state
    assert state.groups is not None and state.groups[0] != state.groups[1]
    box = w.findChild(QtWidgets.QCheckBox, "strip")
    _tab_with(w, box)
    box.click()
    img = _pixels(w.plotter)
    view, strip = w.view, w.view.strip
    assert np.array_equal(strip.tiles[COLUMNS.index("sum")], view.displayed_colors())
    mesh = view.mesh
    for g, material in enumerate(state.groups):
        rows = mesh.groups.vertices(g)
        scene = view.drawings[0].shader.scene.replace(material=material)
        own = Shader(scene, mesh.positions, mesh.normals, precision="float64")
        terms = shader_strip(own, "weighted")
        diffuse = strip.tiles[COLUMNS.index("diffuse")].astype(int)[rows]
        assert np.abs(diffuse - np.rint(terms.tiles["diffuse"][rows] * 255)).max() <= 1
        face = mesh.faces[np.isin(mesh.faces, rows).all(axis=1)][0]  # (a corner lies on the edge)
        x, y = strip.tile_pixel("sum", view.to_view(mesh.positions[face].mean(axis=0)))
        assert in_ring(img[y, x], strip.tiles[COLUMNS.index("sum")], face)


def test_the_compare_views_panes_each_show_their_sides_strip(open_window):
    """The compare view with the strip on: side B's pane has the strip of side B (its
    material and model), side A's pane A's; each sum tile is its pane's own colours, and the
    window's pixel of B's sum tile at the probe is within its one-ring's."""
    w = open_window("--mesh", "sphere", "--preset", "gold")
    box = w.findChild(QtWidgets.QCheckBox, "strip")
    _tab_with(w, box)
    box.click()
    assert w.controller.set_value("compare", True, merge=False)
    state = w.controller.state
    assert state.compare != state.material or state.compare_model != state.scene.model
    img = _pixels(w.plotter_b)
    for view in (w.view, w.view_b):
        assert view.strip.on
        sum_tile = view.strip.tiles[COLUMNS.index("sum")]
        assert np.array_equal(sum_tile, view.displayed_colors())
    assert not np.array_equal(w.view.strip.tiles[3], w.view_b.strip.tiles[3])  # (specular)
    view = w.view_b
    i = view.probe_vertex()
    x, y = view.strip.tile_pixel("sum", view.to_view(view.mesh.positions[i]))
    assert in_ring(img[y, x], view.strip.tiles[COLUMNS.index("sum")], one_ring(view.mesh, i))


def test_side_bs_strip_per_pixel_under_its_caption_and_the_strip_side_row(open_window):
    """Gouraud vs per-pixel with the strip on: side B's pane (lit per pixel) has the per-pixel
    tiles of side B (its sum tile is ``render --per-pixel``'s picture of B's scene at the
    tile's size and the shared camera, bit for bit, read from pane B's pixels), side A's the
    per-vertex ones; each strip's caption names its side (its text drawn at the first tile's
    top left). The ``strip_side`` radios keep the strip in one pane: the other keeps the
    strip's band, empty (its view the same size as the other's)."""
    from explorer.app import model as M
    from explorer.app.effectactions import gouraud_vs_per_pixel
    from explorer.app.termstrip import LABEL_COLOUR
    from explorer.app.view import view_camera
    from explorer.render.live import picture

    w = open_window("--mesh", "torus", "--resolution", "32", "--preset", "glossy_plastic")
    box = w.findChild(QtWidgets.QCheckBox, "strip")
    _tab_with(w, box)
    box.click()
    w.controller.act(gouraud_vs_per_pixel)
    state = w.controller.state
    b = M.side_b(state)
    assert b.scene.shading == "per-pixel" and state.scene.shading == "per-vertex"
    _pixels(w.plotter)
    img = _pixels(w.plotter_b)
    strip_a, strip_b = w.view.strip, w.view_b.strip
    assert strip_a.pixel_tiles is None and strip_b.pixel_tiles is not None
    camera = view_camera(w.plotter_b.camera, state.centre, state.radius)
    scene = M.set_camera(b, camera).shown_scene()
    bg = tuple(w.plotter_b.renderer.GetBackground())
    x, y, tw, th = strip_b.tile_box("sum")
    ref = picture(scene, w.view_b.mesh, (tw, th), camera=camera, background=bg).rgb
    rows = slice(0, th - LABEL_ROWS)
    assert (np.abs(ref.astype(int) - img[y : y + th, x : x + tw]).max(axis=2) > 0).mean() < 0.5
    assert np.array_equal(img[y : y + th, x : x + tw][rows], ref[rows])
    # the captions: named in the report, drawn at the first tile's top left
    light = np.rint(np.multiply(LABEL_COLOUR, 255)).astype(int)
    assert strip_a.report((0, 0, 0))["caption"] == "side A"
    assert strip_b.report((0, 0, 0))["caption"] == "side B"
    x, y, tw, th = strip_b.tile_box("emission")
    corner = img[y + 2 : y + 16, x + 2 : x + 44].reshape(-1, 3)
    assert (np.abs(corner - light).max(axis=1) <= 40).sum() >= 10  # (the text's own pixels)
    # one pane's strip: the other pane's band stays, empty (both views of one size)
    size = tuple(w.plotter_b.renderer.GetSize())
    for side, a_on, b_on in (("b", False, True), ("a", True, False), ("both", True, True)):
        radio = w.findChild(QtWidgets.QRadioButton, side)
        _tab_with(w, radio)
        radio.click()
        assert w.controller.state.strip_side == side
        for pl, strip, on in ((w.plotter, strip_a, a_on), (w.plotter_b, strip_b, b_on)):
            img = _pixels(pl)
            assert strip.on == on and (strip.report((0, 0, 0)) is not None) == on
            assert tuple(pl.renderer.GetSize()) == size  # (the band under the view)
            x, y, tw, th = strip.tile_box("diffuse")
            band = img[y : y + th, x : x + tw].reshape(-1, 3)
            empty = (band == np.rint(np.multiply(bg, 255)).astype(int)).all(axis=1).all()
            assert empty != on, (side, pl is w.plotter)
    w.controller.set_value("compare", False, merge=False)
    assert w.view.strip.on and w.view.strip.report((0, 0, 0))["caption"] == ""


def test_per_pixel_a_mesh_files_groups_each_in_its_material_in_the_tiles(open_window, tmp_path):
    """A mesh file of two groups in two materials, lit per pixel, with the strip on: the sum
    tile is the per-pixel picture of the file in its materials (LivePixels with them) bit for
    bit, and the diffuse tile's pixels of each group are that group's material's diffuse term
    (the per-pixel shader's sums recomposed with it)."""
    from helpers.files import write_two_groups

    from explorer.app import model as M
    from explorer.app.view import view_camera
    from explorer.render.live import LivePixels
    from explorer.shading.display import to_bytes
    from explorer.shading.strip import compose_strip

    w = open_window("--mesh", str(write_two_groups(tmp_path)), "--per-pixel")
    state = w.controller.state
    assert state.groups is not None and state.groups[0] != state.groups[1]
    box = w.findChild(QtWidgets.QCheckBox, "strip")
    _tab_with(w, box)
    box.click()
    img = _pixels(w.plotter)
    strip = w.view.strip
    assert strip.pixel_tiles is not None
    state = w.controller.state
    camera = view_camera(w.plotter.camera, state.centre, state.radius)
    scene = M.set_camera(state, camera).shown_scene()
    bg = tuple(w.plotter.renderer.GetBackground())
    x, y, tw, th = strip.tile_box("sum")
    rows = slice(0, th - LABEL_ROWS)
    groups = state.shown_groups()
    with LivePixels(w.view.mesh) as live:
        ref = live.frame(scene, camera, (tw, th), background=bg, materials=groups).rgb
        assert np.array_equal(img[y : y + th, x : x + tw][rows], ref[rows])
        g, _ = live.gbuffer(camera, (tw, th))
        sh = live.shader
        first = len(sh.colors) - len(g.pixels)
        want = np.array(ref)
        flat = want.reshape(-1, 3)
        for k, r in enumerate(live._group_rows(g, groups, first)):
            own = compose_strip(scene.replace(material=groups[k]), sh.terms, sh.colors)
            flat[g.pixels[r - first]] = to_bytes(own.tiles["diffuse"][r])
        assert len({tuple(c) for c in flat[g.pixels]}) > 10  # (the mesh in the tile)
    x, y, tw, th = strip.tile_box("diffuse")
    assert np.array_equal(img[y : y + th, x : x + tw][rows], want[rows])


def test_a_row_per_light_from_the_panel_each_lights_strip_alone(open_window):
    """The view tab's ``strip_lights`` check box (shown with the strip): a row of tiles per
    light under the strip, each light's sum tile at the probe vertex, read from the window's
    pixels, the engine's colour of that light alone as ``render --strip --strip-lights`` makes
    it; the row goes with the box, in one undo step."""
    from explorer.render.strip import render_strip
    from explorer.shading.display import to_bytes

    w = open_window("--mesh", "sphere", "--preset", "gold")
    box = w.findChild(QtWidgets.QCheckBox, "strip")
    _tab_with(w, box)
    box.click()
    lights = w.findChild(QtWidgets.QCheckBox, "strip_lights")
    assert lights is not None and lights.isVisible()
    lights.click()
    assert w.controller.state.strip_lights
    view = w.view
    img = _pixels(w.plotter)
    i = view.probe_vertex()
    ring = one_ring(view.mesh, i)
    point = view.to_view(view.mesh.positions[i])
    rep = view.strip.report(point)
    assert [r["name"] for r in rep["lights"]] == ["light 1: point"]
    want = render_strip(view.drawings[0].shader.scene, view.mesh, lights=True, tile=(32, 32))
    row = view.strip.lights.rows[0]
    s = COLUMNS.index("sum")
    assert np.array_equal(row.tiles[s], to_bytes(want.strips[1].tiles["sum"]))
    x, y = rep["lights"][0]["px"]["sum"]
    assert y >= sum(rep["boxes"]["sum"][1::2])  # (under the strip's own sum tile)
    assert in_ring(img[y, x], row.tiles[s], ring)
    w.controller.undo()
    assert not w.controller.state.strip_lights and not view.strip.lights.rows
