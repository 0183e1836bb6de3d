"""The per-pixel reference: the engine's lighting evaluated at every pixel, exact normal there.

A per-vertex render (:mod:`explorer.render`) lights the vertices and lets VTK interpolate the
colours across each triangle (Gouraud). The per-pixel reference lights instead the surface
point each pixel sees, with the surface's own normal there, through the *same* camera
(:func:`explorer.render.camera.camera_for`) and the *same* lighting code (:func:`explorer.shade`),
so the only difference between the two pictures is where the lighting is evaluated.

- **Spheres** (the built-in ``sphere`` and ``icosphere``): the ray through each pixel centre
  meets the exact sphere (closed-form ray-sphere intersection); the normal is the radius
  direction. This is the surface the tessellations approximate.
- **Any mesh**: the ray through each pixel centre is cast against the triangles (nearest hit,
  either side, as VTK draws them); the hit's position is on the triangle and its normal is the
  barycentric interpolation of the vertex normals, normalised (Phong shading).

The camera model is VTK's (``vtkCamera``): a pixel (row ``r`` from the top, column ``c``) is
sampled at its centre, normalised device coordinates ``x = 2(c + ½)/w - 1``, ``y = 1 - 2(r +
½)/h``, shifted by the window centre; a parallel camera spans ``±parallel_scale`` vertically
(times the aspect ratio horizontally), a perspective camera ``±tan(view_angle / 2)`` at unit
distance. ``tests/render/test_perpixel.py`` checks this against VTK's own projection matrix and a
per-pixel render of a fine sphere against VTK's render of it.

The ray caster is :func:`explorer.geometry.bvh.nearest_hits`: the pixels' rays go through the
mesh's bounding-volume hierarchy (the one the shadow rays use, built once per mesh and kept
while the mesh lives), in chunks that a ``cancelled`` callable can stop; the nearest hit wins,
at equal distance the lowest triangle index, exactly as testing every triangle would answer.
Nothing here imports VTK.
"""

from __future__ import annotations

import math
import threading
import weakref
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from explorer.core.errors import Cancelled, ExplorerError
from explorer.core.tolerances import DET_EPS, PIXEL_RAY_T_MIN
from explorer.render.camera import _basis, camera_for, mesh_frame, pixel_rays, project
from explorer.render.images import check_size
from explorer.render.offscreen import BACKGROUND
from explorer.shading.display import display_colors, to_bytes
from explorer.shading.shader import shade
from explorer.shading.tiers import ray_engine, ray_work

#: names of built-in meshes that approximate the unit sphere (closed-form reference)
SPHERE_MESHES = ("sphere", "icosphere")
#: methods of :func:`reference`
METHODS = ("auto", "sphere", "raycast")


# -- hits ----------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Hits:
    """The surface points the pixels see.

    mask : (h, w) bool, True where a pixel's ray meets the surface
    positions : (k, 3) float64 world positions of the hits, k = mask.sum(), in row-major
        pixel order (``image[mask]`` order)
    normals : (k, 3) float64 unit normals there
    method : "sphere" (closed form), "raycast" (triangles, interpolated normals) or "raster"
        (:func:`raster_hits`)
    triangles : (k,) int64 the triangle of the mesh each hit lies on (None for the closed form)
    barycentrics : (k, 2) float64 ``(u, v)`` of each hit on its triangle (corner weights
        ``1-u-v, u, v``), for method "raster"; None otherwise
    pixels : (k,) int64 the hits' flat pixel indices (row-major), when the maker had them
        (:func:`compiled_hits`); None otherwise (``np.flatnonzero(mask)``)
    """

    mask: np.ndarray
    positions: np.ndarray
    normals: np.ndarray
    method: str
    triangles: np.ndarray | None = None
    barycentrics: np.ndarray | None = None
    pixels: np.ndarray | None = None


