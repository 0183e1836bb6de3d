"""The panel model (issue 38): one declarative row per control, the one table of edits, the
lights' own controls, the effects as rows (an edit, an undo step, a session that keeps it), and
no front end that knows a light type. Plain Python (no Qt, no browser)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from explorer.app import captions, rowlayout
from explorer.app import model as M
from explorer.app import panelmodel as P
from explorer.app.session import load_session, save_session
from explorer.app.start import first_state
from explorer.core.controls import CONTROLS
from explorer.core.errors import ExplorerError
from explorer.core.lights import DirectionalLight, PointLight, SpotLight
from explorer.core.presets import list_presets
from explorer.core.scene import Scene
from explorer.core.texture import MAP_KEYS
from explorer.geometry.meshes import get_mesh

ROOT = Path(__file__).resolve().parents[2]
#: a value for each row, other than the start's (a spot light and a point light, the HDR
#: display and the compare view on)
SAMPLES = {
    "preset": "jade",
    "ka": 0.1,
    "kd": 0.3,
    "ks": 0.9,
    "shininess": 200.0,
    "opacity": 0.5,
    "ambient": (0.1, 0.2, 0.3),
    "diffuse": (0.5, 0.25, 0.125),
    "specular": (0.2, 0.4, 0.6),
    "emission": (0.05, 0.0, 0.1),
    "model": "phong",
    "show_ambient": False,
    "show_diffuse": False,
    "show_specular": False,
    "fresnel": 0.5,
    "energy_conserving": True,
    "type": "point",
    "color": (1.0, 0.5, 0.0),
    "intensity": 0.7,
    "azimuth": -60.0,
    "elevation": 20.0,
    "distance": 3.0,
    "attenuation": (1.0, 0.2, 0.0),
    "cutoff": 12.0,
    "exponent": 3.0,
    "shadows": True,
    "two_sided": True,
    "hdr": False,
    "exposure": 1.5,
    "tone_map": "aces",
    "local_viewer": False,
    "shading": "per-pixel",
    "light": 1,
    "difference": True,
    "compare": False,
    "compare_preset": "jade",
    "compare_model": "threejs",
    "compare_difference": True,
    # a button's value is whether it can be pressed (still so after each press here)
    "add_light": True,
    "duplicate_light": True,
    "remove_light": True,
    "swap": True,
    "strip": False,  # (on at the start: its mode's row shown)
    "strip_mode": "raw",
    "strip_side": "b",
    "strip_lights": True,
    "lobes": "lights",
    "lobe_view": "cartesian",
    "lobe_quantity": "brdf",
    "lobe_log": True,
    "lobe_ndl": True,
    "lobe_incidence": 30.0,
    "show_lobe_1": False,
    "show_lobe_2": False,
    "show_lobe_3": False,
}
#: the rows of the lobes past the start's three (tried with eight lights, below)
MORE_LOBES = tuple(f"show_lobe_{i}" for i in range(4, 9))
#: the rows of a mesh file's own materials (tried with an OBJ's groups, below)
MESH_MATERIALS = ("mesh_materials", "group", "use_mesh_materials")
#: the rows that are lines of text the state gives (read, never set)
LINES = ("material_line", "maps_note", "no_lights")
#: the material's texture maps (image rows, tried below)
MAPS = MAP_KEYS
TILES = ROOT / "docs" / "examples" / "tiles.png"
#: the presets a preset row's edit is given (the controller's)
PRESETS = list_presets()


@pytest.fixture(scope="module")
def mesh():
    return get_mesh("icosphere", 2)


def start(mesh, **scene) -> M.State:
    """A spot light selected (every light row shown) and a point light, the HDR display on (its
    rows shown), the compare view on (side B's rows shown), the strip on (its mode's row shown)
    and the inset's several lobes (their rows shown)."""
    lights = (
        SpotLight(position=(0.0, 2.0, 2.0), aim=(0.0, -1.0, -1.0), cutoff=30.0),
        PointLight(position=(2.0, 2.0, 0.0)),
    )
    base = Scene(lights=lights, hdr={"exposure": 0.0, "tone_map": "reinhard"})
    s = first_state(base.replace(**scene) if scene else base, mesh, name="icosphere")
    return M.set_compare(s, True).replace(lobes="models", strip=True)


