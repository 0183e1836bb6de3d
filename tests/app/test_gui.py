"""The desktop explorer (explorer.app.window, explorer.cli.gui) driven in-process, off-screen.

Widgets are driven the way VTK drives them: set a representation's value and fire the event the
callback is bound to (see /work/shared/notes/gui-testing.md), or send key events through the
interactor. Every test checks what the window draws against the engine run independently
(``explorer.shade`` in float64, to within one 8-bit level) and fails on any exception a callback
raised ("Encountered issue in callback" warnings included).
"""

from __future__ import annotations

import json
import logging
import math
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

import explorer
from explorer.analysis import comparison as A
from explorer.app import layout as G
from explorer.app import window as gui
from explorer.cli import build_parser, main
from explorer.cli.gui import start
from explorer.core.lights import DirectionalLight, PointLight, direction_of
from explorer.core.material import Material
from explorer.core.presets import find_preset
from explorer.core.scene import Scene, Viewer
from explorer.geometry import meshes as M
from explorer.render.camera import back_to_front, camera_for, camera_from_vtk
from explorer.render.images import read_png
from explorer.shading.display import to_bytes

vtk = pytest.importorskip("vtkmodules.vtkCommonCore")
InteractionEvent = vtk.vtkCommand.InteractionEvent
StartInteractionEvent = vtk.vtkCommand.StartInteractionEvent
EndInteractionEvent = vtk.vtkCommand.EndInteractionEvent
StateChangedEvent = vtk.vtkCommand.StateChangedEvent

SIZE = (900, 600)


def start_scene(mesh, preset="gold") -> Scene:
    az, el, d = gui.DEFAULT_PLACEMENT
    light = PointLight().placed(az, el, d * mesh.radius, mesh.centre)
    eye = mesh.centre + 6.0 * mesh.radius * np.array([0.0, 0.3, 1.0]) / math.hypot(0.3, 1.0)
    return Scene(material=find_preset(preset), lights=(light,), viewer=Viewer(eye=tuple(eye)))


def expected(app, mesh=None) -> np.ndarray:
    """The engine's colours for what the app shows, computed afresh in float64: (n, 3) uint8."""
    mesh = mesh or app.mesh
    return to_bytes(explorer.shade(app.shown_scene(), mesh.positions, mesh.normals))


def assert_shows_engine_colours(app, mesh=None, view=0):
    drawn = np.array(app._views[view].rgb).astype(int)
    diff = np.abs(drawn - expected(app, mesh).astype(int))
    assert diff.max() <= 1, f"drawn colours differ from the engine's by up to {diff.max()}/255"


def fire_slider(app, name, value, event=InteractionEvent):
    w = app.sliders[name]
    w.GetRepresentation().SetValue(value)
    w.InvokeEvent(event)
    app.render()


def click(app, name):
    """A click on a button: VTK advances its state, then fires StateChangedEvent."""
    rep = app.buttons[name].GetRepresentation()
    rep.NextState()
    app.buttons[name].InvokeEvent(StateChangedEvent)
    app.render()


def press(app, key):
    """A key press as the interactor delivers it: KeyPressEvent, then CharEvent."""
    iren = app.plotter.iren.interactor
    code = key if len(key) == 1 else "\0"
    iren.SetKeyEventInformation(0, int(key.isupper()), code, 0, key)
    iren.KeyPressEvent()
    iren.CharEvent()


