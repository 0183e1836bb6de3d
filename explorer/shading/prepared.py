"""The compiled tier's geometry: the normalised frame; for a kept shader, positions and unit
normals as (6, n) rows in the working precision (:func:`explorer.shading.kernels.prepare`); for a
one-shot pass, the caller's vertices as they are (:func:`vertices`: the pass prepares each block
as it reaches it, so that no full-size copy is written); and light culling's chunk bounds of
either.
"""

from __future__ import annotations

import numpy as np

from explorer.geometry.frame import check_finite, frame_from_extent, frame_of, scale_normals
from explorer.shading import kernels as K
from explorer.shading import layout

#: light culling is kept for a mesh where one chunk of vertices in this many or more has a
#: normal cone narrower than 90° (only such chunks can ever be skipped)
CULL_MIN_SHARE = 8
#: :func:`chunk_bounds` tests that share on every CULL_SAMPLE-th chunk before it finds them all
CULL_SAMPLE = 16


def frame_of_positions(P) -> tuple:
    """(centre, scale) of the normalised frame of positions ``P`` (n, 3) (:func:`frame_of`),
    their extent found in one compiled pass that tests them too: a NaN or an infinite value
    raises the error of :func:`~explorer.geometry.frame.check_finite` naming the first one."""
    if not len(P):
        return frame_of(P)
    lohi = K.extent(readonly(P))  # (all NaN when some coordinate is not finite)
    if np.isnan(lohi[0, 0]):
        check_finite("positions", P)
    return frame_from_extent(*lohi)


def prepared_geometry(P, N, dtype, k, bounds: bool = True) -> tuple:
    """The compiled tier's geometry of positions ``P`` and normals ``N`` (n, 3) in precision
    ``dtype`` (``k``: its constants): (centre, scale) of the normalised frame (:func:`frame_of`,
    the extent found in one compiled pass), ``G`` (6, n) (:func:`explorer.shading.kernels.prepare`),
    the chunk bounds (:func:`chunk_bounds`; ``bounds`` False, a shader that does not cull: none,
    two passes fewer) and the normals as prepared: ``N``, or scaled into NORMAL_RANGE where
    some lay outside it (prepare tests what scale_normals would).
    These passes test the values too: a NaN or an infinite value raises the error of
    :func:`~explorer.geometry.frame.check_finite` naming the first such vertex."""
    centre, scale = frame_of_positions(P)
    G = np.empty((6, len(P)), dtype)
    frame = (centre, 1.0 / scale, k)
    if K.prepare(readonly(P), readonly(N), *frame, G):  # (NaN and inf are outside too)
        check_finite("normals", N)
        N = scale_normals(N)
        K.prepare(readonly(P), readonly(N), *frame, G)
    found = chunk_bounds(rows(G), k) if bounds else readonly(np.empty((layout.N_BOUNDS, 0)))
    return centre, scale, G, found, N


def geometry_of(P, N, dtype, k, whole: bool = True, bounds: bool = True) -> tuple:
    """(centre, scale, G, bounds, N): :func:`prepared_geometry` (``bounds``: whether to find
    the chunk bounds); ``whole`` False (a one-shot shader, whose pass prepares each block as it
    shades: :func:`vertices`): the frame alone, (centre, scale, None, None, None)."""
    if whole:
        return prepared_geometry(P, N, dtype, k, bounds)
    return (*frame_of_positions(P), None, None, None)


def vertices(P, N, centre, scale, dtype) -> K.Source:
    """Positions ``P`` and normals ``N`` (n, 3) (one dtype, float32 or float64) in the frame
    ``centre``, ``scale`` as a one-shot pass in precision ``dtype`` takes them
    (:class:`explorer.shading.kernels.Source`, read-only; no prepared rows)."""
    P, N = readonly(P), readonly(N)
    wide = P.dtype == np.float64
    return K.Source(
        np.empty((6, 0), dtype),
        P if wide else _NONE[np.float64],
        N if wide else _NONE[np.float64],
        _NONE[np.float32] if wide else P,
        _NONE[np.float32] if wide else N,
        np.array(centre, np.float64),  # (a writable copy: one record type, see rows)
        1.0 / scale,
    )