def test_every_row_is_one_declared_control():
    assert len(P.BY_KEY) == len(P.ROWS)  # one row a key
    for r in P.ROWS:
        assert r.kind in P.KINDS and r.tab in P.TABS, r.key
        if r.kind in ("number", "triple"):
            assert r.key in CONTROLS, r.key  # its range, scale and decimals: core.controls
        if r.kind in ("choice", "list"):  # fixed values, or items (the state's, a catalogue's)
            assert bool(r.choices) + (r.items is not None) + bool(r.source) == 1, r.key
    assert set(SAMPLES) | set(MESH_MATERIALS) | set(LINES) | set(MORE_LOBES) | set(MAPS) == set(
        P.BY_KEY
    )  # each tried below
    with pytest.raises(ExplorerError, match="no control named 'glossiness'"):
        P.row("glossiness")


@pytest.mark.parametrize("key", list(SAMPLES))
def test_each_row_edits_the_state_in_one_undo_step_that_a_session_keeps(key, mesh, tmp_path):
    s = start(mesh)
    r = P.row(key)
    assert r.visible(s)
    store = M.Store(s)
    action, args, label = P.edit(s, key, SAMPLES[key], PRESETS)
    assert store.apply(action, *args, label=label)
    new = store.state
    if key == "hdr":  # the display off: its own value, and its rows hidden
        assert not r.value(new) and not P.row("exposure").visible(new)
    elif key == "compare":  # the view off: side B's rows hidden
        assert not r.value(new) and not P.row("compare_preset").visible(new)
    elif key == "strip":  # the strip off: its mode's row hidden
        assert not r.value(new) and not P.row("strip_mode").visible(new)
    elif key == "type":
        assert new.selected_light.type == "point"
    else:
        assert r.value(new) == pytest.approx(SAMPLES[key]), key
    # a preset's step says the preset (``preset jade``, ``B jade``); another the row's label
    assert store.undo_label() == (f"{label.split()[0]} jade" if r.source else r.undo_label)
    path = save_session(tmp_path / "s.yaml", new)
    again, _ = load_session(path)
    assert r.value(again) == pytest.approx(r.value(new)), key
    store.undo()
    assert r.value(store.state) == r.value(s)


def test_a_lobe_row_a_lobe_of_the_set_each_hidden_and_kept_by_a_session(mesh, tmp_path):
    """``show_lobe_<i>``: shown while the set has an i-th lobe; off, that lobe is not drawn
    (its legend entry kept, greyed), and a session keeps which; a bad index is one line."""
    from explorer.app import lobeinset as LI

    lights = tuple(DirectionalLight(to_light=(0.1 * i, 0.5, 1.0)) for i in range(8))
    s = first_state(Scene(lights=lights), mesh, name="icosphere").replace(lobes="lights")
    assert [P.row(f"show_lobe_{i}").visible(s) for i in range(1, 9)] == [True] * 8
    assert not P.row("show_lobe_8").visible(s.replace(lobes="models"))
    assert not P.row("show_lobe_1").visible(s.replace(lobes="selected"))
    store = M.Store(s)
    for key in ("show_lobe_2", *MORE_LOBES):
        action, args, label = P.edit(store.state, key, False)
        store.apply(action, *args, label=label)
    assert store.undo_label() == "lobe 8"
    shown = [lb.visible for lb in LI.lobe_set(store.state)]
    assert shown == [True, False, True, False, False, False, False, False]
    again, _ = load_session(save_session(tmp_path / "s.yaml", store.state))
    assert again.lobe_hidden == store.state.lobe_hidden == frozenset({1, 3, 4, 5, 6, 7})
    with pytest.raises(ExplorerError, match="a lobe's index"):
        LI.set_lobe_shown(s, -1, False)


@pytest.mark.parametrize("key", MAPS)
def test_each_map_row_chooses_turns_off_clears_in_undo_steps_a_session_keeps(key, tmp_path):
    """A map row on a mesh with (u, v): a file chosen, turned off (the material keeps it, the
    shown scene has none), cleared: one undo step each, kept by a session; a file that is not
    an image is one line naming it and changes nothing."""
    s = start(get_mesh("icosphere", 2, uv=True))
    r = P.row(key)
    assert r.visible(s) and not P.row("maps_note").visible(s) and r.value(s) == (None, False)
    store = M.Store(s)

    def do(value):
        action, args, label = P.edit(store.state, key, value)
        assert store.apply(action, *args, label=label)
        return label

    assert do(str(TILES)) == f"{key} file"
    assert r.value(store.state) == (str(TILES), True)
    assert getattr(store.state.shown_scene().material, key).file == str(TILES)
    assert do(False) == f"{key} off"
    assert r.value(store.state) == (str(TILES), False)
    assert getattr(store.state.shown_scene().material, key) is None
    again, _ = load_session(save_session(tmp_path / "s.yaml", store.state))
    assert r.value(again) == (str(TILES), False)
    bad = tmp_path / "notes.png"
    bad.write_text("not an image")
    action, args, _ = P.edit(store.state, key, str(bad))
    with pytest.raises(ExplorerError, match=f"{key} '.*notes.png': not a PNG or JPEG image"):
        action(store.state, *args)
    assert do(None) == f"clear {key}" and r.value(store.state) == (None, False)
    store.undo()
    assert r.value(store.state) == (str(TILES), False)
    store.undo()
    assert r.value(store.state) == (str(TILES), True)