@pytest.fixture(autouse=True)
def no_callback_errors():
    """Fail on an exception swallowed by PyVista's callback wrapper."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield
    bad = [str(w.message) for w in caught if "Encountered issue in callback" in str(w.message)]
    assert not bad, "\n".join(bad)


@pytest.fixture(scope="module")
def user_presets(tmp_path_factory):
    d = tmp_path_factory.mktemp("user-presets")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("PHONG_EXPLORER_MATERIALS", str(d))
        yield d


@pytest.fixture(scope="module")
def mesh():
    return M.get_mesh("teapot", 6)


@pytest.fixture(scope="module")
def shared_app(user_presets, mesh, tmp_path_factory):
    out = tmp_path_factory.mktemp("shots")
    a = gui.Explorer(
        start_scene(mesh), mesh, preset="gold", off_screen=True, window_size=SIZE, output_dir=out
    )
    a.render()
    yield a
    a.close()


@pytest.fixture
def app(shared_app, user_presets):
    """The shared window, back at its start, with no messages or errors."""
    for p in user_presets.glob("*.yaml"):
        p.unlink()
    shared_app.presets = shared_app._list_presets()
    shared_app.reset()
    shared_app.errors.clear()
    shared_app._say("")
    shared_app.render()
    assert_shows_engine_colours(shared_app)
    return shared_app


# -- pure functions --------------------------------------------------------------------------


@pytest.mark.parametrize("n", [1.0, 2.5, 12.8, 51.2, 76.8, 128.0, 999.0, 1000.0])
def test_shininess_slider_is_log10_and_round_trips(n):
    v = gui.shininess_to_slider(n)
    assert v == pytest.approx(math.log10(n))
    assert gui.slider_to_shininess(v) == gui.round_sig(n, 3)


def test_shininess_slider_ends_and_values_below_one():
    lo, hi = G.SHININESS_SLIDER_RANGE
    assert gui.slider_to_shininess(lo) == 1.0 and gui.slider_to_shininess(hi) == 1000.0
    assert gui.shininess_to_slider(0.0) == lo and gui.shininess_to_slider(0.5) == lo
    assert gui.shininess_to_slider(5000.0) == hi
    # the middle third of the slider covers n from 10 to 100: the usable part of 1-1000
    assert gui.slider_to_shininess(1.0) == 10.0 and gui.slider_to_shininess(2.0) == 100.0


def test_display_material_hides_terms():
    m = Material(
        ambient=(0.1, 0.2, 0.3), diffuse=(0.4, 0.5, 0.6), specular=(0.7, 0.8, 0.9),
        emission=(0.05, 0.0, 0.0), shininess=20,
    )  # fmt: skip
    assert gui.display_material(m, {t: True for t in gui.TERMS}) == m
    only_spec = gui.display_material(m, {"ambient": False, "diffuse": False, "specular": True})
    assert only_spec.ambient == only_spec.diffuse == only_spec.emission == (0.0, 0.0, 0.0)
    assert only_spec.specular == m.specular and only_spec.shininess == m.shininess


@pytest.mark.parametrize("n", [1.0, 2.0, 5.0, 10.0, 51.2, 500.0])
def test_lobe_curve_is_cos_n_in_polar_coordinates(n):
    p = gui.lobe_curve(n, 721)
    r = np.hypot(p[:, 0], p[:, 1])
    t = np.arctan2(p[:, 1], p[:, 0])
    assert r.max() == pytest.approx(1.0) and abs(t[np.argmax(r)]) < 1e-9  # along R
    # the polar radius is cos(t)^n, and the lobe is symmetric about R
    inside = r > 1e-12
    assert np.allclose(r[inside], np.cos(t[inside]) ** n, atol=1e-12)
    assert np.allclose(p[::-1, 1], -p[:, 1]) and np.allclose(p[::-1, 0], p[:, 0])
    # half width at half maximum: cos(t)^n = 1/2
    half = np.degrees(np.arccos(0.5 ** (1.0 / n)))
    assert np.degrees(np.abs(t[r >= 0.5]).max()) == pytest.approx(half, abs=0.5)


def test_free_name_and_help_text():
    assert gui.free_name("gold", []) == "gold_1"
    assert gui.free_name("gold", ["gold_1", "gold_2", "gold_4"]) == "gold_3"
    text = gui.help_text()
    for key, what in G.KEYS.items():
        assert f"  {key:<4} {what}" in text
    for how, what in G.MOUSE:
        assert how in text and what in text


def test_no_display_reason():
    if sys.platform in ("darwin", "win32"):
        pytest.skip("X11 only")
    assert "DISPLAY is not set" in gui.no_display_reason({})
    forced = gui.no_display_reason({"DISPLAY": ":0", "VTK_DEFAULT_OPENGL_WINDOW": "vtkEGLRender"})
    assert "VTK_DEFAULT_OPENGL_WINDOW" in forced
    assert "cannot open" in gui.no_display_reason({"DISPLAY": ":4321"})
    line = gui.no_display_message("no display (DISPLAY is not set)")
    assert "\n" not in line and "phong-explorer render" in line and "xvfb-run" in line


def test_viewer_of_camera():
    assert gui.viewer_of_camera((1, 2, 3), (0, 0, 0), False) == Viewer(eye=(1, 2, 3))
    v = gui.viewer_of_camera((0, 0, 5), (0, 0, 1), True)
    assert v == Viewer(to_viewer=(0, 0, 1))


def test_widen_to_show_keeps_the_viewer_and_shows_the_points():

    mesh = M.get_mesh("sphere", 16)
    for viewer in (Viewer(eye=(0, 1, 6)), Viewer(to_viewer=(0, 0.3, 1))):
        cam = camera_for(Scene(viewer=viewer), mesh, 1.2)
        far = np.array([2.5, 2.0, 1.0])
        wide = gui.widen_to_show(cam, [far], 1.2, pad=0.1)
        assert wide.position == cam.position and wide.direction.tolist() == cam.direction.tolist()
        rel = far - np.asarray(wide.focal_point if wide.parallel else wide.position)
        up = np.asarray(wide.view_up)
        right = np.cross(wide.direction, up)
        if wide.parallel:
            half_h = wide.parallel_scale
            assert abs(rel @ up) <= half_h and abs(rel @ right) <= half_h * 1.2
        else:
            t = math.tan(math.radians(wide.view_angle) / 2)
            z = rel @ wide.direction
            assert abs(rel @ up) <= z * t and abs(rel @ right) <= z * t * 1.2
        # a point already in view changes nothing
        assert gui.widen_to_show(cam, [mesh.centre], 1.2) == cam


# -- the window: material ----------------------------------------------------------------------


@pytest.mark.parametrize("name, term", [("ka", "ambient"), ("kd", "diffuse"), ("ks", "specular")])
def test_coefficient_slider_changes_exactly_its_term(app, name, term):
    before = app.scene.material
    stats = dict(app.shader.stats)
    fire_slider(app, name, 0.3141)
    after = app.scene.material
    k = after.scalars()[("ka", "kd", "ks").index(name)]
    assert k == 0.314  # 3 decimals, the value the slider shows
    assert np.allclose(np.asarray(getattr(after, term)), 0.314 * np.asarray(before.hue(term)))
    for other in {"ambient", "diffuse", "specular", "emission"} - {term}:
        assert getattr(after, other) == getattr(before, other)
    assert after.shininess == before.shininess
    assert_shows_engine_colours(app)
    # a colour change is a compose pass: no geometry, no light sums again
    for kind in ("geometry", "pass", "diffuse", "specular", "lobe"):
        assert app.shader.stats[kind] == stats.get(kind, 0), kind
    rep = app.sliders[name].GetRepresentation()
    assert rep.GetValue() == pytest.approx(0.3141) and rep.GetTitleText() == name


def test_shininess_slider_shows_the_real_exponent_and_redraws_the_lobe(app):
    stats = dict(app.shader.stats)
    fire_slider(app, "shininess", 2.2)
    n = gui.round_sig(10**2.2, 3)
    assert app.scene.material.shininess == n == 158.0
    assert app.sliders["shininess"].GetRepresentation().GetTitleText() == "shininess 158"
    assert_shows_engine_colours(app)
    assert app.shader.stats["geometry"] == stats["geometry"]
    assert app.shader.stats["diffuse"] == stats["diffuse"]
    # the inset is the lobe of the new exponent
    poly = app._lobe_polys["lobe"]
    pts = np.array([poly.GetPoint(i)[:2] for i in range(poly.GetNumberOfPoints())])
    assert np.allclose(pts, app._lobe_points(n))
    assert app.texts["lobe"].GetInput().endswith("n = 158")
    # a second change re-runs only the lobe from the stored per-light bases
    stats = dict(app.shader.stats)
    fire_slider(app, "shininess", 1.0)
    assert app.scene.material.shininess == 10.0
    assert app.shader.stats["lobe"] == stats.get("lobe", 0) + 1
    assert app.shader.stats["pass"] == stats["pass"]
    assert_shows_engine_colours(app)


def test_dragging_a_slider_in_many_steps_never_recomputes_geometry(app):
    stats = dict(app.shader.stats)
    w = app.sliders["kd"]
    w.InvokeEvent(StartInteractionEvent)
    for v in np.linspace(0.1, 0.9, 9):
        fire_slider(app, "kd", float(v))
        fire_slider(app, "shininess", 1.0 + float(v))
    w.InvokeEvent(EndInteractionEvent)
    app.render()
    assert app.shader.stats["geometry"] == stats["geometry"]
    assert app.shader.stats["diffuse"] == stats["diffuse"]
    assert_shows_engine_colours(app)


def test_camera_is_the_viewer_and_moves_the_highlights_only(app):
    before = app.displayed_colors()
    stats = dict(app.shader.stats)
    cam = app.plotter.camera
    cam.Azimuth(35.0)
    cam.Elevation(10.0)
    app.render()
    assert app.scene.viewer == Viewer(eye=cam.GetPosition())
    assert app.shader.stats["specular"] == stats["specular"] + 1
    assert app.shader.stats["diffuse"] == stats["diffuse"]
    assert app.shader.stats["geometry"] == stats["geometry"]
    assert_shows_engine_colours(app)
    assert (app.displayed_colors() != before).any()  # the highlight moved
    # a parallel projection is an infinite viewer looking along the camera
    cam.ParallelProjectionOn()
    app.render()
    d = np.subtract(cam.GetPosition(), cam.GetFocalPoint())
    assert app.scene.viewer == Viewer(to_viewer=tuple(d))
    assert_shows_engine_colours(app)
    cam.ParallelProjectionOff()


def test_what_is_drawn_is_the_screen(app):
    """The off-screen picture shows the uploaded colours: at the probe vertex the pixel lies
    within the colours of the triangles around it (Gouraud interpolation)."""
    fire_slider(app, "kd", 0.55)
    img = app.plotter.screenshot(return_img=True)[:, :, :3].astype(int)
    i = app.probe_vertex()
    x, y = app.state()["probe"]["px"]
    around = np.unique(app.mesh.faces[(app.mesh.faces == i).any(axis=1)])
    colours = app.displayed_colors()[around].astype(int)
    pixel = img[y, x]
    assert (pixel >= colours.min(axis=0) - 2).all() and (pixel <= colours.max(axis=0) + 2).all()


# -- the window: model, terms, presets, meshes -----------------------------------------------


def test_model_switch(app):
    click(app, "phong")
    assert app.scene.model == "phong"
    assert app.buttons["phong"].GetRepresentation().GetState() == 1
    assert app.buttons["blinn"].GetRepresentation().GetState() == 0
    assert_shows_engine_colours(app)
    click(app, "phong")  # clicking the button that is on keeps it on (a radio button)
    assert app.scene.model == "phong"
    assert app.buttons["phong"].GetRepresentation().GetState() == 1
    press(app, "b")
    assert app.scene.model == "blinn"
    assert_shows_engine_colours(app)


@pytest.mark.parametrize("shown", ["ambient", "diffuse", "specular"])
def test_show_only_one_term(app, shown):
    stats = dict(app.shader.stats)
    for term in gui.TERMS:
        if term != shown:
            click(app, term)
    assert app.terms == {t: t == shown for t in gui.TERMS}
    m = app.scene.material
    drawn = app.displayed_colors().astype(int)
    alone = {t: (0.0, 0.0, 0.0) for t in gui.TERMS if t != shown}
    only = app.scene.replace(material=m.replace(emission=(0, 0, 0), **alone))
    want = to_bytes(explorer.shade(only, app.mesh.positions, app.mesh.normals)).astype(int)
    assert np.abs(drawn - want).max() <= 1
    # the state keeps the real material: saving or the sliders never see the hidden terms
    assert app.scene.material == find_preset("gold")
    assert app.sliders["kd"].GetRepresentation().GetValue() == pytest.approx(max(m.diffuse))
    for key in ("1", "2", "3"):
        press(app, key)
    assert app.terms == {t: t != shown for t in gui.TERMS}
    assert_shows_engine_colours(app)
    # hiding and showing terms is a compose pass: the light sums stay cached
    for kind in ("geometry", "pass", "lobe"):
        assert app.shader.stats[kind] == stats.get(kind, 0), kind


def test_preset_chooser(app):
    names = [p.name for p in app.presets]
    i = names.index("gold")
    click(app, "preset_next")
    assert app.preset_name == names[i + 1]
    assert app.buttons["preset_next"].GetRepresentation().GetState() == 0  # a push button
    m = find_preset(names[i + 1])
    assert app.scene.material == m
    rep = {n: app.sliders[n].GetRepresentation() for n in G.MATERIAL_SLIDERS}
    assert [rep[n].GetValue() for n in ("ka", "kd", "ks")] == pytest.approx(list(m.scalars()))
    assert rep["shininess"].GetTitleText() == f"shininess {m.shininess:g}"
    assert app.texts["preset"].GetInput().startswith(names[i + 1])
    assert_shows_engine_colours(app)
    click(app, "preset_previous")
    press(app, "p")
    assert app.preset_name == names[i - 1]
    press(app, "n")
    assert app.preset_name == "gold"
    assert_shows_engine_colours(app)


def test_preset_name_is_marked_once_edited(app):
    assert app.texts["preset"].GetInput().startswith("gold (")
    fire_slider(app, "ks", 0.2)
    assert app.texts["preset"].GetInput().startswith("gold* (")
    press(app, "n")
    press(app, "p")
    assert app.texts["preset"].GetInput().startswith("gold (")


def test_buttons_follow_a_resized_window(app):
    on = np.rint(np.asarray(G.ACCENT_COLOR) * 255).astype(int)

    def centre_pixel(name, size):
        x, y = G.BUTTONS[name]
        w, h = size
        img = app.plotter.screenshot(return_img=True)[:, :, :3].astype(int)
        px = round(x * w) + G.BUTTON_SIZE // 2
        py = h - 1 - (round(y * h) + G.BUTTON_SIZE // 2)
        return img[py, px]

    assert app.scene.model == "blinn"
    assert np.abs(centre_pixel("blinn", SIZE) - on).max() <= 2
    try:
        app.plotter.window_size = (1200, 800)
        app.render()
        assert np.abs(centre_pixel("blinn", (1200, 800)) - on).max() <= 2
        click_at = app.state()["buttons"]["phong"]["px"]
        assert click_at[0] == round(G.BUTTONS["phong"][0] * 1200) + G.BUTTON_SIZE // 2
    finally:
        app.plotter.window_size = SIZE
        app.render()


def test_translucent_preset_is_drawn_back_to_front(app):

    app.set_preset("emerald")
    m = app.scene.material
    assert m.opacity < 1.0
    assert app._views[0].actor.GetProperty().GetOpacity() == pytest.approx(m.opacity)
    app.plotter.camera.Azimuth(50.0)
    app.render()
    faces = app.mesh.faces[back_to_front(app.mesh, camera_from_vtk(app.plotter.camera))]
    drawn = np.asarray(app._views[0].poly.faces).reshape(-1, 4)[:, 1:]
    assert (drawn == faces).all()


def test_mesh_chooser(app):
    names = list(app.mesh_choices)
    start = app.mesh.name
    click(app, "mesh_next")
    new = names[(names.index(start) + 1) % len(names)]
    assert app.mesh.name == new
    assert app.mesh.n_vertices == M.get_mesh(new, gui.MESH_CHOICES.get(new)).n_vertices
    assert_shows_engine_colours(app)
    assert app.texts["mesh"].GetInput().startswith(new)
    press(app, "M")
    assert app.mesh.name == start
    assert_shows_engine_colours(app)


def test_mesh_file_joins_the_chooser(tmp_path, user_presets):
    import trimesh

    path = tmp_path / "ball.obj"
    trimesh.creation.icosphere(subdivisions=2, radius=3.0).export(path)
    scene, mesh, preset = start(_gui_args("--mesh", str(path), "--preset", "jade"))
    assert mesh.name == "ball.obj" and scene.mesh == str(path)
    a = gui.Explorer(scene, mesh, preset=preset, off_screen=True, window_size=SIZE)
    try:
        a.render()
        assert list(a.mesh_choices)[0] == "ball.obj"
        assert_shows_engine_colours(a)
        # the start light sits 2.5 radii from the file mesh's centre, whatever its size
        assert a._placement()[2] == pytest.approx(gui.DEFAULT_PLACEMENT[2] * a.radius)
        press(a, "m")
        assert a.mesh.name == list(a.mesh_choices)[1]
        press(a, "M")
        assert a.mesh is mesh and a.scene.mesh == str(path)
        assert a._placement()[2] == pytest.approx(gui.DEFAULT_PLACEMENT[2] * a.radius)
        assert_shows_engine_colours(a)
    finally:
        a.close()


# -- the window: lights ----------------------------------------------------------------------


def test_light_sliders_move_the_light_and_the_handle(app):
    fire_slider(app, "azimuth", -60.0)
    fire_slider(app, "elevation", 20.0)
    fire_slider(app, "distance", 3.0)
    light = app.light
    want = app.mesh.centre + 3.0 * direction_of(-60.0, 20.0)
    assert np.allclose(light.position, want)
    assert np.allclose(app.handle.GetCenter(), want)
    assert_shows_engine_colours(app)


def test_dragging_the_handle_moves_the_light_and_the_sliders(app):
    target = app.mesh.centre + 2.5 * direction_of(100.0, -15.0)
    app.handle.SetCenter(*target)
    app.handle.InvokeEvent(InteractionEvent)
    app.render()
    assert np.allclose(app.light.position, target)
    values = {n: app.sliders[n].GetRepresentation().GetValue() for n in G.LIGHT_SLIDERS}
    assert values == pytest.approx({"azimuth": 100.0, "elevation": -15.0, "distance": 2.5})
    assert_shows_engine_colours(app)
    # beyond the distance slider's range the light stops at its end
    lo, hi = app._slider_range("distance")
    app.handle.SetCenter(*(app.mesh.centre + 10 * hi * direction_of(0, 0)))
    app.handle.InvokeEvent(InteractionEvent)
    assert np.linalg.norm(np.subtract(app.light.position, app.mesh.centre)) == pytest.approx(hi)
    assert np.allclose(app.handle.GetCenter(), app.light.position)


@pytest.mark.parametrize("kind", ["directional", "spot", "point"])
def test_light_type_switch(app, kind):
    az, el, d = app._placement()
    click(app, kind)
    assert app.light.type == kind
    for k in G.RADIO_GROUPS["light_type"]:
        assert app.buttons[k].GetRepresentation().GetState() == int(k == kind)
    a, e, dd = app._placement()
    assert (a, e, dd) == pytest.approx((az, el, d))  # the light stays where it was
    assert_shows_engine_colours(app)
    press(app, "t")
    kinds = G.RADIO_GROUPS["light_type"]
    assert app.light.type == kinds[(kinds.index(kind) + 1) % 3]


def test_next_light_in_a_scene_with_two(mesh, user_presets):
    scene = start_scene(mesh).replace(
        lights=(PointLight(position=(2, 2, 2)), DirectionalLight(to_light=(-1, 0.5, 1)))
    )
    a = gui.Explorer(scene, mesh, off_screen=True, window_size=SIZE)
    try:
        a.render()
        press(a, "l")
        assert a.light_index == 1
        fire_slider(a, "azimuth", 10.0)
        assert a.scene.lights[0] == PointLight(position=(2, 2, 2))
        el = a._placement()[1]
        assert np.allclose(a.scene.lights[1].to_light, direction_of(10.0, el))
        assert a.texts["light"].GetInput().startswith("2 of 2: directional")
        assert_shows_engine_colours(a)
    finally:
        a.close()


# -- keys: save, screenshot, reset, help -------------------------------------------------------


def test_save_key_writes_a_new_preset_every_time(app, user_presets):
    fire_slider(app, "ks", 0.9)
    click(app, "phong")
    press(app, "s")
    first = user_presets / "gold_1.yaml"
    assert app.last_saved == str(first) and first.is_file()
    saved = find_preset("gold_1")
    assert saved == app.scene.material.replace(model="phong")
    assert "gold_1" in app.message and app.preset_name == "gold_1"
    before = first.read_bytes()
    press(app, "s")  # never over the first one
    assert first.read_bytes() == before
    assert (user_presets / "gold_1_1.yaml").is_file()
    assert "gold_1" in [p.name for p in app.presets]


def test_screenshot_key(app):
    press(app, "i")
    path = app.last_screenshot
    img = read_png(path)
    assert img.shape[:2] == (SIZE[1], SIZE[0])
    press(app, "i")
    assert app.last_screenshot != path and os.path.isfile(path)


def test_reset_key_restores_the_start(app):
    start_scene_ = app.scene
    cam = app.plotter.camera.GetPosition()
    fire_slider(app, "kd", 0.1)
    click(app, "spot")
    click(app, "specular")
    press(app, "n")
    app.plotter.camera.Azimuth(60)
    app.render()
    press(app, "r")
    assert app.scene == start_scene_ and app.preset_name == "gold"
    assert app.terms == {t: True for t in gui.TERMS}
    assert app.plotter.camera.GetPosition() == pytest.approx(cam)
    assert app.sliders["kd"].GetRepresentation().GetValue() == pytest.approx(0.75164)
    assert_shows_engine_colours(app)


def test_vtk_keeps_none_of_our_keys(app):
    """VTK's own meaning of our keys (r: reset the camera, s: surface, 3: stereo...) is off."""
    app.plotter.camera.Azimuth(60)
    app.render()
    moved = app.plotter.camera.GetPosition()
    press(app, "3")  # hides the specular term; VTK would toggle stereo rendering
    assert not app.plotter.render_window.GetStereoRender()
    assert app.plotter.camera.GetPosition() == moved


