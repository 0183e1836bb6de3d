"""Texture coordinates: every built-in mesh's own (u, v) (seams split, the surface unchanged)
and an OBJ's ``vt`` read with the mesh (issue 40, item 1)."""

from __future__ import annotations

import numpy as np
import pytest

from explorer.core.errors import ExplorerError
from explorer.geometry import meshes as M


def _corners(m: M.Mesh) -> np.ndarray:
    """(m, 3, 6) each triangle's corners as (position, normal), sorted: the surface drawn."""
    return np.concatenate([m.positions[m.faces], m.normals[m.faces]], axis=2)


@pytest.mark.parametrize("name", M.BUILTIN_MESHES)
def test_every_builtin_wears_uv_on_the_same_surface(name):
    plain, textured = M.get_mesh(name), M.get_mesh(name, uv=True)
    assert plain.uv is None
    assert textured.uv is not None and textured.uv.shape == (textured.n_vertices, 2)
    assert not textured.uv.flags.writeable
    # the same triangles, corner by corner, at the same places with the same normals: the
    # split copies change no colour and no pixel
    np.testing.assert_array_equal(_corners(plain), _corners(textured))
    # no triangle spans a seam: its corners' (u, v) lie close together (a cube's triangle is
    # half its face's whole square)
    c = textured.uv[textured.faces]
    assert (c.max(axis=1) - c.min(axis=1)).max() < (1.01 if name == "cube" else 0.2)
    assert textured.uv.min() >= 0.0 and textured.uv.max() <= 1.1


def test_plane_and_cube_need_no_split():
    p = M.plane(4, uv=True)
    np.testing.assert_array_equal(p.uv, 0.5 * (p.positions[:, :2] + 1.0))
    assert M.cube(uv=True).n_vertices == 24


def test_sphere_seam_and_poles():
    s = M.sphere(8, uv=True)
    plain = M.sphere(8)
    # one more column of vertices on the seam (bands - 1 rings), the poles one copy per
    # triangle around them
    assert s.n_vertices == plain.n_vertices + (4 - 1) + 2 * (8 - 1)
    front = np.flatnonzero(np.isclose(s.positions[:, 2], 1.0))  # the +z equator point
    np.testing.assert_array_equal(s.uv[front], [[0.0, 0.5], [1.0, 0.5]])  # both sides
    top = s.uv[np.flatnonzero(np.isclose(s.positions[:, 1], 1.0))]
    assert np.allclose(top[:, 1], 1.0) and len(np.unique(top[:, 0])) == 8


def test_teapot_patches_each_wear_the_whole_square():
    t = M.teapot(4, uv=True)
    assert set(np.round(np.unique(t.uv), 12)) == {0.0, 0.25, 0.5, 0.75, 1.0}
    # the welded seams between patches are split again: more vertices, same normals there
    plain = M.teapot(4)
    assert t.n_vertices > plain.n_vertices
    np.testing.assert_array_equal(_corners(plain), _corners(t))


def test_split_by_uv_keeps_a_mesh_without_seams_as_it_is():
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    src, new_faces, new_uv = M.split_by_uv(faces, uv[faces])
    np.testing.assert_array_equal(src, [0, 1, 2, 3])
    np.testing.assert_array_equal(new_faces, faces)
    np.testing.assert_array_equal(new_uv, uv)


OBJ = """v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vt 0.5 0.5
f 1/1 2/2 3/3
f 1/5 3/3 4/4
"""


def test_obj_vt_read_with_the_mesh_split_where_they_differ(tmp_path):
    path = tmp_path / "quad.obj"
    path.write_text(OBJ)
    m = M.load_mesh(path)
    assert m.uv is not None
    # vertex 1 has two (u, v): two copies; both welded for the normal (a flat quad: +z)
    assert m.n_vertices == 5
    np.testing.assert_allclose(m.normals, np.tile([0, 0, 1.0], (5, 1)))
    corners = m.uv[m.faces]
    np.testing.assert_array_equal(corners[0], [[0, 0], [1, 0], [1, 1]])
    np.testing.assert_array_equal(corners[1], [[0.5, 0.5], [1, 1], [0, 1]])


def test_obj_with_normals_keeps_vt(tmp_path):
    path = tmp_path / "n.obj"
    path.write_text(OBJ.replace("f 1/1 2/2 3/3\nf 1/5 3/3 4/4", "vn 0 0 1\nf 1/1/1 2/2/1 3/3/1"))
    m = M.load_mesh(path)
    np.testing.assert_array_equal(m.uv[m.faces][0], [[0, 0], [1, 0], [1, 1]])


def test_obj_without_vt_has_no_uv(tmp_path):
    path = tmp_path / "plain.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert M.load_mesh(path).uv is None


def test_mesh_refuses_bad_uv():
    with pytest.raises(ExplorerError, match=r"uv must be \(3, 2\)"):
        M.Mesh(np.eye(3), np.eye(3), [[0, 1, 2]], uv=np.zeros((2, 2)))
    with pytest.raises(ExplorerError, match="uv must be"):
        M.Mesh(np.eye(3), np.eye(3), [[0, 1, 2]], uv=[[0, 0], [1, 0], [np.nan, 1]])
