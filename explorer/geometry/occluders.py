"""The triangles that can block rays toward one point: a BVH's boxes refitted around them.

Shadow rays of one light all end at the light (a point light or spot) or all run the same way (a
directional light). Only the front side of a triangle blocks a ray (``det = -D·(e1 × e2) >=
DET_EPS``), so a triangle whose front faces the light cannot block any of them: the ray crosses
its plane, if at all, from its back. On a closed mesh that is about half of the triangles, and
they include every triangle around a lit vertex, where each of its rays starts. A hierarchy
whose boxes hold only the other triangles lets such a ray skip its own neighbourhood: on the
100k-vertex teapot the rays open about a quarter of the nodes and a tenth of the triangles
(``benchmarks/bench_rays.py`` has the timings).

:func:`shared_end` finds the light from the rays themselves (their ends ``O + tmax·D`` agree,
or their directions are equal). :func:`refit_top` and :func:`refit` go down the tree from the
root: with the cone around the normals under each child of a node (:func:`cones`, made with the
tree) and the child's box, :func:`_classify` bounds the light's height over every triangle under
it, so a child whose triangles all face the light with the margin is left out whole and one whose
triangles all face away keeps its boxes as built; only the others are opened, a leaf among them
boxing its triangles that do not face the light one by one, an inner node's box the union of its
children's (:func:`refit_unions`). The result is the box of those triangles wherever a ray can
get; the tree itself (children, leaves, triangle rows) is kept, so the casts run unchanged on the
new boxes.

Why no blocking triangle is dropped (the margin is
:data:`~explorer.core.tolerances.OCCLUDER_MARGIN`, ``μ``): for unit normal ``n̂`` of a
triangle with corner ``v0`` and a light at ``L``, the triangle is dropped only when the light's
height over its plane ``h = (L - v0)·n̂`` exceeds both ``μ·(|L - v0| + 2R)`` (``R`` bounds every
corner's and ray origin's distance from the frame's origin, so ``|L - v0| + 2R`` bounds every
ray's length to the light; the kernel tests the larger ``μ(|L| + 3R)``) and ``2(ε + ulp)/μ``
(``ε``: how far the rays' ends lie from ``L``). A ray from ``O`` then has
``D·n̂ >= (h - (O - v0)·n̂ - ε)/tmax``. When its origin is behind the plane this is
``>= μ/2``, so ``-D·n`` is negative by far more than the rounding of ``det`` (``|n| >=
μ·|e1|·|e2|`` is required: slivers are kept); when the origin is in front, the ray's plane
crossing lies at least ``h·tmax/(O - v0)·n̂`` beyond the light, far beyond rounding and
``RAY_T_EPS``. For a directional light ``D·n̂ > μ`` is required. So every hit the full tree
reports, the refitted one reports: ``tests/geometry/test_occluders.py`` checks the answers
against the brute force, lights grazing and near the surface included.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from explorer.core.tolerances import CONE_ROUND, CONE_SLACK, CONE_WIDEN, OCCLUDER_MARGIN
from explorer.geometry import kernelcache  # noqa: F401 - before the decorators: the cache key
from explorer.geometry.traverse import to_lanes

#: the rays share an end when their ends ``O + tmax·D`` lie within this times (1 + |end|) of the
#: first ray's (shadow rays toward a point light: about 1e-15)
SHARED_END = 1e-9
#: float64's unit roundoff, with room for the few operations that compute a ray's end
_ULP = 4.0 * 2.0**-53


def planes(tri) -> np.ndarray:
    """(m, 4) float64 the plane of each of :func:`~explorer.geometry.rays.pack_triangles`' rows
    ``tri`` (m, 9) (``v0, e1, e2``): the unit normal ``n̂ = e1 × e2 / |e1 × e2|`` and ``n̂·v0``;
    all zero for a sliver (``|e1 × e2| < μ·|e1|·|e2|``) or a degenerate triangle, which is then
    never dropped."""
    e1, e2 = tri[:, 3:6], tri[:, 6:9]
    n = np.cross(e1, e2)
    length = np.sqrt(np.einsum("ij,ij->i", n, n))
    big = np.sqrt(np.einsum("ij,ij->i", e1, e1) * np.einsum("ij,ij->i", e2, e2))
    keep = length >= OCCLUDER_MARGIN * big
    out = np.zeros((len(tri), 4))
    out[keep, :3] = n[keep] / length[keep, None]
    out[:, 3] = np.einsum("ij,ij->i", out[:, :3], tri[:, 0:3])
    return out


def triangle_boxes(tri, pad: float) -> np.ndarray:
    """(m, 6) float32 (x0, x1, y0, y1, z0, z1) box of each row of ``tri`` (m, 9), grown by
    ``pad`` and rounded outward to float32: any union of them is a padded box of the BVH."""
    v = tri[:, 0:3]
    corners = np.stack([v, v + tri[:, 3:6], v + tri[:, 6:9]])
    lo = corners.min(axis=0) - pad
    hi = corners.max(axis=0) + pad
    lo32, hi32 = lo.astype(np.float32), hi.astype(np.float32)
    lo32 = np.where(lo32 > lo, np.nextafter(lo32, np.float32(-np.inf)), lo32)
    hi32 = np.where(hi32 < hi, np.nextafter(hi32, np.float32(np.inf)), hi32)
    box = np.empty((len(tri), 6), np.float32)
    box[:, 0::2], box[:, 1::2] = lo32, hi32
    return box


@nb.njit(cache=True, nogil=True, boundscheck=False)
def _ends(O, D, tmax):
    """(same direction, all ends finite, spread of the ends from the first, the first end,
    the largest ``|O| + tmax``, the largest ``|O|²``) of rays ``O, D`` (k, 3), ``tmax`` (k,)."""
    k = O.shape[0]
    L = np.empty(3)
    for a in range(3):
        L[a] = O[0, a] + tmax[0] * D[0, a]
    same, finite = True, True
    spread, reach, r2 = 0.0, 0.0, 0.0
    for r in range(k):
        o2 = 0.0
        big = 0.0
        for a in range(3):
            same = same and D[r, a] == D[0, a]
            e = O[r, a] + tmax[r] * D[r, a]
            spread = max(spread, abs(e - L[a]))
            o2 += O[r, a] * O[r, a]
            big = max(big, abs(O[r, a]))
        finite = finite and math.isfinite(tmax[r])
        reach = max(reach, big + tmax[r])
        r2 = max(r2, o2)
    return same, finite, spread, L, reach, r2


def shared_end(origins, directions, tmax) -> tuple[int, np.ndarray, float, float] | None:
    """Where the rays go, when they all go to one place.

    origins, directions : (k, 3) float64 C-contiguous; tmax : (k,) float64
    Returns (kind, L (3,), ε, r): kind 0 when every ray ends within ``ε`` of the point ``L``
    (``ε`` includes the rounding of ``O + tmax·D``), kind 1 when every direction is ``L``
    (ε = 0); ``r`` the origins' largest distance from the frame's origin. None otherwise.
    """
    if len(origins) == 0:
        return None
    same, finite, spread, L, reach, r2 = _ends(origins, directions, tmax)
    r = math.sqrt(r2)
    if same:
        return 1, np.array(directions[0], np.float64), 0.0, r
    if not finite or not spread <= SHARED_END * (1.0 + float(np.abs(L).max())):
        return None
    return 0, L, math.sqrt(3.0) * (spread + _ULP * reach), r


@nb.njit(cache=True, inline="always")
def _threshold(light):
    """The height ``h`` over a triangle's plane beyond which the light is in front of it with
    the margin: ``μ(|L| + 3R)`` (which bounds ``μ(|L - v0| + 2R)``) and ``2(ε + ulp)/μ`` for a
    point light, both grown by the rounding of ``h``; ``μ`` for a direction (see the module
    docstring)."""
    kind, L, eps, R = light
    mu = OCCLUDER_MARGIN
    if kind == 1:
        return mu
    size = math.sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2])
    slack = _ULP * (size + R)
    return max(mu * (size + 3.0 * R), 2.0 * (eps + slack) / mu) + 4.0 * slack


@nb.njit(cache=True, inline="always")
def _leaf_box(q, leaf, plane, tbox, light, low, out, i, o):
    """out[i, o:o + 6] the box of leaf ``q``'s triangles whose height ``h`` under the light
    (:func:`_threshold`) is at most ``low``: the ones that can block its rays; all +inf when
    there are none."""
    kind, L = light[0], light[1]
    lx, ly, lz = L[0], L[1], L[2]
    inf = np.float32(np.inf)
    x0 = y0 = z0 = inf
    x1 = y1 = z1 = -inf
    first = leaf[q, 0]
    for j in range(first, first + leaf[q, 1]):
        h = lx * plane[j, 0] + ly * plane[j, 1] + lz * plane[j, 2]
        if kind == 0:
            h -= plane[j, 3]
        if h > low:
            continue  # faces the light: cannot block its rays
        x0 = min(x0, tbox[j, 0])
        x1 = max(x1, tbox[j, 1])
        y0 = min(y0, tbox[j, 2])
        y1 = max(y1, tbox[j, 3])
        z0 = min(z0, tbox[j, 4])
        z1 = max(z1, tbox[j, 5])
    if x0 > x1:
        x0 = x1 = y0 = y1 = z0 = z1 = inf
    out[i, o], out[i, o + 1], out[i, o + 2] = x0, x1, y0
    out[i, o + 3], out[i, o + 4], out[i, o + 5] = y1, z0, z1


#: what :func:`_classify` says of the triangles under a child box
_MIXED, _ALL, _NONE = 0, 1, 2


@nb.njit(cache=True, inline="always")
def _classify(cbox, cone, i, s, light, low):
    """Whether every triangle under child ``s`` of node ``i`` has the light in front of it
    beyond ``low`` (_ALL: the child is left out), none has (_NONE: its boxes stay as built), or
    neither can be told from the child's box and normal cone (_MIXED).

    A triangle under the box (centre ``c``, half-diagonal ``r``) whose unit normal ``n̂`` is
    within angle ``θ`` of the cone's unit axis ``â`` has ``h = n̂·(L - v0) = n̂·w + n̂·(c - v0)
    >= |w| cos(φ + θ) - r`` for ``w = L - c`` at angle ``φ`` from ``â`` (``φ + θ <= π/2`` when
    it is positive); for a direction ``h = n̂·L >= cos(φ + θ)``. ``|w| cos φ`` and ``|w| sin
    φ`` come from the dot and the cross product with the stored axis, within 3e-7 |w| of the
    true axis' (float32): the bound must beat ``low`` by :data:`CONE_SLACK` of ``|w| + r``."""
    kind, L = light[0], light[1]
    o = 6 * s
    x0, x1 = np.float64(cbox[i, o]), np.float64(cbox[i, o + 1])
    y0, y1 = np.float64(cbox[i, o + 2]), np.float64(cbox[i, o + 3])
    z0, z1 = np.float64(cbox[i, o + 4]), np.float64(cbox[i, o + 5])
    if not (x0 <= x1 and y0 <= y1 and z0 <= z1):  # an empty box stays empty
        return _NONE
    wx, wy, wz, r = L[0], L[1], L[2], 0.0
    if kind == 0:
        hx, hy, hz = 0.5 * (x1 - x0), 0.5 * (y1 - y0), 0.5 * (z1 - z0)
        r = math.sqrt(hx * hx + hy * hy + hz * hz)
        wx, wy, wz = wx - 0.5 * (x0 + x1), wy - 0.5 * (y0 + y1), wz - 0.5 * (z0 + z1)
    c = 5 * s
    ax, ay, az = np.float64(cone[i, c]), np.float64(cone[i, c + 1]), np.float64(cone[i, c + 2])
    kappa, st = np.float64(cone[i, c + 3]), np.float64(cone[i, c + 4])  # cos θ, sin θ
    p = ax * wx + ay * wy + az * wz  # |w| cos φ
    cx, cy, cz = ay * wz - az * wy, az * wx - ax * wz, ax * wy - ay * wx
    q = math.sqrt(cx * cx + cy * cy + cz * cz)  # |w| sin φ
    slack = CONE_SLACK * (abs(wx) + abs(wy) + abs(wz) + r)
    if kappa > 0.0 and p * kappa - q * st - r > low + slack:
        return _ALL
    if st * p - kappa * q >= 0.0:  # φ <= θ: the light is within the cone
        return _MIXED
    if p * kappa + q * st + r < low - slack:  # |w| cos(φ - θ) + r: the highest h
        return _NONE
    return _MIXED


