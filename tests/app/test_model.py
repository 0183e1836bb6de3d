"""The explorer's state, actions, undo history and sessions, with no GUI (explorer.app.model,
explorer.app.session, explorer.app.start), and the gui command's start and options."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

import explorer
from explorer.app import model as M
from explorer.app import session as S
from explorer.app import start as A
from explorer.cli import build_parser, main
from explorer.cli.gui import start, start_state
from explorer.core.lights import DirectionalLight, PointLight
from explorer.core.presets import find_preset
from explorer.core.scene import Viewer
from explorer.geometry import meshes as G
from explorer.render.camera import camera_for


@pytest.fixture(scope="module")
def mesh():
    return G.get_mesh("icosphere", 2)


@pytest.fixture
def state(mesh):
    scene, _, preset = start(build_parser().parse_args(["gui", "--mesh", "icosphere"]))
    return A.first_state(scene, mesh, name="icosphere", preset=preset, resolution=2)


def test_nothing_of_qt_vtk_or_pyvista_is_imported_by_the_model():
    code = (
        "import sys, explorer.app.model, explorer.app.session, explorer.app.start, "
        "explorer.app.difference, explorer.app.view, explorer.cli.gui; "
        "print(sorted({m.split('.')[0] for m in sys.modules} & "
        "{'vtk', 'vtkmodules', 'pyvista', 'pyvistaqt', 'PySide6'}))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"


def test_start_state_is_the_gold_preset_clean(state, mesh):
    assert state.preset == A.DEFAULT_PRESET and not state.edited
    assert state.material == find_preset("gold") and len(state.scene.lights) == 1
    assert state.centre == pytest.approx(tuple(mesh.centre)) and state.radius == mesh.radius
    az, el, d = state.placement()
    assert (az, el, d / state.radius) == pytest.approx(M.DEFAULT_PLACEMENT)


def test_material_actions_change_exactly_their_key(state):
    s = M.set_coefficient(state, "kd", 0.5)
    assert s.material.scalars()[1] == 0.5 and s.material.ambient == state.material.ambient
    assert s.material.hue("diffuse") == pytest.approx(state.material.hue("diffuse"))
    assert s.edited
    assert M.set_shininess(state, 0.0).material.shininess == 0.0
    assert M.set_opacity(state, 0.25).material.opacity == 0.25
    for term in ("ambient", "diffuse", "specular", "emission"):
        assert getattr(M.set_colour(state, term, (0.1, 0.2, 0.3)).material, term) == (
            0.1, 0.2, 0.3)  # fmt: skip
    with pytest.raises(explorer.ExplorerError, match="shininess"):
        M.set_shininess(state, -1.0)
    with pytest.raises(explorer.ExplorerError, match="ka, kd or ks"):
        M.set_coefficient(state, "kx", 0.1)


def test_preset_model_and_terms(state):
    jade = find_preset("jade")
    s = M.apply_preset(state, "jade", jade)
    assert s.preset == "jade" and not s.edited and s.material == jade
    s = M.set_model(s, "phong")
    assert s.scene.model == "phong"
    s = M.set_term(s, "ambient", False)
    shown = s.shown_scene().material
    assert shown.ambient == (0, 0, 0) and shown.emission == (0, 0, 0)
    assert s.material == jade  # the material itself is unchanged
    assert M.set_term(s, "ambient", True).hidden == frozenset()


def test_light_actions(state):
    s = M.add_light(state)
    assert len(s.scene.lights) == 2 and s.light == 1
    s = M.duplicate_light(s)
    assert len(s.scene.lights) == 3 and s.light == 2
    assert s.scene.lights[2] == s.scene.lights[1]  # an exact copy, said in the list
    assert M.same_place_as(s, 2) == 1 and M.same_place_as(s, 1) is None
    assert M.same_place_as(M.place_light(s, azimuth=-170.0), 2) is None
    s = M.remove_light(s)
    assert len(s.scene.lights) == 2 and s.light == 1
    s = M.select_light(s, 0)
    s = M.set_light_intensity(s, 0.5)
    assert s.scene.lights[0].diffuse == pytest.approx((0.5, 0.5, 0.5))
    s = M.set_light_colour(s, (1.0, 0.5, 0.0))
    assert s.scene.lights[0].diffuse == pytest.approx((0.5, 0.25, 0.0))
    assert s.scene.lights[0].specular == s.scene.lights[0].diffuse
    hue, k = M.light_colour(s.scene.lights[0])
    assert hue == pytest.approx((1.0, 0.5, 0.0)) and k == pytest.approx(0.5)
    s = M.set_light_field(s, "attenuation", (1.0, 0.1, 0.0))
    assert s.scene.lights[0].attenuation == (1.0, 0.1, 0.0)
    with pytest.raises(explorer.ExplorerError, match="cutoff"):
        M.set_light_field(s, "cutoff", 10.0)  # a point light has no cone
    s = M.set_light_type(s, "spot")
    spot = s.scene.lights[0]
    assert spot.type == "spot" and spot.cutoff == pytest.approx(M.spot_cutoff(
        s.placement()[2], s.radius))  # fmt: skip
    assert spot.cutoff < 25.0  # narrower than the whole mesh
    s = M.set_light_field(s, "cutoff", 10.0)
    s = M.set_light_field(s, "exponent", 4.0)
    assert (s.scene.lights[0].cutoff, s.scene.lights[0].exponent) == (10.0, 4.0)
    s = M.remove_light(M.remove_light(s))
    assert s.scene.lights == () and s.selected_light is None
    with pytest.raises(explorer.ExplorerError, match="no lights"):
        M.place_light(s, 10.0)


def test_place_light_keeps_azimuth_at_the_poles(state):
    s = M.place_light(state, 70.0, 90.0)
    assert s.placement()[:2] == pytest.approx((70.0, 90.0))
    s = M.place_light(s, None, 30.0)  # leaving the pole: the azimuth was kept
    assert s.placement()[:2] == pytest.approx((70.0, 30.0))
    s = M.set_light_type(M.place_light(s, 20.0, -90.0), "directional")
    assert s.placement()[:2] == pytest.approx((20.0, -90.0))
    s = M.place_light(s, distance=3.0 * s.radius)  # directional: the handle moves
    assert s.handle_distance == pytest.approx(3.0)


def test_set_mesh_keeps_the_lights_relative_to_the_mesh(state):
    torus = G.get_mesh("torus", 16)
    s = M.set_mesh(state, "torus", torus.centre, torus.radius)
    assert s.mesh == "torus" and s.scene.mesh == "torus" and s.camera is None
    assert s.placement()[2] / s.radius == pytest.approx(state.placement()[2] / state.radius)


def test_undo_redo_and_one_step_per_drag(state):
    store = M.Store(state)
    seen = []
    store.subscribe(lambda old, new: seen.append(new))
    for v in (0.5, 0.4, 0.3):  # a drag: one step
        store.apply(M.set_coefficient, "kd", v, label="kd", merge="kd")
    store.seal()
    store.apply(M.set_coefficient, "kd", 0.2, label="kd", merge="kd")  # a new step
    assert len(seen) == 4 and store.undo_label() == "kd"
    assert store.undo() and store.state.material.scalars()[1] == pytest.approx(0.3)
    assert store.undo() and store.state == state
    assert not store.undo() and store.can_redo
    assert store.redo() and store.state.material.scalars()[1] == pytest.approx(0.3)
    store.apply(M.set_model, "phong")
    assert not store.can_redo  # a new change forgets the redo steps
    assert not store.commit(store.state, "nothing")  # no change, no step


def test_camera_moves_are_no_undo_steps_and_undo_keeps_the_camera(state, mesh):
    store = M.Store(state)
    store.apply(M.set_model, "phong")
    cam = camera_for(state.scene, mesh, 1.5)
    store.set_camera(cam)
    assert store.state.camera == cam and store.state.scene.viewer.eye == cam.position
    assert store.undo_label() == "set_model"
    store.undo()
    assert store.state.scene.model == "blinn" and store.state.camera == cam
    assert store.state.scene.viewer.eye == cam.position


def test_session_round_trip(state, mesh, tmp_path):
    cam = camera_for(state.scene, mesh, 1.5)
    s = M.set_camera(M.set_term(M.add_light(state), "specular", False), cam)
    s = M.set_difference(M.set_light_type(s, "spot"), True)
    for name in ("s.yaml", "s.json"):
        path = S.save_session(tmp_path / name, s)
        back, m = S.load_session(path)
        # the same surface: a built-in mesh comes back with its (u, v), its vertices split
        # where the texture's seams run (load_mesh_choice), the same triangles and points
        assert m.n_faces == mesh.n_faces and m.uv is not None
        same = np.unique(m.positions, axis=0), np.unique(mesh.positions, axis=0)
        np.testing.assert_array_equal(*same)
        assert back.scene == s.scene and back.hidden == s.hidden and back.light == s.light
        assert back.preset == s.preset and back.difference and not back.edited
        assert back.camera.position == pytest.approx(cam.position)
        with pytest.raises(explorer.ExplorerError, match="exists"):
            S.save_session(path, s)  # never over a file unless asked


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("session: 1\nscene: {}\n", "mesh"),
        ("session: 2\nscene: {}\nmesh: sphere\n", "session"),
        ("session: 1\nscene: {}\nmesh: sphere\nhidden: [glow]\n", "hidden"),
        ("session: 1\nscene: {}\nmesh: sphere\nlight: 3\n", "light"),
        ("session: 1\nscene: {material: nope}\nmesh: sphere\n", "scene"),
        ("session: 1\nscene: {}\nmesh: sphere\ncamera: {position: [0, 0, 1]}\n", "camera"),
        ("session: 1\nscene: {}\nmesh: sphere\nzoom: 2\n", "zoom"),
    ],
)
def test_bad_sessions_name_file_and_key(tmp_path, text, words):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(explorer.ExplorerError) as e:
        S.load_session(path)
    assert "bad.yaml" in str(e.value) and words in str(e.value)


@pytest.mark.parametrize(
    ("text", "value"), [("0.5", 0.5), (" 1000 ", 1000.0), ("-90°", -90.0), ("2.5 r", 2.5)]
)
def test_parse_number_takes_values_in_range(text, value):
    assert M.parse_number("key", text, -90.0, 1000.0) == value


@pytest.mark.parametrize("text", ["5000", "-91", "abc", "", "nan", "inf"])
def test_parse_number_names_the_key_and_range(text):
    with pytest.raises(explorer.ExplorerError) as e:
        M.parse_number("shininess", text, -90.0, 1000.0)
    assert str(e.value) == f"shininess must be a number within -90 .. 1000, got {text.strip()!r}"


@pytest.mark.parametrize(
    ("text", "rgb"),
    [("0.2, 0.4, 0.6", (0.2, 0.4, 0.6)), ("0 1 0.5", (0.0, 1.0, 0.5)),
     ("#ff8000", (1.0, 128 / 255, 0.0)), ("#FFF", (1.0, 1.0, 1.0)), ("00ff00", (0.0, 1.0, 0.0))],
)  # fmt: skip
def test_parse_colour(text, rgb):
    assert M.parse_colour("diffuse", text) == rgb


@pytest.mark.parametrize("text", ["1.5, 0, 0", "0.2, 0.4", "red", "#12345", "-0.1 0 0", ""])
def test_parse_colour_names_the_key_and_the_forms(text):
    with pytest.raises(explorer.ExplorerError, match="^diffuse must be 'r, g, b' with each"):
        M.parse_colour("diffuse", text)


def test_no_display_reason():
    assert A.no_display_reason({}) == "no display (DISPLAY is not set)"
    forced = {"DISPLAY": ":0", "VTK_DEFAULT_OPENGL_WINDOW": "vtkEGLRenderWindow"}
    assert "off-screen" in A.no_display_reason(forced)
    assert "xcb" in A.no_display_reason({"DISPLAY": ":0", "QT_QPA_PLATFORM": "offscreen"})
    assert "cannot open" in A.no_display_reason({"DISPLAY": ":98765"})


def test_no_command_means_gui_with_its_options(tmp_path):
    from explorer.cli import with_default_command

    assert with_default_command([]) == ["gui"]
    assert with_default_command(["--preset", "jade"]) == ["gui", "--preset", "jade"]
    scene = tmp_path / "s.yaml"
    scene.write_text("material: ruby\n")
    assert with_default_command([str(scene)]) == ["gui", str(scene)]
    for kept in (["--help"], ["--version"], ["render", "--preset", "jade"], ["rendr"]):
        assert with_default_command(kept) == kept  # a mistyped command stays refused
    args = build_parser().parse_args(
        with_default_command(["--preset", "jade", "--size", "640x480"])
    )
    assert args.command == "gui" and args.preset == "jade"
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    run = subprocess.run([sys.executable, "-m", "explorer.cli", "--preset", "jade"], env=env,
                         capture_output=True, text=True, timeout=120)  # fmt: skip
    assert run.returncode == 3 and "no display" in run.stderr, run.stderr  # gui's own exit
    assert "invalid choice" not in run.stderr
    run = subprocess.run([sys.executable, "-m", "explorer.cli", "--help"], env=env,
                         capture_output=True, text=True, timeout=120)  # fmt: skip
    from explorer.cli import COMMANDS

    listed = [line.split()[0] for line in run.stdout.splitlines() if line.startswith("    ")]
    assert run.returncode == 0 and [c for c in listed if c in COMMANDS] == list(COMMANDS)
    assert "Without a COMMAND, 'gui' runs" in " ".join(run.stdout.split())


def _gui_args(*argv):
    return build_parser().parse_args(["gui", *argv])


def test_default_start_is_a_preset_on_the_teapot_under_one_light():
    scene, mesh, preset = start(_gui_args())
    assert preset == A.DEFAULT_PRESET and scene.material == find_preset(A.DEFAULT_PRESET)
    assert mesh.name == "teapot" and len(scene.lights) == 1 and scene.viewer.local
    assert mesh.n_vertices == G.get_mesh("teapot", A.MESH_CHOICES["teapot"]).n_vertices


def test_start_from_options_scene_file_and_session(tmp_path):
    scene, mesh, preset = start(_gui_args("--preset", "jade", "--mesh", "torus"))
    assert preset == "jade" and mesh.name == "torus"
    f = tmp_path / "s.yaml"
    f.write_text("material: ruby\nlights: [{type: directional, to_light: [1, 1, 1]}]\n")
    scene, mesh, preset = start(_gui_args(str(f), "--resolution", "5"))
    assert preset == "ruby" and scene.lights == (DirectionalLight(to_light=(1, 1, 1)),)
    state, mesh = start_state(_gui_args("--mesh", "cube"))
    path = S.save_session(tmp_path / "x.yaml", M.set_model(state, "phong"))
    again, _ = start_state(_gui_args("--session", str(path)))
    assert again.scene.model == "phong" and again.mesh == "cube"
    with pytest.raises(explorer.ExplorerError, match="--session and --last"):
        start_state(_gui_args("--session", str(path), "--last"))


def test_last_needs_a_kept_session(tmp_path, monkeypatch):
    monkeypatch.setenv(S.LAST_SESSION_ENV, str(tmp_path / "last.yaml"))
    with pytest.raises(explorer.ExplorerError, match="--last: no session kept"):
        start_state(_gui_args("--last"))


@pytest.mark.parametrize("value", ["inf", "nan", "-1", "0"])
def test_exit_after_must_be_a_finite_positive_number(value, capsys):
    assert main(["gui", f"--exit-after={value}"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: --exit-after")


def test_state_file_is_never_replaced_without_force(tmp_path, capsys):
    f = tmp_path / "state.json"
    f.write_text("keep me")
    assert main(["gui", "--state-file", str(f), "--exit-after", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(f) in err[0] and "--force" in err[0], err
    assert f.read_text() == "keep me"


@pytest.mark.parametrize("argv", [[], ["gui", "--preset", "jade"]])
def test_no_display_one_line_and_exit_status_3(argv):
    if sys.platform in ("darwin", "win32"):
        pytest.skip("X11 only")
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env.pop("VTK_DEFAULT_OPENGL_WINDOW", None)
    r = subprocess.run([sys.executable, "-m", "explorer.cli", *argv], env=env,
                       capture_output=True, text=True, timeout=120)  # fmt: skip
    assert r.returncode == A.NO_DISPLAY_STATUS
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "DISPLAY is not set" in lines[0]
    assert "phong-explorer render" in lines[0] and "xvfb-run" in lines[0]
    assert r.stdout == ""


def test_point_light_default_is_kept(state):
    assert isinstance(state.scene.lights[0], PointLight)


def test_compare_actions(state):
    s = M.start_compare(state)
    assert s.compare == state.material and s.compare_model == "phong"
    assert M.side_b(s).scene.model == "phong" and M.side_b(s).material == state.material
    jade = find_preset("jade")
    s = M.set_compare_preset(s, "jade", jade)
    s = M.swap_compare(s)
    assert s.material == jade and s.preset == "jade" and s.compare == state.material
    assert s.scene.model == (jade.model or "phong") and s.compare_model == "blinn"
    assert M.stop_compare(s).compare is None
    with pytest.raises(explorer.ExplorerError, match="compare view is off"):
        M.swap_compare(state)


def test_a_dragged_handle_stays_on_the_pointers_ray():
    """point_on_ray: on the ray, at the light's distance from the centre (near or far side),
    and the ray's point nearest the centre where the ray passes outside that sphere."""
    centre, d = np.array([1.0, 2.0, 3.0]), 2.0
    o = centre + np.array([0.0, 0.0, 10.0])
    u = np.array([0.6, 0.0, -0.8])  # passes 10 · 0.6 = 6 from the centre: a miss
    p = M.point_on_ray(o, u, centre, d)
    assert np.cross(p - o, u) == pytest.approx(np.zeros(3), abs=1e-12)  # on the ray
    assert np.linalg.norm(p - centre) == pytest.approx(6.0)
    assert (p - o) @ u == pytest.approx(10.0 * 0.8)  # the nearest point: t = (c - o)·u
    u = np.array([0.1, 0.0, -1.0])
    near, far = M.point_on_ray(o, u, centre, d), M.point_on_ray(o, u, centre, d, near=False)
    for p in (near, far):
        assert np.linalg.norm(p - centre) == pytest.approx(d)
        assert np.linalg.norm(np.cross(p - o, u / np.linalg.norm(u))) == pytest.approx(0, abs=1e-12)
    assert near[2] > centre[2] > far[2]
    # straight at the centre: the sphere's pole facing the ray's start
    assert M.point_on_ray(o, [0, 0, -1], centre, d) == pytest.approx(centre + [0, 0, d])