def rows(G) -> K.Source:
    """The prepared rows ``G`` (6, n) (:func:`prepared_geometry`) as a pass takes them
    (:class:`explorer.shading.kernels.Source`; the same record type as :func:`vertices`)."""
    none64, none32 = _NONE[np.float64], _NONE[np.float32]
    return K.Source(G, none64, none64, none32, none32, np.zeros(3), 1.0)


def chunk_bounds(src, k) -> np.ndarray:
    """(N_BOUNDS, ceil(n / CHUNK)) float64 bounds of each chunk of consecutive vertices of a
    pass's geometry ``src``: the prepared G (6, n), or :func:`vertices` (the same bounds; ``k``:
    the working precision's constants), for light culling (see
    :func:`explorer.shading.kernels.bounds`), read-only; (N_BOUNDS, 0) when fewer than one chunk
    in CULL_MIN_SHARE has a normal cone narrower than 90° (shuffled vertices, say): too little
    could be culled to pay for the tests. Every CULL_SAMPLE-th chunk is found first
    (:func:`sample_bounds`): when those already fall short, the rest are not (on vertices in no
    particular order most of the bounds' cost)."""
    sample = sample_bounds(src, k)[layout.B_COS]
    if np.count_nonzero(sample > 0) * CULL_MIN_SHARE < sample.size:
        return readonly(np.empty((layout.N_BOUNDS, 0)))
    n = src.G.shape[1] + len(src.P) + len(src.P32)  # (two of them are empty)
    b = np.empty((layout.N_BOUNDS, -(-n // K.CHUNK)), np.float64)
    K.bounds(src, k, b, 1)
    if np.count_nonzero(b[layout.B_COS] > 0) * CULL_MIN_SHARE < b.shape[1]:
        b = b[:, :0]
    return readonly(b)


def sample_bounds(src, k) -> np.ndarray:
    """The :func:`chunk_bounds` columns of chunks 0, CULL_SAMPLE, 2·CULL_SAMPLE ... (the whole
    chunks; chunk 0 when none is whole), (N_BOUNDS, m) float64, found on a compact copy of
    those chunks' vertices (or prepared rows) rather than in place: in place, each sampled chunk
    is a cache miss of its own and the full-size bounds array is written sparsely (every page
    of it touched, for a sample): 1.9 ms against 0.8 on a million vertices, one thread."""
    n = src.G.shape[1] + len(src.P) + len(src.P32)  # (two of them are empty)
    whole = n // K.CHUNK * K.CHUNK or n
    part = src._replace(
        G=_sampled(src.G.T, whole).T,
        P=_sampled(src.P, whole),
        N=_sampled(src.N, whole),
        P32=_sampled(src.P32, whole),
        N32=_sampled(src.N32, whole),
    )
    m = part.G.shape[1] + len(part.P) + len(part.P32)
    b = np.empty((layout.N_BOUNDS, -(-m // K.CHUNK)), np.float64)
    K.bounds(part, k, b, 1)
    return b


def _sampled(a, whole: int) -> np.ndarray:
    """Rows 0 to ``whole`` of ``a`` (n, c) in chunks of CHUNK, every CULL_SAMPLE-th chunk of
    them, as a copy in ``a``'s memory order, as writable as ``a`` (one numba type: no
    compile); ``a`` itself when empty."""
    if not len(a):
        return a
    chunks = a[:whole].reshape(-1, min(K.CHUNK, whole), a.shape[1])[::CULL_SAMPLE]
    out = np.array(chunks.reshape(-1, a.shape[1]), order="K")
    out = np.ascontiguousarray(out) if a.flags.c_contiguous else np.asfortranarray(out)
    out.flags.writeable = a.flags.writeable
    return out


def readonly(a: np.ndarray) -> np.ndarray:
    """A read-only view (the engine keeps the writable base private, so kernels get one
    array type and compile once)."""
    v = a.view()
    v.flags.writeable = False
    return v


#: the absent vertices of a :class:`~explorer.shading.kernels.Source`, by dtype: (0, 3) read-only
_NONE = {t: readonly(np.empty((0, 3), t)) for t in (np.float64, np.float32)}
