"""Adaptive refinement: split a mesh's edges only where per-vertex shading misses.

:func:`refine_highlights` is the adaptive alternative to a uniformly finer mesh: it splits the
edges at the highlight, the terminator and the clip at 1 (and, on a built-in unit sphere, the
silhouette) until Gouraud interpolation along every edge is within a bound of the exact colour.
The benchmark (:mod:`explorer.analysis.benchmark`) measures it against uniform tessellations.
"""

from __future__ import annotations

import numpy as np

from explorer.geometry.meshes import Mesh
from explorer.render.perpixel import is_unit_sphere, point_colors

#: vertex budget of :func:`refine_highlights`
REFINE_MAX_VERTICES = 400_000


def _split_longest_edge(faces: np.ndarray, mid: np.ndarray, longest: np.ndarray) -> np.ndarray:
    """Split triangles by longest-edge bisection (Rivara): a triangle with marked edges is
    first cut from its longest edge's midpoint to the opposite corner, then each half is cut
    again if its outer edge is marked. Triangles keep their winding and their angles stay
    bounded (no slivers); an edge is split in both of its triangles, so no cracks.

    faces : (m, 3) int; mid : (m, 3) int, the new vertex on edge k = (v_k, v_k+1) or -1 where
    the edge is kept (the longest edge of every triangle with a marked edge is marked);
    longest : (m,) which edge (0, 1, 2) is each triangle's longest. Returns (m', 3) int.
    """
    split = (mid >= 0).any(1)
    out = [faces[~split]]
    sel = np.flatnonzero(split)
    if len(sel):
        rows = np.arange(len(sel))[:, None]
        idx = (np.arange(3)[None, :] + longest[sel][:, None]) % 3  # longest edge -> edge 0
        V = faces[sel][rows, idx]
        E = mid[sel][rows, idx]
        a, b, c = V[:, 0], V[:, 1], V[:, 2]
        m, mbc, mca = E[:, 0], E[:, 1], E[:, 2]
        one = mca < 0  # the half (a, m, c), cut again along c->a when marked
        out += [np.stack([a, m, c], 1)[one]]
        out += [np.stack([m, c, mca], 1)[~one], np.stack([m, mca, a], 1)[~one]]
        two = mbc < 0  # the half (m, b, c), cut again along b->c when marked
        out += [np.stack([m, b, c], 1)[two]]
        out += [np.stack([m, b, mbc], 1)[~two], np.stack([m, mbc, c], 1)[~two]]
    return np.concatenate(out).astype(np.int64)


def _seen_on_sphere(viewer, points: np.ndarray, normals: np.ndarray):
    """Where the line of sight through each point (inside the unit sphere) leaves the sphere
    toward the viewer: the sphere point a pixel showing that point sees, (k, 3) float64; and
    (k,) bool, True where the surface there (``normals``) faces the viewer (elsewhere the
    line of sight shows another part of the sphere)."""
    if viewer.local:
        v = np.asarray(viewer.eye, np.float64) - points
        v /= np.maximum(np.linalg.norm(v, axis=1, keepdims=True), 1e-300)
    else:
        v = np.broadcast_to(np.asarray(viewer.to_viewer, np.float64), points.shape)
    b = np.einsum("ij,ij->i", points, v)
    c = np.einsum("ij,ij->i", points, points) - 1.0
    t = -b + np.sqrt(np.maximum(b * b - c, 0.0))
    q = points + t[:, None] * v
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return q, np.einsum("ij,ij->i", normals, v) > 0.0


def refine_highlights(scene, mesh, max_error: float = 1.0, *, min_edge: float = 0.0,
                      max_rounds: int = 16, max_vertices: int = REFINE_MAX_VERTICES):  # fmt: skip
    """Refine a mesh only where per-vertex shading misses: the adaptive alternative to a
    uniformly finer mesh (it splits at the highlight, the terminator and the clip at 1).

    Each round shades every edge's midpoint exactly and compares it with the average of the
    edge's two vertex colours (what Gouraud interpolation shows there); the edges off by more
    than ``max_error`` levels (largest channel) are split by longest-edge bisection (no
    cracks, no slivers). A built-in unit sphere's new vertices go onto the sphere; any other
    mesh's stay on the triangle with the normalised average of the two normals (the
    interpolated normal the per-pixel ray caster uses). Stops when no edge is off, after
    ``max_rounds`` rounds, or before the mesh would exceed ``max_vertices``. On a sphere the
    comparison is with what the pixel showing the edge's midpoint sees on the true sphere, so
    the silhouette, where the flat triangles lag behind the sphere, is refined too; give
    ``min_edge`` (world units, about a pixel) so edges smaller than a pixel stay whole.

    Returns a new :class:`~explorer.geometry.meshes.Mesh` (same name) whose first vertices are the
    original ones. The result depends on the scene (lights, viewer, material): refine again
    when they change.
    """

    sphere = is_unit_sphere(mesh)
    P = np.array(mesh.positions)
    N = np.array(mesh.normals)
    F = np.array(mesh.faces)
    colors = point_colors(scene, P, N, mesh=mesh)
    for _ in range(max_rounds):
        if not len(F):
            break
        edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
        unique, inverse = np.unique(np.sort(edges, axis=1), axis=0, return_inverse=True)
        tri_edge = inverse.ravel().reshape(3, -1).T  # (m, 3): edges 01, 12, 20
        mid_n = N[unique[:, 0]] + N[unique[:, 1]]
        length = np.linalg.norm(mid_n, axis=1, keepdims=True)
        mid_n = np.divide(mid_n, length, out=np.zeros_like(mid_n), where=length > 1e-12)
        chord = 0.5 * (P[unique[:, 0]] + P[unique[:, 1]])
        mid_p = mid_n.copy() if sphere else chord
        exact = point_colors(scene, mid_p, mid_n, mesh=mesh)
        seen = exact
        if sphere:  # what the pixel showing the chord's midpoint sees on the true sphere
            q, front = _seen_on_sphere(scene.viewer, chord, mid_n)
            if front.any():
                seen = exact.copy()
                seen[front] = point_colors(scene, q[front], q[front], mesh=mesh)
        lerp = 0.5 * (colors[unique[:, 0]] + colors[unique[:, 1]])
        elen = np.linalg.norm(P[unique[:, 0]] - P[unique[:, 1]], axis=1)
        marked = (np.abs(seen - lerp).max(axis=1) * 255.0 > max_error) & (elen > min_edge)
        if not marked.any():
            break
        # each triangle's longest edge (ties broken by edge number), marked with any other
        key = elen[tri_edge] * (1.0 + 1e-12 * tri_edge / max(len(unique), 1))
        longest = np.argmax(key, axis=1)
        longest_id = tri_edge[np.arange(len(F)), longest]
        while True:
            need = marked[tri_edge].any(1) & ~marked[longest_id]
            if not need.any():
                break
            marked[longest_id[need]] = True
        n_new = int(marked.sum())
        if len(P) + n_new > max_vertices:
            break
        new_index = np.full(len(unique), -1, np.int64)
        new_index[marked] = len(P) + np.arange(n_new)
        F = _split_longest_edge(F, new_index[tri_edge], longest)
        P = np.vstack([P, mid_p[marked]])
        N = np.vstack([N, mid_n[marked]])
        colors = np.vstack([colors, exact[marked]])
    return Mesh(P, N, F, mesh.name)