@nb.njit(cache=True, inline="always")
def _open(i, tree, cone, light, low, opened, out):
    """Classify the two children of node ``i`` (:func:`_classify`): left out (+inf), kept as
    built, boxed triangle by triangle (a leaf), or marked opened (an inner node)."""
    child, cbox, leaf, plane, tbox = tree
    for s in range(2):
        c = child[i, s]
        o = 6 * s
        kind = _classify(out, cone, i, s, light, low)  # out: the copy, still as built here
        if kind == _ALL:
            for a in range(6):
                out[i, o + a] = np.inf
        elif c < 0 and kind == _MIXED:
            _leaf_box(~c, leaf, plane, tbox, light, low, out, i, o)
        elif kind == _MIXED:
            opened[c] = 1


@nb.njit(cache=True, inline="always")
def _union(i, child, opened, out):
    """Node ``i``'s boxes of its opened children: the union of each one's two boxes."""
    for s in range(2):
        c = child[i, s]
        if c < 0 or not opened[c]:
            continue
        o = 6 * s
        for a in range(0, 6, 2):
            out[i, o + a] = np.inf
            out[i, o + a + 1] = -np.inf
        for h in range(0, 12, 6):
            if not out[c, h] <= out[c, h + 1] or out[c, h] == np.inf:  # empty
                continue
            for a in range(0, 6, 2):
                out[i, o + a] = min(out[i, o + a], out[c, h + a])
                out[i, o + a + 1] = max(out[i, o + a + 1], out[c, h + a + 1])
        if out[i, o] > out[i, o + 1]:
            for a in range(6):
                out[i, o + a] = np.inf


