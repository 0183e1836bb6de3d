"""The numpy tier's ray casts (explorer.geometry.bvh_numpy) answer exactly what the compiled
BVH and the brute force answer: the same rays hit, the same nearest triangle at the same t."""

from __future__ import annotations

import numpy as np
import pytest

from explorer.core.errors import Cancelled
from explorer.geometry import bvh as B
from explorer.geometry import bvh_numpy as NB
from explorer.geometry.frame import frame_of
from explorer.geometry.meshes import get_mesh, plane, sphere
from explorer.geometry.rays import any_hit as brute_any_hit


def _soup(n, seed):
    rng = np.random.default_rng(seed)
    c = rng.uniform(-1, 1, (n, 1, 3))
    return c + rng.normal(scale=0.15, size=(n, 3, 3)) * rng.uniform(0.1, 2, (n, 1, 1))


def _mesh_triangles(name, *res):
    mesh = get_mesh(name, *res)
    centre, scale = frame_of(mesh.positions)
    Q = (mesh.positions - centre) / scale
    return Q, Q[mesh.faces]


CASES = {
    "teapot 6": lambda: _mesh_triangles("teapot", 6),
    "torus 24": lambda: _mesh_triangles("torus", 24),
    "soup": lambda: (None, _soup(300, 1)),
    "one": lambda: (None, _soup(1, 2)),
    "five": lambda: (None, _soup(5, 3)),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_any_hit_equals_the_compiled_bvh_and_brute_force(name):
    Q, tri = CASES[name]()
    rng = np.random.default_rng(7)
    O = Q if Q is not None else rng.uniform(-1.2, 1.2, (400, 3))
    light = np.array([1.5, 2.5, 1.0])
    D = light - O
    tmax = np.linalg.norm(D, axis=1)
    D /= tmax[:, None]
    got = NB.any_hit(NB.build_bvh(tri), O, D, tmax)
    np.testing.assert_array_equal(got, B.any_hit(B.build_bvh(tri), O, D, tmax))
    np.testing.assert_array_equal(got, brute_any_hit(O, D, tmax, tri))
    inf = NB.any_hit(NB.build_bvh(tri), O, D, np.inf)  # a directional light
    np.testing.assert_array_equal(inf, brute_any_hit(O, D, np.full(len(O), np.inf), tri))


@pytest.mark.parametrize("name", sorted(CASES))
def test_nearest_hits_equal_the_compiled_bvh(name):
    _, tri = CASES[name]()
    rng = np.random.default_rng(11)
    O = rng.uniform(-2, 2, (500, 3))
    D = rng.normal(size=(500, 3))
    D[:5] = [0, 0, 1]  # axis-aligned rays: zero direction components
    D /= np.linalg.norm(D, axis=1)[:, None]
    want = B.nearest_hits(B.build_bvh(tri), O, D, 1e-9)
    got = NB.nearest_hits(NB.build_bvh(tri), O, D, 1e-9)
    for a, b in zip(got, want, strict=True):
        np.testing.assert_array_equal(a, b)
    assert (got[1] >= 0).any() or len(tri) < 10


def test_surface_points_equal_the_compiled_ones():
    mesh = get_mesh("teapot", 6)
    P, F = mesh.positions, np.asarray(mesh.faces, np.int64)
    normals = np.array(mesh.normals, np.float64)
    normals[F[3]] = [[0, 0, 0], [1.0, 0, 0], [-1.0, 0, 0]]  # cancel out mid-edge of triangle 3
    rng = np.random.default_rng(12)
    O = rng.uniform(-3, 3, (600, 3))
    D = P[rng.integers(0, len(P), 600)] - O
    D /= np.linalg.norm(D, axis=1)[:, None]
    t, f, u, v = B.nearest_hits(B.build_bvh(P[F]), O, D, 1e-9)
    f[:40], u[:40], v[:40], t[:40] = 3, 0.5, 0.5, 1.0  # hits on the edge where normals cancel
    got = NB.surface_points(O, D, t, f, u, v, F, normals)
    want = B.surface_points(O, D, t, f, u, v, F, normals)
    for a, b in zip(got, want, strict=True):
        np.testing.assert_array_equal(a, b)
    hit, pos, n = got
    assert 100 < hit.sum() <= 600 and not n[:40].any()
    np.testing.assert_allclose(np.linalg.norm(n[40:], axis=1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(pos, O[hit] + t[hit][:, None] * D[hit], rtol=0, atol=0)


def test_ties_go_to_the_lowest_triangle_index():
    tri = np.array([[[-1, -1, 0], [1, -1, 0], [0, 1, 0]]] * 3, np.float64)  # three alike
    O = np.array([[0.0, 0.0, 2.0]])
    t, f, _, _ = NB.nearest_hits(NB.build_bvh(tri), O, [[0, 0, -1.0]], 0.0)
    assert f[0] == 0 and t[0] == 2.0


def test_empty_mesh_and_planes():
    empty = NB.build_bvh(np.zeros((0, 3, 3)))
    assert not NB.any_hit(empty, [[0, 0, 0]], [[0, 0, 1]], 1.0).any()
    assert NB.nearest_hits(empty, [[0, 0, 0]], [[0, 0, 1]], 0.0)[1][0] == -1
    tri = plane(8).positions[plane(8).faces]
    bvh = NB.build_bvh(tri)
    assert (
        bvh.box.shape[0] == bvh.child.shape[0] and (bvh.count[bvh.child[:, 0] < 0] <= NB.LEAF).all()
    )
    t, f, _, _ = NB.nearest_hits(bvh, [[0.1, 0.2, 3.0]], [[0, 0, -1.0]], 0.0)
    assert f[0] >= 0 and np.isfinite(t[0])


def test_every_triangle_sits_in_exactly_one_leaf_and_inside_every_box_above_it():
    tri = sphere(10).positions[sphere(10).faces]
    bvh = NB.build_bvh(tri)
    leaves = np.flatnonzero(bvh.child[:, 0] < 0)
    covered = np.concatenate(
        [np.arange(f, f + c) for f, c in zip(bvh.first[leaves], bvh.count[leaves], strict=True)]
    )
    assert sorted(covered) == list(range(len(tri)))
    np.testing.assert_array_equal(np.sort(bvh.order), np.arange(len(tri)))
    lo, hi = bvh.tri.min(axis=1), bvh.tri.max(axis=1)
    for node in range(len(bvh.first)):
        s = slice(bvh.first[node], bvh.first[node] + bvh.count[node])
        assert (bvh.box[node, 0::2] <= lo[s]).all() and (bvh.box[node, 1::2] >= hi[s]).all()


def test_a_cast_can_be_cancelled():
    tri = _soup(200, 4)
    with pytest.raises(Cancelled):
        NB.any_hit(NB.build_bvh(tri), np.zeros((10, 3)), np.ones((10, 3)) / 3**0.5, 5.0,
                   cancelled=lambda: True)  # fmt: skip


def _crossing(m, seed):
    """``m`` large triangles whose corners lie on the unit sphere: every one spans the centre's
    neighbourhood, so every box of the tree holds the centre and every ray through it enters
    every leaf (the adversarial case: rays × triangles pairs)."""
    rng = np.random.default_rng(seed)
    c = rng.normal(size=(m, 3, 3))
    return c / np.linalg.norm(c, axis=2, keepdims=True)


def _peak(fn) -> int:
    import tracemalloc

    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@pytest.mark.parametrize("cast", ["any_hit", "nearest_hits"])
def test_a_cast_through_crossing_triangles_is_memory_bounded(monkeypatch, cast):
    # issue 31 item 3: the numpy tier's casts held every (ray, leaf) pair of a level at once,
    # rays × triangles of them on a soup of crossing triangles (9.7 GiB for a 1.5 MB OBJ)
    monkeypatch.setattr(NB, "PAIRS", 512, raising=False)  # a small piece: a small bound
    rng = np.random.default_rng(5)
    k = 400
    O = rng.normal(size=(k, 3)) * 3.0
    D = -O + rng.normal(scale=0.05, size=(k, 3))  # toward the centre, through the soup
    peaks = {}
    for m in (600, 2400):
        tree = NB.build_bvh(_crossing(m, m))
        if cast == "any_hit":
            run = lambda t=tree: NB.any_hit(t, O, D, np.full(k, 1e9))  # noqa: E731
        else:
            run = lambda t=tree: NB.nearest_hits(t, O, D, 1e-9)  # noqa: E731
        peaks[m] = _peak(run)
        per_ray = 200 * k  # the rays' own arrays (O, D, inverses, answers, the root piece)
        assert peaks[m] <= NB.pair_bound(tree) + per_ray, (m, peaks[m], NB.pair_bound(tree))
    # four times the triangles (four times the pairs): the peak grows with the tree's depth only
    assert peaks[2400] < 1.5 * peaks[600], peaks
    # and the answers are still the compiled casts'
    tree = NB.build_bvh(_crossing(600, 600))
    compiled = B.build_bvh(_crossing(600, 600))
    if cast == "any_hit":
        got = NB.any_hit(tree, O, D, np.full(k, 1e9))
        np.testing.assert_array_equal(got, B.any_hit(compiled, O, D, np.full(k, 1e9)))
        assert got.any()
    else:
        t, f, _, _ = NB.nearest_hits(tree, O, D, 1e-9)
        t2, f2, _, _ = B.nearest_hits(compiled, O, D, 1e-9)
        np.testing.assert_array_equal(f, f2)
        np.testing.assert_array_equal(t, t2)
