"""The per-pixel view (explorer.app.pixellayer) in the view port both front ends share, on an
off-screen plotter: the pixels read from the plotter equal the engine's per-pixel picture
(explorer.render.perpixel.reference, what ``render --per-pixel`` writes) for the view's camera
and size; a cube's highlight per pixel that per vertex misses; the drag fallback."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.controllers import FakeFront, FakeWorker
from helpers.probes import interior

from explorer.analysis.comparison import heat_map
from explorer.app import intents
from explorer.app import model as M
from explorer.app import start as A
from explorer.app.controller import Controller
from explorer.app.controller.ports import Ports
from explorer.app.difference import VMAX
from explorer.app.pixellayer import DEPTH_NONE, depth_codes, quad_box
from explorer.app.sides import SideB
from explorer.app.view import HANDLE_RADIUS, RING_GAP, SELECTED_SCALE, handle_point
from explorer.app.viewport import PlotterView
from explorer.cli import build_parser
from explorer.cli.explorerstart import start
from explorer.render.live import picture as render_per_pixel
from explorer.render.perpixel import reference
from explorer.render.vtk import plotter
from explorer.shading.display import to_bytes

SIZE = (320, 240)
BACKGROUND = (0.1, 0.1, 0.1)


class Pictures:
    """The front end's part: a picture is a frame drawn now."""

    def __init__(self):
        self.view = None

    def send(self):
        self.view.plotter.render_window.Render()

    def show_controls(self, state):
        pass

    def show_legend(self, legend, advice):
        pass

    def after_frame(self):
        pass


def make_port(mesh_name, tmp_path, monkeypatch, *args, side_b=None):
    monkeypatch.setenv("PHONG_EXPLORER_MATERIALS", str(tmp_path / "presets"))
    parsed = build_parser().parse_args(["gui", "--mesh", mesh_name, *args])
    scene, mesh, preset = start(parsed)
    state = A.first_state(scene, mesh, name=mesh_name, preset=preset)
    pictures = Pictures()
    view = PlotterView(plotter(SIZE, BACKGROUND), pictures)
    pictures.view = view
    ports = Ports.of(FakeFront(), worker=FakeWorker(), view=view)
    c = Controller(state, mesh, ports, output_dir=tmp_path, last_session=tmp_path / "last.yaml")
    view.attach(c, mesh, side_b=None if side_b is None else SideB(view, side_b))
    c.start()
    view.show_start(c.state)
    view.redraw()
    return view


@pytest.fixture
def torus(tmp_path, monkeypatch):
    view = make_port("torus", tmp_path, monkeypatch, "--preset", "glossy_plastic")
    yield view
    view.plotter.close()


def picture(view) -> np.ndarray:
    view.plotter.render_window.Render()
    return view.plotter.screenshot(return_img=True)[:, :, :3].astype(int)


def handle_disks(view) -> np.ndarray:
    """(h, w) bool: the pixels of every light handle and the selected one's ring."""
    w, h = SIZE
    yy, xx = np.mgrid[0:h, 0:w]
    out = np.zeros((h, w), bool)
    s = view.view.state
    for i, (x, y, _ahead) in enumerate(view.view.handle_pixels()):
        size = HANDLE_RADIUS * SELECTED_SCALE * s.radius / view.view.frame[1]
        r = view.view._pixel_radius(view.view.to_view(handle_point(s, i)), size)
        out |= np.hypot(xx - x, (h - 1 - yy) - y) <= r + RING_GAP + 3
    return out


def overlays(view) -> np.ndarray:
    """(h, w) bool: what the view draws over the mesh (the light handles, the selected one's
    ring, the lobe inset's panel), grown by 2 pixels."""
    w, h = SIZE
    out = handle_disks(view)
    x0, y0, bw, bh = view.view.lobe.box  # display pixels, origin bottom-left
    out[max(h - (y0 + bh) - 2, 0) : h - y0 + 2, max(x0 - 2, 0) : x0 + bw + 2] = True
    return out


