"""The window's File menu in-process under Xvfb (pytest-qt), every file dialog answered through
the window's question methods: a grouped OBJ opened with its own materials (each group drawn in
its colour, the edited group, a preset overriding them undoably), .mtl import into the preset
list, material / view / turntable exports that never replace a file unasked, a cancelled
turntable that leaves no file, recent files."""

from __future__ import annotations

import imageio.v3 as iio
import numpy as np
import pytest
from helpers.files import write_two_groups
from PySide6 import QtCore

from explorer.app import model as M
from explorer.app import session as S
from explorer.core.mtl import read_mtl
from explorer.core.presets import find_preset, load_material_file
from explorer.render.images import read_png
from explorer.shading.display import group_vertex_colors, to_bytes, vertex_colors

pytestmark = pytest.mark.usefixtures("xdisplay")
WAIT_MS = 60_000
MTL_DATA = "tests/data/mtl"


@pytest.fixture
def answers(win, monkeypatch):
    """The window's questions answered from lists (``path``, ``yes``, ``number``) and what it
    told (``told``: ``(title, text, details, error)``)."""
    box = {"path": [], "yes": [], "number": [], "told": [], "asked": []}

    def pop(kind):
        def answer(*args, **kwargs):
            box["asked"].append((kind, args))
            return box[kind].pop(0)

        return answer

    monkeypatch.setattr(win, "ask_path", pop("path"))
    monkeypatch.setattr(win, "ask_yes", pop("yes"))
    monkeypatch.setattr(win, "ask_number", pop("number"))
    monkeypatch.setattr(win, "tell", lambda title, text, *, details="", error=False: box[
        "told"].append((title, text, details, error)))  # fmt: skip
    return box


def drawn_equals_groups(w):
    """The colours VTK draws equal each group's material run afresh in float64 (one level)."""
    s = w.controller.state
    mesh = w.view.mesh
    want = to_bytes(group_vertex_colors(s.shown_scene(), mesh, s.shown_groups())).astype(int)
    diff = np.abs(w.view.displayed_colors().astype(int) - want)
    assert diff.max() <= 1, f"drawn colours differ from the groups' by up to {diff.max()}/255"


def group_rgb(w, name: str) -> np.ndarray:
    """(3,) mean drawn colour of the vertices of group ``name``."""
    mesh = w.view.mesh
    g = mesh.groups.names.index(name)
    return w.view.displayed_colors()[mesh.groups.of_vertex == g].mean(axis=0)