def sphere_hits(camera, size: Sequence[int], centre=(0.0, 0.0, 0.0), radius=1.0) -> Hits:
    """Closed-form hits of the pixel rays on the sphere ``|P - centre| = radius``.

    The nearest intersection in front of the ray's origin; the normal is (P - centre) / radius.
    """
    origins, dirs = pixel_rays(camera, size)
    c = np.asarray(centre, np.float64)
    oc = origins - c
    b = np.einsum("hwi,hwi->hw", dirs, oc)
    q = np.einsum("hwi,hwi->hw", oc, oc) - radius * radius
    disc = b * b - q
    hit = disc >= 0.0
    root = np.sqrt(np.where(hit, disc, 0.0))
    t_near = -b - root
    t_far = -b + root
    t = np.where(t_near > 0.0, t_near, t_far)  # an eye inside the sphere sees the far side
    mask = hit & (t > 0.0)
    P = origins[mask] + t[mask][:, None] * dirs[mask]
    N = (P - c) / radius
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    return Hits(mask, P, N, "sphere")


_bvh_cache: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_bvh_lock = threading.Lock()


def mesh_bvh(mesh, *, cancelled=None, engine=None):
    """The BVH of a mesh's triangles in the mesh's normalised frame
    (:func:`~explorer.render.camera.mesh_frame`: ``(p - centre) / scale``, so that the ray
    arithmetic neither overflows for a mesh of size 1e300 nor underflows at 1e-300), built on
    first use and kept while the mesh lives (a :class:`~explorer.geometry.meshes.Mesh`'s arrays
    are read-only).
    cancelled : () -> bool, asked while the tree is built (:func:`~explorer.geometry.bvh.build_bvh`)
    engine : the ray engine that builds and casts (:func:`explorer.shading.tiers.ray_engine`,
        the default); each keeps its own tree
    """
    engine = ray_engine() if engine is None else engine
    with _bvh_lock:
        bvh = _bvh_cache.get(mesh, {}).get(engine.__name__)
    if bvh is None:
        centre, scale = mesh_frame(mesh)
        P = np.asarray(mesh.positions, np.float64) / scale - centre / scale
        tri = P[np.asarray(mesh.faces, np.int64).reshape(-1, 3)]
        bvh = engine.build_bvh(tri, cancelled=cancelled)
        with _bvh_lock:
            _bvh_cache.setdefault(mesh, {})[engine.__name__] = bvh
    return bvh


def _screen_rect(camera, size, mesh) -> tuple[int, int, int, int] | None:
    """The pixels whose rays may meet the mesh, as (col0, col1, row0, row1) inclusive: the
    projection of its bounding box grown by one pixel, clipped to the picture (the whole
    picture when a corner is behind a perspective camera); None when it covers no pixel."""
    w, h = (int(v) for v in size)
    if mesh.n_faces == 0:
        return None
    lo, hi = mesh.bounds
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])])  # fmt: skip
    col, row, z = project(camera, corners, (w, h))
    if not (np.isfinite(col).all() and np.isfinite(row).all()) or (
        not camera.parallel and (z <= 0.0).any()
    ):
        return 0, w - 1, 0, h - 1
    c0 = max(int(np.floor(col.min())) - 1, 0)
    c1 = min(int(np.ceil(col.max())) + 1, w - 1)
    r0 = max(int(np.floor(row.min())) - 1, 0)
    r1 = min(int(np.ceil(row.max())) + 1, h - 1)
    return (c0, c1, r0, r1) if c0 <= c1 and r0 <= r1 else None


