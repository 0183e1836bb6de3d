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

from explorer.core.errors import ExplorerError


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
    centre = 0.5 * lo + 0.5 * hi  # halves first: lo + hi could overflow near 1e308
    half = float(np.max(0.5 * hi - 0.5 * lo))
    scale = half if half > 0.0 and np.isfinite(half) else 1.0
    return centre, scale


def to_frame(point, centre: np.ndarray, scale: float) -> np.ndarray:
    """A world-space point (3,) in the normalised frame, as float64."""
    return (np.asarray(point, dtype=np.float64) - centre) / scale


def check_vertices(positions, normals) -> tuple[np.ndarray, np.ndarray]:
    """Validate vertex arrays; return them as C-contiguous float arrays (float32 or float64
    kept, anything else converted to float64).

    positions, normals : (n, 3) array-like of finite numbers. NaN or inf raise an
    :class:`~explorer.core.errors.ExplorerError` naming the first bad vertex (the engine never
    guesses a value for it).
    """

    out = []
    for name, a in (("positions", positions), ("normals", normals)):
        arr = np.asarray(a)
        if arr.dtype not in (np.float32, np.float64):
            if not (np.issubdtype(arr.dtype, np.number) or arr.dtype == bool) or np.iscomplexobj(
                arr
            ):
                raise ExplorerError(f"{name} must be an (n, 3) array of real numbers")
            arr = arr.astype(np.float64)
        if arr.ndim != 2 or arr.shape[1] != 3:
            raise ExplorerError(f"{name} must have shape (n, 3), got {arr.shape}")
        if not np.isfinite(arr.reshape(-1)).all():  # flat test first: one fast pass
            i = int(np.argmax(~np.isfinite(arr).all(axis=1)))
            raise ExplorerError(
                f"{name}[{i}] is not finite: {arr[i].tolist()} (vertex {i} of {len(arr)}); "
                "fix or drop such vertices before shading"
            )
        out.append(np.ascontiguousarray(arr))
    if len(out[0]) != len(out[1]):
        raise ExplorerError(
            f"positions and normals must have the same length, got {len(out[0])} and {len(out[1])}"
        )
    return out[0], out[1]
