"""Gouraud vs per-pixel, live: what the compare view says and draws when one side is lit per
vertex and the other per pixel ("Gouraud vs per-pixel": side A per vertex, side B per pixel).

The per-vertex side's picture at the per-pixel side's pixels is computed, not read back from its
window (where the light handles and the lobe inset cover parts of the mesh): each covered pixel
of the per-pixel side's G-buffer (:meth:`explorer.render.live.LivePixels.gbuffer`) lies on one
triangle, at a surface point whose barycentric coordinates are those OpenGL interpolates the
vertex colours with (perspective-correct: the coordinates of the 3D point), so the per-vertex
colour there is the barycentric mix of the triangle's 8-bit vertex colours, as the rasteriser
draws it (within its rounding: 1 level). The error of each pixel is the largest channel's
difference in 8-bit levels; :class:`Figures` holds the line both panes show: the time each side
took for its frame and the error (max, 95th percentile, share of pixels off by more than
:data:`OFF_LEVELS`). With the compare view's difference on, the per-pixel side draws the error as
a heat map (:func:`explorer.analysis.comparison.heat_map`, the difference view's colours).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from explorer.analysis.comparison import heat_map
from explorer.app.difference import VMAX

#: a pixel counts as off when its error is more than this many 8-bit levels
OFF_LEVELS = 2


@dataclass(frozen=True)
class Figures:
    """One frame's comparison: vertex_ms, pixel_ms the time of each side's last frame (ms: the
    per-vertex window's frame, the per-pixel picture);
    max_levels, p95_levels the error's largest value and 95th percentile (8-bit levels); share
    the fraction of covered pixels off by more than :data:`OFF_LEVELS`; pixels how many."""

    vertex_ms: float
    pixel_ms: float
    max_levels: int
    p95_levels: float
    share: float
    pixels: int

    def line(self) -> str:
        """The lines both panes show (the times, the error)."""
        return (
            f"per vertex {self.vertex_ms:.0f} ms, per pixel {self.pixel_ms:.0f} ms\n"
            f"error: max {self.max_levels}, p95 {self.p95_levels:.0f} levels, "
            f"{100.0 * self.share:.1f}% of pixels > {OFF_LEVELS}"
        )


def barycentric(mesh, hits) -> np.ndarray:
    """(k, 3) float64 barycentric coordinates of each hit's point on its triangle
    (``hits.positions``, ``hits.triangles``: :class:`explorer.render.perpixel.Hits`)."""
    F = np.asarray(mesh.faces, np.int64)[hits.triangles]
    P = np.asarray(mesh.positions, np.float64)
    a = P[F[:, 0]]
    e1, e2, p = P[F[:, 1]] - a, P[F[:, 2]] - a, np.asarray(hits.positions) - a
    d11, d12, d22 = (np.einsum("ij,ij->i", x, y) for x, y in ((e1, e1), (e1, e2), (e2, e2)))
    p1, p2 = np.einsum("ij,ij->i", p, e1), np.einsum("ij,ij->i", p, e2)
    det = d11 * d22 - d12 * d12
    det = np.where(np.abs(det) > 0.0, det, 1.0)  # (a degenerate triangle: its first corner)
    u = (d22 * p1 - d12 * p2) / det
    v = (d11 * p2 - d12 * p1) / det
    return np.column_stack([1.0 - u - v, u, v])


def gouraud(mesh, hits, vertex_rgb: np.ndarray) -> np.ndarray:
    """(k, 3) uint8: the per-vertex picture at the hits' pixels, the triangle's 8-bit vertex
    colours ``vertex_rgb`` (n, 3) mixed by :func:`barycentric`."""
    w = barycentric(mesh, hits)
    F = np.asarray(mesh.faces, np.int64)[hits.triangles]
    c = np.asarray(vertex_rgb, np.float64)[F]  # (k, 3 corners, 3 channels)
    return np.clip(np.rint(np.einsum("kc,kcj->kj", w, c)), 0, 255).astype(np.uint8)


def levels(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(k,) int: the largest channel's difference of two (k, 3) uint8 colour lists."""
    return np.abs(a.astype(np.int16) - b.astype(np.int16)).max(axis=1)


def figures(errors: np.ndarray, vertex_ms: float, pixel_ms: float) -> Figures:
    """The :class:`Figures` of the per-pixel ``errors`` (k,) in levels."""
    e = np.asarray(errors)
    if e.size == 0:
        return Figures(vertex_ms, pixel_ms, 0, 0.0, 0.0, 0)
    p95, share = float(np.percentile(e, 95)), float(np.mean(e > OFF_LEVELS))
    return Figures(vertex_ms, pixel_ms, int(e.max()), p95, share, int(e.size))


def heat_picture(errors: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """(h, w, 3) uint8: the errors (k,) of the covered pixels of ``mask`` (h, w) as the
    difference view's heat map."""
    lv = np.zeros(mask.shape, np.int64)
    lv[mask] = errors
    return heat_map(lv, mask, vmax=VMAX)