def mesh_hits(camera, size: Sequence[int], mesh, *, cancelled=None) -> Hits:
    """Ray-cast hits of the pixel rays on a mesh's triangles, with interpolated normals.

    mesh : an :class:`explorer.geometry.meshes.Mesh`
    cancelled : () -> bool, asked between chunks of rays (True: raise
        :class:`~explorer.core.errors.Cancelled`)
    The nearest hit of each ray over all triangles (front or back, as VTK draws both); the
    hit's normal is ``(1-u-v)·n0 + u·n1 + v·n2`` normalised (zero stays zero).
    """
    w, h = (int(v) for v in size)
    mask = np.zeros((h, w), bool)
    rect = _screen_rect(camera, (w, h), mesh)
    if rect is None:
        return Hits(mask, np.zeros((0, 3)), np.zeros((0, 3)), "raycast", np.zeros(0, np.int64))
    origins, dirs = pixel_rays(camera, (w, h), rect)
    O = np.ascontiguousarray(origins.reshape(-1, 3))
    D = np.ascontiguousarray(dirs.reshape(-1, 3))
    F = np.asarray(mesh.faces, np.int64).reshape(-1, 3)
    centre, scale = mesh_frame(mesh)  # the rays are cast in the tree's frame (unit directions)
    Of = np.ascontiguousarray(O / scale - centre / scale)
    reach = max(float(np.abs(Of).max(initial=0.0)), 1.0)
    with _bvh_lock:
        kept = bool(_bvh_cache.get(mesh))
    # the tier choice counts this cast's work: a large picture loads the compiled casts
    engine = ray_engine(ray_work(0 if kept else len(F), len(O)))
    tree = mesh_bvh(mesh, cancelled=cancelled, engine=engine)
    best_t, best_tri, best_u, best_v = engine.nearest_hits(
        tree, Of, D, PIXEL_RAY_T_MIN * reach, cancelled=cancelled
    )
    best_t = best_t * scale  # the distances in world units
    c0, c1, r0, r1 = rect
    Nv = np.asarray(mesh.normals, np.float64)
    hit, pos, n = engine.surface_points(O, D, best_t, best_tri, best_u, best_v, F, Nv)
    mask[r0 : r1 + 1, c0 : c1 + 1] = hit.reshape(r1 - r0 + 1, c1 - c0 + 1)
    return Hits(mask, pos, n, "raycast", best_tri[hit])


_corner_cache: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def triangle_corners(mesh) -> np.ndarray:
    """(9, m) float64 rows of the mesh's triangles, what :func:`raster_hits` reads of each: the
    first corner ``a`` (rows 0-2) and the edges ``e1 = b - a`` (3-5) and ``e2 = c - a`` (6-8);
    made on first use and kept while the mesh lives (a
    :class:`~explorer.geometry.meshes.Mesh`'s arrays are read-only)."""
    with _bvh_lock:
        table = _corner_cache.get(mesh)
    if table is None:
        F = np.asarray(mesh.faces, np.int64).reshape(-1, 3)
        P = np.asarray(mesh.positions, np.float64)
        a = P[F[:, 0]]
        table = np.ascontiguousarray(np.hstack((a, P[F[:, 1]] - a, P[F[:, 2]] - a)).T)
        table.flags.writeable = False
        with _bvh_lock:
            _corner_cache[mesh] = table
    return table


