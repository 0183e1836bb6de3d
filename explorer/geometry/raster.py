"""The per-pixel G-buffer, compiled: which triangle each pixel centre shows, then the surface
point, barycentrics and interpolated normal there, in parallel passes over the picture.

:func:`gbuffer` is what :meth:`explorer.render.live.LivePixels.gbuffer` runs on a camera change
(through :func:`explorer.render.perpixel.compiled_hits`, which gives it the camera's basis) once
the compiled kernels serve (``gbuffer_method`` "auto" while
:func:`explorer.shading.tiers.loaded`, or "compiled"; the background compile,
:mod:`explorer.shading.warm`, compiles it with the engine's kernels): a z-buffer rasteriser
that samples each pixel at its centre, as OpenGL does. Before that, and for a frame it leaves
(see :func:`_setup`), the G-buffer is VTK's picture of triangle indices
(:mod:`explorer.render.faceids`) and the numpy arithmetic of
:func:`explorer.render.perpixel.raster_hits`. When it came, a camera frame of the
100,578-vertex teapot at 800x600 cost about 70 ms of CPU that way under load and 20-30 this
way; docs/perpixel_bench.md gives the compiled G-buffer's share of a camera frame today.

- :func:`_setup` puts every vertex in pixel units (``explorer.render.camera.project``'s
  numbers: pixel centres at whole numbers, row 0 at the top) with the depth key ``1/z``
  (perspective: affine in the picture, so it interpolates exactly across a triangle) or ``-z``
  (parallel), larger nearer, then finds each triangle's rows and columns of pixel centres,
  clamped to the picture (a triangle of no area, or with no pixel centre, gets none). It
  counts the vertices outside the camera's clipping range or not finite; one such vertex and
  :func:`gbuffer` returns None, and the caller leaves the frame to VTK (whose clipping this
  rasteriser does not copy).
- :func:`_bins` lists each horizontal band's triangles (a triangle over several bands is in
  each), in index order.
- :func:`_raster` draws the triangles into the bands, one band per task
  (:data:`BANDS_PER_THREAD` bands a thread; no two tasks write one pixel; each reads only its
  own triangles), keeping at each pixel the triangle with the largest depth key. A pixel
  centre is inside when its three edge functions have the sign of the triangle's area;
  exactly on an edge, the top-left rule decides. Each edge function is computed from its two
  ends in the order of their vertex indices, so two triangles that share an edge get exactly
  opposite values: a centre on a shared edge or a shared corner belongs to exactly one of them
  (no gap, no double hit; as OpenGL's rasterisation rules ask of any rasteriser). Each band
  then counts its rows' pixels whose ray meets its triangle's plane: a ray that runs along the
  plane (Möller-Trumbore's determinant within DET_EPS of 0) makes its pixel a miss, as in
  :func:`~explorer.render.perpixel.raster_hits`.
- :func:`_hits` gives, per covered pixel in row-major order, the Möller-Trumbore arithmetic of
  :func:`explorer.render.perpixel.raster_hits` on the pixel's own ray and triangle (the same
  numbers: the ray of ``explorer.render.camera.pixel_rays``, the point ``O + t·D``, the normal
  ``(1-u-v)·n0 + u·n1 + v·n2`` normalised, one shorter than SURFACE_NORMAL_MIN made zero).

Two parallel regions a frame (:func:`_raster`, :func:`_hits`): under load each costs the
threads' wake-up and spin on top of the work, so the small passes (:func:`_setup`,
:func:`_bins`) run on one thread.

Coverage is that of any OpenGL rasteriser up to where a pixel centre lies within rounding of an
edge (VTK's llvmpipe snaps vertices to 1/256 pixel and draws in float32): a few silhouette pixels
of a large mesh may differ from VTK's picture, as they already may between two VTK windows that
draw the mesh in different frames (:mod:`explorer.app.pixellayer` fills such pixels).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from explorer.core.tolerances import DET_EPS, SURFACE_NORMAL_MIN
from explorer.geometry import kernelcache  # noqa: F401 - before the decorators: the cache key

#: picture bands per thread of :func:`_raster` (more bands: a better share of the work between
#: the threads when the mesh covers some bands more than others)
BANDS_PER_THREAD = 4


@nb.njit(cache=True, nogil=True, boundscheck=False)
def _setup(P, F, cam, persp, w, h, X, Y, Q, spans):
    """Vertices ``P`` (n, 3) float64 into pixel units ``X`` (columns), ``Y`` (rows) and the
    depth key ``Q``, ``cam`` (18,) as :func:`gbuffer` takes it; then each triangle's pixel
    centres' rows and columns, ``spans`` (m, 4) int32: first row, last row, first column,
    last column (inclusive; first row -1: none, or no area). One thread (a parallel region
    costs more than these passes under load). Returns how many vertices lie outside
    [near, far] along the view direction or project to no finite point (then no spans)."""
    bad = 0
    for i in range(P.shape[0]):
        rx, ry, rz = P[i, 0] - cam[0], P[i, 1] - cam[1], P[i, 2] - cam[2]
        x = rx * cam[3] + ry * cam[4] + rz * cam[5]
        y = rx * cam[6] + ry * cam[7] + rz * cam[8]
        z = rx * cam[9] + ry * cam[10] + rz * cam[11]
        if persp:
            nx, ny = x / (z * cam[12]), y / (z * cam[13])
            Q[i] = 1.0 / z
        else:
            nx, ny = x / cam[12], y / cam[13]
            Q[i] = -z
        nx, ny = nx - cam[14], ny - cam[15]
        X[i] = (nx + 1.0) * (w / 2.0) - 0.5
        Y[i] = (1.0 - ny) * (h / 2.0) - 0.5
        inside = z >= cam[16] and z <= cam[17]
        if not (inside and math.isfinite(X[i]) and math.isfinite(Y[i]) and math.isfinite(Q[i])):
            bad += 1
    if bad:
        return bad
    for f in range(F.shape[0]):
        a, b, c = F[f, 0], F[f, 1], F[f, 2]
        # (clamped to the picture before rounding: a vertex far off it stays a small number)
        x0, x1 = max(min(X[a], X[b], X[c]), 0.0), min(max(X[a], X[b], X[c]), w - 1.0)
        y0, y1 = max(min(Y[a], Y[b], Y[c]), 0.0), min(max(Y[a], Y[b], Y[c]), h - 1.0)
        area = (X[b] - X[a]) * (Y[c] - Y[a]) - (Y[b] - Y[a]) * (X[c] - X[a])
        r0, r1, c0, c1 = math.ceil(y0), math.floor(y1), math.ceil(x0), math.floor(x1)
        if area == 0.0 or r0 > r1 or c0 > c1:
            spans[f, 0] = -1
        else:
            spans[f, 0], spans[f, 1], spans[f, 2], spans[f, 3] = r0, r1, c0, c1
    return 0


@nb.njit(inline="always")
def _ray(r, c, w, h, cam, persp, O, D):
    """The ray through pixel (r, c)'s centre into ``O``, ``D`` (3,): the numbers of
    ``explorer.render.camera.pixel_rays``."""
    sx = (2.0 * (c + 0.5)) / w - 1.0 + cam[14]
    sy = 1.0 - (2.0 * (r + 0.5)) / h + cam[15]
    if persp:
        n = 0.0
        for k in range(3):
            O[k] = cam[k]
            D[k] = cam[9 + k] + sx * cam[12] * cam[3 + k] + sy * cam[13] * cam[6 + k]
            n += D[k] * D[k]
        n = math.sqrt(n)
        for k in range(3):
            D[k] /= n
    else:
        for k in range(3):
            O[k] = cam[k] + sx * cam[12] * cam[3 + k] + sy * cam[13] * cam[6 + k]
            D[k] = cam[9 + k]


@nb.njit(inline="always")
def _plane(P, F, f, O, D):
    """Möller-Trumbore without the inside test (:func:`explorer.render.perpixel.raster_hits`):
    (det, u, v, t) of the ray ``O``, ``D`` on triangle ``f``'s plane."""
    i0, i1, i2 = F[f, 0], F[f, 1], F[f, 2]
    a0, a1, a2 = P[i0, 0], P[i0, 1], P[i0, 2]
    e10, e11, e12 = P[i1, 0] - a0, P[i1, 1] - a1, P[i1, 2] - a2
    e20, e21, e22 = P[i2, 0] - a0, P[i2, 1] - a1, P[i2, 2] - a2
    d0, d1, d2 = D[0], D[1], D[2]
    p0, p1, p2 = d1 * e22 - d2 * e21, d2 * e20 - d0 * e22, d0 * e21 - d1 * e20
    det = e10 * p0 + e11 * p1 + e12 * p2
    inv = 1.0 / det if abs(det) > DET_EPS else 1.0
    s0, s1, s2 = O[0] - a0, O[1] - a1, O[2] - a2
    q0, q1, q2 = s1 * e12 - s2 * e11, s2 * e10 - s0 * e12, s0 * e11 - s1 * e10
    u = (s0 * p0 + s1 * p1 + s2 * p2) * inv
    v = (d0 * q0 + d1 * q1 + d2 * q2) * inv
    t = (e20 * q0 + e21 * q1 + e22 * q2) * inv
    return det, u, v, t