def against_reference(view):
    """The view's pixels and the engine's per-pixel picture for its state, camera and size
    (explorer.render.perpixel.reference, what ``render --per-pixel`` writes): the largest
    difference over the interior pixels, the silhouette pixels off by more than 1 and their
    count, over the pixels the overlays leave free."""
    s = view.controller.state
    img = picture(view)
    ref = reference(s.shown_scene(), view.view.mesh, SIZE, camera=s.camera)
    d = np.abs(img - ref.image(BACKGROUND).astype(int)).max(axis=2)
    free = ~overlays(view)
    inner = interior(ref.mask) & free
    edge = ref.mask & ~interior(ref.mask) & free
    return int(d[inner].max()), int((d[edge] > 1).sum()), int(edge.sum()), ref


def test_per_pixel_mode_draws_the_engines_per_pixel_picture(torus):
    c = torus.controller
    before = picture(torus)
    c.set_value("shading", "per-pixel")
    assert c.state.scene.shading == "per-pixel" and torus.pixels.shown
    worst, off, edge, ref = against_reference(torus)
    assert ref.mask.sum() > 5000 and edge > 200
    assert worst <= 1  # every interior pixel within 1 level of the engine's per-pixel picture
    assert off <= 0.05 * edge  # silhouette pixels: where two rasterisations may disagree
    # the per-vertex picture differs from it (else the test could not fail)
    d = np.abs(before - ref.image(BACKGROUND).astype(int)).max(axis=2)
    assert d[interior(ref.mask) & ~overlays(torus)].max() > 4
    # and `render --per-pixel`'s picture (explorer.render.live.picture) of the same state
    s = c.state
    rendered = render_per_pixel(
        s.shown_scene(), torus.view.mesh, SIZE, camera=s.camera, background=BACKGROUND
    )
    d = np.abs(picture(torus) - rendered.rgb.astype(int)).max(axis=2)
    assert d[interior(rendered.mask) & ~overlays(torus)].max() <= 1
    c.undo()  # one undo step: the per-vertex view again
    assert c.state.scene.shading == "per-vertex" and not torus.pixels.shown
    assert np.array_equal(picture(torus), before)


def test_a_material_change_makes_no_gbuffer_nor_light_pass_and_a_camera_change_one(torus):
    c = torus.controller
    c.set_value("shading", "per-pixel")
    live = torus.pixels.live
    made, passes = live.gbuffers, live.light_passes
    c.set_value("kd", 0.3, merge=False)
    assert live.gbuffers == made and live.light_passes == passes  # a recompose, no light pass
    assert against_reference(torus)[0] <= 1
    torus.plotter.camera.Azimuth(30.0)
    torus.plotter.render_window.Render()
    assert live.gbuffers == made + 1
    assert against_reference(torus)[0] <= 1  # the new camera's picture


class Pane:
    """Side B's pane: an off-screen plotter of the same size."""

    handles = False

    def __init__(self):
        self.plotters: list = []

    def make_plotter(self):
        self.plotters.append(plotter(SIZE, BACKGROUND))
        return self.plotters[-1]

    def made(self, pl, view):
        pass

    def show_pane(self, visible):
        pass

    def follow(self):
        self.plotters[-1].render_window.Render()

    def beside(self, img):
        return img


@pytest.fixture
def compare(tmp_path, monkeypatch):
    """The torus with side B in an off-screen pane."""
    view = make_port("torus", tmp_path, monkeypatch, "--preset", "glossy_plastic", side_b=Pane())
    yield view
    view.plotter.close()
    for pl in view.side_b.pane.plotters:
        pl.close()


