"""The compiled tier's geometry: the normalised frame; for a kept shader, positions and unit
normals as (6, n) rows in the working precision (:func:`explorer.shading.kernels.prepare`); for a
one-shot pass, the caller's vertices as they are (:func:`vertices`: the pass prepares each block
as it reaches it, so that no full-size copy is written); and light culling's chunk bounds of
either.
"""

from __future__ import annotations

import sys

import numba
import numpy as np

from explorer.geometry.frame import check_finite, frame_from_extent, frame_of, scale_normals
from explorer.shading import kernels as K
from explorer.shading import layout

#: light culling is kept for a mesh where one chunk of vertices in this many or more has a
#: normal cone narrower than 90° (only such chunks can ever be skipped)
CULL_MIN_SHARE = 8
#: :func:`chunk_bounds` tests that share on every CULL_SAMPLE-th chunk before it finds them all
CULL_SAMPLE = 16
#: ... or on fewer, evenly spaced: at most about this many chunks (:func:`sample_step`). At the
#: share's threshold (one in CULL_MIN_SHARE) 512 chunks hold 64 narrow ones on average, with a
#: standard deviation of 7.5: enough to tell; on a million vertices, every 16th chunk was 1,953
#: chunks, whose bounds took 0.6 ms of CPU, more than half the frame's extent pass
CULL_SAMPLES = 512


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


def prepared_geometry(P, N, dtype, k, bounds: bool = True, memory=None) -> tuple:
    """The compiled tier's geometry of positions ``P`` and normals ``N`` (n, 3) in precision
    ``dtype`` (``k``: its constants): (centre, scale) of the normalised frame (:func:`frame_of`,
    the extent found in one compiled pass), ``G`` (6, n) (:func:`explorer.shading.kernels.prepare`),
    the chunk bounds (:func:`chunk_bounds`; ``bounds`` False, a shader that does not cull: none,
    two passes fewer) and the normals as prepared: ``N``, or scaled into NORMAL_RANGE where
    some lay outside it (prepare tests what scale_normals would).
    These passes test the values too: a NaN or an infinite value raises the error of
    :func:`~explorer.geometry.frame.check_finite` naming the first such vertex. ``memory``: a
    :class:`RowMemory` to take G from (a kept shader's), else G is new."""
    centre, scale = frame_of_positions(P)
    G = np.empty((6, len(P)), dtype) if memory is None else memory.rows(len(P), dtype)
    frame = (centre, 1.0 / scale, k)
    if K.prepare(readonly(P), readonly(N), *frame, G):  # (NaN and inf are outside too)
        check_finite("normals", N)
        N = scale_normals(N)
        K.prepare(readonly(P), readonly(N), *frame, G)
    found = chunk_bounds(rows(G), k) if bounds else readonly(np.empty((layout.N_BOUNDS, 0)))
    return centre, scale, G, found, N


def geometry_of(P, N, dtype, k, whole: bool = True, bounds: bool = True, memory=None) -> tuple:
    """(centre, scale, G, bounds, N): :func:`prepared_geometry` (``bounds``: whether to find
    the chunk bounds; ``memory``: G's); ``whole`` False (a one-shot shader, whose pass prepares
    each block as it shades: :func:`vertices`): the frame alone, (centre, scale, None, None,
    None)."""
    if whole:
        return prepared_geometry(P, N, dtype, k, bounds, memory)
    return (*frame_of_positions(P), None, None, None)