@nb.njit(cache=True, nogil=True, boundscheck=False)
def refit(r0, r1, roots, tree, cone, span, light, marks, out, lanes):
    """The boxes for the rays toward ``light`` in the subtrees of the opened inner nodes
    roots[r0:r1]: writes into out (k, 16) float32, a copy of tree's ``cbox``, the child boxes
    of every node opened there, each holding only the triangles under it that do not face the
    light with the margin (the module docstring); a box with nothing in it is all +inf (no ray
    enters it).

    tree = (child, cbox, leaf, plane, tbox); cone (k, 10) of :func:`cones`; span (k,): each
    inner node's subtree is the nodes ``i .. i + span[i] - 1``; light = (kind, L, ε, R): kind
    0 a point ``L``, 1 a direction ``L``; R bounds every corner's and origin's distance from the
    frame's origin; marks = (opened, order): opened (k,) uint8, 1 for the roots (and the nodes
    above them), 0 below; order (k,) int64 scratch (a subtree uses its own nodes' places);
    lanes = (slot, rows): the boxes of every node opened are copied into their lanes of the
    wide rows ``rows`` too (:func:`~explorer.geometry.traverse.to_lanes`).

    The walk goes down from each root: a child whose triangles all face the light
    (:func:`_classify`, by its normal cone) is left out whole, one whose triangles all face away
    keeps its subtree's boxes as built (skipped), and only the others are opened: a leaf among
    them boxes its triangles one by one, an inner node's box is the union of its children's.
    The boxes of nodes not opened stay as built."""
    child = tree[0]
    opened, order = marks
    low = _threshold(light)
    for j in range(r0, r1):
        root = roots[j]
        end = root + span[root]
        n = root
        i = root
        while i < end:
            if not opened[i]:
                i += span[i]  # a subtree kept as built, or left out
                continue
            order[n] = i
            n += 1
            _open(i, tree, cone, light, low, opened, out)
            i += 1
        for m in range(n - 1, root - 1, -1):  # children's boxes before their parents'
            _union(order[m], child, opened, out)
        for m in range(root, n):
            to_lanes(order[m], lanes[0], out, lanes[1])