def test_a_mesh_without_texture_coordinates_shows_why_and_no_map_row(mesh):
    s = start(mesh)  # (no (u, v))
    assert P.row("maps_note").visible(s) and "no texture coordinates" in P.row("maps_note").value(s)
    assert not any(P.row(k).visible(s) for k in MAPS)


def test_a_button_row_applies_its_action_and_says_when_it_can_be_pressed(mesh):
    s = start(mesh)
    store = M.Store(s)
    for key, n in (("add_light", 3), ("duplicate_light", 4), ("remove_light", 3)):
        action, args, label = P.edit(store.state, key, True)
        store.apply(action, *args, label=label)
        assert len(store.state.scene.lights) == n and store.undo_label() == label
    assert label == "remove light"
    none = M.State(scene=s.scene.replace(lights=()), mesh="icosphere")
    assert [P.row(k).value(none) for k in ("add_light", "duplicate_light", "remove_light")] == [
        True,
        False,
        False,
    ]
    # the line saying so, in both front ends (the window's own label before issue 38's kit)
    assert P.row("no_lights").shown(none) == P.NO_LIGHTS and P.row("no_lights").shown(s) is None
    action, args, _ = P.edit(s, "swap", True)
    swapped = action(s, *args)
    assert (swapped.compare_model, swapped.scene.model) == (s.scene.model, s.compare_model)
    assert not P.row("swap").visible(M.set_compare(s, False))


def test_a_mesh_files_own_materials_are_rows_a_line_a_group_and_a_button(tmp_path):
    from helpers.files import write_two_groups

    from explorer.cli import build_parser
    from explorer.cli.gui import start_state

    two = write_two_groups(tmp_path)
    s, _ = start_state(build_parser().parse_args(["gui", "--mesh", str(two)]))
    line, group, use = (P.row(k) for k in MESH_MATERIALS)
    assert line.value(s) == captions.mesh_materials_line(s) and group.visible(s)
    assert not use.visible(s)
    items = group.items(s)
    assert [i.title for i in items] == list(s.mesh_materials.names)
    assert [i.swatch for i in items] == list(s.groups)  # each with its swatch
    with pytest.raises(ExplorerError, match="'mesh_materials' is a line of text"):
        P.edit(s, "mesh_materials", "x")
    store = M.Store(s)
    for key, value in (("group", 1 - s.group), ("preset", "jade"), ("use_mesh_materials", True)):
        action, args, label = P.edit(store.state, key, value, PRESETS)
        store.apply(action, *args, label=label)
        if key == "preset":  # a preset covers the mesh: the button draws the groups again
            assert not group.visible(store.state) and use.visible(store.state)
            assert "preset 'jade' covers the whole mesh" in line.value(store.state)
    assert store.state.groups is not None and store.state.group == 1 - s.group
    assert store.undo_label() == "mesh materials"
    none = start(get_mesh("icosphere", 1))
    assert not any(P.row(k).visible(none) for k in MESH_MATERIALS)


def test_a_lights_rows_are_the_controls_the_light_declares(mesh):
    s = start(mesh)
    for light, hidden in (
        (SpotLight(), ()),
        (PointLight(), ("cutoff", "exponent")),
        (DirectionalLight(), ("attenuation", "cutoff", "exponent")),
    ):
        t = M.State(scene=s.scene.replace(lights=(light,)), mesh="icosphere")
        lists = {"light", "add_light", "duplicate_light", "remove_light"}  # the scene's
        shown = {r.key for r in P.rows("lights") if r.visible(t)} - lists
        assert shown == set(light.CONTROL_KEYS)
        assert not set(hidden) & set(light.CONTROL_KEYS)
    none = M.State(scene=s.scene.replace(lights=()), mesh="icosphere")
    shown = [r.key for r in P.rows("lights") if r.visible(none)]
    assert shown == ["light", "add_light", "duplicate_light", "remove_light", "no_lights"]
    assert P.row("light").value(none) is None
    store = M.Store(start(mesh, lights=(PointLight(),)))
    with pytest.raises(ExplorerError, match="'cutoff' cannot be set on a point light"):
        action, args, _ = P.edit(store.state, "cutoff", 10.0)
        store.apply(action, *args)


