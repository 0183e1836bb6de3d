"""Hard shadows: per-vertex visibility of a light against the mesh itself.

A vertex is in the shadow of a light when the ray from the vertex toward the light (to infinity
for a directional light, up to the light's position for a point or spot light) enters the mesh
through the front (outward) side of a triangle at a distance beyond
:data:`explorer.core.tolerances.RAY_T_EPS`. Only
front sides occlude, as with back-face-culled shadow rays: a closed mesh shadows exactly like
the solid it bounds, and a ray leaving the surface it starts on (through the triangles around
its vertex, or out through the far side of the body) never counts, so no bias or "shadow acne"
offsets are needed. An open sheet casts shadows from its front side only.

Visibility is 1 (lit) or 0 (shadowed), kept as uint8 and only for the lights that cast
shadows (one byte per vertex and shadowing light: :func:`visibility_rows`); the engine zeroes
the light's diffuse and specular weight where it is 0 (ambient light is not shadowed, as in
OpenGL practice). Between vertices the renderer interpolates colours, so a shadow edge is as
sharp as the mesh is fine.

Ray engine: :func:`explorer.geometry.bvh.any_hit` through a bounding-volume hierarchy of the
mesh (:mod:`explorer.geometry.bvh`), built once per geometry. It runs the same Möller-Trumbore
test as the brute-force :func:`explorer.geometry.rays.any_hit` on the same numbers, only on the
triangles whose boxes a ray crosses, so the shadowed vertices are exactly the brute force's.
A light's rays go through the tree's boxes refitted around the triangles that face away from
it, the only ones that can block them (:mod:`explorer.geometry.occluders`). Rays run in chunks
on the cores; ``cancelled`` (a :class:`~explorer.shading.shader.Shader`'s ``cancelled``) and
Ctrl-C stop them between chunks and the tree's build while it runs.

The plan skips rays where they cannot change anything: lights without ``shadows: true``, and
vertices facing away from the light (N·L <= 0: no diffuse or specular to shadow). It does not
skip meshes that look convex: a convexity test with a tolerance calls a fine torus convex
although its far side is shadowed, and no test is exact at every resolution, so every mesh
casts its rays (a convex mesh's rays leave it after a few boxes).
"""

from __future__ import annotations

import numpy as np

from explorer.core import tolerances as tol
from explorer.geometry.frame import frame_of
from explorer.shading.tiers import ray_engine, ray_work

#: the key under which :func:`visibility_rows` keeps the geometry's frame and BVH in its cache
#: (with the name of the ray engine that built it)
GEOMETRY_KEY = "geometry"


def frame_bvh(positions, faces, engine=None, *, cancelled=None) -> tuple:
    """The normalised frame of ``positions`` and the BVH of ``faces`` in it.

    positions : (n, 3) float; faces : (m, 3) int
    engine : the ray engine (:func:`explorer.shading.tiers.ray_engine`, the default)
    cancelled : () -> bool, asked while the BVH is built (True: raise Cancelled)
    Returns centre (3,), scale, the frame positions Q (n, 3) = (positions - centre) / scale,
    the BVH of Q[faces] (:data:`~explorer.core.tolerances.RAY_T_EPS` is relative to it) and the
    engine that casts through it.
    """
    engine = ray_engine() if engine is None else engine
    P = np.asarray(positions, np.float64)
    centre, scale = frame_of(P)
    Q = (P - centre) / scale
    tree = engine.build_bvh(Q[np.asarray(faces, np.int64).reshape(-1, 3)], cancelled=cancelled)
    return centre, scale, Q, tree, engine