def test_help_overlay_lists_every_key(app):
    press(app, "h")
    assert app.help_visible and app.texts["help"].GetVisibility()
    text = app.texts["help"].GetInput()
    for key in G.KEYS:
        assert f"  {key} " in text
    press(app, "h")
    assert not app.texts["help"].GetVisibility()


# -- errors ------------------------------------------------------------------------------------


def screen(app):
    """The window's pixels: (h, w, 3) uint8."""
    return np.asarray(app.plotter.screenshot(return_img=True))[..., :3]


def test_difference_view_shows_the_heat_map_of_this_view(app):

    w, h = SIZE
    left = (slice(None), slice(0, int(G.PANEL_X * w) - 5))  # the view, left of the panel
    normal = screen(app)
    press(app, "d")
    st = app.state()["difference"]
    assert st["on"] and st["shown"] and not app.errors
    # the same comparison, made independently for the same scene, camera and size
    cam = app._view_camera()
    want = A.compare_view(app.shown_scene(), app.mesh, (w, h), camera=cam)
    assert st["max"] == want.max and st["rmse"] == pytest.approx(want.rmse, abs=0.05)
    assert st["pixels"] == int(want.mask.sum()) > 10_000
    shot = screen(app)
    assert np.abs(shot[left].astype(int) - normal[left]).max() > 50  # the map, not the mesh
    heat = A.heat_map(want.levels, want.mask, background=(0, 0, 0))
    glowing = (heat.sum(axis=2) > 0) & want.mask
    assert glowing[left].sum() > 100  # some pixels err by a level or more on this mesh
    assert "RMSE" in app.texts["difference"].GetInput()
    assert "every pixel" in app.texts["advice"].GetInput()
    # the button shows the state; the key turns it off again and the mesh is back
    assert app.state()["buttons"]["difference"]["state"]
    press(app, "d")
    assert not app.state()["difference"]["shown"]
    middle = (slice(40, h - 60), left[1])  # the view without the status and hint lines
    assert np.array_equal(screen(app)[middle], normal[middle])
    assert_shows_engine_colours(app)