def raster_hits(camera, size: Sequence[int], mesh, faces_seen: np.ndarray) -> Hits:
    """The hits of the pixel rays on the triangles a rasteriser says the pixels show: no search,
    each pixel's ray meets the plane of its own triangle (the Möller-Trumbore arithmetic of
    :func:`explorer.geometry.rays.ray_triangle`, without its inside test: at a shared edge the
    rasteriser and the ray may pick neighbours, whose point and interpolated normal agree).

    faces_seen : (h, w) int triangle index per pixel, -1 where none
        (:class:`explorer.render.faceids.FaceIdRenderer`, same camera and size)
    A pixel whose ray runs within DET_EPS of its triangle's plane counts as a miss. The
    arithmetic runs on one component at a time over the covered pixels (each triangle's corner
    and edges gathered from :func:`triangle_corners`); the point ``O + t·D`` and the normal
    ``(1-u-v)·n0 + u·n1 + v·n2`` normalised (zero stays zero) are the ray engine's
    ``surface_points``, as for the ray caster (:func:`mesh_hits`). Returns :class:`Hits`
    (method "raster").
    """
    w, h = (int(v) for v in size)
    seen = np.asarray(faces_seen)
    if seen.shape != (h, w):
        raise ExplorerError(f"faces_seen must have shape ({h}, {w}), got {seen.shape}")
    flat = np.flatnonzero(seen >= 0)
    if flat.size == 0:
        none = np.zeros((0, 3))
        empty = (np.zeros(0, np.int64), np.zeros((0, 2)))
        return Hits(np.zeros((h, w), bool), none, none, "raster", *empty)
    O, D = pixel_rays(camera, (w, h), pixels=np.divmod(flat, w))  # (k, 3) each
    f = seen.reshape(-1)[flat].astype(np.int64)
    a0, a1, a2, e10, e11, e12, e20, e21, e22 = np.take(triangle_corners(mesh), f, axis=1)
    d0, d1, d2 = D.T  # (one component at a time)
    p0, p1, p2 = d1 * e22 - d2 * e21, d2 * e20 - d0 * e22, d0 * e21 - d1 * e20  # D x e2
    det = e10 * p0 + e11 * p1 + e12 * p2
    ok = np.abs(det) > DET_EPS
    inv = 1.0 / np.where(ok, det, 1.0)
    s0, s1, s2 = O[:, 0] - a0, O[:, 1] - a1, O[:, 2] - a2
    q0, q1, q2 = s1 * e12 - s2 * e11, s2 * e10 - s0 * e12, s0 * e11 - s1 * e10  # s x e1
    u = (s0 * p0 + s1 * p1 + s2 * p2) * inv
    v = (d0 * q0 + d1 * q1 + d2 * q2) * inv
    t = (e20 * q0 + e21 * q1 + e22 * q2) * inv
    tri = np.where(ok, f, -1)  # (rays along their triangle's plane: misses)
    F = np.asarray(mesh.faces, np.int64).reshape(-1, 3)
    Nv = np.asarray(mesh.normals, np.float64)
    engine = ray_engine(ray_work(0, len(f)))  # (the compiled points once the kernels load)
    hit, pos, n = engine.surface_points(O, D, t, tri, u, v, F, Nv)
    mask = np.zeros(h * w, bool)
    mask[flat[hit]] = True
    uv = np.stack([u[hit], v[hit]], axis=1)
    return Hits(mask.reshape(h, w), pos, n, "raster", f[hit], uv)


def compiled_hits(camera, size: Sequence[int], mesh) -> Hits | None:
    """:func:`raster_hits` without VTK: the compiled G-buffer
    (:func:`explorer.geometry.raster.gbuffer`: its own z-buffer rasteriser, sampling pixel
    centres as OpenGL does, then the same arithmetic in one parallel pass), or None when the
    mesh reaches outside the camera's clipping range (VTK's picture, which clips, then
    decides). Returns :class:`Hits` (method "raster") with ``pixels`` given: the covered
    pixels' flat indices."""
    from explorer.geometry.raster import gbuffer  # (compiled: loaded on first use)

    w, h = check_size(size)
    forward, right, up = _basis(camera)
    aspect = w / h
    if camera.parallel:
        s = float(camera.parallel_scale)
        half = (s * aspect, s)
    else:
        t = math.tan(math.radians(camera.view_angle) / 2.0)
        half = (t * aspect, t)
    ends = (camera.position, right, up, forward, half, camera.window_center, camera.clipping_range)
    cam = np.concatenate([np.asarray(x, np.float64) for x in ends])
    out = gbuffer(mesh.positions, mesh.normals, mesh.faces, cam, not camera.parallel, (w, h))
    if out is None:
        return None
    mask, pixels, tri, uv, pos, n = out
    return Hits(mask, pos, n, "raster", tri, uv, pixels)