def test_the_optional_fresnel_turns_off_with_none_and_the_hdr_rows_follow_the_display(mesh):
    s = start(mesh, hdr=None)
    assert P.row("fresnel").value(s) is None
    assert not P.row("exposure").visible(s) and not P.row("tone_map").visible(s)
    on = M.Store(s)
    for key, value in (("hdr", True), ("fresnel", P.row("fresnel").optional)):
        action, args, _ = P.edit(on.state, key, value)
        on.apply(action, *args)
    assert on.state.scene.hdr is not None and P.row("tone_map").visible(on.state)
    assert on.state.material.fresnel == pytest.approx(0.04)
    action, args, _ = P.edit(on.state, "fresnel", None)
    on.apply(action, *args)
    assert on.state.material.fresnel is None


def test_client_keys_name_every_state_key_a_row_lets_the_page_set_with_its_kind():
    keys = P.client_keys()
    for r in P.ROWS:
        if r.kind == "number":
            assert keys[f"{r.key}_step"] == "number"
        elif r.kind == "toggle":
            assert keys[r.key] == "bool"
        elif r.kind in ("choice", "list"):  # a name, or an index into the state's items
            assert keys[r.key] == ("index" if r.items is not None else "text"), r.key
        else:  # typed text, picks and buttons go to the page's handlers, not the state
            assert r.key not in keys
    assert keys["fresnel_on"] == "bool" and keys["tone_map"] == "text"
    assert keys["show_specular"] == keys["shadows"] == keys["hdr"] == keys["compare"] == "bool"
    assert keys["preset"] == keys["compare_preset"] == "text"
    assert keys["light"] == keys["group"] == "index" and "add_light" not in keys


def test_no_front_end_module_names_a_light_type():
    """Which controls a light has is the light's (its CONTROL_KEYS), and what its handle
    shows (its GLYPH): the Qt panel, the web modules and the toolkit-free kit (the view among
    them) hold no light-type rule."""
    files = [*ROOT.glob("explorer/app/**/*.py")]
    assert len(files) > 10, files  # both front ends' modules are read
    pattern = re.compile(r"""["'](directional|point|spot)["']|\.type\s*(==|!=|in)\s*[("']""")
    found = [
        f"{f.name}:{i}"
        for f in files
        for i, line in enumerate(f.read_text().splitlines(), 1)
        if pattern.search(line)
    ]
    assert not found, found


def test_the_material_line_names_the_preset_and_says_when_it_is_edited(mesh):
    """Both front ends' line above the preset list (the page had none: the window's was its
    own code): the preset, then " (edited)" after a change, and a line that cannot be set."""
    jade = next(p for p in PRESETS if p.name == "jade")
    s = M.apply_preset(start(mesh), "jade", jade.material)
    line = P.row("material_line")
    assert line.kind == "text" and line.visible(s)
    assert line.value(s) == "preset: jade"
    assert line.value(M.set_coefficient(s, "kd", 0.1)) == "preset: jade (edited)"
    with pytest.raises(ExplorerError, match="'material_line' is a line of text"):
        P.edit(s, "material_line", "x")


def test_rows_are_laid_out_in_lines_of_toggles_grids_of_colours_and_rows():
    """Both front ends lay a tab out as :func:`~explorer.app.rowlayout.lines` says: the
    window's line of terms is the page's (each drew its own before)."""
    got = {t: [(how, [r.key for r in g]) for how, g in rowlayout.lines(P.rows(t))] for t in P.TABS}
    material = got["material"]
    assert ("grid", ["ambient", "diffuse", "specular", "emission"]) in material
    assert ("line", ["show_ambient", "show_diffuse", "show_specular"]) in material
    assert ("row", ["model"]) in material  # a choice drawn inline: a row of its own
    assert ("line", ["add_light", "duplicate_light", "remove_light"]) in got["lights"]
    assert ("grid", ["type", "color"]) in got["lights"]
    view = got["view"]
    assert ("line", ["lobe_log", "lobe_ndl"]) in view  # two groups side by side: two lines
    assert ("line", [f"show_lobe_{i}" for i in range(1, 9)]) in view
    for t in P.TABS:  # every row once, in order
        assert [k for _, keys in got[t] for k in keys] == [r.key for r in P.rows(t)]
