"""The compiled pieces every BVH cast is made of: a ray's reciprocals, the slab test of a node's
two child boxes, the next node of a depth-first walk, the front-side test of a leaf, and the
walks of shadow rays (:func:`any_range`). :mod:`explorer.geometry.bvh` builds its casts from them.

Shadow rays walk the tree's wide rows (:func:`wide_rows`): the binary tree with every other
level folded in, so that a wide node holds up to four children (its binary node's grandchildren,
or a leaf child) and one ray enters half as many nodes. A wide row keeps the four children's
boxes side by side (x0 of the four, x1 of the four, ...), and :func:`enter4` tests them in one
vector operation: the same float64 arithmetic as :func:`slab`, lane by lane, so a ray enters a
box in a wide row exactly when it enters that box in the binary tree.

These functions are inlined into :mod:`explorer.geometry.bvh`'s and
:mod:`explorer.geometry.occluders`' kernels: an edit here recompiles those (numba's cache of the
kernel files is keyed on every source they import, :mod:`explorer.geometry.kernelcache`).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from llvmlite import ir
from numba import types
from numba.cpython.unsafe.numbers import trailing_zeros
from numba.extending import intrinsic

from explorer.geometry import kernelcache  # noqa: F401 - before the decorators: the cache key
from explorer.geometry.rays import ray_triangle_row

#: the traversal stack; the BVH builder's depth limit plus 64 levels holds any mesh that fits
#: in memory
STACK = 128
#: stands for 1/0 in the slab test (finite, so no 0·inf = NaN)
BIG = 1e300
#: a node row packs a leaf child's first triangle and count as ``first << LEAF_BITS | count``
LEAF_BITS = 5
#: a shadow ray first walks the subtree this many wide levels above the leaf that blocked the
#: previous ray (:func:`any_range`)
UP = 2
#: columns of a wide row (:func:`wide_rows`): 4 lanes of (x0, x1, y0, y1, z0, z1), then each
#: lane's child and packed leaf as int32
WIDE = 32
#: the wide walk's stack: a wide node pushes at most three children more than it pops, and the
#: wide tree has at most STACK / 2 + 1 levels
WIDE_STACK = 2 * STACK


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
    o, d = ray[:3], ray[3:]
    first = np.int64(packed) >> LEAF_BITS
    for j in range(first, first + (np.int64(packed) & ((1 << LEAF_BITS) - 1))):
        t, _, _ = ray_triangle_row(tri, j, o, d, det_eps, True)
        if t > t_eps and t < tm:
            return True
    return False


@intrinsic
def enter4(typingctx, wide, w, ox, oy, oz, ix, iy, iz, t1):
    """The lanes of wide row ``wide[w]`` (:func:`wide_rows`) whose boxes the ray (origin ``o``,
    reciprocals ``i`` of its direction, :func:`inv`) enters within [0, t1], as the bits of an
    int64 (bit j: lane j). Each lane is :func:`slab`'s arithmetic in float64 on the float32
    box, its min and max as numba's (``b if b < a else a``), four lanes in one vector."""
    if not (isinstance(wide, types.Array) and wide.dtype == types.float32 and wide.ndim == 2
            and wide.layout == "C"):  # fmt: skip
        return None
    sig = types.int64(wide, types.int64, *(types.float64,) * 7)

    def codegen(context, builder, sig, args):
        i32, i64 = ir.IntType(32), ir.IntType(64)
        v4f, v4d = ir.VectorType(ir.FloatType(), 4), ir.VectorType(ir.DoubleType(), 4)
        row = context.make_array(sig.args[0])(context, builder, args[0])
        base = builder.gep(row.data, [builder.mul(args[1], ir.Constant(i64, WIDE))])

        def load(col):  # four float32 of the row, as float64
            ptr = builder.gep(base, [ir.Constant(i64, col)])
            return builder.fpext(builder.load(builder.bitcast(ptr, v4f.as_pointer()), align=4),
                                 v4d)  # fmt: skip

        def splat(x):
            v = ir.Constant(v4d, ir.Undefined)
            for j in range(4):
                v = builder.insert_element(v, x, ir.Constant(i32, j))
            return v

        def vmin(a, b):
            return builder.select(builder.fcmp_ordered("<", b, a), b, a)

        def vmax(a, b):
            return builder.select(builder.fcmp_ordered(">", b, a), b, a)

        t0 = tf = None
        for a in range(3):
            o, inv_ = splat(args[2 + a]), splat(args[5 + a])
            p = builder.fmul(builder.fsub(load(8 * a), o), inv_)
            q = builder.fmul(builder.fsub(load(8 * a + 4), o), inv_)
            t0 = vmin(p, q) if t0 is None else vmax(t0, vmin(p, q))
            tf = vmax(p, q) if tf is None else vmin(tf, vmax(p, q))
        t0 = vmax(t0, splat(ir.Constant(ir.DoubleType(), 0.0)))
        tf = vmin(tf, splat(args[8]))
        bits = builder.bitcast(builder.fcmp_ordered("<=", t0, tf), ir.IntType(4))
        return builder.zext(bits, i64)

    return sig, codegen


