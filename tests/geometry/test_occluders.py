"""Shadow rays toward one light through boxes refitted around the triangles that can block them
answer exactly what testing every triangle answers, lights grazing or touching the surface
included."""

from __future__ import annotations

import numpy as np
import pytest

from explorer.core.tolerances import OCCLUDER_MARGIN
from explorer.geometry import bvh as B
from explorer.geometry import occluders as occ
from explorer.geometry.frame import frame_of
from explorer.geometry.meshes import cube, get_mesh, plane, sphere
from explorer.geometry.rays import any_hit as brute_any_hit


def _frame(mesh):
    centre, scale = frame_of(mesh.positions)
    Q = (mesh.positions - centre) / scale
    return np.ascontiguousarray(Q), Q[mesh.faces]


def _toward(O, light):
    D = light - O
    tmax = np.linalg.norm(D, axis=1)
    return np.ascontiguousarray(D / np.where(tmax > 0, tmax, 1.0)[:, None]), tmax


def _refitted(bvh, O, D, tmax):
    """The refitted tree, and the share of leaves no ray can reach (left out under an empty
    box, theirs or an ancestor's)."""
    tree = B.toward_light(bvh, O, D, tmax)
    assert tree is not bvh, "the rays share an end: the boxes are refitted"
    reached, todo = 0, [0]
    while todo:
        i = todo.pop()
        for s in range(2):
            if _empty(tree.cbox[i, 6 * s : 6 * s + 6]):
                continue
            c = tree.child[i, s]
            if c < 0:
                reached += 1
            else:
                todo.append(c)
    return tree, 1.0 - reached / len(tree.leaf)


def _check(tree, O, D, tmax, tri):
    expected = brute_any_hit(O, D, tmax, tri)
    assert np.array_equal(B.any_hit(tree, O, D, tmax), expected)
    return expected


@pytest.mark.parametrize("name", ["teapot 8", "torus 32", "sphere 24"])
def test_point_lights_drop_leaves_and_answer_as_the_brute_force(name):
    kind, res = name.split()
    mesh = sphere(int(res)) if kind == "sphere" else get_mesh(kind, int(res))
    Q, tri = _frame(mesh)
    bvh = B.build_bvh(tri)
    rng = np.random.default_rng(4)
    for light in [np.array([2.0, 3.0, 1.5]), np.array([0.0, 0.2, 0.0]), *rng.normal(size=(4, 3))]:
        D, tmax = _toward(Q, light)
        tree, empty = _refitted(bvh, Q, D, tmax)
        _check(tree, Q, D, tmax, tri)
        if kind == "sphere" and np.linalg.norm(light) > 1.5:
            assert empty > 0.1  # whole leaves facing the light are out of the casts


@pytest.mark.parametrize("make", [cube, lambda: plane(6), lambda: get_mesh("teapot", 6)])
def test_directional_lights_and_grazing_directions(make):
    Q, tri = _frame(make())
    bvh = B.build_bvh(tri)
    for d in ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.3, 0.8, -0.52]):
        D = np.tile(np.asarray(d) / np.linalg.norm(d), (len(Q), 1))
        tmax = np.full(len(Q), np.inf)
        assert occ.shared_end(Q, D, tmax)[0] == 1
        tree, _ = _refitted(bvh, Q, D, tmax)
        _check(tree, Q, D, tmax, tri)


def test_lights_on_near_and_in_the_plane_of_a_sheet():
    """A sheet facing +z; lights in its plane, just above or below it, at a corner; origins
    above, below and on it, far and near: the cases the margin's argument splits into."""
    mesh = plane(8)
    Q, tri = _frame(mesh)
    bvh = B.build_bvh(tri)
    rng = np.random.default_rng(5)
    xy = rng.uniform(-1.2, 1.2, (3000, 2))
    z = np.concatenate([rng.choice([-1, 1], 1000) * 10.0 ** rng.uniform(-14, 0, 1000),
                        np.zeros(1000), rng.uniform(-2, 2, 1000)])  # fmt: skip
    O = np.ascontiguousarray(np.column_stack([xy, z]))
    O = np.vstack([O, Q])
    hits = 0
    for lz in (0.0, 1e-15, 1e-9, 1e-7, 1e-5, 1e-3, 0.3, -1e-9, -0.2):
        for light in ([0.2, -0.1, lz], [Q[0, 0], Q[0, 1], lz], [3.0, 0.0, lz]):
            D, tmax = _toward(O, np.asarray(light))
            ok = tmax > 0
            o, d, t = O[ok], np.ascontiguousarray(D[ok]), tmax[ok]
            tree, _ = _refitted(bvh, o, d, t)
            hits += _check(tree, o, d, t, tri).sum()
    assert hits > 1000  # rays from below the sheet toward a light above it are blocked


