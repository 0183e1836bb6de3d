"""The float64 lobe's lane compaction (explorer.shading.kernels._split_lobe) as a round trip, for
the tests of vmath.compress8 / expand8 (here and, compiled for other CPUs, in a subprocess)."""

import numba as nb
import numpy as np

from explorer.shading import vmath


@nb.njit(error_model="numpy", boundscheck=False)
def round_trip(src, w):
    """Pack the lanes of ``src`` whose ``w`` > 0 to the front of a row, whole groups of 8, and
    put them back: (packed, back, packed count, count taken back)."""
    packed = np.full(src.shape[0], -1.0)
    back = np.full(src.shape[0], -1.0)
    nc = 0
    for i in range(0, src.shape[0] - 7, 8):
        nc += vmath.compress8(src, w, i, packed, nc)
    k = 0
    for i in range(0, src.shape[0] - 7, 8):
        k += vmath.expand8(packed, k, w, i, back)
    return packed, back, nc, k