def is_unit_sphere(mesh, tol: float = 1e-9) -> bool:
    """True for a built-in sphere tessellation: named sphere/icosphere, every vertex on the
    unit sphere about the origin with its radius direction as normal."""
    if mesh.name not in SPHERE_MESHES or mesh.n_vertices == 0:
        return False
    r = np.linalg.norm(mesh.positions, axis=1)
    return bool(np.all(np.abs(r - 1.0) < tol) and np.allclose(mesh.normals, mesh.positions))


def hits(
    scene, mesh, size: Sequence[int], *, camera=None, method: str = "auto", cancelled=None
) -> Hits:
    """What each pixel sees: :func:`sphere_hits` for a built-in sphere (``method="auto"`` or
    ``"sphere"``), :func:`mesh_hits` otherwise (or with ``method="raycast"``).

    camera : default :func:`explorer.render.camera.camera_for` (scene, mesh, w / h), the camera of a
        per-vertex render of the same scene
    cancelled : () -> bool, asked between chunks of rays (:func:`mesh_hits`)
    """

    w, h = check_size(size)
    if method not in METHODS:
        raise ExplorerError(f"per-pixel method must be one of {METHODS}, got {method!r}")
    if camera is None:
        camera = camera_for(scene, mesh, w / h)
    if method == "sphere" or (method == "auto" and is_unit_sphere(mesh)):
        if method == "sphere" and not is_unit_sphere(mesh):
            raise ExplorerError(
                f"mesh {mesh.name!r} is not a built-in unit sphere; use method='raycast'"
            )
        return sphere_hits(camera, (w, h))
    return mesh_hits(camera, (w, h), mesh, cancelled=cancelled)


# -- colours and pictures ------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Reference:
    """A per-pixel reference picture.

    hits : what the pixels see (:class:`Hits`)
    colors : (k, 3) float64 engine colours of the hits, in [0, 1]
    sums : :attr:`specular`, or a function of no arguments that computes it on first use
    """

    hits: Hits
    colors: np.ndarray
    sums: object

    @property
    def specular(self) -> np.ndarray:
        """(k,) float64 unclamped specular light sum (sum of RGB channels) of the hits: its
        largest value marks the highlight peak."""
        if callable(self.sums):
            object.__setattr__(self, "sums", np.asarray(self.sums(), np.float64))
        return self.sums

    @property
    def mask(self) -> np.ndarray:
        return self.hits.mask

    def image(self, background=None) -> np.ndarray:
        """The picture: (h, w, 3) uint8, colours rounded as the per-vertex render rounds
        them, background where no surface is seen."""

        bg = BACKGROUND if background is None else background
        h, w = self.mask.shape
        out = np.empty((h, w, 3), np.uint8)
        out[:] = to_bytes(np.asarray(bg, np.float64)[None, :])[0]
        out[self.mask] = to_bytes(self.colors)
        return out

    def peak_index(self) -> tuple[int, int] | None:
        """(row, column) of the highlight peak (the largest specular sum), or None when no
        pixel has specular light."""
        if self.specular.size == 0 or not float(self.specular.max()) > 0.0:
            return None
        k = int(np.argmax(self.specular))
        rows, cols = np.nonzero(self.mask)
        return int(rows[k]), int(cols[k])


def point_colors(scene, positions, normals, *, mesh=None, precision: str = "float64"):
    """Display colours of surface points, computed as the per-vertex renderer computes its
    vertices' (:func:`explorer.shading.display.display_colors`). With a light that casts
    shadows the points are shaded together with ``mesh``'s vertices and triangles, so the
    engine's own shadow rays decide what each point sees.

    positions, normals : (k, 3) float
    Returns (k, 3) float64 display colours in [0, 1].
    """
    if mesh is None or not any(getattr(lt, "shadows", False) for lt in scene.lights):
        return display_colors(scene, positions, normals, precision=precision)
    both = display_colors(
        scene,
        np.vstack([mesh.positions, positions]),
        np.vstack([mesh.normals, normals]),
        faces=mesh.faces,
        precision=precision,
    )
    return both[mesh.n_vertices :]


