"""A bounding-volume hierarchy over triangles, and the two ray casts that go through it.

:class:`BVH` is a binary tree of axis-aligned boxes built once per mesh (binned surface-area
heuristic, :func:`build_bvh`); a ray visits only the boxes it crosses, so a cast costs about
``log(triangles)`` box tests and a few triangle tests instead of one test per triangle. Its
triangle test is :func:`explorer.geometry.rays.ray_triangle`, the one the brute-force casts
use, on the same ``v0, e1, e2`` numbers, and every box is grown by
:data:`~explorer.core.tolerances.BVH_BOX_PAD` so that rounding in the box test can only add
visits, never drop a triangle. The casts therefore answer exactly what testing every triangle
answers:

- :func:`any_hit`: whether each ray meets a triangle's front side (``det >= DET_EPS``) at
  ``t`` in ``(RAY_T_EPS, tmax - RAY_T_EPS)``: shadow rays (:mod:`explorer.shading.shadows`).
  Rays that all go to one light walk a copy of the tree whose boxes are refitted around the
  triangles that can block them (:func:`toward_light`, :mod:`explorer.geometry.occluders`:
  those facing away from the light); the rays walk the tree's wide rows (four children a
  node, tested in one vector operation: :func:`explorer.geometry.traverse.wide_rows`), each
  first the subtree just above the leaf that blocked the previous ray, when it was blocked
  (:func:`explorer.geometry.traverse.any_range`);
- :func:`nearest_hits`: the nearest hit, either side, beyond ``t_min``; among hits at the same
  ``t`` the lowest triangle index wins, as in a loop over the triangles in order: the
  per-pixel reference (:mod:`explorer.render.perpixel`).

The rays run in chunks of :data:`CHUNK` on a small pool of threads (the compiled kernels
release the GIL), at most one chunk in flight per thread for each call, so two callers (the
window's engine and a background comparison) share the cores instead of queueing behind each
other. Between chunks a ``cancelled`` callable is asked whether to stop (it raises
:class:`~explorer.core.errors.Cancelled`); Ctrl-C (KeyboardInterrupt) stops the work the same
way. No numba threading layer is involved, so the casts may run from any thread.
"""

from __future__ import annotations

import math
import os
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor, TimeoutError
from dataclasses import dataclass

import numba as nb
import numpy as np

from explorer.core.errors import Cancelled, ExplorerError
from explorer.core.tolerances import BVH_BOX_PAD, DET_EPS, RAY_T_EPS, SURFACE_NORMAL_MIN
from explorer.geometry import kernelcache  # noqa: F401 - before the decorators: the cache key
from explorer.geometry import occluders as occ
from explorer.geometry.rays import pack_triangles, ray_triangle_row
from explorer.geometry.traverse import (
    LEAF_BITS,
    STACK,
    WIDE,
    WIDE_STACK,
    any_range,
    enter,
    next_node,
    ray_of,
    wide_count,
    wide_rows,
)

#: rays per chunk at most: the unit of work a thread takes, and how often ``cancelled`` is asked
CHUNK = 8192
#: more rays than a chunk are cut into about this many chunks per thread (fewer when that
#: would make them smaller than :data:`MIN_CHUNK`)
SPLIT = 8
MIN_CHUNK = 1024
#: the per-light refit (:func:`toward_light`) of a tree with at least this many nodes opens the
#: subtrees this many levels below the root on every thread
REFIT_NODES = 16384
REFIT_DEPTH = 3
#: a node with at most this many triangles is always a leaf
LEAF_SIZE = 4
#: a node with more triangles than this is always split
MAX_LEAF = 16
#: bins of the surface-area heuristic along the chosen axis
BINS = 16
#: below this depth the builder splits by the heuristic; deeper, at the median (so the tree
#: is never deeper than about MEDIAN_DEPTH + log2(triangles))
MEDIAN_DEPTH = 64
#: shadow rays go through boxes refitted around their light's possible occluders
#: (:func:`toward_light`, cost about one ray per 50 triangles) when they number at least the
#: triangles divided by this
OCCLUDER_RAYS = 16
#: a tree holds fewer triangles than this: the node rows pack a leaf's first triangle and count
#: (at most :data:`MAX_LEAF`) into one int32 (:data:`~explorer.geometry.traverse.LEAF_BITS`)
MAX_TRIANGLES = 1 << 26
#: how often (seconds) a waiting caller asks ``cancelled`` while a tree is built
POLL = 0.05