def test_gouraud_vs_per_pixel_says_each_sides_time_and_the_error(compare):
    c, b = compare.controller, compare.side_b
    intents.run("gouraud_vs_per_pixel", c, {})  # View > Gouraud vs per-pixel
    assert c.state.scene.shading == "per-vertex" and b.pixels.shown and not compare.pixels.shown
    assert c.store.undo_label() == "Gouraud vs per-pixel"  # one undo step
    a_img = picture(compare)  # (side B follows side A's frame)
    b_img = b.plotter.screenshot(return_img=True)[:, :, :3].astype(int)
    errors, mask = b.errors
    # the errors are the two pictures' differences, pixel by pixel (within the rasteriser's
    # rounding of the interpolated colours) where nothing is drawn over the mesh
    seen = np.zeros(mask.shape, np.int64)
    seen[mask] = errors
    free = interior(mask) & ~overlays(compare)
    free[:60] = False  # (the captions)
    shown = np.abs(a_img - b_img).max(axis=2)
    assert free.sum() > 5000 and np.abs(shown[free] - seen[free]).max() <= 1
    f = b.figures
    assert f.pixels == mask.sum() == errors.size
    assert f.max_levels == errors.max() > 10  # Gouraud misses the highlight's shape
    assert f.p95_levels == pytest.approx(np.percentile(errors, 95))
    assert f.share == pytest.approx(np.count_nonzero(errors > 2) / errors.size)
    assert 0.0 < f.vertex_ms < 1e5 and 0.0 < f.pixel_ms < 1e5
    line = f.line()
    assert f"error: max {f.max_levels}, p95 {f.p95_levels:.0f} levels" in line
    for view in (compare.view, b.view):  # the line in both panes
        assert view.caption.GetInput().endswith(line)
    assert "per-vertex" in compare.view.caption.GetInput()
    assert "per-pixel" in b.view.caption.GetInput()


def test_gouraud_vs_per_pixel_difference_draws_the_heat_map_per_pixel(compare):
    c, b = compare.controller, compare.side_b
    intents.run("gouraud_vs_per_pixel", c, {})  # View > Gouraud vs per-pixel
    c.act(M.set_compare_difference, True)
    picture(compare)
    errors, mask = b.errors
    b_img = b.plotter.screenshot(return_img=True)[:, :, :3].astype(int)
    want = heat_map(_levels(errors, mask), mask, vmax=VMAX)
    free = interior(mask) & ~overlays(compare)
    free[:60] = False
    assert np.abs(b_img[free] - want[free]).max() == 0  # the map, texel for pixel
    c.act(M.set_compare_difference, False)
    picture(compare)
    b_img = b.plotter.screenshot(return_img=True)[:, :, :3].astype(int)
    assert np.abs(b_img[free] - b.pixels.rgb[free]).max() == 0  # the picture again


def _levels(errors, mask):
    out = np.zeros(mask.shape, np.int64)
    out[mask] = errors
    return out


@pytest.mark.parametrize(
    ("ms", "vertex_ms", "falls_back"), [(30.0, 10.0, True), (15.0, 10.0, False)]
)
def test_a_camera_drag_falls_back_to_per_vertex_when_per_pixel_costs_twice(
    torus, ms, vertex_ms, falls_back
):
    c, layer = torus.controller, torus.pixels
    c.set_value("shading", "per-pixel")
    picture(torus)
    made = layer.live.gbuffers
    torus.begin_drag()
    c.set_value("kd", 0.4)  # a slider drag moves no camera: per pixel still
    assert layer.shown and not layer.fallback
    layer.ms, layer.vertex_ms = ms, vertex_ms  # what the last frames measured
    drags, per_vertex = layer.drags, layer.vertex_frames
    torus.plotter.camera.Azimuth(20.0)
    torus.plotter.render_window.Render()  # a frame of the camera drag
    assert layer.fallback is falls_back and layer.shown is not falls_back
    # the decision as a report gives it: the times it compared, what it decided, once a drag
    assert layer.drags == drags + 1 and layer.drag_decision == (ms, vertex_ms, falls_back)
    assert layer.vertex_frames == per_vertex + int(falls_back)
    drawn = torus.report()["pixels"]
    assert drawn["drag"] == {"ms": ms, "vertex_ms": vertex_ms, "fallback": falls_back}
    assert drawn["vertex_frames"] == layer.vertex_frames and drawn["drags"] == layer.drags
    said = [m for m in c.ports.messages.messages if "camera drag drawn per vertex" in m[1]]
    assert bool(said) is falls_back
    assert layer.live.gbuffers == made + (0 if falls_back else 1)
    torus.end_drag()  # the release: per pixel again, for the camera where the drag ended
    assert layer.shown and not layer.fallback and layer.live.gbuffers == made + 1
    assert layer.drags == drags + 1 and layer.vertex_frames == per_vertex + int(falls_back)
    assert against_reference(torus)[0] <= 1