@nb.njit(cache=True, nogil=True, boundscheck=False)
def refit_top(tree, cone, light, opened, out, depth):
    """:func:`refit` for the nodes less than ``depth`` levels below the root, without their
    unions (:func:`refit_unions`, after :func:`refit` below them). Returns (those nodes,
    parents first; the opened inner nodes ``depth`` levels down: the roots for :func:`refit`)."""
    child = tree[0]
    low = _threshold(light)
    top = np.empty(2**depth, np.int64)
    roots = np.empty(2**depth, np.int64)
    opened[0] = 1
    n = nr = 0
    level = np.zeros(1, np.int64)  # the nodes of this level
    for _ in range(depth):
        below = np.empty(2 * len(level), np.int64)
        nb_ = 0
        for i in level:
            top[n] = i
            n += 1
            _open(i, tree, cone, light, low, opened, out)
            for s in range(2):
                c = child[i, s]
                if c >= 0 and opened[c]:
                    below[nb_] = c
                    nb_ += 1
        level = below[:nb_]
    for i in level:
        roots[nr] = i
        nr += 1
    return top[:n], roots[:nr]


@nb.njit(cache=True, nogil=True, boundscheck=False)
def refit_unions(top, child, opened, out, lanes):
    """The unions of :func:`refit_top`'s nodes, children before parents, and their boxes in
    the wide rows (lanes = (slot, rows), as :func:`refit`)."""
    for m in range(len(top) - 1, -1, -1):
        _union(top[m], child, opened, out)
    for i in top:
        to_lanes(i, lanes[0], out, lanes[1])


