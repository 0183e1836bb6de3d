"""The explorer's 3D view without Qt (an off-screen plotter): the level of detail drawn while
dragging, for a plain mesh and for a mesh file's material groups."""

from __future__ import annotations

import numpy as np
import pytest

from explorer.app import model as M
from explorer.app.view import SceneView, lod_mesh
from explorer.cli import build_parser
from explorer.cli.gui import start_state
from explorer.geometry import meshes as G
from explorer.render.vtk import plotter
from explorer.shading.display import group_vertex_colors, to_bytes


def write_two_tori(directory, resolution: int = 96):
    """An OBJ of two tori side by side, ``usemtl red`` and ``usemtl blue``, and its .mtl."""
    t = G.torus(resolution)
    (directory / "tori.mtl").write_text("newmtl red\nKd 1 0 0\nKs 0.5 0.5 0.5\nNs 40\n"
                                        "newmtl blue\nKd 0 0 1\nNs 10\n")  # fmt: skip
    lines = ["mtllib tori.mtl"]
    n = t.n_vertices
    for shift in (-1.2, 1.2):
        lines += [f"v {x + shift} {y} {z}" for x, y, z in t.positions]
    lines += [f"vn {x} {y} {z}" for x, y, z in np.vstack([t.normals, t.normals])]
    for g, name in enumerate(("red", "blue")):
        lines.append(f"usemtl {name}")
        lines += [f"f {a}//{a} {b}//{b} {c}//{c}" for a, b, c in t.faces + 1 + g * n]
    path = directory / "tori.obj"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture
def tori(tmp_path):
    return start_state(build_parser().parse_args(["gui", "--mesh", str(write_two_tori(tmp_path))]))


def test_level_of_detail_of_a_plain_mesh():
    mesh = G.sphere(256)
    lod = lod_mesh(mesh, 2000)
    assert 1500 <= lod.n_vertices <= 2500 and lod.groups is None
    assert np.allclose(np.linalg.norm(lod.normals, axis=1), 1.0)
    assert np.abs(np.linalg.norm(lod.positions, axis=1) - 1.0).max() < 0.05  # on the sphere


def test_level_of_detail_keeps_each_vertex_in_its_group(tori):
    state, mesh = tori
    lod = lod_mesh(mesh, 1000)
    assert lod.groups.names == mesh.groups.names == ("red", "blue")
    counts = np.bincount(lod.groups.of_vertex, minlength=2)
    assert 700 <= counts.sum() <= 1300 and abs(counts[0] - counts[1]) < 0.2 * counts.sum()
    # the tori lie apart (x < 0: red, x > 0: blue), so a vertex's side names its group
    assert np.array_equal(lod.groups.of_vertex, (lod.positions[:, 0] > 0).astype(np.int32))


def test_dragging_draws_the_groups_level_of_detail_in_their_materials(tori):
    state, mesh = tori
    assert state.groups is not None
    pl = plotter((200, 150), (0.3, 0.3, 0.3))
    try:
        view = SceneView(pl, mesh, state, lod_vertices=1000, lod_target=800)
        assert len(view.drawings) == 2
        view.begin_drag()
        lod = view.drawings[1]
        assert view.active is lod and lod.actor.GetVisibility()
        assert not view.drawings[0].actor.GetVisibility()
        state = M.set_coefficient(state, "kd", 0.4)  # edits the group the panel edits
        view.show_state(state)
        want = to_bytes(group_vertex_colors(state.shown_scene(), lod.mesh, state.shown_groups()))
        assert np.abs(lod.rgb.astype(int) - want.astype(int)).max() <= 1
        red, blue = lod.rgb[lod.mesh.groups.of_vertex == 0], lod.rgb[lod.mesh.groups.of_vertex == 1]
        assert (red[:, 0] >= red[:, 2]).all() and (blue[:, 2] >= blue[:, 0]).all()
        view.end_drag()
        full = view.drawings[0]
        assert view.active is full and full.actor.GetVisibility()
        want = to_bytes(group_vertex_colors(state.shown_scene(), mesh, state.shown_groups()))
        assert np.abs(full.rgb.astype(int) - want.astype(int)).max() <= 1
    finally:
        pl.close()


def test_edge_marker_points_from_the_views_edge_to_a_handle_out_of_it():
    from explorer.app.view import MARKER_MARGIN, MARKER_SIZE, edge_marker

    assert edge_marker(50, 40, True, 200, 100) is None  # in the view: no arrow
    tri = edge_marker(100, 400, True, 200, 100)  # straight above
    assert tri[0] == pytest.approx([100, 100 - MARKER_MARGIN])  # the tip at the top edge
    assert tri[1:, 1] == pytest.approx([100 - MARKER_MARGIN - MARKER_SIZE] * 2)
    behind = edge_marker(100, 400, False, 200, 100)  # behind the camera: mirrored, downward
    assert behind[0] == pytest.approx([100, MARKER_MARGIN])
    tri = edge_marker(-1000, 50, True, 200, 100)  # far left
    assert tri[0] == pytest.approx([MARKER_MARGIN, 50]) and (tri[:, 0] >= 0).all()
    corner = edge_marker(1e6, 1e6, True, 200, 100)
    assert 0 <= corner[0, 0] <= 200 and 0 <= corner[0, 1] <= 100


