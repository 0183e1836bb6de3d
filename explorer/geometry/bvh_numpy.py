"""Ray casts through a bounding-volume hierarchy in plain numpy: the rays of the numpy tier.

The engine's ray casts (:mod:`explorer.geometry.bvh`) are compiled with numba; on a machine whose
numba cache does not hold them yet, the numpy tier of the engine
(:mod:`explorer.shading.tiers`) casts its shadow rays and per-pixel rays here instead, with no
compile. The answers are the same: the same Möller-Trumbore arithmetic in float64
(:func:`explorer.geometry.rays.ray_triangle`, written out for arrays in the same order of
operations), the same rules (any hit: front side, ``det >= DET_EPS``, ``RAY_T_EPS < t < tmax -
RAY_T_EPS``; nearest hit: either side, ``t > t_min``, a tie to the lowest triangle index); the
hierarchy only decides which triangles are tested, and its boxes are padded
(:data:`explorer.core.tolerances.BVH_BOX_PAD`) so that it never skips one a ray meets.

The hierarchy is built level by level, every node of a level at once: each node's triangles are
split at the median of their centres along the longest axis of the centres' bounds (one sort per
level). The casts walk it with a frontier of (ray, node) pairs, worked in pieces of at most
:data:`PAIRS` pairs, depth first: a piece's box tests and leaf tests are done for all its pairs at
once, and its children (at most ``2·PAIRS`` pairs) go on a stack above what is left of the
frontier. So a cast's memory beyond its rays (k per-ray values) and the tree is bounded whatever
the triangles: the stack holds at most ``2·PAIRS`` pairs per level of the tree (its depth is
``log2(m / LEAF) + 1``), and a piece's leaf tests at most ``LEAF·PAIRS`` (ray, triangle) pairs,
about 48 float64 of temporaries each (:func:`pair_bound` gives the bound in bytes). A mesh whose
triangles all cross (every ray enters every leaf) costs time, not memory.

:func:`build_bvh`, :func:`any_hit`, :func:`nearest_hits` and :func:`surface_points` take the
arguments of their compiled namesakes, so a caller picks either module
(:func:`explorer.shading.tiers.ray_engine`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from explorer.core.errors import Cancelled
from explorer.core.tolerances import BVH_BOX_PAD, DET_EPS, RAY_T_EPS, SURFACE_NORMAL_MIN

#: triangles per leaf (at most)
LEAF = 4
#: the stand-in for 1/0 in the slab test (as the compiled casts)
_BIG = 1e300
#: (ray, node) pairs a step of the walk tests at once at most (see the module docstring)
PAIRS = 16384
#: bytes a (ray, triangle) pair of a leaf test holds at most: the pair (two int64) and about 48
#: float64 of temporaries (the Möller-Trumbore test's, the selections of the hits; measured with
#: tracemalloc at 300-350 bytes: tests/geometry/test_bvh_numpy.py)
PAIR_BYTES = 16 + 48 * 8
#: bytes a (ray, node) pair on the walk's stack holds (two int64)
STACK_BYTES = 16


@dataclass(frozen=True)
class NumpyBVH:
    """A hierarchy over ``m`` triangles.

    tri : (m, 3, 3) float64 triangles in leaf order; order : (m,) int64 their input indices
    box : (k, 6) float64 node bounds (x0, x1, y0, y1, z0, z1), padded; node 0 is the root
    child : (k, 2) int64 the children of an inner node (-1 -1 for a leaf)
    first, count : (k,) int64 a node's range of ``tri`` (every node's triangles are contiguous)
    """

    tri: np.ndarray
    order: np.ndarray
    box: np.ndarray
    child: np.ndarray
    first: np.ndarray
    count: np.ndarray


def build_bvh(triangles, *, cancelled=None) -> NumpyBVH:
    """The hierarchy of ``triangles`` : (m, 3, 3) float (see the module docstring).
    cancelled : () -> bool, asked once per level (True: raise Cancelled)"""
    tri = np.asarray(triangles, np.float64).reshape(-1, 3, 3)
    m = len(tri)
    cent = tri.mean(axis=1)
    order = np.arange(m)
    first, count, parent = [0], [m], [-1]  # the nodes, root first
    level = np.array([0]) if m > LEAF else np.zeros(0, np.int64)
    while len(level):
        _check(cancelled)
        s = np.array([first[i] for i in level])
        n = np.array([count[i] for i in level])
        seg = np.repeat(np.arange(len(level)), n)  # segment of each triangle of the level
        pos = np.concatenate([np.arange(a, a + b) for a, b in zip(s, n, strict=True)])
        c = cent[order[pos]]
        lo = np.minimum.reduceat(c, np.cumsum(n) - n)
        hi = np.maximum.reduceat(c, np.cumsum(n) - n)
        axis = np.argmax(hi - lo, axis=1)
        key = c[np.arange(len(pos)), axis[seg]]
        order[pos] = order[pos[np.lexsort((key, seg))]]
        nxt = []
        for i, a, b in zip(level, s, n, strict=True):
            half = b // 2
            for f, k in ((a, half), (a + half, b - half)):
                parent.append(i)
                first.append(f)
                count.append(k)
                if k > LEAF:
                    nxt.append(len(first) - 1)
        level = np.array(nxt, np.int64)
    first, count, parent = (np.array(x, np.int64) for x in (first, count, parent))
    child = np.full((len(first), 2), -1, np.int64)
    kids = np.flatnonzero(parent >= 0)
    child[parent[kids[0::2]], 0] = kids[0::2]  # children are appended in pairs
    child[parent[kids[1::2]], 1] = kids[1::2]
    tri = tri[order]
    return NumpyBVH(tri, order, _boxes(tri, first, count), child, first, count)


def _boxes(tri: np.ndarray, first: np.ndarray, count: np.ndarray) -> np.ndarray:
    """(k, 6) padded bounds of each node's triangles."""
    lo, hi = tri.min(axis=1), tri.max(axis=1)
    box = np.empty((len(first), 6))
    if len(tri) == 0:
        box[:] = [0, -1, 0, -1, 0, -1]  # empty: no ray enters
        return box
    # reduceat over [first, first + count): pairs of indices, every other result kept
    end = first + count
    idx = np.stack([first, np.minimum(end, len(tri) - 1)], axis=1).reshape(-1)
    lo_pad = np.vstack([lo, lo[-1:]])
    hi_pad = np.vstack([hi, hi[-1:]])
    mn = np.minimum.reduceat(lo_pad, idx)[0::2]
    mx = np.maximum.reduceat(hi_pad, idx)[0::2]
    last = end == len(tri)  # reduceat's pair stops one short of the end: add the last one
    mn[last] = np.minimum(mn[last], lo[-1])
    mx[last] = np.maximum(mx[last], hi[-1])
    pad = BVH_BOX_PAD * (1.0 + np.maximum(np.abs(mn), np.abs(mx)))
    box[:, 0::2] = mn - pad
    box[:, 1::2] = mx + pad
    return box


