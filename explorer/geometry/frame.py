"""The normalised frame the engine shades in.

Shading depends only on directions and distances, so the engine moves the scene to put the
mesh's bounding-box centre at the origin and divides every coordinate by the largest half-extent.
Coordinates near 1e8 or 1e-8 then become numbers near 1, where float32 keeps 7 digits, and the
epsilons in :mod:`explorer.core.tolerances` mean the same thing for every mesh. Distances used for
attenuation are scaled back (``kl·s`` and ``kq·s²``), so colours do not change. A light far
from the mesh in this frame (beyond ``tolerances.FAR_LIGHT``), where ``d²`` would overflow, is
shaded as a directional light toward it (:meth:`explorer.core.lights.PositionalLight.framed`).
"""

from __future__ import annotations

import numpy as np

from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError
from explorer.core.tolerances import NORMAL_RANGE


def frame_of(positions: np.ndarray) -> tuple[np.ndarray, float]:
    """Centre and scale of the normalised frame.

    positions : (n, 3) float, finite
    Returns ``centre : (3,) float64`` and ``scale : float > 0`` such that
    ``(positions - centre) / scale`` lies in [-1, 1]³. An empty mesh or a single point gives
    scale 1.
    """
    if len(positions) == 0:
        return np.zeros(3), 1.0
    # column by column: numpy's axis-0 reduction of a strided (n, 3) array is much slower
    lo = np.array([positions[:, c].min() for c in range(3)], dtype=np.float64)
    hi = np.array([positions[:, c].max() for c in range(3)], dtype=np.float64)
    return frame_from_extent(lo, hi)


