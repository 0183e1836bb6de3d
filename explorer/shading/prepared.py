"""The compiled tier's prepared geometry: the normalised frame, positions and unit normals as
(6, n) rows in the working precision (:func:`explorer.shading.kernels.prepare`) and light
culling's chunk bounds; for a one-shot pass, the same slab by slab (:func:`slabs`), so that no
full-size copy is written.
"""

from __future__ import annotations

import threading

import numpy as np

from explorer.geometry.frame import check_finite, frame_from_extent, frame_of, scale_normals
from explorer.shading import kernels as K

#: light culling is kept for a mesh where one chunk of vertices in this many or more has a
#: normal cone narrower than 90° (only such chunks can ever be skipped)
CULL_MIN_SHARE = 8
#: vertices per slab of a one-shot pass (:func:`slabs`; a multiple of BLOCK): its
#: prepared geometry, 48 bytes a vertex in float64 (12 MB), stays in the cache between being
#: written and being shaded; each slab costs three parallel regions, each of which waits for a
#: thread another process holds (``benchmarks/bench_engine.py --slabs`` measures the choice)
SLAB = 256 * 1024
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


def prepared_geometry(P, N, dtype, k) -> tuple:
    """The compiled tier's geometry of positions ``P`` and normals ``N`` (n, 3) in precision
    ``dtype`` (``k``: its constants): (centre, scale) of the normalised frame (:func:`frame_of`,
    the extent found in one compiled pass), ``G`` (6, n) (:func:`explorer.shading.kernels.prepare`),
    the chunk bounds (:func:`chunk_bounds`) and the normals as prepared: ``N``, or scaled into
    NORMAL_RANGE where some lay outside it (prepare tests what scale_normals would).
    These passes test the values too: a NaN or an infinite value raises the error of
    :func:`~explorer.geometry.frame.check_finite` naming the first such vertex."""
    centre, scale = frame_of_positions(P)
    G = np.empty((6, len(P)), dtype)
    frame = (centre, 1.0 / scale, k)
    if K.prepare(readonly(P), readonly(N), *frame, G):  # (NaN and inf are outside too)
        check_finite("normals", N)
        N = scale_normals(N)
        K.prepare(readonly(P), readonly(N), *frame, G)
    return centre, scale, G, chunk_bounds(G), N


def geometry_of(P, N, dtype, k, whole: bool = True) -> tuple:
    """(centre, scale, G, bounds, N): :func:`prepared_geometry`; ``whole`` False (a one-shot
    shader, which prepares slabs as it shades: :func:`slabs`): the frame alone,
    (centre, scale, None, None, None)."""
    if whole:
        return prepared_geometry(P, N, dtype, k)
    return (*frame_of_positions(P), None, None, None)


def chunk_bounds(G: np.ndarray) -> np.ndarray:
    """(N_BOUNDS, ceil(n / CHUNK)) float64 bounds of each chunk of consecutive vertices of the
    prepared geometry ``G`` (6, n), for light culling (see :func:`explorer.shading.kernels.bounds`),
    read-only; (N_BOUNDS, 0) when fewer than one chunk in CULL_MIN_SHARE has a normal cone
    narrower than 90° (shuffled vertices, say): too little could be culled to pay for the tests.
    Every CULL_SAMPLE-th chunk is found first: when those already fall short, the rest are not
    (on vertices in no particular order most of the bounds' cost)."""
    b = np.empty((K.N_BOUNDS, -(-G.shape[1] // K.CHUNK)), np.float64)
    K.bounds(G, b, CULL_SAMPLE)
    sample = b[K.B_COS, ::CULL_SAMPLE]
    if np.count_nonzero(sample > 0) * CULL_MIN_SHARE < sample.size:
        return readonly(b[:, :0])
    K.bounds(G, b, 1)
    if np.count_nonzero(b[K.B_COS] > 0) * CULL_MIN_SHARE < b.shape[1]:
        b = b[:, :0]
    return readonly(b)


def slabs(P, N, dtype, k, centre, scale):
    """The prepared geometry of a one-shot pass, slab by slab: yields (s, e, G, bounds, N) for
    vertices s to e, :data:`SLAB` at a time (a multiple of BLOCK; the last one fewer): G
    (6, e - s) in precision ``dtype`` (``k``: its constants) in the frame ``centre``, ``scale``,
    in one reused buffer (a second one for the last slab: the kernels take contiguous rows), its
    chunk bounds (:func:`chunk_bounds`) and the normals ``N`` as prepared so far (scaled into
    NORMAL_RANGE, all of them, once a slab held one outside it, as :func:`prepared_geometry`
    does). Slab after slab stays in the cache, and no full-size G is written (48 MB at 1M
    vertices in float64). A NaN or an infinite normal raises
    :func:`~explorer.geometry.frame.check_finite`'s error naming the first one."""
    n = len(P)
    frame = (centre, 1.0 / scale, k)
    P = readonly(P)
    size = min(n, SLAB)
    buffers = [SPARES.take((6, size), dtype)]
    try:
        for s in range(0, max(n, 1), SLAB):
            e = min(n, s + SLAB)
            if e - s != size:  # the last, shorter slab
                buffers.append(SPARES.take((6, e - s), dtype))
            G = buffers[-1]
            if K.prepare(P[s:e], readonly(N)[s:e], *frame, G):  # (NaN and inf are outside too)
                check_finite("normals", N)
                N = scale_normals(N)
                K.prepare(P[s:e], readonly(N)[s:e], *frame, G)
            yield s, e, G, chunk_bounds(G), N
    finally:
        for b in buffers:
            SPARES.give(b)


class _Spare:
    """The few arrays finished one-shot passes left, for the next call: the slab buffers of
    their prepared geometry (:func:`slabs`: 6·SLAB values, 12 MB in float64, whose first
    touch costs more page faults than preparing them costs work). Thread-safe: an array is taken
    by one pass, which owns it until it gives it back."""

    #: arrays kept at most (the latest given)
    KEEP = 4

    def __init__(self):
        self._lock = threading.Lock()
        self._spare: list[np.ndarray] = []

    def take(self, shape: tuple, dtype) -> np.ndarray:
        """A spare array of this shape and dtype, or a new one."""
        with self._lock:
            for i, a in enumerate(self._spare):
                if a.shape == shape and a.dtype == dtype:
                    return self._spare.pop(i)
        return np.empty(shape, dtype)

    def give(self, a) -> None:
        """Keep ``a`` (nothing else may use it any more) for a later :meth:`take`."""
        with self._lock:
            self._spare = [a, *self._spare[: self.KEEP - 1]]


#: the slab buffers one-shot passes left for the next
SPARES = _Spare()


def readonly(a: np.ndarray) -> np.ndarray:
    """A read-only view (the engine keeps the writable base private, so kernels get one
    array type and compile once)."""
    v = a.view()
    v.flags.writeable = False
    return v
