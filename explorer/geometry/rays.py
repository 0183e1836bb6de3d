"""Rays against triangles: one Möller-Trumbore test and the two casts built on it.

:func:`ray_triangle` is the intersection test (Möller & Trumbore 1997): for a ray ``O + t·D``
and a triangle ``v0, v0 + e1, v0 + e2`` it solves ``O + t·D = v0 + u·e1 + v·e2`` with

    p = D × e2,  det = e1 · p,  s = O - v0,  q = s × e1,
    u = (s · p) / det,  v = (D · q) / det,  t = (e2 · q) / det,

a hit when ``u >= 0``, ``v >= 0`` and ``u + v <= 1``. ``det`` is ``-D · (e1 × e2)``: positive
when the ray meets the triangle's front (counter-clockwise) side.

Two casts call it (compiled with numba, the test inlined into their loops):

- :func:`nearest_hits`: the nearest hit of each pixel's ray, front or back side (the per-pixel
  reference, :mod:`explorer.render.perpixel`); each triangle is tested against the rays of the
  pixels its projection covers.
- :func:`any_hit`: whether each ray meets a triangle's front side before a distance (shadow
  rays, :mod:`explorer.shading.shadows`).

The epsilons are in :mod:`explorer.core.tolerances` (``RAY_T_EPS``, ``DET_EPS``,
``PIXEL_RAY_T_MIN``).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from explorer.core.tolerances import DET_EPS, RAY_T_EPS


@nb.njit(inline="always")
def ray_triangle(ox, oy, oz, dx, dy, dz, ax, ay, az, px, py, pz, qx, qy, qz, det_min, front_only):
    """Möller-Trumbore: ray origin ``o``, direction ``d``; triangle corner ``a``, edges ``p``
    (= e1) and ``q`` (= e2), all as scalars.

    front_only : True: only ``det >= det_min`` counts (the front side); False: any
        ``det != 0`` (both sides, ``det_min`` unused)
    Returns (t, u, v): the ray parameter and barycentric coordinates of the hit, or
    ``t = inf`` for a miss (no bound ``t < tmax`` accepts it).
    """
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
    """The casts' triangle layout: first corners ``v0`` and edges ``e1 = v1 - v0``,
    ``e2 = v2 - v0``.

    triangles : (m, 3, 3) float, corners in counter-clockwise order seen from the front
    Returns three (m, 3) float64 C-contiguous arrays.
    """
    tri = np.asarray(triangles, np.float64)
    v0 = np.ascontiguousarray(tri[:, 0])
    e1 = np.ascontiguousarray(tri[:, 1] - tri[:, 0])
    e2 = np.ascontiguousarray(tri[:, 2] - tri[:, 0])
    return v0, e1, e2


# -- nearest hit: the per-pixel reference ----------------------------------------------------


@nb.njit(cache=True, nogil=True)
def nearest_hits(v0, e1, e2, box, orig, dirs, t_min, best_t, best_tri, best_u, best_v):
    """The nearest hit, front or back side, of the rays of a picture.

    v0, e1, e2 : (m, 3) float64 (:func:`triangle_edges`)
    box : (m, 4) int64 inclusive pixel ranges (col0, col1, row0, row1) whose rays are tested
        against each triangle (empty when col0 > col1 or row0 > row1)
    orig, dirs : (h, w, 3) float64 ray origins and directions
    t_min : hits at ``t <= t_min`` are ignored
    best_t : (h, w) float64, in: the farthest ``t`` accepted (inf: any), out: the hit's ``t``
    best_tri, best_u, best_v : (h, w) out: the hit triangle (unchanged where none is nearer
        than ``best_t``) and the barycentric coordinates there
    """
    m = v0.shape[0]
    for f in range(m):
        c0, c1, r0, r1 = box[f, 0], box[f, 1], box[f, 2], box[f, 3]
        a0, a1, a2 = v0[f, 0], v0[f, 1], v0[f, 2]
        p0, p1, p2 = e1[f, 0], e1[f, 1], e1[f, 2]
        q0, q1, q2 = e2[f, 0], e2[f, 1], e2[f, 2]
        for r in range(r0, r1 + 1):
            for c in range(c0, c1 + 1):
                t, u, v = ray_triangle(
                    orig[r, c, 0], orig[r, c, 1], orig[r, c, 2],
                    dirs[r, c, 0], dirs[r, c, 1], dirs[r, c, 2],
                    a0, a1, a2, p0, p1, p2, q0, q1, q2, 0.0, False,
                )  # fmt: skip
                if t > t_min and t < best_t[r, c]:
                    best_t[r, c] = t
                    best_tri[r, c] = f
                    best_u[r, c] = u
                    best_v[r, c] = v


# -- any hit: shadow rays --------------------------------------------------------------------


@nb.njit(parallel=True, cache=True, boundscheck=False)
def _any_hit(O, D, tmax, v0, e1, e2, t_eps, det_eps, out):
    """Every ray against every triangle, front sides only (det >= det_eps), a hit at t in
    (t_eps, tmax - t_eps); each ray stops at its first hit."""
    m = v0.shape[0]
    for r in nb.prange(O.shape[0]):
        ox, oy, oz = O[r, 0], O[r, 1], O[r, 2]
        dx, dy, dz = D[r, 0], D[r, 1], D[r, 2]
        tm = tmax[r] - t_eps
        for j in range(m):
            t, _, _ = ray_triangle(
                ox, oy, oz, dx, dy, dz,
                v0[j, 0], v0[j, 1], v0[j, 2],
                e1[j, 0], e1[j, 1], e1[j, 2],
                e2[j, 0], e2[j, 1], e2[j, 2],
                det_eps, True,
            )  # fmt: skip
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
    v0, e1, e2 = triangle_edges(triangles)
    _any_hit(
        np.ascontiguousarray(origins, np.float64),
        np.ascontiguousarray(directions, np.float64),
        np.ascontiguousarray(tmax, np.float64),
        v0,
        e1,
        e2,
        RAY_T_EPS,
        DET_EPS,
        hit,
    )
    return hit
