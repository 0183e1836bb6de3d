"""The nearest hit by testing every ray against every triangle: what the BVH must answer."""

from __future__ import annotations

import numpy as np
from numba import njit

from explorer.geometry.rays import pack_triangles, ray_triangle_row


@njit(cache=True)
def _nearest(O, D, tri, t_min):
    k = O.shape[0]
    bt = np.full(k, np.inf)
    bf = np.full(k, -1, np.int64)
    bu = np.zeros(k)
    bv = np.zeros(k)
    for r in range(k):
        for f in range(tri.shape[0]):
            o, d = (O[r, 0], O[r, 1], O[r, 2]), (D[r, 0], D[r, 1], D[r, 2])
            t, u, v = ray_triangle_row(tri, f, o, d, 0.0, False)
            if t > t_min and t < bt[r]:
                bt[r], bf[r], bu[r], bv[r] = t, f, u, v
    return bt, bf, bu, bv


def brute_nearest(origins, directions, triangles, t_min: float):
    """Every ray against every triangle in index order, front or back side, at ``t > t_min``;
    the first of equal nearest hits. Returns (t, triangle, u, v) as the BVH's
    :func:`explorer.geometry.bvh.nearest_hits` does."""
    O = np.ascontiguousarray(origins, np.float64).reshape(-1, 3)
    D = np.ascontiguousarray(directions, np.float64).reshape(-1, 3)
    return _nearest(O, D, pack_triangles(triangles), float(t_min))