def test_handle_point_of_each_light(state):
    s = M.add_light(state)
    for i in range(2):
        az, el, d = s.placement(i)
        assert np.linalg.norm(M.handle_point(s, i) - np.asarray(s.centre)) == pytest.approx(d)
    assert M.handle_point(s) == pytest.approx(M.handle_point(s, s.light))
    assert not np.allclose(M.handle_point(s, 0), M.handle_point(s, 1))


@pytest.mark.parametrize("kind", ["no directory", "a directory"])
def test_a_state_file_that_cannot_be_written_is_refused_at_start(tmp_path, kind):
    """``gui --state-file nodir/s.json`` (or a directory, even with --force) ran with an error
    logged per frame and rc 0: refused before the display is looked for."""
    from explorer.cli.gui import check_options

    target = tmp_path / "nodir" / "s.json" if kind == "no directory" else tmp_path
    with pytest.raises(explorer.ExplorerError, match="--state-file") as info:
        check_options(_gui_args("--state-file", str(target), "--force"))
    assert ("does not exist" if kind == "no directory" else "is a directory") in str(info.value)
    check_options(_gui_args("--state-file", str(tmp_path / "s.json")))  # a new file is fine


def test_the_window_holds_at_most_max_window_lights(tmp_path):
    """A 20,000-light session took 40-50 s to open and close (and the session it kept was over
    the reader's 1 MiB): a session, a scene or added lights beyond the cap are refused."""
    from explorer.core import tolerances as tol

    n = tol.MAX_WINDOW_LIGHTS
    state, _ = start_state(_gui_args("--mesh", "cube"))
    light = state.scene.lights[0]
    full = state.replace(scene=state.scene.replace(lights=(light,) * n))
    path = S.save_session(tmp_path / "full.yaml", full)
    assert len(S.load_session(path)[0].scene.lights) == n
    with pytest.raises(explorer.ExplorerError, match=rf"the window holds at most {n}"):
        M.add_light(full)
    over = full.replace(scene=full.scene.replace(lights=(light,) * (n + 1)))
    text = path.read_text()
    path.write_text(text.replace("lights:", "lights:\n  - {type: point, position: [1, 2, 3]}", 1))
    with pytest.raises(explorer.ExplorerError, match=rf"full.yaml: scene: {n + 1} lights; the"):
        S.load_session(path)
    with pytest.raises(explorer.ExplorerError, match=rf"{n + 1} lights"):
        A.first_state(over.scene, G.get_mesh("cube"))