def _slab(box, O, inv, t1):
    """Where each ray enters its box within [0, t1] (inf: not at all), as the compiled test."""
    p = (box[:, 0::2] - O) * inv
    q = (box[:, 1::2] - O) * inv
    near, far = np.minimum(p, q), np.maximum(p, q)
    t0 = np.maximum(np.maximum(near[:, 0], near[:, 1]), np.maximum(near[:, 2], 0.0))
    tf = np.minimum(np.minimum(far[:, 0], far[:, 1]), np.minimum(far[:, 2], t1))
    return np.where(t0 <= tf, t0, np.inf)


def _dot(a, b):
    """Row dot products, summed left to right as the compiled test does."""
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1] + a[:, 2] * b[:, 2]


def _cross(a, b):
    """Row cross products, term by term as the compiled test does."""
    return np.stack(
        [
            a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1],
            a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
            a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0],
        ],
        axis=1,
    )


def _moller_trumbore(O, D, tri, front_only: bool):
    """Möller-Trumbore for pairs: (t, u, v), t = inf for a miss (see rays.ray_triangle, whose
    order of operations this follows, so that both give the same bits)."""
    a = tri[:, 0]
    e1 = tri[:, 1] - a
    e2 = tri[:, 2] - a
    pv = _cross(D, e2)  # p = d × e2
    det = _dot(e1, pv)
    ok = det >= DET_EPS if front_only else det != 0.0
    inv = 1.0 / np.where(ok, det, 1.0)
    s = O - a
    u = _dot(s, pv) * inv
    w = _cross(s, e1)  # q = s × e1
    v = _dot(D, w) * inv
    ok &= (u >= 0.0) & (u <= 1.0) & (v >= 0.0) & (u + v <= 1.0)
    t = np.where(ok, _dot(e2, w) * inv, np.inf)
    return t, u, v