def test_a_cube_lit_near_a_face_shows_the_highlight_per_pixel_only(tmp_path, monkeypatch):
    light = ("--light-type", "point", "--light-position", "0.2", "0.3", "1.6")
    args = ("--preset", "glossy_plastic", *light, "--viewer-eye", "0.4", "0.6", "6")
    view = make_port("cube", tmp_path, monkeypatch, *args)
    try:
        c = view.controller
        for handle in view.view.handles:
            handle.Off()
        vertex = picture(view)
        c.set_value("shading", "per-pixel")
        for handle in view.view.handles:
            handle.Off()  # (the light's handle is right over the highlight)
        pixel = picture(view)
        s = c.state
        ref = reference(s.shown_scene(), view.view.mesh, SIZE, camera=s.camera)
        peak = ref.peak_index()
        x0, y0, bw, bh = view.view.lobe.box
        assert peak is not None and not (peak[1] <= x0 + bw and peak[0] >= SIZE[1] - y0 - bh)
        want = ref.image(BACKGROUND)[peak].astype(int)
        assert np.abs(pixel[peak] - want).max() <= 1  # the peak where the engine puts it
        white = want.min()  # (a highlight is whiter than the blue plastic: its least channel)
        assert white > 150  # a highlight...
        assert vertex[peak].min() < white - 100  # ...that per vertex does not show
        face = interior(ref.mask)
        face[SIZE[1] - y0 - bh :, : x0 + bw + 1] = False  # (the inset)
        face &= ~handle_disks(view)  # (the selected light's ring, drawn with its handle off)
        assert vertex[face].min(axis=1).max() < white - 100  # anywhere on the cube
    finally:
        view.plotter.close()


def test_a_mesh_switch_in_per_pixel_mode_draws_the_new_mesh_per_pixel(torus):
    c = torus.controller
    c.set_value("shading", "per-pixel")
    c.files.choose_mesh("cube")
    assert torus.view.mesh is c.meshes["cube"] and torus.pixels.shown
    worst, off, edge, ref = against_reference(torus)
    assert ref.mask.sum() > 5000 and worst <= 1 and off <= 0.05 * edge


def test_the_per_pixel_view_carries_every_setting_of_the_state(torus):
    """A spot that casts shadows, HDR with a tone map, Fresnel, an infinite viewer and a
    hidden term: the view's per-pixel picture is still the engine's for the state."""
    c = torus.controller
    c.set_value("shading", "per-pixel")
    settings = {"type": "spot", "cutoff": 40.0, "shadows": True, "hdr": True}
    settings.update(tone_map="aces", fresnel=0.2, local_viewer=False, show_ambient=False)
    for key, value in settings.items():
        c.set_value(key, value, merge=False)
    s = c.state
    assert s.selected_light.shadows and s.scene.hdr.tone_map == "aces" and not s.local_viewer
    worst, off, edge, ref = against_reference(torus)
    assert worst <= 1 and off <= 0.05 * edge


