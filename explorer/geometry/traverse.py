"""The compiled pieces every BVH cast is made of: a ray's reciprocals, the slab test of a node's
two child boxes, the next node of a depth-first walk, the front-side test of a leaf, and the
walk of one shadow ray (:func:`any_one`). :mod:`explorer.geometry.bvh` builds its casts from them.
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
#: a node row packs a leaf child's first triangle and count as ``first << LEAF_BITS | count``
LEAF_BITS = 5
#: a shadow ray first walks the subtree this many levels above the leaf that blocked the last
#: blocked ray (:func:`any_one`)
UP = 4


@nb.njit(cache=True, inline="always")
def inv(d):
    return 1.0 / d if d != 0.0 else math.copysign(BIG, d)


@nb.njit(cache=True, inline="always")
def enter(cbox, node, ox, oy, oz, ix, iy, iz, t1):
    """Where the ray enters each of node ``node``'s two child boxes ``cbox[node]``
    (:func:`slab`). (Indexing ``cbox`` here rather than taking its row keeps numba from
    counting references to a row view at every node.)"""
    return (slab(cbox, node, 0, ox, oy, oz, ix, iy, iz, t1),
            slab(cbox, node, 6, ox, oy, oz, ix, iy, iz, t1))  # fmt: skip


@nb.njit(cache=True, inline="always")
def ray_of(O, D, r):
    """Ray ``r``: origin, direction and the direction's reciprocals (:func:`inv`)."""
    dx, dy, dz = D[r, 0], D[r, 1], D[r, 2]
    return O[r, 0], O[r, 1], O[r, 2], dx, dy, dz, inv(dx), inv(dy), inv(dz)


@nb.njit(cache=True, inline="always")
def slab(cbox, node, o, ox, oy, oz, ix, iy, iz, t1):
    """Where the ray enters the box ``cbox[node, o:o + 6]`` within [0, t1], or inf when it
    does not."""
    p = (cbox[node, o] - ox) * ix
    q = (cbox[node, o + 1] - ox) * ix
    t0 = min(p, q)
    tf = max(p, q)
    p = (cbox[node, o + 2] - oy) * iy
    q = (cbox[node, o + 3] - oy) * iy
    t0 = max(t0, min(p, q))
    tf = min(tf, max(p, q))
    p = (cbox[node, o + 4] - oz) * iz
    q = (cbox[node, o + 5] - oz) * iz
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
def leaf_any(packed, tri, ray, t_eps, tm, det_eps):
    """Whether the ray ``(ox, oy, oz, dx, dy, dz)`` meets a front side in the leaf whose first
    triangle and count are ``packed`` (:data:`LEAF_BITS`, as the node rows hold them)."""
    ox, oy, oz, dx, dy, dz = ray
    first = np.int64(packed) >> LEAF_BITS
    for j in range(first, first + (np.int64(packed) & ((1 << LEAF_BITS) - 1))):
        t, _, _ = ray_triangle_row(tri, j, ox, oy, oz, dx, dy, dz, det_eps, True)
        if t > t_eps and t < tm:
            return True
    return False


@nb.njit(cache=True, inline="always")
def walk(start, ray, inv, tm, tree, eps, stack):
    """Walk the subtree under inner node ``start`` of tree = (link, cbox, leaf, tri) (``link``
    the int32 view of the node rows ``cbox``: columns 12, 13 the children, 14, 15 their
    leaves' triangles) with a shadow ray (ray = (ox, oy, oz, dx, dy, dz), inv its direction's
    reciprocals, ``tm`` its end), eps = (t_eps, det_eps); returns the node whose leaf holds a
    front side the ray meets, or -1."""
    link, cbox, _, tri = tree
    t_eps, det_eps = eps
    ox, oy, oz = ray[0], ray[1], ray[2]
    ix, iy, iz = inv
    sp = 0
    node = start
    while True:
        ta, tb = enter(cbox, node, ox, oy, oz, ix, iy, iz, tm)
        ca, cb = np.int64(link[node, 12]), np.int64(link[node, 13])
        if ta < math.inf and ca < 0:
            if leaf_any(link[node, 14], tri, ray, t_eps, tm, det_eps):
                return node
            ta = math.inf
        if tb < math.inf and cb < 0:
            if leaf_any(link[node, 15], tri, ray, t_eps, tm, det_eps):
                return node
            tb = math.inf
        node, sp = next_node(stack, sp, ca, cb, ta, tb)
        if node < 0:
            return np.int64(-1)


@nb.njit(cache=True, inline="always")
def any_one(O, D, tmax, r, tree, parent, eps, stack, near):
    """Whether ray ``r`` of (O, D, tmax) meets a front side in tree = (link, cbox, leaf, tri)
    (``parent`` (k,) each inner node's parent, -1 for the root) with eps = (t_eps, det_eps).

    The subtree under ``near`` (-1: none) is walked first: pass what the previous call
    returned, :data:`UP` levels above the leaf that blocked the last blocked ray (neighbouring
    rays tend to share their occluders). Returns (hit, the next ``near``).
    """
    ox, oy, oz, dx, dy, dz, ix, iy, iz = ray_of(O, D, r)
    ray = (ox, oy, oz, dx, dy, dz)
    inv = (ix, iy, iz)
    tm = tmax[r] - eps[0]
    if near >= 0 and walk(near, ray, inv, tm, tree, eps, stack) >= 0:
        return True, near
    node = walk(0, ray, inv, tm, tree, eps, stack)
    if node < 0:
        return False, near
    for _ in range(UP):
        if parent[node] >= 0:
            node = parent[node]
    return True, node