def test_difference_view_follows_the_shininess_and_the_camera(app):
    def drag(name, value):  # press, move, release: as a mouse drags a slider
        fire_slider(app, name, value, StartInteractionEvent)
        fire_slider(app, name, value)
        assert not app.state()["difference"]["shown"]  # the live view while dragging
        fire_slider(app, name, value, EndInteractionEvent)
        assert app.state()["difference"]["shown"]  # the map again on release
        return app.state()["difference"]

    click(app, "difference")
    assert app.state()["difference"]["shown"]
    low = drag("shininess", gui.shininess_to_slider(10.0))
    high = drag("shininess", gui.shininess_to_slider(1000.0))
    assert "shininess 10 " in low["advice"] and "shininess 1000 " in high["advice"]
    assert low["advice"] != high["advice"]
    assert high["rmse"] != low["rmse"]  # the map was made again for the new exponent
    before = app.state()["difference"]["rmse"]
    app.plotter.camera.Azimuth(40)
    app.render()
    after = app.state()["difference"]
    assert after["shown"] and after["rmse"] != before
    click(app, "difference")
    assert not app.state()["difference"]["on"]
    assert_shows_engine_colours(app)


def test_error_in_a_callback_is_shown_and_logged(app, user_presets, caplog, monkeypatch):
    not_a_dir = user_presets / "a-file"
    not_a_dir.write_text("")
    monkeypatch.setattr(app, "preset_dir", str(not_a_dir))
    with caplog.at_level(logging.ERROR, logger="explorer.app.window"):
        press(app, "s")
    assert app.errors and "key s" in app.errors[0]
    assert app.message.startswith("error (key s):")
    assert app.texts["message"].GetInput() == app.message
    assert app.texts["message"].GetTextProperty().GetColor() == pytest.approx(G.ERROR_COLOR)
    assert any("key s" in r.getMessage() for r in caplog.records)

    def broken(*_):
        raise RuntimeError("broken on purpose")

    monkeypatch.setattr(app, "set_model", broken)
    with caplog.at_level(logging.ERROR, logger="explorer.app.window"):
        click(app, "phong")  # a widget callback this time
    assert "RuntimeError: broken on purpose" in app.message
    assert any(r.exc_info for r in caplog.records)  # the traceback is in the log