def test_a_textured_mesh_wears_its_texture_again_after_per_pixel(tmp_path, monkeypatch):
    """A mesh wearing a diffuse_map, shown per pixel and then per vertex again: the
    texture is back, the picture the same as before (leaving per-pixel cleared the actor's
    texture and shader, and the mesh came back untextured)."""
    from pathlib import Path

    tiles = Path(__file__).resolve().parents[2] / "docs" / "examples" / "tiles.png"
    view = make_port("teapot", tmp_path, monkeypatch, "--diffuse-map", str(tiles))
    try:
        c = view.controller
        assert view.view.drawings[0].texture is not None
        before = picture(view)
        assert c.set_value("shading", "per-pixel", merge=False)
        picture(view)
        assert c.set_value("shading", "per-vertex", merge=False)
        after = picture(view)
        assert view.view.drawings[0].texture is not None
        np.testing.assert_array_equal(after, before)
    finally:
        view.plotter.close()


def test_a_built_in_mesh_chosen_after_the_start_wears_the_map(tmp_path, monkeypatch):
    """The explorer started on the teapot with a diffuse_map; the sphere chosen after it comes
    with its (u, v) and wears the map (it was drawn untextured: the chooser loaded it without
    texture coordinates)."""
    from pathlib import Path

    tiles = Path(__file__).resolve().parents[2] / "docs" / "examples" / "tiles.png"
    view = make_port("teapot", tmp_path, monkeypatch, "--diffuse-map", str(tiles))
    try:
        c = view.controller
        assert c.files.choose_mesh("sphere")
        view.redraw()
        assert c.meshes["sphere"].uv is not None
        assert view.view.drawings[0].texture is not None
        tiled = picture(view)
        material = c.state.scene.material
        assert c.set_value("preset", "gold", merge=False)  # a material without the map
        view.redraw()
        assert c.state.scene.material.diffuse_map is None and material.diffuse_map is not None
        assert view.view.drawings[0].texture is None
        assert np.abs(picture(view) - tiled).max() > 100
    finally:
        view.plotter.close()


def test_a_mesh_without_uv_is_drawn_untextured_per_pixel(tmp_path, monkeypatch):
    """An OBJ without vt lines under a material with a diffuse_map: per pixel as per vertex,
    the view draws it untextured (the per-pixel frame raised 'no texture coordinates' at every
    frame)."""
    from pathlib import Path

    examples = Path(__file__).resolve().parents[2] / "docs" / "examples"
    view = make_port(
        str(examples / "teapot_parts.obj"),
        tmp_path,
        monkeypatch,
        "--preset",
        "gold",
        "--diffuse-map",
        str(examples / "tiles.png"),
    )
    try:
        c = view.controller
        assert view.view.mesh.uv is None and c.state.scene.material.diffuse_map is not None
        before = picture(view)
        assert c.set_value("shading", "per-pixel", merge=False)
        view.redraw()
        after = picture(view)
        assert view.pixels.frames >= 1 and view.pixels.last is not None
        assert np.abs(after - before).max() > 0  # (the per-pixel picture is drawn)
    finally:
        view.plotter.close()


def test_a_minus_b_per_pixel_is_the_difference_of_the_two_per_pixel_pictures(tmp_path, monkeypatch):
    """Both sides per pixel (a coarse sphere, B the same material under the other model): A − B
    draws, at every free pixel, the heat map of the difference of the two ``render
    --per-pixel`` pictures, not the per-vertex colours' difference (the map per vertex
    differs), and B's picture again when turned off."""
    pane = Pane()
    args = ("--preset", "glossy_plastic", "--resolution", "8")
    view = make_port("sphere", tmp_path, monkeypatch, *args, side_b=pane)
    try:
        c, b = view.controller, view.side_b
        c.act(M.set_compare, True)
        c.act(M.set_compare_difference, True)
        picture(view)
        vertex_map = b.plotter.screenshot(return_img=True)[:, :, :3].astype(int)
        c.set_value("shading", "per-pixel")
        picture(view)
        shown = b.plotter.screenshot(return_img=True)[:, :, :3].astype(int)
        s = c.state
        assert s.scene.shading == M.side_b(s).scene.shading == "per-pixel"
        kw = {"camera": s.camera, "background": BACKGROUND}
        pa = render_per_pixel(s.shown_scene(), view.view.mesh, SIZE, **kw)
        pb = render_per_pixel(M.side_b(s).shown_scene(), view.view.mesh, SIZE, **kw)
        mask = pa.mask & pb.mask
        d = np.abs(pa.rgb.astype(int) - pb.rgb.astype(int)).max(axis=2)
        want = heat_map(np.where(mask, d, 0), mask, vmax=VMAX)
        free = interior(mask) & ~overlays(view)
        free[:60] = False  # (the captions)
        assert free.sum() > 5000 and d[free].max() > 10  # the models differ in the highlight
        assert np.abs(shown[free] - want[free]).max() == 0  # the map, texel for pixel
        assert np.count_nonzero(np.abs(vertex_map[free] - want[free]).max(axis=1) > 8) > 200
        c.act(M.set_compare_difference, False)
        picture(view)
        shown = b.plotter.screenshot(return_img=True)[:, :, :3].astype(int)
        assert np.abs(shown[free] - pb.rgb[free].astype(int)).max() <= 1  # B's picture again
    finally:
        view.plotter.close()
        for pl in pane.plotters:
            pl.close()


