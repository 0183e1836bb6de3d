"""The BVH answers exactly what testing every triangle answers, and its work can be cancelled."""

from __future__ import annotations

import math
import threading

import numpy as np
import pytest
from helpers.brute_rays import brute_nearest

from explorer.core.errors import Cancelled
from explorer.geometry import bvh as B
from explorer.geometry.frame import frame_of
from explorer.geometry.meshes import get_mesh, plane, sphere
from explorer.geometry.rays import any_hit as brute_any_hit
from explorer.geometry.rays import pack_triangles


def _frame(mesh):
    centre, scale = frame_of(mesh.positions)
    Q = (mesh.positions - centre) / scale
    return Q, Q[mesh.faces]


def _toward(Q, light):
    D = light - Q
    tmax = np.linalg.norm(D, axis=1)
    return D / tmax[:, None], tmax


def _soup(n, seed):
    """Random triangles, some long and thin, overlapping each other."""
    rng = np.random.default_rng(seed)
    c = rng.uniform(-1, 1, (n, 1, 3))
    return c + rng.normal(scale=0.15, size=(n, 3, 3)) * rng.uniform(0.1, 2, (n, 1, 1))


MESHES = {
    "teapot 6": lambda: get_mesh("teapot", 6),
    "torus 24": lambda: get_mesh("torus", 24),
    "sphere 16": lambda: sphere(16),
    "plane 8 (axis-aligned grid)": lambda: plane(8),
}


@pytest.mark.parametrize("name", MESHES)
def test_shadow_rays_equal_brute_force(name):
    mesh = MESHES[name]()
    Q, tri = _frame(mesh)
    bvh = B.build_bvh(tri)
    rng = np.random.default_rng(1)
    for light in [np.array([2.0, 3.0, 1.0]), np.array([0.0, 0.3, 0.0]), *rng.normal(size=(3, 3))]:
        D, tmax = _toward(Q, light)
        expected = brute_any_hit(Q, D, tmax, tri)
        assert np.array_equal(B.any_hit(bvh, Q, D, tmax), expected)
    # directional light, and axis-parallel rays (zero direction components) along the grid
    for d in ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.3, 0.8, -0.52]):
        D = np.tile(np.asarray(d) / np.linalg.norm(d), (len(Q), 1))
        tmax = np.full(len(Q), np.inf)
        assert np.array_equal(B.any_hit(bvh, Q, D, tmax), brute_any_hit(Q, D, tmax, tri))


def test_shadow_rays_equal_brute_force_on_a_triangle_soup():
    tri = _soup(3000, 2)
    bvh = B.build_bvh(tri)
    rng = np.random.default_rng(3)
    O = rng.uniform(-1.5, 1.5, (4000, 3))
    O[:1000] = tri[:1000, 0]  # rays from corners, as shadow rays start
    D = rng.normal(size=(4000, 3))
    D /= np.linalg.norm(D, axis=1, keepdims=True)
    tmax = np.where(rng.random(4000) < 0.5, np.inf, rng.uniform(0.1, 3, 4000))
    hit = B.any_hit(bvh, O, D, tmax)
    assert np.array_equal(hit, brute_any_hit(O, D, tmax, tri))
    assert 0.05 < hit.mean() < 0.95  # the rays test something


@pytest.mark.parametrize("name", ["teapot 6", "torus 24"])
def test_nearest_hits_equal_brute_force(name):
    mesh = MESHES[name]()
    tri = mesh.positions[mesh.faces]
    bvh = B.build_bvh(tri)
    rng = np.random.default_rng(5)
    O = rng.normal(size=(3000, 3)) * 3.0
    target = rng.uniform(-0.8, 0.8, (3000, 3))
    D = target - O
    D /= np.linalg.norm(D, axis=1, keepdims=True)
    got = B.nearest_hits(bvh, O, D, 1e-9)
    want = brute_nearest(O, D, tri, 1e-9)
    for a, b in zip(got, want, strict=True):
        assert np.array_equal(a, b)
    assert (got[1] >= 0).mean() > 0.3


def test_nearest_hits_tie_goes_to_the_lowest_index():
    # the same triangle three times, in the middle of others: every hit ties
    tri = np.concatenate([_soup(50, 4), np.repeat(_soup(1, 9), 3, axis=0) * 0 + [[[0, 0, 0]]]])
    tri[-3:] = [[-1, -1, 0], [1, -1, 0], [0, 1, 0]]
    bvh = B.build_bvh(tri)
    O = np.array([[0.0, 0.0, 5.0]])
    D = np.array([[0.0, 0.0, -1.0]])
    t, f, _, _ = B.nearest_hits(bvh, O, D, 0.0)
    want = brute_nearest(O, D, tri, 0.0)
    assert f[0] == want[1][0] and t[0] == want[0][0]


def test_tree_holds_every_triangle_once_inside_its_boxes():
    tri = _soup(2000, 6)
    bvh = B.build_bvh(tri)
    assert sorted(bvh.order.tolist()) == list(range(2000))
    assert np.array_equal(bvh.tri, pack_triangles(tri[bvh.order]))
    covered = np.zeros(2000, int)
    # walk the tree: every leaf's triangles lie inside the box its parent keeps for it
    stack = [0]
    while stack:
        node = stack.pop()
        for side in range(2):
            c = int(bvh.child[node, side])
            box = bvh.cbox[node, 6 * side : 6 * side + 6].astype(np.float64)
            if c >= 0:
                stack.append(c)
                continue
            first, count = bvh.leaf[~c]
            pts = tri[bvh.order[first : first + count]].reshape(-1, 3)
            assert (pts >= box[0::2]).all() and (pts <= box[1::2]).all()
            covered[first : first + count] += 1
    assert (covered == 1).all()
    assert (bvh.leaf[:, 1] <= B.MAX_LEAF).all()