@pytest.mark.parametrize("scale", [1e-30, 1e39])
def test_level_of_detail_of_a_mesh_at_any_scale(scale):
    """Clustered in the mesh's frame: float32 points of a mesh scaled by 1e39 were inf."""
    unit = G.sphere(64)
    mesh = G.Mesh(unit.positions * scale, unit.normals, unit.faces)
    lod = lod_mesh(mesh, 1000)
    assert np.isfinite(lod.positions).all() and 700 <= lod.n_vertices <= 1300
    assert np.abs(np.linalg.norm(lod.positions / scale, axis=1) - 1.0).max() < 0.05


def test_the_view_wears_a_mesh_files_texture_as_render_does(tmp_path):
    """The window's and the page's view (SceneView) draws the .mtl's map_Kd with render's one
    pass (explorer.render.textured): a white image changes no pixel, the tiles change many,
    and under separate specular the highlight goes to its own vertex array."""
    import dataclasses
    from pathlib import Path

    from PIL import Image

    from explorer.shading.display import vertex_colors

    obj = Path(__file__).resolve().parents[2] / "docs" / "examples" / "textured_teapot.obj"
    state, mesh = start_state(build_parser().parse_args(["gui", "--mesh", str(obj)]))
    Image.fromarray(np.full((2, 2, 3), 255, np.uint8)).save(tmp_path / "white.png")

    def with_map(tmap):
        return tuple(m.replace(diffuse_map=tmap) for m in state.groups)

    pl = plotter((200, 150), (0.3, 0.3, 0.3))
    try:
        view = SceneView(pl, mesh, state)
        pl.view_xy()  # the teapot from the front, the same camera for every picture

        def picture(s):
            view.show_state(s)
            pl.render()
            return pl.screenshot(return_img=True)[:, :, :3].copy()

        tiled = picture(state)
        assert view.drawings[0].texture is not None
        plain = picture(dataclasses.replace(state, groups=with_map(None)))
        assert view.drawings[0].texture is None
        assert np.abs(tiled.astype(int) - plain.astype(int)).max() > 100
        white = picture(dataclasses.replace(state, groups=with_map(str(tmp_path / "white.png"))))
        np.testing.assert_array_equal(white, plain)
        separate = dataclasses.replace(state, scene=state.scene.replace(color_control="separate"))
        picture(separate)
        shown_scene = separate.shown_scene().replace(material=separate.shown_groups()[0])
        only = shown_scene.material.replace(ambient=(0, 0, 0), diffuse=(0, 0, 0))
        want = to_bytes(vertex_colors(shown_scene.replace(material=only), mesh))
        got = np.rint(np.asarray(view.drawings[0].secondary)[:, :3] * 255).astype(int)
        assert np.abs(got - want.astype(int)).max() <= 1  # the window shades in float32
    finally:
        pl.close()


def test_the_view_wears_ambient_and_emission_maps_as_layers(tmp_path):
    """An emission map and an ambient map on the window's (and page's) view: each layer's
    colour array holds its term (the engine's, within the float32 window's one level), a black
    emission map takes the emission off every pixel (the picture is the material without
    emission, within two levels: each term is rounded apart), a white one gives it back."""
    import dataclasses

    from PIL import Image

    from explorer.render.textured import only
    from explorer.shading.display import vertex_colors

    for name, value in (("white", 255), ("black", 0)):
        Image.fromarray(np.full((2, 2, 3), value, np.uint8)).save(tmp_path / f"{name}.png")
    state, _ = start_state(build_parser().parse_args(["gui", "--mesh", "torus"]))
    mesh = G.torus(uv=True)
    grey = (0.2, 0.2, 0.2)
    base = state.scene.material.replace(
        emission=(0.3, 0.2, 0.1), ambient=grey, diffuse=(0.3, 0.3, 0.3), specular=grey
    )

    def wearing(**maps):
        return dataclasses.replace(state, scene=state.scene.replace(material=base.replace(**maps)))

    pl = plotter((200, 150), (0.3, 0.3, 0.3))
    try:
        view = SceneView(pl, mesh, wearing())
        pl.view_xy()

        def picture(s):
            view.show_state(s)
            pl.render()
            return pl.screenshot(return_img=True)[:, :, :3].astype(int)

        plain = picture(wearing())
        lit = wearing(
            emission_map=str(tmp_path / "white.png"), ambient_map=str(tmp_path / "white.png")
        )
        white = picture(lit)
        d = view.drawings[0]
        assert set(d.layers) == {"emission", "ambient"}
        scene = lit.shown_scene()
        for term, name in d.layers.items():
            want = to_bytes(vertex_colors(scene.replace(material=only(term)(scene.material)), mesh))
            got = np.rint(np.asarray(d.poly.point_data[name])[:, :3] * 255).astype(int)
            assert np.abs(got - want.astype(int)).max() <= 1
        assert np.abs(white - plain).max() <= 2
        dark = picture(wearing(emission_map=str(tmp_path / "black.png")))
        no_emission = picture(
            dataclasses.replace(
                state, scene=state.scene.replace(material=base.replace(emission=(0.0, 0.0, 0.0)))
            )
        )
        assert np.abs(dark - no_emission).max() <= 2
        assert np.abs(dark - plain).max() > 40
    finally:
        pl.close()
