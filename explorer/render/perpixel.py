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

The ray caster is :func:`explorer.geometry.rays.nearest_hits` (no R-tree or Embree needed): each
triangle's projected bounding box selects the pixels whose rays are tested against it exactly
(Möller-Trumbore), and the nearest hit wins. Nothing here imports VTK.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from explorer.core.errors import ExplorerError
from explorer.core.tolerances import PIXEL_RAY_T_MIN
from explorer.geometry.rays import nearest_hits, triangle_edges
from explorer.render.camera import camera_for, pixel_rays, project
from explorer.render.images import check_size
from explorer.render.offscreen import BACKGROUND
from explorer.shading.display import display_colors, to_bytes
from explorer.shading.equation import equation_terms

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
    method : "sphere" (closed form) or "raycast" (triangles, interpolated normals)
    """

    mask: np.ndarray
    positions: np.ndarray
    normals: np.ndarray
    method: str


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


def _pixel_boxes(camera, size, tri: np.ndarray) -> np.ndarray:
    """Inclusive pixel ranges (col0, col1, row0, row1) whose rays may meet each triangle: its
    projected bounding box grown by one pixel, clipped to the picture (empty, col0 > col1 or
    row0 > row1, when off it); the whole picture for a triangle that reaches behind a
    perspective camera. tri : (m, 3, 3). Returns (m, 4) int64."""
    w, h = (int(v) for v in size)
    m = len(tri)
    col, row, z = (a.reshape(m, 3) for a in project(camera, tri.reshape(-1, 3), size))
    ok = np.isfinite(col).all(1) & np.isfinite(row).all(1)
    if not camera.parallel:
        ok &= (z > 0.0).all(1)
    col = np.where(ok[:, None], col, 0.0)
    row = np.where(ok[:, None], row, 0.0)
    box = np.stack(
        [
            np.floor(col.min(1)) - 1.0,
            np.ceil(col.max(1)) + 1.0,
            np.floor(row.min(1)) - 1.0,
            np.ceil(row.max(1)) + 1.0,
        ],
        1,
    )
    box[~ok] = (0, w - 1, 0, h - 1)
    box[:, 0] = np.clip(box[:, 0], 0, w)  # col0 = w: empty
    box[:, 1] = np.clip(box[:, 1], -1, w - 1)  # col1 = -1: empty
    box[:, 2] = np.clip(box[:, 2], 0, h)
    box[:, 3] = np.clip(box[:, 3], -1, h - 1)
    return box.astype(np.int64)


def mesh_hits(camera, size: Sequence[int], mesh) -> Hits:
    """Ray-cast hits of the pixel rays on a mesh's triangles, with interpolated normals.

    mesh : an :class:`explorer.geometry.meshes.Mesh`
    The nearest hit of each ray over all triangles (front or back, as VTK draws both); the
    hit's normal is ``(1-u-v)·n0 + u·n1 + v·n2`` normalised (zero stays zero).
    """
    w, h = (int(v) for v in size)
    origins, dirs = pixel_rays(camera, (w, h))
    P = np.asarray(mesh.positions, np.float64)
    F = np.asarray(mesh.faces, np.int64)
    tri = P[F]  # (m, 3, 3)
    v0, e1, e2 = triangle_edges(tri)
    box = np.ascontiguousarray(_pixel_boxes(camera, (w, h), tri))
    best_t = np.full((h, w), np.inf)
    best_tri = np.full((h, w), -1, np.int64)
    best_u = np.zeros((h, w))
    best_v = np.zeros((h, w))
    scale = max(float(np.abs(P).max(initial=0.0)), 1.0)
    if len(F):
        nearest_hits(
            v0,
            e1,
            e2,
            box,
            np.ascontiguousarray(origins),
            np.ascontiguousarray(dirs),
            PIXEL_RAY_T_MIN * scale,
            best_t,
            best_tri,
            best_u,
            best_v,
        )
    mask = best_tri >= 0
    f = best_tri[mask]
    u, v = best_u[mask], best_v[mask]
    pos = origins[mask] + best_t[mask][:, None] * dirs[mask]
    Nv = np.asarray(mesh.normals, np.float64)
    n = (1.0 - u - v)[:, None] * Nv[F[f, 0]] + u[:, None] * Nv[F[f, 1]] + v[:, None] * Nv[F[f, 2]]
    length = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.divide(n, length, out=np.zeros_like(n), where=length > 1e-12)
    return Hits(mask, pos, n, "raycast")


def is_unit_sphere(mesh, tol: float = 1e-9) -> bool:
    """True for a built-in sphere tessellation: named sphere/icosphere, every vertex on the
    unit sphere about the origin with its radius direction as normal."""
    if mesh.name not in SPHERE_MESHES or mesh.n_vertices == 0:
        return False
    r = np.linalg.norm(mesh.positions, axis=1)
    return bool(np.all(np.abs(r - 1.0) < tol) and np.allclose(mesh.normals, mesh.positions))


def hits(scene, mesh, size: Sequence[int], *, camera=None, method: str = "auto") -> Hits:
    """What each pixel sees: :func:`sphere_hits` for a built-in sphere (``method="auto"`` or
    ``"sphere"``), :func:`mesh_hits` otherwise (or with ``method="raycast"``).

    camera : default :func:`explorer.render.camera.camera_for` (scene, mesh, w / h), the camera of a
        per-vertex render of the same scene
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
    return mesh_hits(camera, (w, h), mesh)


# -- colours and pictures ------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Reference:
    """A per-pixel reference picture.

    hits : what the pixels see (:class:`Hits`)
    colors : (k, 3) float64 engine colours of the hits, in [0, 1]
    specular : (k,) float64 unclamped specular light sum (sum of RGB channels) of the hits:
        its largest value marks the highlight peak
    """

    hits: Hits
    colors: np.ndarray
    specular: np.ndarray

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


def reference(
    scene,
    mesh,
    size: Sequence[int],
    *,
    camera=None,
    method: str = "auto",
    precision: str = "float64",
) -> Reference:
    """The per-pixel reference of a scene on a mesh (see the module docstring).

    The colours come from :func:`point_colors` (the engine, :func:`explorer.shade`) on the hit
    positions and normals; the scene is used unchanged (model, lights, viewer, material).
    Returns a :class:`Reference`.
    """

    h = hits(scene, mesh, size, camera=camera, method=method)
    if len(h.positions):
        colors = point_colors(scene, h.positions, h.normals, mesh=mesh, precision=precision)
        spec = equation_terms(scene, h.positions, h.normals)["specular"].sum(axis=1)
    else:
        colors = np.zeros((0, 3))
        spec = np.zeros(0)
    return Reference(h, colors, spec)