@nb.njit(cache=True, inline="always")
def walk(start, ray, inv, tm, tree, eps, stack):
    """Walk the wide subtree under wide node ``start`` of tree = (link, wide, tri) (``wide``
    the wide rows of :func:`wide_rows`, ``link`` their int32 view) with a shadow ray (ray =
    (ox, oy, oz, dx, dy, dz), inv its direction's reciprocals, ``tm`` its end), eps = (t_eps,
    det_eps); returns the wide node whose leaf holds a front side the ray meets, or -1."""
    link, wide, tri = tree
    t_eps, det_eps = eps
    ox, oy, oz = ray[0], ray[1], ray[2]
    ix, iy, iz = inv
    sp = 0
    node = start
    while True:
        lanes = enter4(wide, node, ox, oy, oz, ix, iy, iz, tm)
        while lanes:
            j = trailing_zeros(lanes)
            lanes &= lanes - 1
            c = np.int64(link[node, 24 + j])
            if c >= 0:
                stack[sp] = c
                sp += 1
            elif leaf_any(link[node, 28 + j], tri, ray, t_eps, tm, det_eps):
                return node
        if sp == 0:
            return np.int64(-1)
        sp -= 1
        node = stack[sp]


@nb.njit(cache=True, inline="always")
def any_range(r0, r1, rays, tree, parent, eps, out, stack):
    """out[r] for rays r0..r1 of rays = (O, D, tmax): whether ray ``r`` meets a front side in
    tree = (link, wide, tri) (:func:`walk`; ``parent`` (n,) each wide node's parent, -1 for
    the root) with eps = (t_eps, det_eps); ``stack`` (:data:`WIDE_STACK`,) int64 scratch.

    A ray first walks the wide subtree :data:`UP` wide levels above the leaf that blocked the
    previous ray, when that ray was blocked (neighbouring rays tend to share their occluders,
    and lit rays come in runs), then, if that finds nothing, the whole tree.
    """
    O, D, tmax = rays
    near = np.int64(-1)
    for r in range(r0, r1):
        ox, oy, oz, dx, dy, dz, ix, iy, iz = ray_of(O, D, r)
        ray = (ox, oy, oz, dx, dy, dz)
        inv = (ix, iy, iz)
        tm = tmax[r] - eps[0]
        if near >= 0 and walk(near, ray, inv, tm, tree, eps, stack) >= 0:
            out[r] = True
            continue
        node = walk(0, ray, inv, tm, tree, eps, stack)
        if node < 0:
            out[r] = False
            near = -1
            continue
        for _ in range(UP):
            if parent[node] >= 0:
                node = parent[node]
        out[r] = True
        near = node


