"""Rays against triangles: the Möller-Trumbore test, and the brute-force shadow cast.

:func:`ray_triangle` is the intersection test (Möller & Trumbore 1997): for a ray ``O + t·D``
and a triangle ``v0, v0 + e1, v0 + e2`` it solves ``O + t·D = v0 + u·e1 + v·e2`` with

    p = D × e2,  det = e1 · p,  s = O - v0,  q = s × e1,
    u = (s · p) / det,  v = (D · q) / det,  t = (e2 · q) / det,

a hit when ``u >= 0``, ``v >= 0`` and ``u + v <= 1``. ``det`` is ``-D · (e1 × e2)``: positive
when the ray meets the triangle's front (counter-clockwise) side.

The casts of the project go through a bounding-volume hierarchy (:mod:`explorer.geometry.bvh`)
whose leaves call this test. :func:`any_hit` here tests every ray against every triangle (cost
rays × triangles): the brute force that the BVH's answers are tested and benchmarked against
(``tests/geometry/test_bvh.py``, ``benchmarks/bench_rays.py``).

The epsilons are in :mod:`explorer.core.tolerances` (``RAY_T_EPS``, ``DET_EPS``,
``PIXEL_RAY_T_MIN``).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from explorer.core.tolerances import DET_EPS, RAY_T_EPS
from explorer.geometry import kernelcache  # noqa: F401 - before the decorators: the cache key


@nb.njit(inline="always")
def ray_triangle(o, d, a, p, q, det_min, front_only):
    """Möller-Trumbore: ray origin ``o``, direction ``d``; triangle corner ``a``, edges ``p``
    (= e1) and ``q`` (= e2), each a tuple (x, y, z) of floats (inlined: the tuples cost
    nothing).

    front_only : True: only ``det >= det_min`` counts (the front side); False: any
        ``det != 0`` (both sides, ``det_min`` unused)
    Returns (t, u, v): the ray parameter and barycentric coordinates of the hit, or
    ``t = inf`` for a miss (no bound ``t < tmax`` accepts it).
    """
    ox, oy, oz = o
    dx, dy, dz = d
    ax, ay, az = a
    px, py, pz = p
    qx, qy, qz = q
    # p = d × e2, det = e1 · p
    pv0 = dy * qz - dz * qy
    pv1 = dz * qx - dx * qz
    pv2 = dx * qy - dy * qx
    det = px * pv0 + py * pv1 + pz * pv2
    if front_only:
        if det < det_min:
            return math.inf, 0.0, 0.0
    elif det == 0.0:
        return math.inf, 0.0, 0.0
    inv = 1.0 / det
    s0 = ox - ax
    s1 = oy - ay
    s2 = oz - az
    u = (s0 * pv0 + s1 * pv1 + s2 * pv2) * inv
    if u < 0.0 or u > 1.0:
        return math.inf, 0.0, 0.0
    # q = s × e1
    w0 = s1 * pz - s2 * py
    w1 = s2 * px - s0 * pz
    w2 = s0 * py - s1 * px
    v = (dx * w0 + dy * w1 + dz * w2) * inv
    if v < 0.0 or u + v > 1.0:
        return math.inf, 0.0, 0.0
    return (qx * w0 + qy * w1 + qz * w2) * inv, u, v


def triangle_edges(triangles) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The triangle layout of the casts: first corners ``v0`` and edges ``e1 = v1 - v0``,
    ``e2 = v2 - v0``.

    triangles : (m, 3, 3) float, corners in counter-clockwise order seen from the front
    Returns three (m, 3) float64 C-contiguous arrays.
    """
    tri = np.asarray(triangles, np.float64)
    v0 = np.ascontiguousarray(tri[:, 0])
    e1 = np.ascontiguousarray(tri[:, 1] - tri[:, 0])
    e2 = np.ascontiguousarray(tri[:, 2] - tri[:, 0])
    return v0, e1, e2


def pack_triangles(triangles) -> np.ndarray:
    """The casts' triangle rows: (m, 9) float64 C-contiguous, ``v0, e1, e2`` of each triangle
    (:func:`triangle_edges`) side by side.

    triangles : (m, 3, 3) float, corners in counter-clockwise order seen from the front
    """
    return np.ascontiguousarray(np.concatenate(triangle_edges(triangles), axis=1))


@nb.njit(inline="always")
def ray_triangle_row(tri, j, o, d, det_min, front_only):
    """:func:`ray_triangle` of the ray ``o``, ``d`` (tuples) against row ``j`` of
    :func:`pack_triangles`' rows ``tri``."""
    a = (tri[j, 0], tri[j, 1], tri[j, 2])
    p = (tri[j, 3], tri[j, 4], tri[j, 5])
    return ray_triangle(o, d, a, p, (tri[j, 6], tri[j, 7], tri[j, 8]), det_min, front_only)


# -- any hit: shadow rays --------------------------------------------------------------------


@nb.njit(parallel=True, cache=True, boundscheck=False)
def _any_hit(O, D, tmax, tri, t_eps, det_eps, out):
    """Every ray against every triangle, front sides only (det >= det_eps), a hit at t in
    (t_eps, tmax - t_eps); each ray stops at its first hit."""
    m = tri.shape[0]
    for r in nb.prange(O.shape[0]):
        o = (O[r, 0], O[r, 1], O[r, 2])
        d = (D[r, 0], D[r, 1], D[r, 2])
        tm = tmax[r] - t_eps
        for j in range(m):
            t, _, _ = ray_triangle_row(tri, j, o, d, det_eps, True)
            if t > t_eps and t < tm:
                out[r] = True
                break


def any_hit(origins, directions, tmax, triangles) -> np.ndarray:
    """Whether each ray meets the front side of a triangle between :data:`RAY_T_EPS` and
    ``tmax - RAY_T_EPS`` (in the triangles' units: the caller normalises the scene).

    origins, directions : (k, 3) float (directions of unit length)
    tmax : (k,) float, the distance to the light (inf: none)
    triangles : (m, 3, 3) float, counter-clockwise seen from the front
    Returns (k,) bool.
    """
    hit = np.zeros(len(origins), np.bool_)
    _any_hit(
        np.ascontiguousarray(origins, np.float64),
        np.ascontiguousarray(directions, np.float64),
        np.ascontiguousarray(tmax, np.float64),
        pack_triangles(triangles),
        RAY_T_EPS,
        DET_EPS,
        hit,
    )
    return hit