def test_a_grouped_obj_opens_with_its_own_materials(win, answers, tmp_path, qtbot):
    two = write_two_groups(tmp_path)
    answers["path"].append(str(two))
    win.menu_actions["open"].trigger()
    s = win.controller.state
    assert s.mesh == str(two) and s.groups is not None and s.preset is None
    red, blue = group_rgb(win, "left_red"), group_rgb(win, "right_blue")
    assert red[0] > 100 > red[2] and blue[2] > 100 > blue[0]  # both group colours drawn
    drawn_equals_groups(win)
    rows = win.panel.material.rows.widgets  # the mesh's own materials: rows of the tab
    line, group, use = rows["mesh_materials"], rows["group"], rows["use_mesh_materials"]
    assert line.isVisibleTo(win.panel) and "two.obj brings its own materials" in line.text()
    assert group.count() == 2 and not use.isVisibleTo(win.panel)
    assert not group.itemIcon(0).isNull()  # each group with its swatch
    assert "of the mesh" in win.panel.material.preset_label.text()
    assert "two.obj's materials" in win.status_label.text()
    # the controls edit the chosen group only
    i = s.mesh_materials.names.index("right_blue")
    group.activated.emit(i)
    assert win.controller.state.group == i and line.text().endswith("'right_blue'")
    before = group_rgb(win, "left_red")
    win.panel.material.sliders["kd"].field.setValue(0.3)
    assert max(win.controller.state.groups[i].diffuse) == pytest.approx(0.3)
    assert np.array_equal(group_rgb(win, "left_red"), before)
    win.render()
    drawn_equals_groups(win)
    # the edited group's material saved as a preset: the groups stay
    path = win.controller.files.save_preset_as("my_blue")
    assert load_material_file(path).diffuse == win.controller.state.groups[i].diffuse
    assert win.controller.state.groups is not None and "my_blue" in {
        p.name for p in win.controller.presets
    }
    # a preset covers the whole mesh; undo brings the groups back; so does the button
    tab = win.panel.material
    item = tab.presets.findItems("jade", QtCore.Qt.MatchFlag.MatchExactly)[0]
    tab.presets.itemClicked.emit(item)  # a click on it
    s = win.controller.state
    assert s.groups is None and s.preset == "jade" and use.isVisibleTo(win.panel)
    assert not group.isVisibleTo(win.panel)
    assert "preset 'jade' covers the whole mesh" in line.text()
    want = to_bytes(vertex_colors(s.shown_scene(), win.view.mesh)).astype(int)
    assert np.abs(win.view.displayed_colors().astype(int) - want).max() <= 1  # jade all over
    win.controller.undo()
    assert (
        win.controller.state.groups is not None
        and max(win.controller.state.groups[i].diffuse) == 0.3
    )
    win.controller.redo()
    qtbot.mouseClick(use, QtCore.Qt.MouseButton.LeftButton)
    assert win.controller.state.groups == win.controller.state.mesh_materials.materials
    # the difference view compares each group in its own material; editing a group that is
    # not the one drawn by the scene's material asks for a new map
    win.controller.toggle_difference()
    qtbot.waitUntil(lambda: win.heat.shown, timeout=WAIT_MS)
    job = win.heat.result.job
    assert job.materials == win.controller.state.shown_groups() and len(job.materials) == 2
    assert win.heat.result.comparison.mask.sum() > 1000
    edited = win.controller.state.group
    win.controller.act(M.select_group, 1 - edited, label="group")
    win.panel.material.sliders["shininess"].field.setValue(7.0)
    assert not win.heat.shown  # stale: the live view until the new map comes
    qtbot.waitUntil(lambda: win.heat.shown, timeout=WAIT_MS)
    assert win.heat.result.job.materials[1 - edited].shininess == 7.0
    win.controller.undo()
    win.controller.act(M.select_group, edited, label="group")
    win.controller.toggle_difference()
    # the session keeps the mesh and its materials
    win.panel.material.sliders["shininess"].field.setValue(5.0)
    saved = win.controller.state
    path = win.controller.files.save_session_as(tmp_path / "grouped.yaml")
    win.controller.reset_all()
    assert win.controller.state.mesh == "icosphere"
    win.controller.files.open_file(path)
    s = win.controller.state
    assert s.mesh == str(two) and s.groups == saved.groups and s.group == saved.group
    win.render()
    drawn_equals_groups(win)


def test_import_materials_adds_presets_asks_before_replacing_and_names_bad_lines(
    win, answers, tmp_path
):
    answers["path"].append(f"{MTL_DATA}/several.mtl")
    win.menu_actions["import_materials"].trigger()
    names = {p.name for p in win.controller.presets}
    assert {"red_paint", "red_paint_2", "blue"} <= names  # in the list at once
    listed = {win.panel.material.presets.item(i).text()
              for i in range(win.panel.material.presets.count())}  # fmt: skip
    assert {"red_paint", "red_paint_2", "blue"} <= listed
    blue = tmp_path / "presets" / "blue.yaml"
    assert load_material_file(blue).specular == (0.5, 0.5, 0.5)
    text = blue.read_text()
    # again: asked, said no: nothing replaced
    answers["yes"].append(False)
    assert win.controller.files.import_materials(f"{MTL_DATA}/several.mtl") == []
    assert answers["asked"][-1][0] == "yes" and "3 preset files" in answers["asked"][-1][1][0]
    assert blue.read_text() == text and "nothing imported" in win.message
    # a bad file: a dialog naming the file and line, nothing written
    answers["path"].append(f"{MTL_DATA}/bad_number.mtl")
    win.menu_actions["import_materials"].trigger()
    title, said, _, error = answers["told"][-1]
    assert error and f"{MTL_DATA}/bad_number.mtl:" in said and "Nothing was imported" in said
    assert win.message.startswith("error")
    # warnings are shown
    win.controller.files.import_materials(f"{MTL_DATA}/blender.mtl")
    _, said, details, error = answers["told"][-1]
    assert not error and "warning" in said and "Ka 1 1 1" in details and "Ni" in details