def _handle_on_the_ray_of(view, row: int, col: int, along: float) -> None:
    """Move the selected light so that its handle lies on the ray of pixel (row, col),
    ``along`` mesh radii past the surface point the pixel shows (negative: before it)."""
    s = view.controller.state
    g, _ = view.pixels.live.gbuffer(view.pixels.camera, view.pixels.size)
    hit = g.hits.positions[int(np.searchsorted(g.pixels, row * SIZE[0] + col))]
    ray = hit - np.asarray(s.camera.position)
    point = hit + along * s.radius * ray / np.linalg.norm(ray)
    view.controller.act(M.place_light, *M.angles_of(point - np.asarray(s.centre)))


def test_the_light_handle_passes_in_front_of_and_behind_the_per_pixel_surface(torus):
    """The per-pixel picture is drawn by a screen quad that writes each pixel's depth from
    the G-buffer (the mesh is not rasterised): a handle before the surface is drawn over it,
    the same handle past the surface on the same pixel's ray is hidden by it, near the
    surface and farther (no one depth for the whole quad passes)."""
    from scipy.ndimage import distance_transform_edt

    c = torus.controller
    c.set_value("shading", "per-pixel")
    picture(torus)
    assert torus.view.drawings[0].actor.GetMapper() is not torus.pixels._mapper  # the quad's
    inside = distance_transform_edt(torus.pixels.last.mask)
    row, col = np.unravel_index(int(np.argmax(inside)), inside.shape)
    assert inside[row, col] > 8  # (a pixel deep inside the surface: the handle's centre)
    for along in (-0.5, -0.15, 0.15, 0.5):
        _handle_on_the_ray_of(torus, row, col, along)
        img = picture(torus)
        x, y, ahead = torus.view.handle_pixels()[c.state.light]
        assert ahead and abs(x - col) < 1.5 and abs((SIZE[1] - 1 - y) - row) < 1.5
        want = torus.pixels.rgb[row - 1 : row + 2, col - 1 : col + 2].astype(int)
        off = np.abs(img[row - 1 : row + 2, col - 1 : col + 2] - want).max()
        if along < 0:
            assert off > 40, along  # the handle in front: drawn over the surface
        else:
            assert off <= 1, along  # the handle behind: the surface's own pixels


def test_a_camera_change_per_pixel_runs_no_per_vertex_pass_and_per_vertex_is_current_after(torus):
    """While the per-pixel picture stands in for the mesh, a camera change (the local viewer
    moves: every specular sum changes) computes no per-vertex colours (the full mesh's shader
    runs no pass); back per vertex, the mesh's colours are those of the new camera."""
    c = torus.controller
    c.set_value("shading", "per-pixel")
    picture(torus)
    drawing = torus.view.drawings[0]
    passes = sum(drawing.shader.stats.values())
    torus.plotter.camera.Azimuth(40.0)
    picture(torus)
    assert sum(drawing.shader.stats.values()) == passes  # no per-vertex work
    c.set_value("shading", "per-vertex")
    picture(torus)
    assert np.array_equal(drawing.rgb, to_bytes(drawing.colors()))  # the new camera's colours