@dataclass(frozen=True, eq=False)
class BVH:
    """A bounding-volume hierarchy over ``m`` triangles, as the casts read it.

    child : (k, 2) int64 the two children of each inner node: ``c >= 0`` an inner node,
        ``c < 0`` the leaf ``~c``; node 0 is the root (a tree of one leaf, or none, has a root
        whose other child's box is empty)
    cbox : (k, 16) float32 one 64-byte row per node (the array starts on a 64-byte boundary,
        :func:`node_rows`): columns 0-11 the children's boxes, (x0, x1, y0, y1, z0, z1) each,
        grown by the pad and rounded outward to float32 (an empty box, x0 > x1, is never
        entered); columns 12 and 13 hold ``child``'s row as int32, and 14 and 15 for a child
        that is a leaf its first triangle and count (``first << LEAF_BITS | count``), else
        zero (read through ``cbox.view(np.int32)``: a shadow ray's walk reads one cache line
        per node and none for the leaves' ranges)
    leaf : (q, 2) int64 per leaf: first triangle and count
    tri : (m, 9) float64 the triangles in leaf order, ``v0, e1, e2`` of each in a row
        (:func:`~explorer.geometry.rays.pack_triangles`)
    order : (m,) int64 the original index of each triangle in leaf order
    parent : (k,) int64 each inner node's parent (-1 for the root)
    tbox : (m, 6) float32 each triangle's padded box, rounded outward (leaf order), and
    plane : (m, 4) float64 its unit normal and the normal's dot with ``v0`` (zero for a
        sliver),
    cone : (k, 10) float32 the normal cone of each node's two children
        (:func:`~explorer.geometry.occluders.cones`) and
    span : (k,) int64 the inner nodes in each inner node's subtree: what
        :mod:`~explorer.geometry.occluders` refits the boxes from for the rays toward one light
    wide : (n, 32) float32 the wide rows the shadow rays walk, 128 bytes each, 64-byte aligned
        (:func:`~explorer.geometry.traverse.wide_rows`: up to four children a node, their boxes
        as in ``cbox``), with
    wparent : (n,) int64 each wide node's parent (-1 for the root) and
    slot : (k, 2) int64 where each child box of ``cbox`` is in ``wide.ravel()`` (-1: folded
        away)
    """

    child: np.ndarray
    cbox: np.ndarray
    leaf: np.ndarray
    tri: np.ndarray
    order: np.ndarray
    parent: np.ndarray
    tbox: np.ndarray
    plane: np.ndarray
    cone: np.ndarray
    span: np.ndarray
    wide: np.ndarray
    wparent: np.ndarray
    slot: np.ndarray

    @property
    def n_triangles(self) -> int:
        return len(self.order)

    @property
    def n_nodes(self) -> int:
        return len(self.child)


def build_bvh(triangles, *, cancelled=None) -> BVH:
    """The BVH of ``triangles`` : (m, 3, 3) float (corners counter-clockwise seen from the
    front).

    cancelled : () -> bool, asked every :data:`POLL` seconds while the tree is built (True:
        raise :class:`~explorer.core.errors.Cancelled`); Ctrl-C stops the build the same way
    """
    tri = np.ascontiguousarray(triangles, np.float64).reshape(-1, 3, 3)
    m = len(tri)
    if m >= MAX_TRIANGLES:
        raise ExplorerError(
            f"{m:,} triangles: a BVH holds fewer than {MAX_TRIANGLES:,} (shadow rays and the "
            "per-pixel reference need one: turn shadows off, or decimate the mesh)"
        )
    if m == 0:  # a root whose children are nothing
        child = np.full((1, 2), -1, np.int64)
        box = np.tile(np.array([1, -1, 1, -1, 1, -1], np.float32), (1, 2))
        cbox = node_rows(child, box, np.zeros((0, 2), np.int64))
        no = np.zeros(0, np.int64)
        root = np.full(1, -1, np.int64)
        return BVH(child, cbox, np.zeros((0, 2), np.int64), np.zeros((0, 9)), no, root,
                   np.zeros((0, 6), np.float32), np.zeros((0, 4)),
                   np.zeros((1, 10), np.float32), np.ones(1, np.int64),
                   *_wide(child, cbox))  # fmt: skip
    box, link, order, pad = _stoppable(_build, (tri,), cancelled)
    child, box64, leaf = _children(box, link)
    lo32 = box64[:, 0::2].astype(np.float32)
    hi32 = box64[:, 1::2].astype(np.float32)
    lo32 = np.where(lo32 > box64[:, 0::2], np.nextafter(lo32, np.float32(-np.inf)), lo32)
    hi32 = np.where(hi32 < box64[:, 1::2], np.nextafter(hi32, np.float32(np.inf)), hi32)
    box32 = np.empty(box64.shape, np.float32)
    box32[:, 0::2], box32[:, 1::2] = lo32, hi32
    cbox = node_rows(child, box32, leaf)
    rows = np.ascontiguousarray(pack_triangles(tri)[order])
    plane = occ.planes(rows)
    return BVH(child, cbox, leaf, rows, order, _parents(child), occ.triangle_boxes(rows, pad),
               plane, occ.cones(child, leaf, plane), occ.spans(child),
               *_wide(child, cbox))  # fmt: skip