# -- state file, level of detail -------------------------------------------------------------------


def test_state_file_is_written_after_each_frame(mesh, user_presets, tmp_path):
    path = tmp_path / "state.json"
    a = gui.Explorer(start_scene(mesh), mesh, off_screen=True, window_size=SIZE, state_file=path)
    try:
        a.render()
        s = json.loads(path.read_text())
        assert s["frame"] == a.frames == 1 and s["preset"] == "gold"
        fire_slider(a, "kd", 0.2)
        s = json.loads(path.read_text())
        assert s["frame"] == 2 and s["material"]["kd"] == 0.2
        assert s["sliders"]["kd"]["value"] == pytest.approx(0.2)
        assert s["scene"]["viewer"] == {"eye": list(a.plotter.camera.GetPosition())}
        # slider knob pixels: the left end for the lowest value, the right end for the highest
        x0 = s["sliders"]["ka"]["knob_px"][0]
        assert a.slider_pixels("ka", 0.0)[0] < x0 < a.slider_pixels("ka", 1.0)[0]
        assert not list(tmp_path.glob(".state.json.*"))  # no temporary files left
    finally:
        a.close()


def test_level_of_detail_while_dragging(user_presets):
    mesh = M.get_mesh("sphere", 96)
    a = gui.Explorer(
        start_scene(mesh), mesh, off_screen=True, window_size=SIZE, lod_vertices=1000,
        lod_target=1000,
    )  # fmt: skip
    try:
        a.render()
        full, lod = a._views
        assert lod.mesh.n_vertices < mesh.n_vertices / 2
        assert full.actor.GetVisibility() and not lod.actor.GetVisibility()
        stats = dict(full.shader.stats)
        w = a.sliders["kd"]
        w.InvokeEvent(StartInteractionEvent)
        fire_slider(a, "kd", 0.3)
        fire_slider(a, "shininess", 2.0)
        a.plotter.camera.Azimuth(20)
        a.render()
        assert a.state()["lod"] and lod.actor.GetVisibility() and not full.actor.GetVisibility()
        assert_shows_engine_colours(a, lod.mesh, view=1)
        assert full.shader.stats == stats  # the full mesh does nothing while dragging
        w.InvokeEvent(EndInteractionEvent)
        a.render()
        assert full.actor.GetVisibility() and not lod.actor.GetVisibility()
        assert_shows_engine_colours(a)
    finally:
        a.close()