def test_export_material_never_replaces_unasked(win, answers, tmp_path):
    out = tmp_path / "gold.mtl"
    out.write_text("mine\n")
    answers["path"].append(str(out))
    answers["yes"].append(False)
    win.menu_actions["export_material"].trigger()
    assert out.read_text() == "mine\n"  # asked, said no
    answers["yes"].append(True)
    assert win.controller.files.export_material(out) == out
    (m,) = read_mtl(out)
    s = win.controller.state
    keys = ("ambient", "diffuse", "specular", "emission", "shininess", "opacity")
    assert m.name == "gold"
    assert [getattr(m.material, k) for k in keys] == [getattr(s.material, k) for k in keys]
    for suffix, word in ((".json", "MeshPhongMaterial"), (".x3d", "<Material")):
        path = win.controller.files.export_material(tmp_path / f"g{suffix}")
        assert word in path.read_text()
    assert answers["told"] and "approximation" in answers["told"][-1][1]
    back = load_material_file(win.controller.files.export_material(tmp_path / "g.yaml"))
    assert [getattr(back, k) for k in keys] == [getattr(s.material, k) for k in keys]
    assert back.model == s.scene.model
    answers["path"].append(str(tmp_path / "bad.txt"))
    win.menu_actions["export_material"].trigger()
    assert "must end in .mtl, .json, .x3d, .yaml" in win.message
    assert not (tmp_path / "bad.txt").exists()
    win.controller.errors.clear()


def test_export_material_of_a_grouped_mesh_writes_every_group(win, answers, tmp_path):
    two = write_two_groups(tmp_path)
    text = two.read_text().replace("left_red", "Left_Red")
    two.write_text(text)
    mtl = tmp_path / "two_groups.mtl"
    mtl.write_text(mtl.read_text().replace("left_red", "Left_Red"))
    win.controller.files.open_file(two)
    win.panel.material.sliders["ks"].field.setValue(0.25)  # the edited group, as edited
    s = win.controller.state
    path = win.controller.files.export_material(tmp_path / "out.mtl")
    read = {m.name: m.material for m in read_mtl(path)}
    assert {n: m.diffuse for n, m in read.items()} == {"Left_Red": (1.0, 0.0, 0.0),
                                                      "right_blue": (0.0, 0.0, 1.0)}  # fmt: skip
    name = s.mesh_materials.names[s.group]
    assert read[name].specular == s.groups[s.group].specular and max(read[name].specular) == 0.25
    # the exported library serves the OBJ: it reopens with the same materials
    (tmp_path / "two_groups.mtl").write_bytes(path.read_bytes())
    win.controller.meshes.clear()
    win.controller.files.choose_mesh("cube")
    win.controller.files.open_file(two)
    assert [m.specular for m in win.controller.state.groups] == [m.specular for m in s.groups]


def test_export_view_png_asks_before_replacing(win, answers, tmp_path):
    out = tmp_path / "view.png"
    answers["path"].append(str(out))
    win.menu_actions["export_render"].trigger()
    picture = read_png(out)
    w, h = win.plotter.window_size
    assert picture.shape[:2] == (h, w)
    stamp = out.stat().st_mtime_ns
    answers["yes"].append(False)
    assert win.controller.files.export_render(out) is None and out.stat().st_mtime_ns == stamp