@nb.njit(cache=True, boundscheck=False)
def wide_rows(child, cbox, rows):
    """Fill ``rows`` (n, :data:`WIDE`) float32 (n from :func:`wide_count`) with the wide tree of
    the binary ``child`` (k, 2) and its node rows ``cbox`` (k, 16) float32 (int32 view: the
    packed leaves in columns 14, 15). The wide nodes are the binary nodes an even number of
    inner levels below the root, in depth-first order (the root is wide node 0); a wide node's
    lanes are its binary node's children, each inner one replaced by its own two children.
    Row ``w``: columns ``8a + j`` and ``8a + 4 + j`` lane ``j``'s box along axis ``a`` (as
    ``cbox`` holds it), ``24 + j`` (int32) the lane's wide node (-1: a leaf, or no child: the
    box (1, -1) is never entered), ``28 + j`` a leaf's packed first triangle and count, else 0.

    Returns (parent (n,) int64 each wide node's parent, -1 for the root; slot (k, 2) int64 the
    index into ``rows.ravel()`` of each binary child box's x0 in its wide row, -1 for an inner
    child whose box is folded away)."""
    k = child.shape[0]
    n = rows.shape[0]
    link = cbox.view(np.int32)
    wlink = rows.view(np.int32)
    wid = np.full(k, -1, np.int64)
    order = np.empty(n, np.int64)
    stack = np.empty(4 * STACK, np.int64)
    stack[0] = 0
    sp, w = 1, 0
    while sp:  # number the wide nodes depth-first
        sp -= 1
        b = stack[sp]
        wid[b] = w
        order[w] = b
        w += 1
        for s in range(1, -1, -1):
            c = child[b, s]
            for t in range(1, -1, -1):
                if c >= 0 and child[c, t] >= 0:
                    stack[sp] = child[c, t]
                    sp += 1
    parent = np.full(n, -1, np.int64)
    slot = np.full((k, 2), -1, np.int64)
    for w in range(n):
        for j in range(4):
            for a in range(3):
                rows[w, 8 * a + j], rows[w, 8 * a + 4 + j] = 1.0, -1.0
            wlink[w, 24 + j], wlink[w, 28 + j] = -1, 0
        b = order[w]
        j = 0
        for s in range(2):
            c = child[b, s]
            for p in range(1 if c < 0 else 2):  # the lane's box: side h of binary node i
                i, h = (b, s) if c < 0 else (c, p)
                for a in range(6):
                    rows[w, 8 * (a // 2) + 4 * (a % 2) + j] = cbox[i, 6 * h + a]
                g = child[i, h]
                if g >= 0:
                    wlink[w, 24 + j] = wid[g]
                    parent[wid[g]] = w
                else:
                    wlink[w, 28 + j] = link[i, 14 + h]
                slot[i, h] = WIDE * w + j
                j += 1
    return parent, slot


@nb.njit(cache=True, boundscheck=False)
def wide_count(child):
    """The number of wide nodes of the binary tree ``child`` (k, 2) (:func:`wide_rows`)."""
    k = child.shape[0]
    even = np.zeros(k, np.bool_)
    even[0] = True
    n = 0
    for b in range(k):  # parents before children
        if not even[b]:
            continue
        n += 1
        for s in range(2):
            c = child[b, s]
            for t in range(2):
                if c >= 0 and child[c, t] >= 0:
                    even[child[c, t]] = True
    return n


@nb.njit(cache=True, inline="always")
def to_lanes(i, slot, cbox, rows):
    """Copy binary node ``i``'s two child boxes from its row of ``cbox`` (k, 16) into their
    lanes of the wide rows ``rows`` (n, :data:`WIDE`) (``slot`` of :func:`wide_rows`; a
    folded-away box is skipped)."""
    for s in range(2):
        at = slot[i, s]
        if at < 0:
            continue
        w, j = at // WIDE, at % WIDE
        for a in range(6):
            rows[w, 8 * (a // 2) + 4 * (a % 2) + j] = cbox[i, 6 * s + a]