# -- the command -------------------------------------------------------------------------------


def _gui_args(*argv):

    return build_parser().parse_args(["gui", *argv])


def test_default_start_is_a_preset_on_the_teapot_under_one_light():

    scene, mesh, preset = start(_gui_args())
    assert preset == gui.DEFAULT_PRESET and scene.material == find_preset(gui.DEFAULT_PRESET)
    assert mesh.name == "teapot" and len(scene.lights) == 1
    assert mesh.n_vertices == M.get_mesh("teapot", gui.MESH_CHOICES["teapot"]).n_vertices
    az, el, d = scene.lights[0].placement(mesh.centre)
    assert (az, el, d) == pytest.approx(
        (gui.DEFAULT_PLACEMENT[0], gui.DEFAULT_PLACEMENT[1], gui.DEFAULT_PLACEMENT[2] * mesh.radius)
    )
    assert scene.viewer.local


def test_start_from_options_and_scene_file(tmp_path):

    scene, mesh, preset = start(_gui_args("--preset", "jade", "--mesh", "torus"))
    assert preset == "jade" and mesh.name == "torus" and scene.model == "blinn"
    f = tmp_path / "s.yaml"
    f.write_text("material: ruby\nlights: [{type: directional, to_light: [1, 1, 1]}]\n")
    scene, mesh, preset = start(_gui_args(str(f), "--resolution", "5"))
    assert preset == "ruby" and mesh.name == "teapot"
    assert mesh.n_vertices == M.get_mesh("teapot", 5).n_vertices
    assert scene.lights == (DirectionalLight(to_light=(1, 1, 1)),)
    with pytest.raises(explorer.ExplorerError, match="--exit-after"):
        start(_gui_args("--exit-after", "0"))