@nb.njit(cache=True, boundscheck=False)
def cones(child, leaf, plane):
    """The normal cone of each child of each node: (k, 10) float32, ``cone[i, 5s:5s + 5]`` the
    unit axis (3,), ``cos θ`` and ``sin θ``: every triangle under child ``s`` of node ``i`` has
    its unit normal (``plane`` (m, 4) of :func:`planes`) within angle ``θ`` of the axis (the
    float64 axis the float32 one rounds); ``cos θ = -1`` (no bound) when a sliver is among them.
    Leaves are bounded triangle by triangle, inner nodes from their children's cones (wider by
    :data:`CONE_WIDEN` a level for the rounding of the angles); the stored angle is widened by
    :data:`CONE_ROUND` for its rounding to float32.

    child : (k, 2) int64 the tree (children after their parents); leaf : (q, 2) int64"""
    k, q = child.shape[0], leaf.shape[0]
    lsum = np.zeros((q, 3))  # sum of the normals, and κ about their direction
    lkap = np.empty(q)
    for lf in range(q):
        first, count = leaf[lf, 0], leaf[lf, 1]
        sliver = False
        for j in range(first, first + count):
            sliver = sliver or (plane[j, 0] == 0.0 and plane[j, 1] == 0.0 and plane[j, 2] == 0.0)
            for a in range(3):
                lsum[lf, a] += plane[j, a]
        length = math.sqrt(lsum[lf, 0] ** 2 + lsum[lf, 1] ** 2 + lsum[lf, 2] ** 2)
        kap = -1.0
        if not sliver and length > 0.0:
            kap = 1.0
            for j in range(first, first + count):
                d = (lsum[lf, 0] * plane[j, 0] + lsum[lf, 1] * plane[j, 1]
                     + lsum[lf, 2] * plane[j, 2]) / length  # fmt: skip
                kap = min(kap, d)
        lkap[lf] = kap
    nsum = np.zeros((k, 3))
    nkap = np.empty(k)
    out = np.empty((k, 10), np.float32)
    for i in range(k - 1, -1, -1):
        for s in range(2):  # each child's own cone, as the node stores it
            c = child[i, s]
            sc = lsum[~c] if c < 0 else nsum[c]
            kc = lkap[~c] if c < 0 else nkap[c]
            lc = math.sqrt(sc[0] ** 2 + sc[1] ** 2 + sc[2] ** 2)
            for a in range(3):
                out[i, 5 * s + a] = sc[a] / lc if lc > 0.0 else 0.0
                nsum[i, a] += sc[a]
            kc = kc - CONE_ROUND if kc > -1.0 and lc > 0.0 else -1.0
            out[i, 5 * s + 3] = kc
            out[i, 5 * s + 4] = min(math.sqrt(max(1.0 - kc * kc, 0.0)) + CONE_ROUND, 1.0)
        length = math.sqrt(nsum[i, 0] ** 2 + nsum[i, 1] ** 2 + nsum[i, 2] ** 2)
        kap = 1.0
        for s in range(2):  # the node's cone about the sum of its normals holds both
            c = child[i, s]
            sc = lsum[~c] if c < 0 else nsum[c]
            kc = lkap[~c] if c < 0 else nkap[c]
            lc = math.sqrt(sc[0] ** 2 + sc[1] ** 2 + sc[2] ** 2)
            if kc <= -1.0 or not lc > 0.0 or not length > 0.0:
                kap = -1.0
                continue
            g = (nsum[i, 0] * sc[0] + nsum[i, 1] * sc[1] + nsum[i, 2] * sc[2]) / (length * lc)
            g = min(max(g, -1.0), 1.0)
            if g < -kc:  # the two angles add up beyond π: no bound
                kap = -1.0
                continue
            both = g * kc - math.sqrt(1.0 - g * g) * math.sqrt(max(1.0 - kc * kc, 0.0))
            kap = min(kap, both - CONE_WIDEN)
        nkap[i] = max(kap, -1.0)
    return out


@nb.njit(cache=True, boundscheck=False)
def spans(child):
    """(k,) int64 the number of inner nodes in each inner node's subtree (itself included) of
    ``child`` (k, 2) in depth-first order: the subtree of ``i`` is ``i .. i + span[i] - 1``."""
    k = child.shape[0]
    span = np.ones(k, np.int64)
    for i in range(k - 1, -1, -1):
        for s in range(2):
            if child[i, s] >= 0:
                span[i] += span[child[i, s]]
    return span
