"""The shading choice ``per-vertex | per-pixel`` (issue 39): the scene and session key, the
panel's row, ``gui / web --per-pixel``, undo, and "Gouraud vs per-pixel" (side A per vertex,
side B per pixel)."""

from __future__ import annotations

import pytest

from explorer.app import effectactions as E
from explorer.app import model as M
from explorer.app import panelmodel as P
from explorer.app import session as S
from explorer.app import start as A
from explorer.cli import build_parser
from explorer.cli.explorerstart import start_state
from explorer.core.errors import ExplorerError
from explorer.core.scene import SHADINGS, Scene, load_scene
from explorer.geometry import meshes as G


@pytest.fixture(scope="module")
def mesh():
    return G.get_mesh("cube")


@pytest.fixture
def state(mesh):
    return A.first_state(Scene(), mesh, name="cube")


def test_the_scene_key_reads_writes_and_defaults_to_per_vertex(tmp_path):
    assert SHADINGS == ("per-vertex", "per-pixel") and Scene().shading == "per-vertex"
    f = tmp_path / "s.yaml"
    f.write_text("material: jade\nshading: per-pixel\n")
    scene = load_scene(str(f))
    assert scene.shading == "per-pixel" and scene.to_mapping()["shading"] == "per-pixel"
    assert load_scene(scene.to_mapping()) == scene
    assert "shading" not in Scene().to_mapping()  # the default is not written


def test_the_row_is_a_choice_of_the_view_tab_and_one_undo_step(state):
    row = P.row("shading")
    assert (row.tab, row.kind, row.choices, row.inline) == ("view", "choice", SHADINGS, True)
    store = M.Store(state)
    action, args, label = P.edit(state, "shading", "per-pixel")
    store.apply(action, *args, label=label)
    assert store.state.scene.shading == "per-pixel" and store.undo_label() == "shading"
    store.undo()
    assert store.state.scene.shading == "per-vertex"
    with pytest.raises(ExplorerError, match="must be one of per-vertex, per-pixel"):
        E.set_shading(state, "flat")


def test_gouraud_vs_per_pixel_is_side_a_per_vertex_and_side_b_per_pixel(state):
    s = E.gouraud_vs_per_pixel(E.set_shading(state, "per-pixel"))
    b = M.side_b(s)
    assert s.scene.shading == "per-vertex" and b.scene.shading == "per-pixel"
    assert b.scene.replace(shading="per-vertex") == s.scene  # nothing else differs
    swapped = M.swap_compare(s)
    assert swapped.scene.shading == "per-pixel" and M.side_b(swapped).scene.shading == (
        "per-vertex"
    )
    assert M.stop_compare(s).compare_shading is None


def test_sessions_keep_the_shading_of_both_sides(state, tmp_path):
    s = E.gouraud_vs_per_pixel(state)
    back, _ = S.load_session(S.save_session(tmp_path / "a.yaml", s))
    assert back.scene.shading == "per-vertex" and back.compare_shading == "per-pixel"
    s = E.set_shading(state, "per-pixel")
    back, _ = S.load_session(S.save_session(tmp_path / "b.yaml", s))
    assert back.scene.shading == "per-pixel" and back.compare_shading is None
    bad = tmp_path / "bad.yaml"
    bad.write_text((tmp_path / "a.yaml").read_text().replace("shading: per-pixel", "shading: x"))
    with pytest.raises(ExplorerError, match=r"compare\.shading.*must be one of"):
        S.load_session(bad)


@pytest.mark.parametrize("command", ["gui", "web"])
def test_per_pixel_flag_starts_the_view_per_pixel(command, tmp_path):
    args = build_parser().parse_args([command, "--mesh", "cube", "--per-pixel"])
    state, _ = start_state(args)
    assert state.scene.shading == "per-pixel"
    plain, _ = start_state(build_parser().parse_args([command, "--mesh", "cube"]))
    assert plain.scene.shading == "per-vertex"
    path = S.save_session(tmp_path / "s.yaml", plain)
    args = build_parser().parse_args([command, "--session", str(path), "--per-pixel"])
    assert start_state(args)[0].scene.shading == "per-pixel"


def test_render_draws_a_scene_that_asks_for_per_pixel_per_pixel(tmp_path, capsys):
    from explorer.cli import main

    scene = tmp_path / "s.yaml"
    scene.write_text("material: gold\nshading: per-pixel\n")
    out = tmp_path / "a.png"
    assert main(["render", str(scene), "--mesh", "cube", "--size", "64x48", "--out", str(out)]) == 0
    assert "per-pixel picture" in capsys.readouterr().out and out.exists()
    ply = tmp_path / "a.ply"  # a mesh file is per vertex whatever the scene asks
    assert main(["render", str(scene), "--mesh", "cube", "--out", str(ply)]) == 0
    assert "vertices with colours" in capsys.readouterr().out