def _wide(child, cbox) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(wide, wparent, slot) of :class:`BVH` for the binary tree ``child``, ``cbox``."""
    wide = aligned_rows(wide_count(child), WIDE)
    return (wide, *wide_rows(child, cbox, wide))


def aligned_rows(k: int, width: int = 16) -> np.ndarray:
    """An uninitialised (k, width) float32 array starting on a 64-byte boundary (width 16: a
    row fills one cache line)."""
    raw = np.empty(width * k + 16, np.float32)
    skip = (-raw.ctypes.data % 64) // 4
    return raw[skip : skip + width * k].reshape(k, width)


def node_rows(child, boxes, leaf) -> np.ndarray:
    """The (k, 16) float32 node rows of :class:`BVH`'s ``cbox`` from ``child`` (k, 2) int, the
    children's boxes ``boxes`` (k, 12) float32 and ``leaf`` (q, 2) int (first, count)."""
    rows = aligned_rows(len(child))
    rows[:, :12] = boxes
    link = rows.view(np.int32)
    link[:, 12:14] = child
    q = np.where(child < 0, ~child, 0)
    packed = (leaf[q, 0] << LEAF_BITS | leaf[q, 1]) if len(leaf) else np.zeros_like(child)
    link[:, 14:] = np.where(child < 0, packed, 0)
    return rows


def copy_rows(cbox) -> np.ndarray:
    """A copy of node rows ``cbox`` (k, w) float32, aligned like them (:func:`aligned_rows`)."""
    rows = aligned_rows(*cbox.shape)
    rows.view(np.int32)[:] = cbox.view(np.int32)  # bits as they are (a child may read as NaN)
    return rows


def _parents(child) -> np.ndarray:
    """(k,) int64 the parent of each inner node of ``child`` (k, 2); -1 for the root."""
    parent = np.full(len(child), -1, np.int64)
    inner = child >= 0
    parent[child[inner]] = np.nonzero(inner)[0]
    return parent


# -- building ------------------------------------------------------------------------------


def _stoppable(build, args, cancelled):
    """Run ``build(*args, stop)`` on a worker thread while this one waits, so that Ctrl-C and
    ``cancelled`` stop it: ``stop[0] = 1`` ends the build within 1024 nodes."""
    _check(cancelled)
    stop = np.zeros(1, np.uint8)
    future = _get_pool().submit(build, *args, stop)
    try:
        while True:
            try:
                return future.result(timeout=POLL)
            except TimeoutError:
                _check(cancelled)
    finally:
        if not future.done():
            stop[0] = 1
            future.exception()  # waits for the build to notice


@nb.njit(cache=True, inline="always")
def _area(x0, x1, y0, y1, z0, z1):
    dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
    return dx * dy + dy * dz + dz * dx  # half the surface area: only ratios matter


@nb.njit(cache=True, inline="always")
def _bin(c, c0, scale):
    b = int((c - c0) * scale)
    return min(max(b, 0), BINS - 1)


