"""A mesh file's own materials in the explorer's model (no Qt): an OBJ's usemtl groups shown
each in its material, the group the panel edits, a preset that overrides them (undoable), the
``gui`` command's start, and sessions that keep them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from helpers.files import write_two_groups

from explorer.app import model as M
from explorer.app import session as S
from explorer.cli import build_parser
from explorer.cli.gui import start_state
from explorer.core.errors import ExplorerError
from explorer.core.presets import find_preset


#: two unit squares side by side, each its own usemtl group (red on the left, blue on the
#: right), and their .mtl
@pytest.fixture
def two(tmp_path) -> Path:
    return write_two_groups(tmp_path)


def gui_state(*argv):
    return start_state(build_parser().parse_args(["gui", *argv]))


def test_a_grouped_obj_starts_with_its_own_materials(two):
    state, mesh = gui_state("--mesh", str(two))
    mm = state.mesh_materials
    assert sorted(mm.names) == ["left_red", "right_blue"] and mm.source == "two.obj"
    assert state.groups == mm.materials and state.preset is None and not state.edited
    diffuse = {n: m.diffuse for n, m in zip(mm.names, state.groups, strict=True)}
    assert diffuse == {"left_red": (1.0, 0.0, 0.0), "right_blue": (0.0, 0.0, 1.0)}
    assert state.material == state.groups[state.group]
    assert len(mesh.groups.names) == len(state.groups)


def test_preset_option_overrides_the_mesh_materials(two):
    state, _ = gui_state("--mesh", str(two), "--preset", "jade")
    assert state.groups is None and state.mesh_materials is not None
    assert state.preset == "jade" and state.material == find_preset("jade")


def test_edits_go_to_the_edited_group_and_a_preset_overrides_undoably(two):
    state, _ = gui_state("--mesh", str(two))
    store = M.Store(M.select_group(state, 0))
    store.apply(M.set_coefficient, "kd", 0.5)
    s = store.state
    kd = max(state.groups[0].diffuse)
    assert s.groups[0].diffuse == tuple(0.5 * c / kd for c in state.groups[0].diffuse)
    assert s.groups[1] == state.groups[1]
    assert s.material == s.groups[0] and s.edited
    store.apply(M.select_group, 1)
    s = store.state
    assert s.material == s.groups[1] and not s.edited  # group 2 as its file has it
    assert max(s.groups[0].diffuse) == 0.5  # group 1's edit is kept
    gold = find_preset("gold")
    store.apply(M.apply_preset, "gold", gold)
    s = store.state
    assert s.groups is None and s.material == gold and s.preset == "gold"
    assert s.shown_groups() is None
    store.undo()
    assert max(store.state.groups[0].diffuse) == 0.5 and store.state.group == 1
    store.redo()
    store.apply(M.use_mesh_materials)
    s = store.state
    assert s.groups == state.mesh_materials.materials and s.group == 1 and s.preset is None


def test_hidden_terms_apply_to_every_group(two):
    state, _ = gui_state("--mesh", str(two))
    s = M.set_term(state, "ambient", False)
    assert all(m.ambient == (0.0, 0.0, 0.0) for m in s.shown_groups())
    assert s.groups == state.groups  # the materials themselves are unchanged


def test_group_actions_refuse_what_cannot_be(two):
    state, _ = gui_state("--mesh", str(two))
    with pytest.raises(ExplorerError, match="group must be 1 to 2, got 3"):
        M.select_group(state, 2)
    plain, _ = gui_state("--mesh", "icosphere")
    with pytest.raises(ExplorerError, match="brings no materials of its own"):
        M.use_mesh_materials(plain)
    with pytest.raises(ExplorerError, match="no group to edit"):
        M.select_group(plain, 0)
    other = M.set_mesh(state, "cube", (0, 0, 0), 1.0)
    assert other.mesh_materials is None and other.groups is None


def test_sessions_keep_the_mesh_materials_as_edited(two, tmp_path):
    state, _ = gui_state("--mesh", str(two))
    state = M.set_shininess(M.select_group(state, 1), 7.0)
    path = S.save_session(tmp_path / "s.yaml", state)
    back, mesh = S.load_session(path)
    assert back.groups == state.groups and back.group == 1 and back.material == state.material
    assert back.mesh_materials == state.mesh_materials and back.edited
    override = M.apply_preset(state, "ruby", find_preset("ruby"))
    back, _ = S.load_session(S.save_session(tmp_path / "o.yaml", override))
    assert back.groups is None and back.mesh_materials is not None and back.preset == "ruby"


def test_a_session_with_the_wrong_number_of_groups_names_the_key(two, tmp_path):
    state, _ = gui_state("--mesh", str(two))
    data = S.session_mapping(state)
    data["groups"]["materials"] = data["groups"]["materials"][:1]
    path = tmp_path / "bad.json"
    import json

    path.write_text(json.dumps(data))
    with pytest.raises(ExplorerError, match=r"bad\.json.*groups\.materials.*has 2 material groups"):
        S.load_session(path)


def test_difference_view_follows_the_groups(two):
    """With the mesh's own materials shown, the difference view compares each pixel in its
    triangle's group's material: red pixels on the left square, blue on the right, and the
    worker's map equals a direct comparison (ray cast, and from the rasteriser's triangles)."""
    from explorer.analysis import comparison as C
    from explorer.app.difference import Job, run_job
    from explorer.render.camera import camera_for
    from explorer.render.perpixel import reference
    from explorer.shading.display import group_vertex_colors

    state, mesh = gui_state("--mesh", str(two))
    state = M.set_difference(state, True)
    assert M.use_mesh_materials(state).difference  # showing the groups keeps it on
    scene, materials = state.shown_scene(), state.shown_groups()
    size = (120, 80)
    cam = camera_for(scene, mesh, size[0] / size[1])
    ref = reference(scene, mesh, size, camera=cam, materials=materials)
    cols = np.nonzero(ref.mask)[1]
    left, right = ref.colors[cols < 60], ref.colors[cols >= 60]
    assert len(left) > 500 and len(right) > 500
    assert (left[:, 0] > left[:, 2]).all() and (right[:, 2] > right[:, 0]).all()
    colors = group_vertex_colors(scene, mesh, materials)
    job = Job(0, scene, mesh, colors, cam, size, (0.3, 0.3, 0.3), materials)
    got = run_job(job).comparison
    for method in ("raycast", "raster"):
        want = C.compare_view(scene, mesh, size, camera=cam, method=method, materials=materials)
        assert np.array_equal(got.levels, want.levels) and got.mask.sum() > 1000
    one = C.compare_view(scene, mesh, size, camera=cam, colors=colors)  # one material: wrong
    assert one.max > got.max + 20