def _leaf_pairs(bvh: NumpyBVH, rays: np.ndarray, nodes: np.ndarray):
    """Every (ray, triangle) pair of rays at leaves: two (p,) int64 arrays."""
    n = bvh.count[nodes]
    r = np.repeat(rays, n)
    start = np.repeat(bvh.first[nodes] - np.cumsum(n) + n, n)
    return r, start + np.arange(len(r))


def _rays(origins, directions):
    O = np.asarray(origins, np.float64).reshape(-1, 3)
    D = np.asarray(directions, np.float64).reshape(-1, 3)
    with np.errstate(divide="ignore"):
        inv = np.where(D != 0.0, 1.0 / np.where(D != 0.0, D, 1.0), np.copysign(_BIG, D))
    return O, D, inv


def _check(cancelled) -> None:
    if cancelled is not None and cancelled():
        raise Cancelled("ray cast cancelled")


def depth(bvh: NumpyBVH) -> int:
    """The number of levels of the tree (1 for a root that is a leaf)."""
    m = len(bvh.tri)
    return 1 + max(0, int(np.ceil(np.log2(max(m, 1) / LEAF))))


def pair_bound(bvh: NumpyBVH) -> int:
    """Bytes a cast through ``bvh`` holds at most beyond its rays and the tree: the walk's stack
    (``2·PAIRS`` pairs per level) and one piece's leaf tests (``LEAF·PAIRS`` pairs); see the
    module docstring. It grows with the log of the triangle count only."""
    return (2 * depth(bvh) + 1) * PAIRS * STACK_BYTES + LEAF * PAIRS * PAIR_BYTES


def _walk(bvh: NumpyBVH, O, inv, limit, cancelled):
    """Walk the tree (see the module docstring); yield the (ray, triangle) pairs at the leaves
    the rays enter within [0, limit[ray]], at most ``LEAF·PAIRS`` at a time. ``limit`` (k,) is
    read at every step: the caller lowers it as hits are found (below 0: the ray is done)."""
    stack = [(np.arange(len(O)), np.zeros(len(O), np.int64))]
    while stack:
        _check(cancelled)
        rays, nodes = stack.pop()
        if len(rays) > PAIRS:  # a piece of it now, the rest (a view) later
            stack.append((rays[PAIRS:], nodes[PAIRS:]))
            rays, nodes = rays[:PAIRS], nodes[:PAIRS]
        enter = _slab(bvh.box[nodes], O[rays], inv[rays], limit[rays]) < np.inf
        rays, nodes = rays[enter], nodes[enter]
        leaf = bvh.child[nodes, 0] < 0
        if leaf.any():
            yield _leaf_pairs(bvh, rays[leaf], nodes[leaf])
        rays, nodes = rays[~leaf], nodes[~leaf]
        if len(rays):
            stack.append(
                (np.concatenate([rays, rays]),
                 np.concatenate([bvh.child[nodes, 0], bvh.child[nodes, 1]]))
            )  # fmt: skip