@nb.njit(cache=True)
def _sah_split(boxes, idx, start, end, axis, c0, c1, node_area, scratch):
    """The bin boundary (1..BINS-1) with the lowest surface-area cost for
    idx[start:end] along ``axis``, or -1 when no split beats a leaf (only for small nodes).
    boxes : (lo, hi, cent), each (m, 3): the triangles' boxes and centroids
    scratch : (cnt, bb, right): (BINS,) int64, (BINS + 1, 6), (BINS, 2)"""
    lo, hi, cent = boxes
    cnt, bb, right = scratch
    scale = BINS / (c1 - c0)
    for b in range(BINS):
        cnt[b] = 0
        for a in range(3):
            bb[b, 2 * a] = math.inf
            bb[b, 2 * a + 1] = -math.inf
    for k in range(start, end):
        t = idx[k]
        b = _bin(cent[t, axis], c0, scale)
        cnt[b] += 1
        for a in range(3):
            bb[b, 2 * a] = min(bb[b, 2 * a], lo[t, a])
            bb[b, 2 * a + 1] = max(bb[b, 2 * a + 1], hi[t, a])
    # right-to-left sweep: area and count of bins s..BINS-1
    acc = bb[BINS]
    for a in range(6):
        acc[a] = math.inf if a % 2 == 0 else -math.inf
    right[:, :] = 0.0  # area and count of the bins s..BINS-1
    n = 0
    for s in range(BINS - 1, 0, -1):
        n += cnt[s]
        for a in range(3):
            acc[2 * a] = min(acc[2 * a], bb[s, 2 * a])
            acc[2 * a + 1] = max(acc[2 * a + 1], bb[s, 2 * a + 1])
        right[s, 1] = n
        if n > 0:
            right[s, 0] = _area(acc[0], acc[1], acc[2], acc[3], acc[4], acc[5])
    best, best_s = math.inf, -1
    for a in range(6):
        acc[a] = math.inf if a % 2 == 0 else -math.inf
    n = 0
    for s in range(1, BINS):
        n += cnt[s - 1]
        for a in range(3):
            acc[2 * a] = min(acc[2 * a], bb[s - 1, 2 * a])
            acc[2 * a + 1] = max(acc[2 * a + 1], bb[s - 1, 2 * a + 1])
        if n == 0 or right[s, 1] == 0:
            continue
        cost = _area(acc[0], acc[1], acc[2], acc[3], acc[4], acc[5]) * n
        cost += right[s, 0] * right[s, 1]
        if cost < best:
            best, best_s = cost, s
    count = end - start
    # traversal 1, triangle test 1 per triangle: a leaf costs ``count``
    if count <= MAX_LEAF and (best_s < 0 or 1.0 + best / max(node_area, 1e-300) >= count):
        return -1
    return best_s