def visibility(positions, faces, light, *, only=None, geometry=None, cancelled=None):
    """Visibility of ``light`` at each vertex: (n,) uint8, 1 lit, 0 shadowed.

    positions : (n, 3) float; faces : (m, 3) int (counter-clockwise seen from the front)
    light : a light of :mod:`explorer.core.lights` (it gives the rays: :meth:`shadow_ray`)
    only : (n,) bool, the vertices to cast rays from (the others get 1); default all
    geometry : :func:`frame_bvh` of these positions and faces, when the caller keeps it
    cancelled : () -> bool, asked between chunks of rays (True: raise
        :class:`~explorer.core.errors.Cancelled`)
    """
    n = len(positions)
    vis = np.ones(n, np.uint8)
    idx = np.arange(n) if only is None else np.flatnonzero(only)
    if len(idx) == 0 or len(faces) == 0:
        return vis
    centre, scale, Q, bvh, engine = frame_bvh(positions, faces) if geometry is None else geometry
    D, tmax = light.shadow_ray(Q[idx], centre, scale)
    hit = engine.any_hit(bvh, Q[idx], D, tmax, cancelled=cancelled)
    vis[idx[hit]] = 0
    return vis


def pending_work(cache, scene, shadowed, n: int, faces, *, force_all) -> int:
    """The ray work (:func:`explorer.shading.tiers.ray_work`) :func:`visibility_rows` would do
    now with this ``cache`` on the numpy tier, at most: a tree when none is kept (by any ray
    engine) and a ray from each of the ``n`` vertices for every ``shadowed`` light of
    ``scene`` whose row is not kept."""
    lights = sum(
        1
        for light, on in zip(scene.lights, shadowed, strict=True)
        if on and (light.anchor, scene.two_sided, force_all) not in cache
    )
    tree = lights and not any(isinstance(k, tuple) and k[:1] == (GEOMETRY_KEY,) for k in cache)
    return ray_work(len(faces) if tree else 0, lights * n)


def visibility_rows(
    positions,
    normals,
    faces,
    lights,
    shadowed,
    *,
    two_sided,
    force_all,
    cache,
    cancelled=None,
    engine=None,
):
    """The visibility rows of the lights the plan casts rays for: (S, n) uint8, 1 lit, 0
    shadowed, one row per ``shadowed`` light in order (at least one row: (1, 0) when none, as
    :class:`explorer.shading.kernels.Shadows` takes them), and (L,) int64 each light's row (-1:
    not shadowed). Memory: one byte per vertex and shadowing light (lights without shadows
    take none).

    positions, normals : (n, 3) float; faces : (m, 3) int
    lights : the scene's lights; shadowed : (L,) bool, the lights the plan casts rays for
    two_sided : N flips with V: rays from every vertex with a normal (either side may be lit)
    force_all : rays from every vertex (benchmark); else only where N·L > -SHADOW_NDL_MARGIN
        (:mod:`explorer.core.tolerances`)
    cache : dict kept by the caller for this geometry: it keeps the frame and the BVH
        (:data:`GEOMETRY_KEY` and the ray engine's name), and a light whose rays are unchanged
        (same position or direction) reuses its row
    cancelled : () -> bool, asked while the BVH is built and between chunks of rays (True:
        raise :class:`~explorer.core.errors.Cancelled`; the rows finished so far stay cached)
    engine : the ray engine (default :func:`explorer.shading.tiers.ray_engine`)
    Returns the rows, the index and the number of rays cast."""
    P = positions
    n = len(P)
    index = np.cumsum(np.asarray(shadowed, np.bool_), dtype=np.int64) - 1
    index[~np.asarray(shadowed, np.bool_)] = -1
    count = int(index.max(initial=-1)) + 1
    if not count:  # no light casts shadows: nothing to keep
        return np.ones((1, 0), np.uint8), index, 0
    vis = np.empty((count, n), np.uint8)
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
            engine = ray_engine() if engine is None else engine
            geometry = (GEOMETRY_KEY, engine.__name__)
            if geometry not in cache:
                cache[geometry] = frame_bvh(P, faces, engine, cancelled=cancelled)
            v = visibility(P, faces, light, only=only, geometry=cache[geometry],
                           cancelled=cancelled)  # fmt: skip
            cache[key] = v
            rays += int(n if only is None else only.sum())
        vis[index[i]] = v
    return vis, index, rays