@pytest.mark.parametrize("value", ["inf", "-inf", "nan", "-1", "0", "1e400"])
def test_exit_after_must_be_a_finite_positive_number(value, capsys):
    with pytest.raises(explorer.ExplorerError, match="--exit-after"):
        start(_gui_args(f"--exit-after={value}"))
    assert main(["gui", f"--exit-after={value}"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: --exit-after") and "Traceback" not in err[0]


def test_state_file_is_never_replaced_without_force(tmp_path, capsys):
    f = tmp_path / "state.json"
    f.write_text("keep me")
    assert main(["gui", "--state-file", str(f), "--exit-after", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(f) in err[0] and "--force" in err[0], err
    assert f.read_text() == "keep me"
    start(_gui_args("--state-file", str(f), "--force"))  # --force: accepted
    start(_gui_args("--state-file", str(tmp_path / "new.json")))  # a new file: accepted


@pytest.mark.parametrize("argv", [[], ["gui", "--preset", "jade"]])
def test_no_display_one_line_and_nonzero_exit(argv):
    if sys.platform in ("darwin", "win32"):
        pytest.skip("X11 only")
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env.pop("VTK_DEFAULT_OPENGL_WINDOW", None)
    r = subprocess.run(
        [sys.executable, "-m", "explorer.cli", *argv],
        env=env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert r.returncode == gui.NO_DISPLAY_STATUS
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "DISPLAY is not set" in lines[0]
    assert "phong-explorer render" in lines[0] and "xvfb-run" in lines[0]
    assert r.stdout == ""