def test_a_triangle_soup_with_lights_among_the_triangles():
    rng = np.random.default_rng(6)
    c = rng.uniform(-1, 1, (2000, 1, 3))
    tri = c + rng.normal(scale=0.1, size=(2000, 3, 3))
    bvh = B.build_bvh(tri)
    O = np.ascontiguousarray(np.vstack([tri[:, 0], tri[:, 1] * 0.5 + tri[:, 2] * 0.5]))
    for light in [tri[7, 0], tri[7].mean(axis=0) + 1e-9, *rng.uniform(-1, 1, (3, 3))]:
        D, tmax = _toward(O, light)
        ok = tmax > 0
        o, d, t = O[ok], np.ascontiguousarray(D[ok]), tmax[ok]
        tree, empty = _refitted(bvh, o, d, t)
        hit = _check(tree, o, d, t, tri)
        assert 0.05 < hit.mean() < 0.95


def test_shared_end_finds_the_light_or_nothing():
    rng = np.random.default_rng(7)
    O = rng.normal(size=(50, 3))
    light = np.array([1.0, 2.0, 3.0])
    D, tmax = _toward(O, light)
    kind, L, eps, r = occ.shared_end(O, D, tmax)
    assert kind == 0 and np.allclose(L, light) and 0 < eps < 1e-12
    assert r == pytest.approx(np.linalg.norm(O, axis=1).max())
    D2, t2 = _toward(O, light + np.array([0.0, 0.0, 1e-6]) * (np.arange(50) % 2)[:, None])
    assert occ.shared_end(O, D2, t2) is None  # two lights
    assert occ.shared_end(O, D, np.full(50, np.inf)) is None  # no end and no one direction
    assert occ.shared_end(O[:0], D[:0], tmax[:0]) is None


def test_slivers_and_degenerate_triangles_are_never_dropped():
    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]],
                    [[0, 0, 0], [1, 0, 0], [2, OCCLUDER_MARGIN / 4, 0]],
                    [[0, 0, 0], [1, 1, 1], [2, 2, 2]]], float)  # fmt: skip
    tri[:, :, 2] += 0.5
    n = occ.planes(B.pack_triangles(tri))
    assert np.allclose(n[0], [0, 0, 1, 0.5]) and not n[1:].any()


def test_few_rays_keep_the_full_tree(monkeypatch):
    mesh = sphere(16)
    Q, tri = _frame(mesh)
    bvh = B.build_bvh(tri)
    seen = []
    real = B.toward_light
    monkeypatch.setattr(B, "toward_light", lambda *a, **k: seen.append(1) or real(*a, **k))
    D, tmax = _toward(Q[:3], np.array([2.0, 0, 0]))
    B.any_hit(bvh, Q[:3], D, tmax)
    assert not seen  # 3 rays: refitting would cost more than it saves
    D, tmax = _toward(Q, np.array([2.0, 0, 0]))
    B.any_hit(bvh, Q, D, tmax)
    assert seen


def _empty(box) -> bool:
    return box[0] == np.inf or box[0] > box[1]


def _reference_boxes(bvh, light):
    """The child boxes of ``bvh`` refitted triangle by triangle (numpy): every triangle whose
    height under the light is at most the threshold, nothing else."""
    kind, L, eps, R = light
    low = occ._threshold((np.int64(kind), L, eps, R))
    h = bvh.plane[:, :3] @ L - (bvh.plane[:, 3] if kind == 0 else 0.0)
    keep = ~(h > low)
    empty = np.array([1, -1] * 3, np.float32) * np.inf
    leaf_box = np.tile(empty, (len(bvh.leaf), 1))
    for q, (first, count) in enumerate(bvh.leaf):
        rows = bvh.tbox[first : first + count][keep[first : first + count]]
        if len(rows):
            leaf_box[q, 0::2], leaf_box[q, 1::2] = rows[:, 0::2].min(0), rows[:, 1::2].max(0)
    node_box = np.tile(empty, (len(bvh.child), 1))
    cbox = np.full((len(bvh.child), 12), np.inf, np.float32)
    for i in range(len(bvh.child) - 1, -1, -1):
        for s, c in enumerate(bvh.child[i]):
            box = leaf_box[~c] if c < 0 else node_box[c]
            if box[0] <= box[1]:
                cbox[i, 6 * s : 6 * s + 6] = box
                node_box[i, 0::2] = np.minimum(node_box[i, 0::2], box[0::2])
                node_box[i, 1::2] = np.maximum(node_box[i, 1::2], box[1::2])
    return cbox