def frame_from_extent(lo, hi) -> tuple[np.ndarray, float]:
    """:func:`frame_of` from the positions' smallest and largest coordinates ``lo``, ``hi``
    (3,) float (the compiled engine finds them in one parallel pass)."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    centre = 0.5 * lo + 0.5 * hi  # halves first: lo + hi could overflow near 1e308
    half = float(np.max(0.5 * hi - 0.5 * lo))
    if half == 0.0:  # halving a subnormal extent can round to 0: use the whole extent
        half = float(np.max(hi - lo))
    if not (half > 0.0 and np.isfinite(half)):
        return centre, 1.0
    return centre, max(half, tol.MIN_FRAME_SCALE)  # 1 / scale must be finite too


def to_frame(point, centre: np.ndarray, scale: float) -> np.ndarray:
    """A world-space point (3,) in the normalised frame, as float64."""
    return (np.asarray(point, dtype=np.float64) - centre) / scale


def check_vertices(
    positions, normals, scale: bool = True, finite: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """Validate vertex arrays; return them as C-contiguous float arrays (float32 or float64
    kept, anything else converted to float64), the normals scaled by :func:`scale_normals`
    (``scale`` False: as given, for a caller that tests their range in a pass of its own).

    positions, normals : (n, 3) array-like of finite real numbers. Anything else (a ragged list,
    text, complex numbers, the wrong shape, NaN or inf) raises an
    :class:`~explorer.core.errors.ExplorerError` (a ValueError) naming the argument, and for a
    non-finite value the first bad vertex (the engine never guesses a value for it).
    ``finite`` False leaves out the test for NaN and inf, for a caller whose own pass over the
    arrays finds them (it then calls :func:`check_finite` for the error).
    """
    P = _vertex_array("positions", positions, finite)
    N = _vertex_array("normals", normals, finite)
    if len(P) != len(N):
        raise ExplorerError(
            f"positions and normals must have the same length, got {len(P)} and {len(N)}"
        )
    return P, scale_normals(N) if scale else N


def _vertex_array(name: str, a, finite: bool = True) -> np.ndarray:
    """One (n, 3) array of finite reals, C-contiguous float32/float64 (see check_vertices)."""
    try:
        arr = np.asarray(a)
    except (ValueError, TypeError, OverflowError):  # a ragged list, say
        arr = None
    if arr is None or arr.dtype == object:
        raise ExplorerError(f"{name} must be an (n, 3) array of real numbers (not a ragged list)")
    if arr.dtype not in (np.float32, np.float64):
        if not (np.issubdtype(arr.dtype, np.number) or arr.dtype == bool) or np.iscomplexobj(arr):
            raise ExplorerError(f"{name} must be an (n, 3) array of real numbers, got {arr.dtype}")
        arr = arr.astype(np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ExplorerError(f"{name} must have shape (n, 3), got {arr.shape}")
    if finite:
        check_finite(name, arr)
    return np.ascontiguousarray(arr)


def check_finite(name: str, arr: np.ndarray) -> None:
    """Raise an :class:`~explorer.core.errors.ExplorerError` naming ``name`` and the first
    vertex of ``arr`` (n, 3) float with a NaN or an infinite value, if any."""
    if not np.isfinite(arr.reshape(-1)).all():  # flat test first: one fast pass
        i = int(np.argmax(~np.isfinite(arr).all(axis=1)))
        raise ExplorerError(
            f"{name}[{i}] is not finite: {arr[i].tolist()} (vertex {i} of {len(arr)}); "
            "fix or drop such vertices before shading"
        )


def scale_normals(normals: np.ndarray) -> np.ndarray:
    """Normals whose largest component lies in :data:`NORMAL_RANGE`, scaled by exact powers of
    two (same directions, bit for bit): a normal of length 1e-20 or 1e300 is a direction, and its
    squared length neither underflows nor overflows, in float32 too. Zero rows stay zero (no
    normal: see :data:`explorer.core.tolerances.NORMAL_EPS`).

    normals : (n, 3) float32/float64, finite. Returns the same array when every row is already in
    range (the usual case: no copy), else a scaled copy, (n, 3), same dtype.
    """
    if len(normals) == 0:
        return normals
    lo, hi = NORMAL_RANGE
    # the usual case in one fast pass: a squared length in [3·lo², hi²] puts the largest
    # component in [lo, hi] (it lies between length/√3 and length); anything else (a zero row,
    # or one whose square underflows) takes the exact path below
    s = np.einsum("ij,ij->i", normals, normals, dtype=np.float64)
    if ((s >= 3.0 * lo * lo) & (s <= hi * hi)).all():
        return normals
    big = np.abs(normals).max(axis=1)  # (n,) largest component of each normal
    out_of_range = (big > 0) & ((big < lo) | (big > hi))
    if not out_of_range.any():
        return normals
    _, exponent = np.frexp(big[out_of_range])  # big = m · 2**exponent, m in [0.5, 1)
    out = normals.copy()
    out[out_of_range] = np.ldexp(out[out_of_range], -exponent[:, None].astype(np.int32))
    return out


def check_faces(faces, n_vertices: int, name: str = "faces") -> np.ndarray:
    """Validate triangles: an (m, 3) array-like of whole numbers in [0, n_vertices).

    Returns ``faces : (m, 3) int64``. An empty list gives (0, 3). Anything else (a ragged list,
    rows of two, fractions, an index like 2**70 or -1) raises an
    :class:`~explorer.core.errors.ExplorerError` (a ValueError) naming ``name``.
    """
    try:
        arr = np.asarray(faces)
        if arr.dtype == object:  # Python ints beyond int64: compare them as floats
            arr = np.asarray(faces, dtype=np.float64)
    except (ValueError, TypeError, OverflowError):
        raise ExplorerError(f"{name} must be an (m, 3) array of vertex indices") from None
    if arr.size == 0:
        return np.zeros((0, 3), np.int64)
    if arr.dtype == bool or not (np.issubdtype(arr.dtype, np.integer) or arr.dtype.kind == "f"):
        raise ExplorerError(f"{name} must be an (m, 3) array of vertex indices, got {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ExplorerError(f"{name} must have shape (m, 3): one row per triangle, got {arr.shape}")
    if arr.dtype.kind == "f" and not (np.isfinite(arr).all() and (arr == np.round(arr)).all()):
        raise ExplorerError(f"{name} must hold whole numbers (vertex indices)")
    lo, hi = arr.min(), arr.max()  # compared in the array's own type: no overflow
    if lo < 0 or hi >= n_vertices:
        bad = lo if lo < 0 else hi
        raise ExplorerError(
            f"{name} index vertices that do not exist: {int(bad)} is not in [0, {n_vertices})"
        )
    return np.ascontiguousarray(arr, dtype=np.int64)