def specular_sums(scene, positions, normals) -> np.ndarray:
    """The unclamped specular light sum of each point, summed over RGB: (k,) float64.

    The engine's colours with a material that keeps only its specular, at 1 (the lobe, Fresnel
    and energy factors stay): ``colour = s_m · S`` with ``s_m = 1`` is the specular sum ``S`` of
    :func:`explorer.shading.equation.equation_terms`, computed by the engine (:func:`shade`).
    """
    black = (0.0, 0.0, 0.0)
    m = scene.material.replace(ambient=black, diffuse=black, emission=black, specular=(1.0,) * 3)
    return shade(scene.replace(material=m), positions, normals, clamp=False).sum(axis=1)


def reference(
    scene,
    mesh,
    size: Sequence[int],
    *,
    camera=None,
    method: str = "auto",
    precision: str = "float64",
    cancelled=None,
    materials=None,
) -> Reference:
    """The per-pixel reference of a scene on a mesh (see the module docstring).

    The colours come from :func:`point_colors` (the engine, :func:`explorer.shade`) on the hit
    positions and normals; the scene is used unchanged (model, lights, viewer, material). The
    specular sums (:attr:`Reference.specular`) are computed when first asked for.
    cancelled : () -> bool, asked between chunks of rays and before the colours (True: raise
        :class:`~explorer.core.errors.Cancelled`)
    materials : one :class:`~explorer.core.material.Material` per group of ``mesh.groups`` (a
        mesh file's own materials): each pixel in its triangle's group's material, as
        :func:`explorer.shading.display.group_vertex_colors` colours the vertices (method
        "auto" then casts rays); None: the scene's material everywhere
    Returns a :class:`Reference`.
    """

    if materials is not None and method == "auto":
        method = "raycast"  # (the triangle of each hit names its group)
    h = hits(scene, mesh, size, camera=camera, method=method, cancelled=cancelled)
    return reference_of(scene, mesh, h, materials=materials, precision=precision,
                        cancelled=cancelled)  # fmt: skip


def reference_of(scene, mesh, h: Hits, *, materials=None, precision: str = "float64",
                 cancelled=None) -> Reference:  # fmt: skip
    """The per-pixel reference of the hits ``h`` (as :func:`reference`, whose hits are found
    by :func:`hits`; :func:`raster_hits` gives others). Returns a :class:`Reference`."""
    if cancelled is not None and cancelled():
        raise Cancelled("the per-pixel reference was cancelled")
    parts = _parts(scene, mesh, h, materials)
    colors = np.zeros((len(h.positions), 3))
    for rows, sc in parts:
        P, N = h.positions[rows], h.normals[rows]
        if len(P):
            colors[rows] = point_colors(sc, P, N, mesh=mesh, precision=precision)

    def sums():
        out = np.zeros(len(h.positions))
        for rows, sc in parts:
            P, N = h.positions[rows], h.normals[rows]
            if len(P):
                out[rows] = specular_sums(sc, P, N)
        return out

    return Reference(h, colors, sums)


def _parts(scene, mesh, h: Hits, materials) -> list[tuple[object, object]]:
    """Which hits each material shades: [(rows: a slice of every hit, or (j,) int64 indices;
    the scene in that material)]."""
    if materials is None:
        return [(slice(None), scene)]  # (a view: no copy of the hits)
    every = np.arange(len(h.positions))
    groups = mesh.groups
    if groups is None or len(materials) != len(groups.names):
        n = 0 if groups is None else len(groups.names)
        raise ExplorerError(f"need one material per group of the mesh ({n}), got {len(materials)}")
    if h.triangles is None:
        raise ExplorerError("per-group colours need the triangle of each hit (method 'raycast')")
    of_hit = groups.of_vertex[np.asarray(mesh.faces, np.int64)[h.triangles, 0]]
    return [(every[of_hit == g], scene.replace(material=m)) for g, m in enumerate(materials)]
