"""The ray-triangle test and the brute-force shadow cast."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from explorer.core.tolerances import RAY_T_EPS
from explorer.geometry.rays import any_hit, ray_triangle, triangle_edges

#: the triangle (0,0,1), (1,0,1), (0,1,1): its front (counter-clockwise) side faces +z
TRI = np.array([[[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]]])


@njit
def _test(o, d, tri, det_min, front_only):
    a, p, q = tri[0], tri[1] - tri[0], tri[2] - tri[0]
    return ray_triangle(
        (o[0], o[1], o[2]), (d[0], d[1], d[2]),
        (a[0], a[1], a[2]), (p[0], p[1], p[2]), (q[0], q[1], q[2]),
        det_min, front_only,
    )  # fmt: skip


def test_ray_triangle_hit_and_barycentrics():
    o = np.array([0.25, 0.5, 3.0])
    t, u, v = _test(o, np.array([0.0, 0.0, -1.0]), TRI[0], 0.0, True)
    assert (t, u, v) == (2.0, 0.25, 0.5)
    # from behind: a back side, seen by the two-sided test only
    o = np.array([0.25, 0.5, -1.0])
    assert _test(o, np.array([0.0, 0.0, 1.0]), TRI[0], 0.0, True)[0] == math.inf
    assert _test(o, np.array([0.0, 0.0, 1.0]), TRI[0], 0.0, False)[:1] == (2.0,)
    # outside the triangle, and parallel to it: misses
    assert (
        _test(np.array([0.8, 0.8, 3.0]), np.array([0.0, 0.0, -1.0]), TRI[0], 0.0, False)[0]
        == math.inf
    )
    assert (
        _test(np.array([0.2, 0.2, 1.0]), np.array([1.0, 0.0, 0.0]), TRI[0], 0.0, False)[0]
        == math.inf
    )


def test_triangle_edges():
    v0, e1, e2 = triangle_edges(TRI)
    assert v0.tolist() == [[0, 0, 1]] and e1.tolist() == [[1, 0, 0]] and e2.tolist() == [[0, 1, 0]]
    assert all(a.flags.c_contiguous and a.dtype == np.float64 for a in (v0, e1, e2))


def test_any_hit_front_sides_before_tmax():
    o = np.array([[0.25, 0.25, 0.0], [0.25, 0.25, 2.0], [0.25, 0.25, 0.0], [2.0, 2.0, 0.0]])
    d = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    tmax = np.array([np.inf, np.inf, 1.0 - 0.5 * RAY_T_EPS, np.inf])
    # ray 0 meets the back side; ray 1 the front; ray 2 stops at the triangle; ray 3 misses
    assert any_hit(o, -d, tmax, TRI).tolist() == [False, False, False, False]
    assert any_hit(o[[1]], d[[1]], tmax[[1]], TRI).tolist() == [True]
    flipped = TRI[:, ::-1]  # front side toward -z
    assert any_hit(o, d, tmax, flipped).tolist() == [True, False, False, False]