@pytest.mark.parametrize("name", ["teapot 8", "torus 32", "sphere 24", "cube"])
def test_the_refit_by_normal_cones_equals_the_refit_triangle_by_triangle(name):
    """Wherever a ray can get (every box under the root that is not empty), the boxes the cones
    give are those of boxing every triangle that does not face the light (up to float32
    rounding): no triangle that can block is left out, and none that cannot is kept."""
    kind, *res = name.split()
    mesh = {"sphere": sphere, "cube": cube}.get(kind, lambda r: get_mesh(kind, r))(*map(int, res))
    Q, tri = _frame(mesh)
    bvh = B.build_bvh(tri)
    rng = np.random.default_rng(9)
    for light in [np.array([2.0, 3.0, 1.5]), np.array([0.0, 0.1, 0.0]), *rng.normal(size=(3, 3))]:
        D, tmax = _toward(Q, light)
        tree = B.toward_light(bvh, Q, D, tmax)
        kind_, L, eps, reach = occ.shared_end(Q, D, tmax)
        corner = np.abs(bvh.cbox[0, :12]).astype(np.float64).reshape(2, 3, 2).max(axis=(0, 2))
        R = max(float(np.sqrt(corner @ corner)), reach)
        want = _reference_boxes(bvh, (kind_, L, eps, R))
        todo, seen = [0], 0
        while todo:
            i = todo.pop()
            for s in range(2):
                box, ref = tree.cbox[i, 6 * s : 6 * s + 6], want[i, 6 * s : 6 * s + 6]
                if _empty(box):
                    assert _empty(ref), (name, light, i, s)
                    continue
                # a box kept as built may differ from its triangles' boxes in rounding only
                assert np.allclose(box, ref, rtol=1e-6, atol=1e-8), (name, light, i, s)
                seen += 1
                if tree.child[i, s] >= 0:
                    todo.append(tree.child[i, s])
        assert seen > 1


def test_normal_cones_hold_every_normal_under_them():
    mesh = get_mesh("teapot", 8)
    _, tri = _frame(mesh)
    bvh = B.build_bvh(tri)

    def under(c):
        if c < 0:
            f, n = bvh.leaf[~c]
            return np.arange(f, f + n)
        return np.concatenate([under(g) for g in bvh.child[c]])

    bounded = 0
    for i in range(len(bvh.child)):
        for s in range(2):
            axis, cos = bvh.cone[i, 5 * s : 5 * s + 3], bvh.cone[i, 5 * s + 3]
            n = bvh.plane[under(bvh.child[i, s]), :3]
            if cos > -1:
                bounded += 1
                a = axis.astype(np.float64)
                assert np.all(n @ a >= cos - 3e-7), (i, s)
                if cos > 0:  # within a half-angle below 90°: the sine bounds the angle too
                    sines = np.linalg.norm(np.cross(n, a), axis=1)
                    assert np.all(sines <= bvh.cone[i, 5 * s + 4] + 3e-7), (i, s)
    assert bounded > len(bvh.child)  # most children have a cone


def test_the_refit_on_every_thread_equals_the_refit_on_one(monkeypatch):
    Q, tri = _frame(get_mesh("teapot", 12))
    bvh = B.build_bvh(tri)
    D, tmax = _toward(Q, np.array([2.0, 3.0, 1.5]))
    monkeypatch.setattr(B, "REFIT_NODES", 1 << 60)
    one = B.toward_light(bvh, Q, D, tmax)
    monkeypatch.setattr(B, "REFIT_NODES", 0)
    monkeypatch.setattr(B, "workers", lambda: 2)
    split = B.toward_light(bvh, Q, D, tmax)
    assert np.array_equal(one.cbox.view(np.int32), split.cbox.view(np.int32))
    assert not np.array_equal(one.cbox, bvh.cbox)
    assert np.array_equal(one.wide.view(np.int32), split.wide.view(np.int32))  # the lanes too
    assert not np.array_equal(one.wide, bvh.wide)