class RowMemory:
    """The memory of a kept shader's prepared rows G (6, n), kept from one geometry to the next.

    A new G of 48 MB (a million float64 vertices) is above glibc's largest threshold for
    mapping memory afresh (32 MB), so each was new pages from the kernel, zeroed and faulted
    in by the threads that first wrote them: 8 ms of CPU for 48 MB, and 40-47 ms of wall clock
    for two threads faulting at once on the 2-core VM, where preparing into warm memory takes
    5 ms. Here G is a (6, n) view of a flat buffer of this memory's that nothing else views
    any more (a caller's earlier G, or a view of one, is never written), the first of the
    geometry's size, later ones with room to spare (an eighth: a per-pixel shader's hits change
    in number from frame to frame); at most two
    buffers are kept, the shader's current G and the spare its next geometry is prepared into
    (a geometry that fails half-way leaves the current one as it was)."""

    #: buffers kept (the current G's and a spare)
    KEEP = 2

    def __init__(self):
        self.buffers: list[np.ndarray] = []

    def rows(self, n: int, dtype) -> np.ndarray:
        """A writable (6, n) C-contiguous array of ``dtype``, its contents undefined (as
        np.empty's), in a kept buffer when a free one fits: no array handed out views it, and it
        holds 6n values but not more than twice that (a mesh much smaller than the last lets the
        larger memory go)."""
        need = 6 * n
        if not need:
            return np.empty((6, n), dtype)
        for i in range(len(self.buffers)):
            buf = self.buffers[i]  # (not enumerate: its tuple would hold one more reference)
            # references: the list, ``buf``, getrefcount's argument (each view of it one more)
            if buf.dtype == dtype and need <= buf.size <= 2 * need and sys.getrefcount(buf) <= 3:
                self.buffers.append(self.buffers.pop(i))  # (the last: the latest taken)
                return buf[:need].reshape(6, n)
        # none fits: the free ones are let go, and of those still viewed the latest taken (the
        # shader's current G, free once the new one replaces it) is kept beside the new one
        buf = None  # (the loop's last one: not a view)
        held = [b for b in self.buffers if sys.getrefcount(b) > 3]  # (list, b, the argument)
        buf = np.empty(need + (need // 8 if self.buffers else 0), dtype)  # (room: a change)
        self.buffers = [*held[len(held) - self.KEEP + 1 :], buf]
        return buf[:need].reshape(6, n)


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
    """The :func:`chunk_bounds` columns of chunks 0, s, 2·s ... (s: :func:`sample_step` of the
    whole chunks; chunk 0 when none is whole), (N_BOUNDS, m) float64, found on a compact copy of
    those chunks' vertices (or prepared rows) rather than in place: in place, each sampled chunk
    is a cache miss of its own and the full-size bounds array is written sparsely (every page
    of it touched, for a sample): 1.9 ms against 0.8 on a million vertices, one thread. On one
    numba thread: on the 2-core VM at a load average of 17, a one-shot call's geometry took
    7.5 ms with the sample on one thread against 12.3 on two (medians of 31, wall clock)."""
    n = src.G.shape[1] + len(src.P) + len(src.P32)  # (two of them are empty)
    whole = n // K.CHUNK * K.CHUNK or n
    step = sample_step(whole // K.CHUNK)
    part = src._replace(
        G=_sampled_rows(src.G, whole, step),
        P=_sampled(src.P, whole, step),
        N=_sampled(src.N, whole, step),
        P32=_sampled(src.P32, whole, step),
        N32=_sampled(src.N32, whole, step),
    )
    m = part.G.shape[1] + len(part.P) + len(part.P32)
    b = np.empty((layout.N_BOUNDS, -(-m // K.CHUNK)), np.float64)
    threads = numba.get_num_threads()
    numba.set_num_threads(1)  # (this thread's own setting: other threads keep theirs)
    try:  # at most CULL_SAMPLES chunks, about 0.1 ms: less than waking a second thread and
        K.bounds(part, k, b, 1)  # waiting for it costs (a core's time slice on a busy machine)
    finally:
        numba.set_num_threads(threads)
    return b


def sample_step(chunks: int) -> int:
    """Which chunks :func:`sample_bounds` samples of ``chunks`` whole ones: every
    CULL_SAMPLE-th, or every s-th with s so large that at most CULL_SAMPLES are sampled."""
    return max(CULL_SAMPLE, -(-chunks // CULL_SAMPLES))


def _sampled(a, whole: int, step: int) -> np.ndarray:
    """Vertices 0 to ``whole`` of ``a`` (n, 3) in chunks of CHUNK, every ``step``-th chunk of
    them, as a C-contiguous copy, as writable as ``a`` (one numba type: no compile); ``a``
    itself when empty."""
    if not len(a):
        return a
    chunks = a[:whole].reshape(-1, min(K.CHUNK, whole), a.shape[1])[::step]
    out = np.ascontiguousarray(chunks).reshape(-1, a.shape[1])
    out.flags.writeable = a.flags.writeable
    return out


def _sampled_rows(G, whole: int, step: int) -> np.ndarray:
    """The columns of prepared rows ``G`` (6, n) that :func:`_sampled` takes of vertices, as a
    C-contiguous (6, m) copy; ``G`` itself when empty. (Through the transpose, (n, 6), the copy
    read one element of a row, then the next row's, n apart: a million float64 vertices' sample
    of every 16th chunk took 2.0 ms of CPU, against 0.36 ms row by row.)"""
    if not G.shape[1]:
        return G
    chunks = G[:, :whole].reshape(len(G), -1, min(K.CHUNK, whole))[:, ::step]
    return np.ascontiguousarray(chunks).reshape(len(G), -1)


def readonly(a: np.ndarray) -> np.ndarray:
    """A read-only view (the engine keeps the writable base private, so kernels get one
    array type and compile once)."""
    v = a.view()
    v.flags.writeable = False
    return v


#: the absent vertices of a :class:`~explorer.shading.kernels.Source`, by dtype: (0, 3) read-only
_NONE = {t: readonly(np.empty((0, 3), t)) for t in (np.float64, np.float32)}