def test_depth_codes_and_the_quad_box():
    """The depth half's 24-bit codes decode (as the quad's fragment shader does) to the
    distances within one step; the quad covers exactly the surface pixels' bounding box."""
    d = np.array([3.0, 3.25, 4.0, 3.0000001])
    codes, first, step = depth_codes(d)
    c = codes.astype(np.int64)
    decoded = first + step * (c[:, 0] * 65536 + c[:, 1] * 256 + c[:, 2])
    assert np.abs(decoded - d).max() <= step and step == pytest.approx(1.0 / (DEPTH_NONE - 1))
    assert (c[:, 0] * 65536 + c[:, 1] * 256 + c[:, 2]).max() == DEPTH_NONE - 1
    mask = np.zeros((4, 8), bool)
    mask[1, 2] = mask[2, 5] = True  # rows 1-2 of 4, columns 2-5 of 8
    assert quad_box(mask) == pytest.approx((-0.5, -0.5, 0.5, 0.5))
    assert quad_box(np.zeros((4, 8), bool)) == (0.0, 0.0, 0.0, 0.0)


def test_the_per_vertex_frame_time_is_a_per_vertex_frames(torus):
    """The drag fallback compares a per-pixel picture with the last frame drawn per vertex:
    per-pixel frames (the quad: no mesh drawn nor shaded) leave that time as it was."""
    c, layer = torus.controller, torus.pixels
    torus.plotter.camera.Azimuth(10.0)
    picture(torus)  # a camera frame per vertex
    vertex_ms = layer.vertex_ms
    assert 0.0 < vertex_ms < 1e5
    c.set_value("shading", "per-pixel")
    for _ in range(2):
        torus.plotter.camera.Azimuth(10.0)
        picture(torus)
    assert layer.shown and layer.vertex_ms == vertex_ms


def test_the_drag_fallback_is_decided_once_when_the_camera_first_moves(torus):
    """A drag that starts per pixel stays per pixel though a later picture of it costs more
    than FALLBACK_RATIO per-vertex frames (under load one picture may): the decision is the
    drag's first camera frame's, on the pictures made before it."""
    c, layer = torus.controller, torus.pixels
    c.set_value("shading", "per-pixel")
    picture(torus)
    torus.begin_drag()
    layer.ms, layer.vertex_ms = 10.0, 10.0
    torus.plotter.camera.Azimuth(10.0)
    picture(torus)  # the decision: per pixel
    assert layer.shown and not layer.fallback
    layer.ms, layer.vertex_ms = 50.0, 10.0  # a slow picture in the drag
    torus.plotter.camera.Azimuth(10.0)
    picture(torus)
    assert layer.shown and not layer.fallback  # still per pixel
    torus.end_drag()


def test_a_minus_b_per_vertex_under_a_per_pixel_side_a_is_of_the_current_colours(compare):
    """Side A per pixel, side B per vertex, A − B on: B's mesh shows the per-vertex A − B of
    A's current colours (A's are not uploaded while its per-pixel picture stands in: they were
    those of the start)."""
    c, b = compare.controller, compare.side_b
    c.set_value("shading", "per-pixel")
    c.act(lambda s: s.replace(compare_shading="per-vertex"))
    c.act(M.set_compare, True)
    c.act(M.set_compare_difference, True)
    c.set_value("kd", 0.1, merge=False)
    picture(compare)
    a = to_bytes(compare.view.drawings[0].colors()).astype(int)
    other = to_bytes(b.view.drawings[0].colors()).astype(int)
    want = heat_map(np.abs(a - other).max(axis=1)[None, :], vmax=VMAX)[0]
    assert np.abs(a - other).max() > 10  # (B's material differs from A's)
    assert np.array_equal(b.view.drawings[0].rgb, want)
