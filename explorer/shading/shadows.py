"""Hard shadows: per-vertex visibility of a light against the mesh itself.

A vertex is in the shadow of a light when the ray from the vertex toward the light (to infinity
for a directional light, up to the light's position for a point or spot light) enters the mesh
through the front (outward) side of a triangle at a distance beyond
:data:`explorer.core.tolerances.RAY_T_EPS`. Only
front sides occlude, as with back-face-culled shadow rays: a closed mesh shadows exactly like
the solid it bounds, and a ray leaving the surface it starts on (through the triangles around
its vertex, or out through the far side of the body) never counts, so no bias or "shadow acne"
offsets are needed. An open sheet casts shadows from its front side only.

Visibility is 1 (lit) or 0 (shadowed); the engine multiplies it into the light's diffuse and
specular weight (ambient light is not shadowed, as in OpenGL practice). Between vertices the
renderer interpolates colours, so a shadow edge is as sharp as the mesh is fine.

Ray engine: :func:`explorer.geometry.rays.any_hit`, a compiled Möller-Trumbore test of every
ray against every triangle on both cores (instant for the built-in meshes, seconds for meshes of
100k triangles). trimesh's embree- or rtree-backed intersectors report the nearest hit
only, which cannot skip back faces and the triangles at the ray's own vertex, so they are not
used.

With these rules a convex closed mesh can never shadow itself (a line meets a convex body in
one segment: a ray that starts on it never re-enters it), so skipping it changes nothing.

The plan skips rays where they cannot change anything: lights without ``shadows: true``,
vertices facing away from the light (N·L <= 0: no diffuse or specular to shadow), and convex
meshes (:func:`is_convex`: a convex surface cannot shadow itself).
"""

from __future__ import annotations

import numpy as np

from explorer.core import tolerances as tol
from explorer.geometry.frame import frame_of
from explorer.geometry.rays import any_hit


def is_convex(positions, faces) -> bool:
    """True when the mesh is a closed convex surface (trimesh ``is_convex``): it cannot shadow
    itself. Open or non-convex meshes (a plane under a sphere) are False."""
    import trimesh

    if faces is None or len(faces) == 0:
        return True
    tm = trimesh.Trimesh(np.asarray(positions), np.asarray(faces), process=False)
    if not tm.is_watertight:  # seams with duplicated vertices: merge before deciding
        tm = trimesh.Trimesh(np.asarray(positions), np.asarray(faces), process=True)
    return bool(tm.is_convex)


def visibility(positions, faces, light, *, only=None):
    """Visibility of ``light`` at each vertex: (n,) float64, 1 lit, 0 shadowed.

    positions : (n, 3) float; faces : (m, 3) int (counter-clockwise seen from the front)
    light : a light of :mod:`explorer.core.lights` (it gives the rays: :meth:`shadow_ray`)
    only : (n,) bool, the vertices to cast rays from (the others get 1); default all
    """
    P = np.asarray(positions, np.float64)
    n = len(P)
    vis = np.ones(n)
    faces = np.asarray(faces, np.int64).reshape(-1, 3)
    idx = np.arange(n) if only is None else np.flatnonzero(only)
    if len(idx) == 0 or len(faces) == 0:
        return vis
    centre, scale = frame_of(P)
    Q = (P - centre) / scale  # the normalised frame: RAY_T_EPS is relative to the mesh
    D, tmax = light.shadow_ray(Q[idx], centre, scale)
    D = np.ascontiguousarray(D)
    tri = Q[faces]
    hit = any_hit(Q[idx], D, tmax, tri)
    vis[idx[hit]] = 0.0
    return vis


def visibility_rows(
    positions, normals, faces, lights, shadowed, *, two_sided, force_all, cache, dtype=np.float64
):
    """(L, n) ``dtype`` visibility rows, one per light (rows of lights not ``shadowed`` are 1).

    positions, normals : (n, 3) float; faces : (m, 3) int
    lights : the scene's lights; shadowed : (L,) bool, the lights the plan casts rays for
    two_sided : N flips with V: rays from every vertex with a normal (either side may be lit)
    force_all : rays from every vertex (benchmark); else only where N·L > -SHADOW_NDL_MARGIN
        (:mod:`explorer.core.tolerances`)
    cache : dict kept by the caller for this geometry: a light whose rays are unchanged (same
        position or direction) reuses its row
    Returns the rows and the number of rays cast."""
    P = positions
    n = len(P)
    vis = np.ones((len(lights), n), dtype)
    N = np.asarray(normals, np.float64)
    length = np.sqrt(np.einsum("ij,ij->i", N, N))
    unit = N / np.where(length > 0, length, 1.0)[:, None]
    rays = 0
    for i, (light, on) in enumerate(zip(lights, shadowed, strict=True)):
        if not on:
            continue
        key = (light.anchor, two_sided, force_all)
        v = cache.get(key)
        if v is None:
            only = None
            if not force_all:  # rays only where N·L can be > 0 (either side if two-sided)
                ndl = np.einsum("ij,ij->i", light.toward(P), unit)
                # a margin: a ray more than needed is harmless, one fewer is not
                only = length > 0 if two_sided else ndl > -tol.SHADOW_NDL_MARGIN
            v = visibility(P, faces, light, only=only)
            cache[key] = v
            rays += int(n if only is None else only.sum())
        vis[i] = v
    return vis, rays