@nb.njit(cache=True, nogil=True)
def _build(tri, stop):
    """Top-down build over ``tri`` (m, 3, 3) in depth-first order; returns (box, link, order,
    pad), or empty arrays when ``stop[0]`` became non-zero (it is read every 1024 nodes)."""
    m = tri.shape[0]
    lo = np.empty((m, 3))
    hi = np.empty((m, 3))
    cent = np.empty((m, 3))
    size = 1.0
    for t in range(m):
        for a in range(3):
            x, y, z = tri[t, 0, a], tri[t, 1, a], tri[t, 2, a]
            lo[t, a] = min(x, y, z)
            hi[t, a] = max(x, y, z)
            cent[t, a] = 0.5 * (lo[t, a] + hi[t, a])
            size = max(size, abs(lo[t, a]), abs(hi[t, a]))
    pad = BVH_BOX_PAD * size
    idx = np.arange(m)
    cap = 2 * m
    box = np.empty((cap, 6))
    link = np.zeros((cap, 3), np.int64)
    st = np.empty((2 * STACK + 8, 4), np.int64)  # start, end, parent, depth
    st[0, 0], st[0, 1], st[0, 2], st[0, 3] = 0, m, -1, 0
    sp = 1
    n_nodes = 0
    b = np.empty(6)  # the node's box
    c = np.empty(6)  # its centroids' box
    scratch = (np.zeros(BINS, np.int64), np.empty((BINS + 1, 6)), np.empty((BINS, 2)))
    boxes = (lo, hi, cent)
    while sp > 0:
        if n_nodes % 1024 == 0 and stop[0]:
            return box[:0].copy(), link[:0].copy(), idx[:0].copy(), pad
        sp -= 1
        start, end, parent, depth = st[sp, 0], st[sp, 1], st[sp, 2], st[sp, 3]
        node = n_nodes
        n_nodes += 1
        if parent >= 0:
            link[parent, 0] = node
        for a in range(6):
            b[a] = c[a] = math.inf if a % 2 == 0 else -math.inf
        for k in range(start, end):
            t = idx[k]
            for a in range(3):
                b[2 * a] = min(b[2 * a], lo[t, a])
                b[2 * a + 1] = max(b[2 * a + 1], hi[t, a])
                c[2 * a] = min(c[2 * a], cent[t, a])
                c[2 * a + 1] = max(c[2 * a + 1], cent[t, a])
        for a in range(3):
            box[node, 2 * a] = b[2 * a] - pad
            box[node, 2 * a + 1] = b[2 * a + 1] + pad
        count = end - start
        if count <= LEAF_SIZE:
            link[node, 0], link[node, 1] = start, count
            continue
        axis = 0
        for a in range(1, 3):
            if c[2 * a + 1] - c[2 * a] > c[2 * axis + 1] - c[2 * axis]:
                axis = a
        c0, c1 = c[2 * axis], c[2 * axis + 1]
        mid = -1
        if c1 > c0 and depth < MEDIAN_DEPTH:
            area = _area(b[0], b[1], b[2], b[3], b[4], b[5])
            s = _sah_split(boxes, idx, start, end, axis, c0, c1, area, scratch)
            if s < 0:
                link[node, 0], link[node, 1] = start, count
                continue
            scale = BINS / (c1 - c0)
            i, j = start, end - 1
            while i <= j:  # partition: bins below s to the left
                if _bin(cent[idx[i], axis], c0, scale) < s:
                    i += 1
                else:
                    idx[i], idx[j] = idx[j], idx[i]
                    j -= 1
            mid = i
        if mid <= start or mid >= end:  # equal centroids, or too deep: split at the median
            if c1 == c0 and count <= MAX_LEAF:
                link[node, 0], link[node, 1] = start, count
                continue
            part = idx[start:end]
            idx[start:end] = part[np.argsort(cent[part, axis], kind="mergesort")]
            mid = start + count // 2
        link[node, 2] = axis
        st[sp, 0], st[sp, 1], st[sp, 2], st[sp, 3] = mid, end, node, depth + 1
        st[sp + 1, 0], st[sp + 1, 1], st[sp + 1, 2], st[sp + 1, 3] = start, mid, -1, depth + 1
        sp += 2
    return box[:n_nodes].copy(), link[:n_nodes].copy(), idx, pad


@nb.njit(cache=True)
def _children(box, link):
    """The depth-first tree of :func:`_build` as child pairs: (child, cbox float64, leaf)."""
    n = box.shape[0]
    ident = np.empty(n, np.int64)  # inner node: its index; leaf: ~its leaf index
    ni = 0
    nl = 0
    for i in range(n):
        if link[i, 1] == 0:
            ident[i] = ni
            ni += 1
        else:
            ident[i] = ~nl
            nl += 1
    leaf = np.empty((nl, 2), np.int64)
    for i in range(n):
        if link[i, 1] > 0:
            leaf[~ident[i], 0] = link[i, 0]
            leaf[~ident[i], 1] = link[i, 1]
    k = max(ni, 1)
    child = np.empty((k, 2), np.int64)
    cbox = np.empty((k, 12))
    if ni == 0:  # the root is a leaf: one child, and a box nothing enters
        child[0, 0], child[0, 1] = ident[0], ident[0]
        for a in range(6):
            cbox[0, a] = box[0, a]
            cbox[0, 6 + a] = 1.0 if a % 2 == 0 else -1.0
        return child, cbox, leaf
    for i in range(n):
        if link[i, 1] == 0:
            j = ident[i]
            right = link[i, 0]
            child[j, 0], child[j, 1] = ident[i + 1], ident[right]
            for a in range(6):
                cbox[j, a] = box[i + 1, a]
                cbox[j, 6 + a] = box[right, a]
    return child, cbox, leaf


# -- traversal -----------------------------------------------------------------------------


@nb.njit(cache=True, nogil=True, boundscheck=False)
def _any_hit_chunk(r0, r1, rays, tree, parent, eps, out):
    """Rays r0..r1 of rays = (O, D, tmax) through tree = (link, wide, tri) (``wide`` the wide
    rows of :class:`BVH`, ``link`` their int32 view; ``parent`` (n,) each wide node's parent)
    with eps = (t_eps, det_eps): out[r] True where the ray is blocked
    (:func:`~explorer.geometry.traverse.any_range`)."""
    any_range(r0, r1, rays, tree, parent, eps, out, np.empty(WIDE_STACK, np.int64))


