"""The panel model (issue 38): one declarative row per control, the one table of edits, the
lights' own controls, the effects as rows (an edit, an undo step, a session that keeps it), and
no front end that knows a light type. Plain Python (no Qt, no browser)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from explorer.app import model as M
from explorer.app import panelmodel as P
from explorer.app.session import load_session, save_session
from explorer.app.start import first_state
from explorer.core.controls import CONTROLS
from explorer.core.errors import ExplorerError
from explorer.core.lights import DirectionalLight, PointLight, SpotLight
from explorer.core.scene import Scene
from explorer.geometry.meshes import get_mesh

ROOT = Path(__file__).resolve().parents[2]
#: a value for each row, other than the start's (a spot light, the HDR display on)
SAMPLES = {
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
    "strip": True,
    "strip_mode": "raw",
    "lobes": "lights",
    "lobe_view": "cartesian",
    "lobe_quantity": "brdf",
    "lobe_log": True,
    "lobe_ndl": True,
}


@pytest.fixture(scope="module")
def mesh():
    return get_mesh("icosphere", 2)


def start(mesh, **scene) -> M.State:
    """A spot light (every light row shown), the HDR display on and the inset's several lobes
    (their rows shown)."""
    lights = (SpotLight(position=(0.0, 2.0, 2.0), aim=(0.0, -1.0, -1.0), cutoff=30.0),)
    base = Scene(lights=lights, hdr={"exposure": 0.0, "tone_map": "reinhard"})
    state = first_state(base.replace(**scene) if scene else base, mesh, name="icosphere")
    return state.replace(lobes="models")


def test_every_row_is_one_declared_control():
    assert len(P.BY_KEY) == len(P.ROWS)  # one row a key
    for r in P.ROWS:
        assert r.kind in P.KINDS and r.tab in P.TABS, r.key
        if r.kind in ("number", "triple"):
            assert r.key in CONTROLS, r.key  # its range, scale and decimals: core.controls
        if r.kind == "choice":
            assert r.choices, r.key
    assert set(SAMPLES) == set(P.BY_KEY)  # every row is tried below
    with pytest.raises(ExplorerError, match="no control named 'glossiness'"):
        P.row("glossiness")


@pytest.mark.parametrize("key", list(SAMPLES))
def test_each_row_edits_the_state_in_one_undo_step_that_a_session_keeps(key, mesh, tmp_path):
    s = start(mesh)
    r = P.row(key)
    assert r.visible(s)
    store = M.Store(s)
    action, args, label = P.edit(s, key, SAMPLES[key])
    assert store.apply(action, *args, label=label)
    new = store.state
    if key == "hdr":  # the display off: its own value, and its rows hidden
        assert not r.value(new) and not P.row("exposure").visible(new)
    elif key == "type":
        assert new.selected_light.type == "point"
    else:
        assert r.value(new) == pytest.approx(SAMPLES[key]), key
    assert store.undo_label() == r.undo_label
    path = save_session(tmp_path / "s.yaml", new)
    again, _ = load_session(path)
    assert r.value(again) == pytest.approx(r.value(new)), key
    store.undo()
    assert r.value(store.state) == r.value(s)


def test_a_lights_rows_are_the_controls_the_light_declares(mesh):
    s = start(mesh)
    for light, hidden in (
        (SpotLight(), ()),
        (PointLight(), ("cutoff", "exponent")),
        (DirectionalLight(), ("attenuation", "cutoff", "exponent")),
    ):
        t = M.State(scene=s.scene.replace(lights=(light,)), mesh="icosphere")
        shown = {r.key for r in P.rows("lights") if r.visible(t)}
        assert shown == set(light.CONTROL_KEYS)
        assert not set(hidden) & set(light.CONTROL_KEYS)
    none = M.State(scene=s.scene.replace(lights=()), mesh="icosphere")
    assert not any(r.visible(none) for r in P.rows("lights"))
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
        elif r.kind in ("choice", "toggle"):
            assert keys[r.key] == ("text" if r.kind == "choice" else "bool")
        else:  # typed text and picks go to the page's handlers, not the state
            assert r.key not in keys
    assert keys["fresnel_on"] == "bool" and keys["tone_map"] == "text"
    assert keys["show_specular"] == keys["shadows"] == keys["hdr"] == "bool"


def test_no_front_end_module_names_a_light_type():
    """Which controls a light has is the light's (its CONTROL_KEYS): the Qt panel and the web
    modules hold no light-type rule."""
    files = [*ROOT.glob("explorer/app/qt/*.py"), *ROOT.glob("explorer/app/web/*.py")]
    assert len(files) > 10, files  # both front ends' modules are read
    pattern = re.compile(r"""["'](directional|point|spot)["']|\.type\s*(==|!=|in)\s*[("']""")
    found = [
        f"{f.name}:{i}"
        for f in files
        for i, line in enumerate(f.read_text().splitlines(), 1)
        if pattern.search(line)
    ]
    assert not found, found
