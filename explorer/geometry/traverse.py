"""The compiled pieces every BVH cast is made of: a ray's reciprocals, the slab test of a node's
two child boxes, the next node of a depth-first walk, the front-side test of a leaf, and the
walk of one shadow ray (:func:`any_one`). :mod:`explorer.geometry.bvh` and
:mod:`explorer.geometry.packets` build their casts from them.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from explorer.geometry.rays import ray_triangle_row

#: the traversal stack; the BVH builder's depth limit plus 64 levels holds any mesh that fits
#: in memory
STACK = 128
#: stands for 1/0 in the slab test (finite, so no 0·inf = NaN)
BIG = 1e300


@nb.njit(cache=True, inline="always")
def inv(d):
    return 1.0 / d if d != 0.0 else math.copysign(BIG, d)


@nb.njit(cache=True, inline="always")
def enter(b, ox, oy, oz, ix, iy, iz, t1):
    """Where the ray enters each of a node's two child boxes ``b`` (12,) (:func:`slab`)."""
    return slab(b, 0, ox, oy, oz, ix, iy, iz, t1), slab(b, 6, ox, oy, oz, ix, iy, iz, t1)


@nb.njit(cache=True, inline="always")
def ray_of(O, D, r):
    """Ray ``r``: origin, direction and the direction's reciprocals (:func:`inv`)."""
    dx, dy, dz = D[r, 0], D[r, 1], D[r, 2]
    return O[r, 0], O[r, 1], O[r, 2], dx, dy, dz, inv(dx), inv(dy), inv(dz)


@nb.njit(cache=True, inline="always")
def slab(b, o, ox, oy, oz, ix, iy, iz, t1):
    """Where the ray enters the box ``b[o:o + 6]`` within [0, t1], or inf when it does not."""
    p = (b[o] - ox) * ix
    q = (b[o + 1] - ox) * ix
    t0 = min(p, q)
    tf = max(p, q)
    p = (b[o + 2] - oy) * iy
    q = (b[o + 3] - oy) * iy
    t0 = max(t0, min(p, q))
    tf = min(tf, max(p, q))
    p = (b[o + 4] - oz) * iz
    q = (b[o + 5] - oz) * iz
    t0 = max(t0, min(p, q), 0.0)
    tf = min(tf, max(p, q), t1)
    return t0 if t0 <= tf else math.inf


@nb.njit(cache=True, inline="always")
def next_node(stack, sp, ca, cb, ta, tb):
    """The next inner node: the nearer of the children the ray enters (``t < inf``; the other
    one is pushed), else the top of the stack; (-1, 0) when nothing is left."""
    if ta < math.inf and tb < math.inf:
        if ta <= tb:
            stack[sp] = cb
            return ca, sp + 1
        stack[sp] = ca
        return cb, sp + 1
    if ta < math.inf:
        return ca, sp
    if tb < math.inf:
        return cb, sp
    if sp == 0:
        return np.int64(-1), 0
    return stack[sp - 1], sp - 1


@nb.njit(cache=True, inline="always")
def leaf_any(leaf, q, tri, ray, t_eps, tm, det_eps):
    """Whether the ray ``(ox, oy, oz, dx, dy, dz)`` meets a front side in leaf ``q``."""
    ox, oy, oz, dx, dy, dz = ray
    first = leaf[q, 0]
    for j in range(first, first + leaf[q, 1]):
        t, _, _ = ray_triangle_row(tri, j, ox, oy, oz, dx, dy, dz, det_eps, True)
        if t > t_eps and t < tm:
            return True
    return False


@nb.njit(cache=True, inline="always")
def any_one(O, D, tmax, r, tree, eps, stack, last):
    """Whether ray ``r`` of (O, D, tmax) meets a front side in tree = (child, cbox, leaf, tri)
    with eps = (t_eps, det_eps), trying leaf ``last`` first (-1: none); returns (hit, the leaf
    that blocked it or ``last``)."""
    child, cbox, leaf, tri = tree
    t_eps, det_eps = eps
    ox, oy, oz, dx, dy, dz, ix, iy, iz = ray_of(O, D, r)
    ray = (ox, oy, oz, dx, dy, dz)
    tm = tmax[r] - t_eps
    if last >= 0 and leaf_any(leaf, last, tri, ray, t_eps, tm, det_eps):
        return True, last
    sp = 0
    node = 0
    while True:
        ta, tb = enter(cbox[node], ox, oy, oz, ix, iy, iz, tm)
        ca, cb = child[node, 0], child[node, 1]
        if ta < math.inf and ca < 0:
            if leaf_any(leaf, ~ca, tri, ray, t_eps, tm, det_eps):
                return True, ~ca
            ta = math.inf
        if tb < math.inf and cb < 0:
            if leaf_any(leaf, ~cb, tri, ray, t_eps, tm, det_eps):
                return True, ~cb
            tb = math.inf
        node, sp = next_node(stack, sp, ca, cb, ta, tb)
        if node < 0:
            return False, last