@pytest.mark.parametrize("m", [0, 1, 2000])
def test_each_node_is_one_cache_line_holding_its_children(m):
    bvh = B.build_bvh(_soup(m, 6) if m else np.zeros((0, 3, 3)))
    O, D = np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]])
    for rows in (bvh.cbox, B.toward_light(bvh, O, D, np.full(1, 9.0)).cbox):
        assert rows.dtype == np.float32 and rows.shape == (len(bvh.child), 16)
        assert rows.flags.c_contiguous and rows.ctypes.data % 64 == 0
        link = rows.view(np.int32)
        assert np.array_equal(link[:, 12:14], bvh.child)
        assert B.MAX_LEAF < 1 << B.LEAF_BITS
        for s in range(2):  # a leaf child's first triangle and count, packed
            c = bvh.child[:, s]
            packed = link[:, 14 + s]
            assert not packed[c >= 0].any()
            if m:
                assert np.array_equal(packed[c < 0] >> B.LEAF_BITS, bvh.leaf[~c[c < 0], 0])
                assert np.array_equal(packed[c < 0] & 31, bvh.leaf[~c[c < 0], 1])


def test_too_many_triangles_for_the_node_rows(monkeypatch):
    monkeypatch.setattr(B, "MAX_TRIANGLES", 40)
    with pytest.raises(ValueError, match="40 triangles: a BVH holds fewer than 40"):
        B.build_bvh(_soup(40, 1))


@pytest.mark.parametrize("m", [0, 1, 3, 40])
def test_small_and_degenerate_trees(m):
    tri = np.tile([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]], (m, 1, 1))  # all equal
    bvh = B.build_bvh(tri)
    O = np.array([[0.2, 0.2, -1.0], [0.2, 0.2, 1.0], [2.0, 2.0, 1.0]])
    D = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.0, 0.0, -1.0]])
    tmax = np.full(3, np.inf)
    assert np.array_equal(B.any_hit(bvh, O, D, tmax), brute_any_hit(O, D, tmax, tri))
    t, f, _, _ = B.nearest_hits(bvh, O, D, 0.0)
    assert f.tolist() == ([0, 0, -1] if m else [-1, -1, -1])
    assert t[2] == math.inf


def test_cancelled_stops_between_chunks():
    tri = _soup(500, 7)
    bvh = B.build_bvh(tri)
    n = 12 * B.CHUNK
    rng = np.random.default_rng(8)
    O = rng.uniform(-1, 1, (n, 3))
    D = np.tile([0.0, 0.0, 1.0], (n, 1))
    asked = []

    def cancelled():
        asked.append(1)
        return len(asked) > 3

    with pytest.raises(Cancelled):
        B.any_hit(bvh, O, D, np.full(n, np.inf), cancelled=cancelled)
    assert 3 < len(asked) < 12  # asked once before each chunk, stopped early
    with pytest.raises(Cancelled):  # already cancelled: no work at all
        B.nearest_hits(bvh, O, D, 0.0, cancelled=lambda: True)
    # not cancelled: the same answer as without the callable
    done = B.any_hit(bvh, O, D, np.full(n, np.inf), cancelled=lambda: False)
    assert np.array_equal(done, B.any_hit(bvh, O, D, np.full(n, np.inf)))


def test_casts_run_from_other_threads_at_once():
    mesh = get_mesh("teapot", 6)
    Q, tri = _frame(mesh)
    bvh = B.build_bvh(tri)
    D, tmax = _toward(np.repeat(Q, 8, axis=0), np.array([2.0, 3.0, 1.0]))
    O = np.repeat(Q, 8, axis=0)
    want = B.any_hit(bvh, O, D, tmax)
    out = [None] * 3

    def work(i):
        out[i] = B.any_hit(bvh, O, D, tmax)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(np.array_equal(o, want) for o in out)


def test_building_can_be_stopped():
    tri = _soup(5000, 10)
    with pytest.raises(Cancelled):  # asked before the build starts, then while it runs
        B.build_bvh(tri, cancelled=lambda: True)
    box, link, order, _ = B._build(tri, np.ones(1, np.uint8))  # the flag a waiting caller sets
    assert len(box) == len(link) == len(order) == 0
    assert B.build_bvh(tri, cancelled=lambda: False).n_triangles == 5000


def test_work_on_other_threads_releases_the_gil():
    """The builder and the casts run on the pool's threads while the caller's thread waits for
    them, asking ``cancelled`` and taking Ctrl-C: they must not hold the GIL meanwhile (a
    builder that did made Ctrl-C wait for a whole 2M-triangle build)."""
    from explorer.geometry import occluders as occ

    for kernel in (B._build, B._any_hit_chunk, B._nearest_chunk, occ.refit, occ.refit_top):
        assert kernel.targetoptions.get("nogil"), kernel.__name__
