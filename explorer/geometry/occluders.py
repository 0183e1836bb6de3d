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
or their directions are equal), :func:`leaf_boxes` boxes each leaf's triangles that do not face
it with a margin, and :func:`node_boxes` gives the hierarchy's child boxes from those; the tree
itself (children, leaves, triangle rows) is kept, so the casts run unchanged on the new boxes.

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

from explorer.core.tolerances import OCCLUDER_MARGIN

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


@nb.njit(cache=True, boundscheck=False)
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


@nb.njit(cache=True, nogil=True, boundscheck=False)
def leaf_boxes(q0, q1, leaf, plane, tbox, light, lbox):
    """Leaves q0..q1: lbox[q] (6,) float32 the box of leaf ``q``'s triangles that do not face
    the light with the margin (see the module docstring); empty (x0 > x1) when none.
    plane : (m, 4) :func:`planes`; light = (kind, L, ε, R): kind 0 a point ``L``, 1 a
    direction ``L``; R bounds every corner's and origin's distance from the frame's origin.

    A triangle faces a point light when ``h = n̂·L - n̂·v0`` exceeds ``μ(|L| + 3R)`` (which
    bounds ``μ(|L - v0| + 2R)``) and ``2(ε + ulp)/μ``, both grown by the rounding of ``h``."""
    kind, L, eps, R = light
    mu = OCCLUDER_MARGIN
    lx, ly, lz = L[0], L[1], L[2]
    size = math.sqrt(lx * lx + ly * ly + lz * lz)
    slack = _ULP * (size + R)
    low = max(mu * (size + 3.0 * R), 2.0 * (eps + slack) / mu) + 4.0 * slack
    if kind == 1:
        low = mu
    inf = np.float32(np.inf)
    for q in range(q0, q1):
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
        lbox[q, 0], lbox[q, 1], lbox[q, 2] = x0, x1, y0
        lbox[q, 3], lbox[q, 4], lbox[q, 5] = y1, z0, z1


@nb.njit(cache=True, boundscheck=False)
def node_boxes(child, lbox):
    """The child boxes (k, 12) float32 of the tree ``child`` (k, 2) whose leaves' boxes are
    ``lbox`` (q, 6): each node's box the union of its children's; a box with nothing in it is
    all +inf (no ray enters it)."""
    inf = np.float32(np.inf)
    k = child.shape[0]
    nbox = np.empty((k, 6), np.float32)
    cbox = np.empty((k, 12), np.float32)
    for i in range(k - 1, -1, -1):  # children come after their parent (depth-first order)
        for a in range(0, 6, 2):
            nbox[i, a] = inf
            nbox[i, a + 1] = -inf
        for s in range(2):
            c = child[i, s]
            o = 6 * s
            for a in range(6):
                cbox[i, o + a] = lbox[~c, a] if c < 0 else nbox[c, a]
            if cbox[i, o] > cbox[i, o + 1]:  # empty
                for a in range(6):
                    cbox[i, o + a] = inf
                continue
            for a in range(0, 6, 2):
                nbox[i, a] = min(nbox[i, a], cbox[i, o + a])
                nbox[i, a + 1] = max(nbox[i, a + 1], cbox[i, o + a + 1])
    return cbox
