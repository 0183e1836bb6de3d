"""What both front ends share, tested once in the toolkit-free kit (:mod:`explorer.app`): the
start's light, the message log, the state's summary, a long job's steps, a typed value's
meaning, a material's swatch; and no front end holds a light-type site."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from explorer.app import captions, panelmodel, start
from explorer.app.colours import rgb_bytes, swatch_squares
from explorer.app.messagelog import MessageLog
from explorer.app.model import DEFAULT_PLACEMENT
from explorer.app.steps import Steps
from explorer.core.errors import ExplorerError
from explorer.core.lights import LIGHT_CLASSES
from explorer.core.scene import Scene
from explorer.geometry.meshes import Mesh, get_mesh

APP = Path(__file__).resolve().parents[2] / "explorer" / "app"


def test_no_front_end_file_imports_the_lights_or_names_a_light_class():
    """The front ends (explorer/app/qt, explorer/app/web) hold no light-type site: not even the
    start's light (the notebook's start placed a PointLight itself)."""
    files = [*APP.glob("qt/*.py"), *APP.glob("web/*.py")]
    assert len(files) > 15, files
    names = "|".join(c.__name__ for c in {*LIGHT_CLASSES.values()})
    pattern = re.compile(rf"explorer\.core\.lights|\b({names})\b")
    found = [
        f"{f.parent.name}/{f.name}:{i}"
        for f in files
        for i, line in enumerate(f.read_text().splitlines(), 1)
        if pattern.search(line)
    ]
    assert not found, found


def test_no_front_end_file_writes_a_shortcut_the_registry_holds():
    """Every key a front end shows (a tooltip's, a menu's, the help's) comes from the intent
    registry (:mod:`explorer.app.intents`): no string of a front-end file's code (its
    docstrings aside) writes one (the page's undo and redo tooltips said ``(Ctrl+Z)`` and
    ``(Ctrl+Shift+Z)`` themselves, without redo's Ctrl+Y)."""
    import ast

    from explorer.app import intents as X

    files = [*APP.glob("qt/*.py"), *APP.glob("web/*.py")]
    keys = {k for i in X.INTENTS for k in i.keys + (i.page_keys or ()) if "+" in k or len(k) > 1}
    assert {"Ctrl+Z", "Ctrl+Shift+Z", "F1"} <= keys
    pattern = re.compile(r"\b(" + "|".join(re.escape(k) for k in sorted(keys)) + r")\b")
    found = []
    for f in files:
        tree = ast.parse(f.read_text())
        docs = {
            id(n.body[0].value)
            for n in ast.walk(tree)
            if isinstance(n, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef)
            and n.body
            and isinstance(n.body[0], ast.Expr)
        }
        found += [
            f"{f.parent.name}/{f.name}:{n.lineno}: {m.group(0)}"
            for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docs
            if (m := pattern.search(n.value))
        ]
    assert not found, found


def test_a_buttons_tooltip_is_its_intents_title_and_keys_from_the_registry():
    from explorer.app import intents as X

    assert X.tooltip("save_preset") == "Save preset as… (Ctrl+Shift+S)"
    assert X.tooltip("screenshot") == "Save screenshot (i)"  # the 3D view's key
    assert X.tooltip("undo", "kd") == "Undo kd (Ctrl+Z)"
    # the page's: what its help says, its keys (Ctrl+T is the browser's: Alt+T)
    assert X.tooltip("redo", "kd", page=True) == "redo kd (Ctrl+Shift+Z / Ctrl+Y)"
    assert X.tooltip("export_turntable", page=True) == "make a turntable (the view tab) (Alt+T)"
    assert X.tooltip("messages", page=True) == "the message log (Ctrl+M)"
    assert X.history_title("undo", "kd") == "&Undo kd" and X.history_title("redo", None) == "&Redo"


def test_the_start_light_is_a_point_light_at_the_default_placement_in_mesh_radii():
    unit = get_mesh("sphere", 8)
    mesh = Mesh(unit.positions * 2.0 + (1.0, 0.0, 0.0), unit.normals, unit.faces)
    light = start.default_light(mesh)
    assert light.type == "point"
    az, el, d = light.placement(mesh.centre)
    assert (az, el) == pytest.approx(DEFAULT_PLACEMENT[:2])
    assert d == pytest.approx(DEFAULT_PLACEMENT[2] * mesh.radius)
    assert mesh.radius == pytest.approx(2.0 * unit.radius)
    assert np.allclose(mesh.centre, (1.0, 0.0, 0.0), atol=1e-9)


def test_the_notebooks_start_is_the_preset_on_the_mesh_under_the_start_light():
    """The notebook's start (:func:`explorer.app.start.notebook_state`, the kit's since the
    page's module computed it): the preset on the built-in mesh under the start's light, seen
    from the start's camera; a scene given keeps its lights."""
    state, mesh = start.notebook_state(mesh="sphere")
    assert state.mesh == "sphere" and state.preset == start.DEFAULT_PRESET
    assert state.scene.lights == (start.default_light(mesh),)
    assert state.scene.viewer == start.default_viewer(mesh)
    scene = Scene(lights=(start.default_light(mesh),) * 2)
    state, _ = start.notebook_state(scene, preset=None, mesh="sphere")
    assert len(state.scene.lights) == 2 and state.preset is None


def test_the_message_log_keeps_each_message_whole_with_its_head_and_the_last_ones():
    log = MessageLog(keep=2)
    log.add("info", "saved")
    log.add("warning", "two materials", ["a.mtl:3: Ka 2", "a.mtl:4: Kd -1"])
    m = log.add("error", "error (kd): kd must be in [0, 1]")
    assert [x.text for x in log.messages] == ["two materials", m.text]  # the oldest went
    assert log.count("warning") == 1 and log.count("info") == 0
    assert m.head == f"{m.at} error (kd): kd must be in [0, 1]"  # the level said once
    w = log.messages[0]
    assert w.lines() == [
        f"{w.at} warning: two materials",
        "    a.mtl:3: Ka 2",
        "    a.mtl:4: Kd -1",
    ]
    assert w.as_dict() == {
        "text": "two materials",
        "level": "warning",
        "at": w.at,
        "details": ["a.mtl:3: Ka 2", "a.mtl:4: Kd -1"],
        "head": w.head,
    }
    assert len(MessageLog().messages) == 0


def test_the_tally_counts_errors_and_warnings_and_an_error_or_a_long_warning_opens_the_log():
    from explorer.app.messagelog import LEVEL_COLOURS, opens_log

    log = MessageLog()
    assert log.tally() == ("messages", "")
    log.add("warning", "w")
    assert log.tally() == ("1 warning", LEVEL_COLOURS["warning"])
    log.add("error", "e")
    log.add("warning", "w")
    assert log.tally() == ("1 error, 2 warnings", LEVEL_COLOURS["error"])
    assert not opens_log("info", ["a detail"], fits=False)  # information never opens it
    assert opens_log("warning", ["a detail"]) and opens_log("error", (), fits=False)
    assert not opens_log("error", (), fits=True)  # the status line shows it whole


def test_the_mesh_line_and_a_recent_files_entry_in_words():
    assert captions.mesh_line("teapot", 12345) == "teapot: 12,345 vertices"
    assert captions.recent_entry(1, "/a/b/c.yaml") == "&2 c.yaml   (/a/b)"


def test_the_summary_names_the_material_the_model_and_what_is_hidden():
    mesh = get_mesh("sphere", 8)
    scene = Scene(lights=(start.default_light(mesh),))
    state = start.first_state(scene, mesh, preset="gold")
    assert captions.summary(state) == f"gold;  {state.scene.model}"
    hidden = state.replace(hidden=frozenset({"specular", "ambient", "diffuse_map"}))
    assert (
        captions.summary(hidden)
        == f"gold;  {state.scene.model};  hidden: ambient, specular, diffuse_map"
    )


def test_a_long_jobs_steps_run_until_it_says_it_is_over_and_a_cancel_stops_them_once():
    said = []
    left = iter([(1, None), (2, "encoding"), None])
    job = Steps("turntable", "drawing", 3, lambda: next(left), lambda: said.append("cancel"))
    shown = {"title": "turntable", "text": "drawing", "done": 0, "total": 3, "running": True}
    assert job.as_dict() == shown
    assert job.next() and (job.done, job.text) == (1, "drawing")  # the text stays
    assert job.next() and (job.done, job.text) == (2, "encoding")
    assert not job.next() and not job.running and not job.next()  # over: no more steps
    job.cancel()
    assert said == []  # a finished job is not cancelled
    other = Steps("t", "x", 5, lambda: (1, None), lambda: said.append("cancel"))
    other.cancel()
    other.cancel()
    assert said == ["cancel"] and not other.next() and other.done == 0


@pytest.mark.parametrize(
    ("key", "text", "value"),
    [
        ("kd", " 0.25 ", 0.25),
        ("cutoff", "45°", 45.0),  # the unit the field shows, typed back
        ("color", "1, 0.5, 0", (1.0, 0.5, 0.0)),
        ("color", "#ff0000", (1.0, 0.0, 0.0)),
        ("attenuation", "1, 0.5, 0.25", (1.0, 0.5, 0.25)),
    ],
)
def test_a_typed_value_is_read_as_its_row_reads_it(key, text, value):
    assert panelmodel.row(key).parse(text) == pytest.approx(value)


@pytest.mark.parametrize(
    ("key", "text", "said"),
    [
        ("kd", "5000", "kd must be a number within 0 .. 1, got '5000'"),
        ("kd", "abc", "kd"),
        ("color", "1, 2", "color"),
        ("attenuation", "1, 0.5", "attenuation: give 3 numbers kc, kl, kq, got '1, 0.5'"),
        ("model", "phong", "'model' takes no typed value"),
    ],
)
def test_a_typed_value_out_of_range_or_of_another_shape_is_one_line_naming_the_key(key, text, said):
    with pytest.raises(ExplorerError, match=said):
        panelmodel.row(key).parse(text)


def test_a_swatch_is_the_diffuse_colour_with_the_specular_in_the_top_right_quarter():
    from explorer.core.presets import find_preset

    gold = find_preset("gold")
    d, s = rgb_bytes(gold.diffuse), rgb_bytes(gold.specular)
    assert swatch_squares(gold, 18) == ((0, 0, 18, 18, d), (9, 0, 9, 9, s))
    assert swatch_squares(gold, 17) == ((0, 0, 17, 17, d), (8, 0, 9, 8, s))  # the quarter whole