def test_range_errors_show_every_digit_needed(tmp_path):
    """``view_angle 179.0001`` was refused as "got 179"."""
    from explorer.core.validate import format_number

    assert [format_number(x) for x in (179.0001, 179.0, 0.5, 1e6, 1e-320)] == [
        "179.0001", "179", "0.5", "1e+06", "1e-320"]  # fmt: skip
    state, _ = start_state(_gui_args("--mesh", "cube"))
    state = state.replace(camera=camera_for(state.scene, G.get_mesh("cube")))
    path = S.save_session(tmp_path / "s.yaml", state)
    text = path.read_text()
    import re

    path.write_text(re.sub(r"view_angle: [0-9.e+-]+", "view_angle: 179.0001", text))
    with pytest.raises(
        explorer.ExplorerError, match=r"view_angle: must be in \(0, 179\], got 179.0001"
    ):
        S.load_session(path)


@pytest.mark.parametrize("scale", [1e-20, 1e39, 1e300])
def test_a_new_mesh_keeps_the_viewer_and_lights_in_mesh_radii(state, scale):
    """The viewer (a local eye) and the lights keep their places in mesh radii, so a mesh of
    size 1e-20 is framed as the last one was (the eye stayed 6.5 units from it: a dot)."""
    s = state.replace(scene=state.scene.replace(viewer=Viewer(eye=(0.0, 2.0, 6.0))))
    new = M.set_mesh(s, "big", (scale, 0.0, 0.0), scale)
    eye = (np.asarray(new.scene.viewer.eye) - new.centre) / new.radius
    assert eye == pytest.approx((np.asarray(s.scene.viewer.eye) - s.centre) / s.radius)
    assert new.placement()[2] / new.radius == pytest.approx(s.placement()[2] / s.radius)
    assert new.placement()[:2] == pytest.approx(s.placement()[:2])
    cam = camera_for(new.scene, G.Mesh(G.sphere(8).positions * scale + (scale, 0, 0),
                                      G.sphere(8).normals, G.sphere(8).faces))  # fmt: skip
    assert cam.view_angle == pytest.approx(camera_for(s.scene, G.sphere(8)).view_angle)


def test_a_mesh_too_large_for_its_lights_is_refused_as_render_refuses_it(state):
    with pytest.raises(
        explorer.core.errors.ExplorerError, match="'huge.obj' is too large to frame"
    ):
        M.set_mesh(state, "/models/huge.obj", (0.0, 0.0, 0.0), 1.5e308)