@nb.njit(inline="always")
def _edge(ia, ib, X, Y, s):
    """The edge from vertex ``ia`` to ``ib`` of a triangle whose area has the sign ``s``, as
    (x0, y0, dx, dy, sign, top_left): its edge function at (px, py) is
    ``sign * (dx * (py - y0) - dy * (px - x0))``, computed from its ends in the order of their
    indices (so that the edge's other triangle gets exactly the opposite value: a negation is
    exact); ``top_left``: the edge, directed with the triangle's interior on its positive side,
    is a top or a left one (the top-left rule: of two triangles sharing the edge, exactly one
    owns a pixel centre on it)."""
    if ia < ib:
        x0, y0, dx, dy, sign = X[ia], Y[ia], X[ib] - X[ia], Y[ib] - Y[ia], 1.0
    else:
        x0, y0, dx, dy, sign = X[ib], Y[ib], X[ia] - X[ib], Y[ia] - Y[ib], -1.0
    tx, ty = s * sign * dx, s * sign * dy  # (the edge ia -> ib, interior on its left)
    return x0, y0, dx, dy, sign, ty > 0.0 or (ty == 0.0 and tx < 0.0)


@nb.njit(cache=True, nogil=True, boundscheck=False)
def _bins(spans, bands, size):
    """Each band's triangles (those with pixel centres among its ``size`` rows), in index
    order: (starts (bands + 1,), triangles): band b's are ``triangles[starts[b]:starts[b+1]]``
    (a triangle over several bands is in each)."""
    starts = np.zeros(bands + 1, np.int64)
    for f in range(spans.shape[0]):
        if spans[f, 0] >= 0:
            for band in range(spans[f, 0] // size, spans[f, 1] // size + 1):
                starts[band + 1] += 1
    for band in range(bands):
        starts[band + 1] += starts[band]
    fill = starts[:-1].copy()
    out = np.empty(starts[bands], np.int64)
    for f in range(spans.shape[0]):
        if spans[f, 0] >= 0:
            for band in range(spans[f, 0] // size, spans[f, 1] // size + 1):
                out[fill[band]] = f
                fill[band] += 1
    return starts, out


@nb.njit(cache=True, nogil=True, parallel=True, boundscheck=False)
def _raster(P, F, screen, view, bins, out):
    """Draw the triangles into ``ids`` (h, w) int64 (-1: none) with the depth test on
    ``depth`` (h, w) float64, one horizontal band per task (its triangles: :func:`_bins`'
    ``starts``, ``order``); then per row, how many pixels hit their triangle's plane
    (``counts`` (h,)): a pixel whose ray runs within DET_EPS of the plane is made a miss (-1).
    ``screen``: (X, Y, Q, spans) of :func:`_setup`; ``view``: (cam, persp); ``bins``:
    (starts, order); ``out``: (ids, depth, counts).
    A pixel centre is inside when its three edge functions have the sign of the triangle's
    area, or one is zero and its edge is a top-left one (:func:`_edge`)."""
    X, Y, Q, spans = screen
    cam, persp = view
    starts, order = bins
    ids, depth, counts = out
    h, w = ids.shape
    bands = len(starts) - 1
    size = -(-h // bands)
    for band in nb.prange(bands):
        top, bottom = band * size, min((band + 1) * size, h) - 1
        for r in range(top, bottom + 1):
            for c in range(w):
                ids[r, c] = -1
                depth[r, c] = -np.inf
        for j in range(starts[band], starts[band + 1]):
            f = order[j]
            a, b, c3 = F[f, 0], F[f, 1], F[f, 2]
            area = (X[b] - X[a]) * (Y[c3] - Y[a]) - (Y[b] - Y[a]) * (X[c3] - X[a])
            s = 1.0 if area > 0.0 else -1.0
            ax, ay, adx, ady, asg, atl = _edge(b, c3, X, Y, s)  # (the weight of corner a)
            bx, by, bdx, bdy, bsg, btl = _edge(c3, a, X, Y, s)
            cx, cy, cdx, cdy, csg, ctl = _edge(a, b, X, Y, s)
            qa, qb, qc = Q[a], Q[b], Q[c3]
            for r in range(max(spans[f, 0], top), min(spans[f, 1], bottom) + 1):
                py = float(r)
                for c in range(spans[f, 2], spans[f, 3] + 1):
                    px = float(c)
                    ea = asg * (adx * (py - ay) - ady * (px - ax))
                    v = s * ea
                    if v < 0.0 or (v == 0.0 and not atl):
                        continue
                    eb = bsg * (bdx * (py - by) - bdy * (px - bx))
                    v = s * eb
                    if v < 0.0 or (v == 0.0 and not btl):
                        continue
                    ec = csg * (cdx * (py - cy) - cdy * (px - cx))
                    v = s * ec
                    if v < 0.0 or (v == 0.0 and not ctl):
                        continue
                    q = (ea * qa + eb * qb + ec * qc) / area
                    if q > depth[r, c]:
                        depth[r, c] = q
                        ids[r, c] = f
        O, D = np.empty(3), np.empty(3)
        for r in range(top, bottom + 1):
            k = 0
            for c in range(w):
                f = ids[r, c]
                if f < 0:
                    continue
                _ray(r, c, w, h, cam, persp, O, D)
                if abs(_plane(P, F, f, O, D)[0]) > DET_EPS:
                    k += 1
                else:
                    ids[r, c] = -1
            counts[r] = k


@nb.njit(cache=True, nogil=True, parallel=True, boundscheck=False)
def _hits(P, N, F, view, ids, starts, out):
    """Per covered pixel (row-major; row r's first at ``starts[r]``): its flat index, triangle,
    (u, v), point and unit interpolated normal, into ``out`` (pixels, tri, uv, pos, nrm);
    ``view``: (cam, persp)."""
    cam, persp = view
    pixels, tri, uv, pos, nrm = out
    h, w = ids.shape
    for r in nb.prange(h):
        O, D = np.empty(3), np.empty(3)
        k = starts[r]
        for c in range(w):
            f = ids[r, c]
            if f < 0:
                continue
            _ray(r, c, w, h, cam, persp, O, D)
            _, u, v, t = _plane(P, F, f, O, D)
            pixels[k], tri[k], uv[k, 0], uv[k, 1] = r * w + c, f, u, v
            i0, i1, i2 = F[f, 0], F[f, 1], F[f, 2]
            a = 1.0 - u - v
            length = 0.0
            for j in range(3):
                pos[k, j] = O[j] + t * D[j]
                nrm[k, j] = a * N[i0, j] + u * N[i1, j] + v * N[i2, j]
                length += nrm[k, j] * nrm[k, j]
            length = math.sqrt(length)
            for j in range(3):
                nrm[k, j] = nrm[k, j] / length if length > SURFACE_NORMAL_MIN else 0.0
            k += 1


def gbuffer(positions, normals, faces, cam, persp: bool, size) -> tuple | None:
    """The G-buffer of a mesh (see the module docstring), or None when some vertex lies outside
    the camera's clipping range or projects to no finite point (VTK's picture then decides).

    positions, normals : (n, 3) float64; faces : (m, 3) int64
    cam : (18,) float64: position, right, up, forward (unit), the view's half extents
        (perspective: tan(angle / 2)·aspect, tan(angle / 2); parallel: scale·aspect, scale), the
        window centre, the clipping range (near, far)
    size : (width, height)
    Returns (mask (h, w) bool, pixels (k,) int64 flat indices of the covered pixels in row-major
    order, triangles (k,) int64, barycentrics (k, 2), positions (k, 3), normals (k, 3)).
    """
    w, h = (int(v) for v in size)
    P = np.ascontiguousarray(positions, np.float64)
    N = np.ascontiguousarray(normals, np.float64)
    F = np.ascontiguousarray(faces, np.int64).reshape(-1, 3)
    cam = np.ascontiguousarray(cam, np.float64)
    X, Y, Q = np.empty(len(P)), np.empty(len(P)), np.empty(len(P))
    spans = np.empty((len(F), 4), np.int32)
    if _setup(P, F, cam, persp, w, h, X, Y, Q, spans):
        return None
    ids, depth, counts = np.empty((h, w), np.int64), np.empty((h, w)), np.empty(h, np.int64)
    bands = max(1, min(h, nb.get_num_threads() * BANDS_PER_THREAD))
    starts, order = _bins(spans, bands, -(-h // bands))
    view = (cam, persp)
    _raster(P, F, (X, Y, Q, spans), view, (starts, order), (ids, depth, counts))
    starts = np.zeros(h, np.int64)
    np.cumsum(counts[:-1], out=starts[1:])
    k = int(counts.sum())
    pixels, tri = np.empty(k, np.int64), np.empty(k, np.int64)
    uv, pos, nrm = np.empty((k, 2)), np.empty((k, 3)), np.empty((k, 3))
    _hits(P, N, F, view, ids, starts, (pixels, tri, uv, pos, nrm))
    return ids >= 0, pixels, tri, uv, pos, nrm