@nb.njit(cache=True, inline="always")
def _leaf_nearest(leaf, q, tri, order, ray, t_min, best):
    """Leaf ``q``'s hits of the ray ``(ox, oy, oz, dx, dy, dz)`` against best = (t, triangle,
    u, v, leaf): the nearer hit beyond ``t_min``, at equal ``t`` the lower triangle index."""
    o, d = ray[:3], ray[3:]
    bt, bf, bu, bv, bq = best
    first = leaf[q, 0]
    for j in range(first, first + leaf[q, 1]):
        t, u, v = ray_triangle_row(tri, j, o, d, 0.0, False)
        if t > t_min and (t < bt or (t == bt and t < math.inf and (bf < 0 or order[j] < bf))):
            bt, bf, bu, bv, bq = t, order[j], u, v, q
    return bt, bf, bu, bv, bq


@nb.njit(cache=True, nogil=True, boundscheck=False)
def _nearest_chunk(r0, r1, rays, t_min, tree, order, out):
    """Rays r0..r1 of rays = (O, D) through tree = (child, cbox, leaf, tri); writes the
    nearest hit into out = (best_t, best_f, bu, bv) (best_t in: the farthest t accepted).
    The leaf the previous ray's hit is in is tested first: neighbouring pixels tend to see
    the same few triangles, and a near ``best`` early keeps the walk from boxes beyond it."""
    O, D = rays
    child, cbox, leaf, tri = tree
    best_t, best_f, bu, bv = out
    stack = np.empty(STACK, np.int64)
    last = np.int64(-1)
    for r in range(r0, r1):
        ox, oy, oz, dx, dy, dz, ix, iy, iz = ray_of(O, D, r)
        ray = (ox, oy, oz, dx, dy, dz)
        best = (best_t[r], np.int64(-1), 0.0, 0.0, np.int64(-1))
        if last >= 0:
            best = _leaf_nearest(leaf, last, tri, order, ray, t_min, best)
        sp = 0
        node = 0
        while True:
            # boxes entered at t == best are still visited: a tie may go to a lower index
            ta, tb = enter(cbox, node, ox, oy, oz, ix, iy, iz, best[0])
            ca, cb = child[node, 0], child[node, 1]
            if ca < 0 and ta < math.inf:
                best = _leaf_nearest(leaf, ~ca, tri, order, ray, t_min, best)
                ta = math.inf
            if cb < 0 and tb < math.inf:
                best = _leaf_nearest(leaf, ~cb, tri, order, ray, t_min, best)
                tb = math.inf
            node, sp = next_node(stack, sp, ca, cb, ta, tb)
            if node < 0:
                break
        if best[1] >= 0:
            best_t[r], best_f[r], bu[r], bv[r], last = best
        else:
            last = np.int64(-1)


# -- running in chunks ---------------------------------------------------------------------

_pool: ThreadPoolExecutor | None = None
_pool_lock = threading.Lock()


def workers() -> int:
    """Threads the casts use: numba's thread count (``NUMBA_NUM_THREADS``), else the cores."""
    return max(1, int(nb.config.NUMBA_NUM_THREADS or os.cpu_count() or 1))


def _get_pool() -> ThreadPoolExecutor:
    global _pool
    with _pool_lock:
        if _pool is None:
            _pool = ThreadPoolExecutor(workers(), thread_name_prefix="explorer-rays")
        return _pool


def _check(cancelled: Callable[[], bool] | None) -> None:
    if cancelled is not None and cancelled():
        raise Cancelled("ray casting was cancelled")


