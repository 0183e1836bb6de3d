"""Texture coordinates of the built-in meshes, and vertices split where (u, v) differ.

A built-in mesh asked for texture coordinates (``explorer.geometry.meshes.get_mesh(name,
uv=True)``) gets its own parametrisation, the vertices on a seam split so each side keeps its
(u, v) (same position and normal, so the same colours and pixels):

=============  ================================================================================
name           (u, v)
=============  ================================================================================
``sphere``     longitude / 2π from the +z meridian eastward, latitude from the south pole (0)
               to the north (1); the seam at u = 0 | 1 split, a pole takes its triangle's u
``icosphere``  the same spherical mapping
``torus``      around the ring / 2π, around the tube / 2π; both seams split
``cube``       each face the whole [0, 1]² square
``plane``      ((x + 1) / 2, (y + 1) / 2)
``teapot``     each Bézier patch its own (u, v) in [0, 1]², as ``glMap2``/``glutSolidTeapot``
               give them; vertices welded across patches split again by (u, v)
=============  ================================================================================
"""

from __future__ import annotations

import numpy as np


def split_by_uv(faces, corner_uv, decimals: int = 12):
    """Vertices split where the triangles meeting there give them different (u, v).

    faces : (m, 3) int; corner_uv : (m, 3, 2) the (u, v) of each triangle's corners
    Returns ``(source, faces, uv)``: (k,) the vertex each new vertex copies (in the old order,
    copies of one vertex side by side, so a mesh with no seam keeps its vertices as they were),
    the (m, 3) triangles over the new vertices, (k, 2) their (u, v).
    """
    faces = np.asarray(faces, np.int64).reshape(-1, 3)
    uv = np.asarray(corner_uv, np.float64).reshape(-1, 2)
    q = np.round(uv, decimals)
    q[q == 0] = 0.0
    table = np.column_stack([faces.reshape(-1).astype(np.float64), q])
    unique, first, inverse = np.unique(table, axis=0, return_index=True, return_inverse=True)
    return unique[:, 0].astype(np.int64), inverse.reshape(-1, 3), uv[first]


def wrapped_corners(uv: np.ndarray, faces: np.ndarray, wrap=(True, False), poles=None):
    """(m, 3, 2) corner (u, v) of a mesh whose vertex (u, v) wraps around (1 is 0 again): in a
    triangle spanning the seam, the corners more than 0.5 below its largest take + 1; a pole
    vertex (its u undefined) takes the mean u of its triangle's other corners."""
    c = uv[faces].copy()
    for axis, wraps in enumerate(wrap):
        if wraps:
            col = c[:, :, axis]
            span = col.max(axis=1) - col.min(axis=1)
            across = (span > 0.5)[:, None] & (col < col.max(axis=1, keepdims=True) - 0.5)
            col[across] += 1.0
    if poles is not None:
        at = poles[faces]
        for k in range(3):
            rows = np.flatnonzero(at[:, k])
            others = [j for j in range(3) if j != k]
            c[rows, k, 0] = c[rows][:, others, 0].mean(axis=1)
    return c


def spherical_corners(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(m, 3, 2) corner (u, v) of a sphere about the origin, poles on ±y: u the longitude / 2π
    eastward from the +z meridian, v from the south pole (0) to the north (1)."""
    p = positions
    u = np.mod(np.arctan2(p[:, 0], p[:, 2]) / (2.0 * np.pi), 1.0)
    v = 0.5 + np.arcsin(np.clip(p[:, 1], -1.0, 1.0)) / np.pi
    poles = np.hypot(p[:, 0], p[:, 2]) < 1e-12
    return wrapped_corners(np.column_stack([u, v]), faces, poles=poles)