def any_hit(bvh: NumpyBVH, origins, directions, tmax, *, cancelled=None) -> np.ndarray:
    """Whether each ray meets the front side of a triangle between RAY_T_EPS and
    ``tmax - RAY_T_EPS``: (k,) bool (see :func:`explorer.geometry.bvh.any_hit`).

    origins, directions : (k, 3) float; tmax : (k,) float or a scalar
    cancelled : () -> bool, asked once per level (True: raise Cancelled)
    """
    O, D, inv = _rays(origins, directions)
    tm = np.broadcast_to(np.asarray(tmax, np.float64), (len(O),)) - RAY_T_EPS
    limit = tm.copy()
    hit = np.zeros(len(O), np.bool_)
    if len(bvh.tri) == 0:
        return hit
    for r, j in _walk(bvh, O, inv, limit, cancelled):
        t, _, _ = _moller_trumbore(O[r], D[r], bvh.tri[j], True)
        found = r[(t > RAY_T_EPS) & (t < tm[r])]
        hit[found] = True
        limit[found] = -1.0  # done: no box is entered below t = 0
    return hit


def nearest_hits(bvh: NumpyBVH, origins, directions, t_min: float, *, cancelled=None):
    """The nearest hit of each ray, either side, at ``t > t_min``, a tie to the lowest triangle
    index: (t, triangle, u, v) as :func:`explorer.geometry.bvh.nearest_hits` (t = inf and
    triangle -1 where none)."""
    O, D, inv = _rays(origins, directions)
    k = len(O)
    best_t, best_f = np.full(k, np.inf), np.full(k, -1, np.int64)
    bu, bv = np.zeros(k), np.zeros(k)
    if len(bvh.tri) == 0:
        return best_t, best_f, bu, bv
    for r, j in _walk(bvh, O, inv, best_t, cancelled):  # boxes beyond the best so far: skipped
        t, u, v = _moller_trumbore(O[r], D[r], bvh.tri[j], False)
        f = bvh.order[j]
        ok = t > t_min
        r, t, u, v, f = r[ok], t[ok], u[ok], v[ok], f[ok]
        if len(r):
            pick = np.lexsort((f, t, r))  # per ray: nearest, then lowest index
            first = np.r_[True, r[pick][1:] != r[pick][:-1]]
            r, t, u, v, f = (x[pick][first] for x in (r, t, u, v, f))
            better = (t < best_t[r]) | ((t == best_t[r]) & (f < best_f[r]))
            r, t, u, v, f = (x[better] for x in (r, t, u, v, f))
            best_t[r], best_f[r], bu[r], bv[r] = t, f, u, v
    return best_t, best_f, bu, bv


def surface_points(origins, directions, t, triangle, u, v, faces, normals):
    """The points the rays hit and the normals there: for each ray with ``triangle >= 0``,
    ``O + t·D`` and ``(1-u-v)·n0 + u·n1 + v·n2`` of its triangle's corners' ``normals``,
    normalised (zero stays zero).

    origins, directions : (k, 3) float64; t, u, v : (k,) float64; triangle : (k,) int64
    (:func:`nearest_hits`' answers); faces : (m, 3) int64; normals : (n, 3) float64
    Returns (hit (k,) bool, positions (h, 3), normals (h, 3)) for the h hits in ray order.
    """
    hit = triangle >= 0
    f = triangle[hit]
    a, b = u[hit], v[hit]
    pos = origins[hit] + t[hit][:, None] * directions[hit]
    corners = faces[f]
    n = ((1.0 - a - b)[:, None] * normals[corners[:, 0]] + a[:, None] * normals[corners[:, 1]]
         + b[:, None] * normals[corners[:, 2]])  # fmt: skip
    length = np.sqrt(n[:, 0] * n[:, 0] + n[:, 1] * n[:, 1] + n[:, 2] * n[:, 2])[:, None]
    n = np.divide(n, length, out=np.zeros_like(n), where=length > SURFACE_NORMAL_MIN)
    return hit, pos, n
