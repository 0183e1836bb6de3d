"""The shadow rays' wide rows hold the binary tree's boxes, and their vector box test enters
exactly the boxes the binary walk's slab test enters."""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest

from explorer.geometry import bvh as B
from explorer.geometry import traverse as T


def _soup(n, seed):
    rng = np.random.default_rng(seed)
    c = rng.uniform(-1, 1, (n, 1, 3))
    return c + rng.normal(scale=0.15, size=(n, 3, 3)) * rng.uniform(0.1, 2, (n, 1, 1))


def _lane_box(rows, w, j):
    """(x0, x1, y0, y1, z0, z1) of lane j of wide row w."""
    return np.array([rows[w, 8 * (a // 2) + 4 * (a % 2) + j] for a in range(6)], np.float32)


def _check_wide(bvh, cbox, wide):
    """Every child box of the binary rows ``cbox`` that a wide row keeps is in its lane, with
    the lane's child; the boxes folded away are exactly the inner children of the wide nodes."""
    n = len(wide)
    assert wide.shape == (n, T.WIDE) and wide.dtype == np.float32
    assert wide.flags.c_contiguous and wide.ctypes.data % 64 == 0
    wlink, link = wide.view(np.int32), cbox.view(np.int32)
    flat = np.arange(wide.size).reshape(wide.shape)
    used = np.zeros((n, 4), bool)
    # the wide nodes are the binary nodes an even number of levels down: walk the binary tree
    level = np.full(len(bvh.child), -1)
    level[0] = 0
    wid = {0: 0}
    for i in range(len(bvh.child)):  # parents before children
        for s in range(2):
            c = bvh.child[i, s]
            if c >= 0:
                level[c] = level[i] + 1
    for i in range(len(bvh.child)):
        for s in range(2):
            c, at = bvh.child[i, s], bvh.slot[i, s]
            if level[i] % 2 == 0 and c >= 0:
                assert at == -1  # folded away: its children are the lanes
                continue
            assert at >= 0
            w, j = divmod(at, T.WIDE)
            assert flat[w, j] == at and j < 4 and not used[w, j]
            used[w, j] = True
            assert np.array_equal(_lane_box(wide, w, j).view(np.int32),
                                  cbox[i, 6 * s : 6 * s + 6].view(np.int32))  # fmt: skip
            if c >= 0:
                w_child = wlink[w, 24 + j]
                assert bvh.wparent[w_child] == w and wlink[w, 28 + j] == 0
                wid[c] = w_child
            else:
                assert wlink[w, 24 + j] == -1 and wlink[w, 28 + j] == link[i, 14 + s]
    assert sorted(wid.values()) == list(range(n))  # every wide node is a binary node's
    assert bvh.wparent[0] == -1
    for w, j in zip(*np.nonzero(~used), strict=True):  # a lane nothing became: never entered
        box = _lane_box(wide, w, j)
        assert (box[0::2] > box[1::2]).all() and wlink[w, 24 + j] == -1


@pytest.mark.parametrize("m", [0, 1, 3, 2000])
def test_wide_rows_hold_the_binary_boxes_built_and_refitted(m):
    tri = _soup(m, 6) if m else np.zeros((0, 3, 3))
    bvh = B.build_bvh(tri)
    _check_wide(bvh, bvh.cbox, bvh.wide)
    O = np.random.default_rng(1).uniform(-1, 1, (50, 3))
    L = np.array([0.3, 2.0, 0.5])
    D = L - O
    tmax = np.linalg.norm(D, axis=1)
    lit = B.toward_light(bvh, O, D / tmax[:, None], tmax)
    _check_wide(lit, lit.cbox, lit.wide)
    if m == 2000:  # the refit changed boxes, and the wide rows followed
        assert not np.array_equal(lit.wide, bvh.wide)


@nb.njit(cache=True)
def _enter_both(wide, w, O, D, t1, out):
    """out[r, j]: enter4's bit j, and the binary slab test of the same box (1: entered)."""
    for r in range(O.shape[0]):
        ox, oy, oz, _, _, _, ix, iy, iz = T.ray_of(O, D, r)
        bits = T.enter4(wide, w, ox, oy, oz, ix, iy, iz, t1[r])
        for j in range(4):
            out[r, 0, j] = (bits >> j) & 1
    return out


def _slab(box, o, d, t1):
    """The binary walk's test (traverse.slab) in Python float64, for one box."""
    inv = [1.0 / x if x != 0.0 else math.copysign(T.BIG, x) for x in d]
    t0, tf = None, None
    for a in range(3):
        p = (float(box[2 * a]) - o[a]) * inv[a]
        q = (float(box[2 * a + 1]) - o[a]) * inv[a]
        lo, hi = (q if q < p else p), (q if q > p else p)
        t0 = lo if t0 is None else (lo if lo > t0 else t0)
        tf = hi if tf is None else (hi if hi < tf else tf)
    t0 = 0.0 if 0.0 > t0 else t0
    tf = t1 if t1 < tf else tf
    return t0 <= tf


def test_the_vector_box_test_enters_what_the_slab_test_enters():
    rng = np.random.default_rng(3)
    wide = B.aligned_rows(3, T.WIDE)
    lo = rng.uniform(-1, 1, (3, 4, 3)).astype(np.float32)
    hi = lo + rng.uniform(0, 0.6, (3, 4, 3)).astype(np.float32)
    hi[0, 1] = lo[0, 1]  # a flat box
    lo[0, 2], hi[0, 2] = 1.0, -1.0  # an empty one
    lo[1, 0] = hi[1, 0] = np.inf  # one left out by a refit
    lo[2, 3], hi[2, 3] = -np.inf, np.inf  # everything
    for w in range(3):
        for j in range(4):
            for a in range(3):
                wide[w, 8 * a + j], wide[w, 8 * a + 4 + j] = lo[w, j, a], hi[w, j, a]
    k = 4000
    O = rng.uniform(-1.5, 1.5, (k, 3))
    D = rng.normal(size=(k, 3))
    D[::7, rng.integers(0, 3)] = 0.0  # rays parallel to a box's faces
    D[::11, :2] = 0.0
    D /= np.linalg.norm(D, axis=1)[:, None]
    O[::13] = lo[0, 0] + (hi[0, 0] - lo[0, 0]) * 0.5  # origins inside, on a face's plane
    O[::17, 0] = lo[0, 0, 0]
    t1 = rng.choice([0.05, 0.7, 3.0, np.inf], k)
    entered = 0
    for w in range(3):
        out = _enter_both(wide, w, O, D, t1, np.zeros((k, 1, 4), np.int64))
        for r in range(k):
            for j in range(4):
                box = np.ravel(np.column_stack([lo[w, j], hi[w, j]]))
                want = _slab(box, O[r], D[r], t1[r])
                assert out[r, 0, j] == want, (w, j, r)
                entered += want
    assert 0.1 * 12 * k < entered < 0.9 * 12 * k  # both answers are common


def test_the_refit_on_every_thread_fills_the_lanes(monkeypatch):
    bvh = B.build_bvh(_soup(3000, 2))
    O = np.random.default_rng(1).uniform(-1, 1, (50, 3))
    D = np.array([0.3, 2.0, 0.5]) - O
    tmax = np.linalg.norm(D, axis=1)
    monkeypatch.setattr(B, "REFIT_NODES", 0)
    monkeypatch.setattr(B, "workers", lambda: 2)
    lit = B.toward_light(bvh, O, D / tmax[:, None], tmax)
    _check_wide(lit, lit.cbox, lit.wide)
    assert not np.array_equal(lit.wide, bvh.wide)
