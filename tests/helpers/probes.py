"""Reading a Gouraud-shaded picture at a vertex: the pixel where a vertex projects lies in the
triangles around it, so its colour lies between its one-ring's vertex colours (a bound that
holds at any tile size, where a fixed tolerance would depend on the colours' gradient)."""

from __future__ import annotations

import numpy as np


def one_ring(mesh, i: int) -> np.ndarray:
    """Vertex ``i`` and the vertices that share a triangle with it: (k,) int."""
    faces = np.asarray(mesh.faces)
    return np.unique(faces[np.any(faces == i, axis=1)].ravel())


def in_ring(pixel, colours, ring, slack: int = 1) -> bool:
    """Whether ``pixel`` (3,) lies within the ring's ``colours`` (n, 3) uint8 per channel, give
    or take ``slack`` levels (the rasteriser's rounding)."""
    c = np.asarray(colours, int)[ring]
    p = np.asarray(pixel, int)
    return bool(np.all(p >= c.min(axis=0) - slack) and np.all(p <= c.max(axis=0) + slack))


def interior(mask: np.ndarray) -> np.ndarray:
    """(h, w) bool: the covered pixels of ``mask`` whose 8 neighbours are covered too (the
    rest of ``mask`` is the silhouette, where two rasterisations may differ by a pixel)."""
    m = np.pad(mask, 1)
    h, w = mask.shape
    out = mask.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            out &= m[1 + dy : 1 + dy + h, 1 + dx : 1 + dx + w]
    return out