def test_turntable_writes_the_frames_and_cancel_leaves_no_file(win, answers, tmp_path, qtbot):
    out = tmp_path / "spin.gif"
    answers["path"].append(str(out))
    answers["number"].append(3)
    win.controller.files.export_turntable(size=(48, 40))
    job = win.controller.turntable
    assert job.dialog.isVisible()
    seen = []  # the event loop runs between the frames: the window keeps painting
    other = QtCore.QTimer()
    other.timeout.connect(lambda: seen.append(job.done))
    other.start(0)
    qtbot.waitUntil(lambda: job.stage == "written", timeout=WAIT_MS)
    other.stop()
    assert {1, 2, 3} <= set(seen)
    frames = iio.imread(out, index=None)
    assert frames.shape[:3] == (3, 40, 48) and "wrote" in win.message
    assert not (frames[0] == frames[1]).all()  # the lights and camera turned
    # asked before replacing: no
    answers["yes"].append(False)
    assert win.controller.files.export_turntable(out, 3, size=(48, 40)) is None
    # cancelled part way: no file, nothing left behind
    gone = tmp_path / "gone.mp4"
    job = win.controller.files.export_turntable(gone, 40, size=(48, 40))
    qtbot.waitUntil(lambda: job.done >= 2, timeout=WAIT_MS)
    job.dialog.cancel()
    qtbot.waitUntil(lambda: job.stage == "cancelled", timeout=WAIT_MS)
    assert job.done < 40 and not gone.exists() and "cancelled" in win.message
    assert sorted(p.name for p in tmp_path.iterdir() if "gone" in p.name) == []


def test_recent_files(win, answers, tmp_path):
    two = write_two_groups(tmp_path)
    win.controller.files.open_file(two)
    win.controller.files.save_session_as(tmp_path / "s.yaml")
    recent = win.controller.files.recent_files()
    assert recent == [str(tmp_path / "s.yaml"), str(two)]
    actions = [a for a in win.recent_menu.actions() if a.objectName().startswith("recent_")]
    assert [a.objectName() for a in actions] == ["recent_1", "recent_2"]
    win.controller.act(M.apply_preset, "ruby", find_preset("ruby"))
    actions[1].trigger()  # two.obj again: its own materials
    assert win.controller.state.mesh == str(two)
    assert win.controller.files.recent_files()[0] == str(two)
    two.unlink()
    [a for a in win.recent_menu.actions() if a.objectName() == "recent_1"][0].trigger()
    assert "no such file" in win.message and str(two) not in win.controller.files.recent_files()
    win.controller.errors.clear()
    assert S.last_session_path  # the list lives beside the last session
    assert (tmp_path / "recent-files.json").is_file()


def test_an_obj_whose_mtl_is_bad_opens_in_the_present_material(win, tmp_path):
    two = write_two_groups(tmp_path)
    (tmp_path / "two_groups.mtl").write_text("newmtl left_red\nKd 1 zero 0\n")
    before = win.controller.state.material
    win.controller.files.open_file(two)
    s = win.controller.state
    assert s.mesh == str(two) and s.groups is None and s.material == before
    assert "two_groups.mtl:2" in win.message and win.message.startswith("error")
    win.controller.errors.clear()


def test_compare_beside_the_mesh_materials(win, tmp_path, qtbot):
    win.controller.files.open_file(write_two_groups(tmp_path))
    win.controller.toggle_compare()
    s = win.controller.state
    assert s.groups is not None and s.compare == s.material and win.plotter_b.isVisible()
    qtbot.waitUntil(lambda: win.plotter_b.width() > 100)
    mesh = win.view_b.mesh
    want = to_bytes(vertex_colors(M.side_b(s).shown_scene(), mesh)).astype(int)
    assert np.abs(win.view_b.displayed_colors().astype(int) - want).max() <= 1  # B: one material
    drawn_equals_groups(win)  # A: the groups
    win.controller.swap_sides()
    assert win.controller.state.groups is None
    win.controller.undo()
    assert win.controller.state.groups is not None