def run_chunks(kernel, n: int, args: tuple, *, cancelled=None, chunk: int = CHUNK,
               split: bool = True) -> None:  # fmt: skip
    """Call ``kernel(r0, r1, *args)`` over ``[0, n)`` in chunks of at most ``chunk`` rays, on
    :func:`workers` threads: this one and helpers from the pool, each taking the next chunk
    when it is done with one (rays cost unequally: a shadowed one several lit ones), about
    :data:`SPLIT` chunks per thread (``split=False``: chunks of ``chunk``). This thread asks
    ``cancelled()`` before each of its chunks. A helper that has not started when the work is
    done is withdrawn, so two callers share the cores instead of one waiting for the other's
    work.

    Raises :class:`~explorer.core.errors.Cancelled` when ``cancelled()`` returns True. On any
    exception (Ctrl-C too) no chunk starts any more and the running ones are waited for, so
    nothing writes into the outputs after this returns or raises.
    """
    _check(cancelled)
    threads = workers()
    if split and n > chunk and threads > 1:
        chunk = max(MIN_CHUNK, -(-n // (threads * SPLIT)))
    if n <= chunk or threads == 1:
        for s in range(0, n, chunk):
            _check(cancelled)
            kernel(s, min(s + chunk, n), *args)
        return
    state = [0, False]  # the next chunk's first ray; stop
    lock = threading.Lock()

    def take() -> int:
        with lock:
            s = state[0]
            state[0] = n if state[1] else s + chunk
            return s

    def work() -> None:
        while (s := take()) < n:
            kernel(s, min(s + chunk, n), *args)

    helpers = [_get_pool().submit(work) for _ in range(threads - 1)]
    try:
        while (s := take()) < n:
            kernel(s, min(s + chunk, n), *args)
            _check(cancelled)
    except BaseException:
        with lock:
            state[1] = True
        for f in helpers:
            if not f.cancel():
                f.exception()  # waits for its chunk; the caller's exception propagates
        raise
    for f in helpers:
        if not f.cancel():
            f.result()  # waits for its last chunk (and raises what it raised)


# -- the casts -----------------------------------------------------------------------------


def _tree(bvh: BVH) -> tuple:
    return bvh.child, bvh.cbox, bvh.leaf, bvh.tri


def _rays(origins, directions) -> tuple[np.ndarray, np.ndarray]:
    O = np.ascontiguousarray(origins, np.float64).reshape(-1, 3)
    D = np.ascontiguousarray(directions, np.float64).reshape(-1, 3)
    if O.shape != D.shape:
        raise ValueError(f"origins {O.shape} and directions {D.shape} differ in shape")
    return O, D


def any_hit(bvh: BVH, origins, directions, tmax, *, cancelled=None, refit=True) -> np.ndarray:
    """Whether each ray meets the front side of a triangle between :data:`RAY_T_EPS` and
    ``tmax - RAY_T_EPS`` (the same answer as :func:`explorer.geometry.rays.any_hit`).

    origins, directions : (k, 3) float (directions of unit length, in the triangles' units)
    tmax : (k,) float, the distance to the light (inf: none)
    cancelled : () -> bool, asked between chunks (True: raise Cancelled)
    Returns (k,) bool.

    Rays that all go to one light (shadow rays) and are at least 1/:data:`OCCLUDER_RAYS` of
    the triangles in number go through :func:`toward_light`'s boxes (``refit=False``: never;
    the same answers, for benchmarks).
    """
    O, D = _rays(origins, directions)
    tm = np.ascontiguousarray(np.broadcast_to(np.asarray(tmax, np.float64), (len(O),)))
    hit = np.zeros(len(O), np.bool_)
    if not bvh.n_triangles:
        return hit
    if refit and len(O) * OCCLUDER_RAYS >= bvh.n_triangles:
        bvh = toward_light(bvh, O, D, tm, cancelled=cancelled)
    tree = (bvh.wide.view(np.int32), bvh.wide, bvh.tri)
    args = ((O, D, tm), tree, bvh.wparent, (RAY_T_EPS, DET_EPS), hit)
    run_chunks(_any_hit_chunk, len(O), args, cancelled=cancelled)
    return hit


def toward_light(bvh: BVH, origins, directions, tmax, *, cancelled=None, split=None) -> BVH:
    """``bvh`` with its boxes refitted around the triangles that can block the rays, when the
    rays all end at one point or all run one way (:mod:`explorer.geometry.occluders`); else
    ``bvh`` itself. Casting the rays through either gives the same answers.

    origins, directions : (k, 3) float64 C-contiguous; tmax : (k,) float64
    split : the refit's walk split among the threads REFIT_DEPTH levels down; None (default):
        for a tree of REFIT_NODES nodes or more on more than one core (the background compile
        takes both ways on a small tree: :mod:`explorer.shading.warm`)
    """
    big = bvh.n_nodes >= REFIT_NODES and workers() > 1 if split is None else bool(split)
    # a large tree's copy of the binary rows is made on another thread meanwhile
    copy = _get_pool().submit(copy_rows, bvh.cbox) if big else None
    end = occ.shared_end(origins, directions, tmax)
    if end is None or not bvh.n_triangles:
        return bvh
    kind, L, eps, reach = end
    corner = np.maximum(np.abs(bvh.cbox[0, 0:12:2]), np.abs(bvh.cbox[0, 1:12:2]))
    corner = corner.astype(np.float64)
    corner = np.maximum(corner[:3], corner[3:])  # the root's two children's boxes
    radius = max(float(np.sqrt(corner @ corner)), reach)
    _check(cancelled)
    tree = (bvh.child, bvh.cbox, bvh.leaf, bvh.plane, bvh.tbox)
    light = (np.int64(kind), L, eps, radius)
    k = bvh.n_nodes
    wide = copy_rows(bvh.wide)
    cbox = copy_rows(bvh.cbox) if copy is None or copy.cancel() else copy.result()
    opened = np.zeros(k, np.uint8)
    order = np.empty(k, np.int64)
    # the walk is bound by reading the nodes it opens from memory: a large tree's subtrees
    # REFIT_DEPTH levels down go to every thread
    if big:
        top, roots = occ.refit_top(tree, bvh.cone, light, opened, cbox, REFIT_DEPTH)
        args = (roots, tree, bvh.cone, bvh.span, light, (opened, order), cbox, (bvh.slot, wide))
        run_chunks(occ.refit, len(roots), args, cancelled=cancelled, chunk=1, split=False)
        occ.refit_unions(top, bvh.child, opened, cbox, (bvh.slot, wide))
    else:
        opened[0] = 1
        occ.refit(0, 1, np.zeros(1, np.int64), tree, bvh.cone, bvh.span, light,
                  (opened, order), cbox, (bvh.slot, wide))  # fmt: skip
    return BVH(bvh.child, cbox, bvh.leaf, bvh.tri, bvh.order, bvh.parent, bvh.tbox, bvh.plane,
               bvh.cone, bvh.span, wide, bvh.wparent, bvh.slot)  # fmt: skip


def nearest_hits(bvh: BVH, origins, directions, t_min: float, *, cancelled=None):
    """The nearest hit of each ray, front or back side, at ``t > t_min``; at equal ``t`` the
    lowest triangle index.

    origins, directions : (k, 3) float
    Returns (t, triangle, u, v): (k,) float64 ``t`` (inf: no hit), (k,) int64 original
    triangle index (-1: no hit), (k,) float64 barycentric ``u``, ``v`` of the hit.
    """
    O, D = _rays(origins, directions)
    k = len(O)
    best_t = np.full(k, np.inf)
    best_f = np.full(k, -1, np.int64)
    bu, bv = np.zeros(k), np.zeros(k)
    if bvh.n_triangles:
        args = ((O, D), float(t_min), _tree(bvh), bvh.order, (best_t, best_f, bu, bv))
        run_chunks(_nearest_chunk, k, args, cancelled=cancelled)
    return best_t, best_f, bu, bv


def surface_points(origins, directions, t, triangle, u, v, faces, normals):
    """The points the rays hit and the normals there (the same numbers as
    :func:`explorer.geometry.bvh_numpy.surface_points`, compiled).

    origins, directions : (k, 3) float64; t, u, v : (k,) float64; triangle : (k,) int64
    (:func:`nearest_hits`' answers); faces : (m, 3) int64; normals : (n, 3) float64
    Returns (hit (k,) bool, positions (h, 3), normals (h, 3)) for the h hits in ray order.
    """
    hit = triangle >= 0
    h = int(hit.sum())
    pos, n = np.empty((h, 3)), np.empty((h, 3))
    _surface(origins, directions, t, triangle, u, v, faces, normals, pos, n)
    return hit, pos, n


@nb.njit(cache=True, nogil=True, boundscheck=False)
def _surface(O, D, t, f, u, v, faces, normals, pos, nrm):
    k = 0
    for r in range(len(f)):
        if f[r] < 0:
            continue
        a, b = u[r], v[r]
        w = 1.0 - a - b
        i0, i1, i2 = faces[f[r], 0], faces[f[r], 1], faces[f[r], 2]
        for c in range(3):
            pos[k, c] = O[r, c] + t[r] * D[r, c]
            nrm[k, c] = w * normals[i0, c] + a * normals[i1, c] + b * normals[i2, c]
        length = math.sqrt(nrm[k, 0] * nrm[k, 0] + nrm[k, 1] * nrm[k, 1] + nrm[k, 2] * nrm[k, 2])
        for c in range(3):
            nrm[k, c] = nrm[k, c] / length if length > SURFACE_NORMAL_MIN else 0.0
        k += 1
