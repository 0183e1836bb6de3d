"""Cameras: where a picture is taken from, how it frames a mesh, and the pixel rays it casts.

One camera model for the whole project, VTK's (``vtkCamera``): :class:`Camera` holds its
fields, :func:`camera_for` frames a mesh as the scene's viewer sees it, :func:`apply_camera` and
:func:`camera_from_vtk` convert to and from a live ``vtkCamera``, and :func:`pixel_rays` /
:func:`project` give the ray through each pixel centre and where a point lands (the per-pixel
reference and the tests use them).

Scale: a camera is computed with scale-safe lengths (:func:`vector_length`), so a mesh of size
1e-300 or 1e300 is framed as a unit one; the renderers hand VTK the mesh and the camera in the
mesh's normalised frame (:func:`in_frame`, the same similarity for both: the same picture), so
that VTK's float32 drawing never meets coordinates beyond its range. A mesh too large for its
camera's coordinates (4 radii from the centre) to be finite float64 numbers is refused with an
:class:`~explorer.core.errors.ExplorerError`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from explorer.core.errors import ExplorerError
from explorer.geometry.frame import frame_of
from explorer.geometry.meshes import Mesh

Vec3 = tuple[float, float, float]
#: the mesh's bounding sphere spans 1 / FRAME_MARGIN of the image's smaller side
FRAME_MARGIN = 1.08


# -- camera --------------------------------------------------------------------------------


@dataclass(frozen=True)
class Camera:
    """Where the picture is taken from.

    position, focal_point, view_up : (3,) world coordinates
    parallel : True for a parallel projection (infinite viewer)
    parallel_scale : half the view's height in world units (parallel projection)
    view_angle : vertical field of view in degrees (perspective)
    clipping_range : (near, far) distances from the camera
    window_center : shift of the image centre in normalised viewport units ([-1, 1]²); it
        moves the picture without turning the camera (used to leave room for a label)
    """

    position: Vec3
    focal_point: Vec3
    view_up: Vec3
    parallel: bool
    parallel_scale: float
    view_angle: float
    clipping_range: tuple[float, float]
    window_center: tuple[float, float] = (0.0, 0.0)

    @property
    def direction(self) -> np.ndarray:
        """(3,) unit vector from the camera toward the focal point."""
        d = np.subtract(self.focal_point, self.position)
        return d / vector_length(d)  # scale-safe: a camera 4e300 from its focal point too


def _view_up(forward: np.ndarray) -> np.ndarray:
    """+y made perpendicular to ``forward``; looking straight down (up) use -z (+z), so +x
    stays on the right."""
    up = np.array([0.0, 1.0, 0.0])
    if abs(float(forward @ up)) > 0.999:
        up = np.array([0.0, 0.0, -1.0 if forward[1] < 0 else 1.0])
    up = up - (up @ forward) * forward
    return up / np.linalg.norm(up)


def vector_length(v) -> float:
    """The length of a vector (3,), without overflow or underflow of its squares."""
    v = np.asarray(v, np.float64)
    with np.errstate(over="ignore", under="ignore"):
        n = float(np.linalg.norm(v))
    if 1e-150 < n < 1e150:  # the squares neither overflowed nor underflowed
        return n
    m = float(np.max(np.abs(v)))
    if m == 0.0 or not math.isfinite(m):
        return m
    u = v / m
    return m * math.sqrt(float(u @ u))


def in_frame(camera: Camera, centre, scale: float) -> Camera:
    """``camera`` in the normalised frame ``(centre, scale)`` (:func:`explorer.geometry.frame.
    frame_of`): points ``(p - centre) / scale``, lengths ``/ scale``, angles as they are. A
    mesh in that frame seen by this camera gives the world camera's picture."""
    c = np.asarray(centre, np.float64) / scale

    def point(p):
        return tuple(float(x) for x in np.asarray(p, np.float64) / scale - c)

    near, far = camera.clipping_range
    return Camera(point(camera.position), point(camera.focal_point), camera.view_up,
                  camera.parallel, camera.parallel_scale / scale, camera.view_angle,
                  (near / scale, far / scale), camera.window_center)  # fmt: skip


def out_of_frame(camera: Camera, centre, scale: float) -> Camera:
    """The inverse of :func:`in_frame`: ``camera`` given in the frame ``(centre, scale)`` as
    the world camera (points ``p * scale + centre``, lengths ``* scale``)."""
    c = np.asarray(centre, np.float64)

    def point(p):
        return tuple(float(x) for x in np.asarray(p, np.float64) * scale + c)

    near, far = camera.clipping_range
    return Camera(point(camera.position), point(camera.focal_point), camera.view_up,
                  camera.parallel, camera.parallel_scale * scale, camera.view_angle,
                  (near * scale, far * scale), camera.window_center)  # fmt: skip


def mesh_frame(mesh: Mesh) -> tuple[np.ndarray, float]:
    """The frame the renderers hand VTK a mesh in (:func:`in_frame`)."""
    return frame_of(np.asarray(mesh.positions, np.float64))


def _finite(camera: Camera, mesh: Mesh) -> Camera:
    """``camera``, when every field is a finite number; else the mesh is too large to frame."""
    values = [*camera.position, *camera.focal_point, camera.parallel_scale, *camera.clipping_range]
    if not all(math.isfinite(v) for v in values):
        raise _too_large(mesh)
    return camera


def _too_large(mesh: Mesh) -> ExplorerError:
    return too_large(mesh.name, mesh.radius)


def too_large(name: str, radius: float) -> ExplorerError:
    """The refusal of a mesh too large to frame (mesh ``name`` of ``radius``), the renderers'
    and the explorer's (whose lights and viewer keep their places in mesh radii)."""
    return ExplorerError(
        f"mesh '{name}' is too large to frame (radius {radius:.3g}): its camera would "
        "lie beyond the float64 range; scale it down (coordinates up to about 1e300 render)"
    )


def camera_for(scene, mesh: Mesh, aspect: float = 1.0, *, bottom: float = 0.0) -> Camera:
    """The camera that sees what the scene's viewer sees, framing the mesh.

    scene : a :class:`~explorer.core.scene.Scene` (only ``scene.viewer`` is used)
    mesh : the mesh to frame
    aspect : image width / height
    bottom : fraction of the image height kept free at the bottom (for a label), in [0, 0.9]

    Infinite viewer (``viewer.to_viewer``): parallel projection along ``-to_viewer``, so every
    pixel is seen along the engine's constant ``V``; the view is fitted to the mesh's
    projected bounding box (times :data:`FRAME_MARGIN`) and centred on it.

    Local viewer (``viewer.eye``): perspective camera *at the eye* looking at the mesh's
    bounding-box centre; the field of view is the smallest that holds the mesh's bounding
    sphere (times :data:`FRAME_MARGIN`) across both image directions, at most 150 degrees (an
    eye inside the sphere sees what fits).
    """
    bottom = min(max(float(bottom), 0.0), 0.9)
    centre = np.asarray(mesh.centre, np.float64)
    radius = float(mesh.radius)
    if not radius > 0.0:  # a single point: any small sphere about it
        radius = max(1e-12 * vector_length(centre), 1e-300)
    viewer = scene.viewer
    if viewer.eye is not None:
        eye = np.asarray(viewer.eye, np.float64)
        with np.errstate(over="ignore"):
            offset = centre - eye
        dist = vector_length(offset)
        if not math.isfinite(dist):
            raise _too_large(mesh)
        if dist <= 1e-9 * radius:  # eye at the centre: look down -z as OpenGL does
            forward = np.array([0.0, 0.0, -1.0])
            focal = eye + forward * radius
        else:
            forward = offset / dist
            focal = centre
        ratio = radius * FRAME_MARGIN / dist if dist > 0 else math.inf
        half = math.asin(ratio) if ratio < 1.0 else math.radians(75.0)
        t = math.tan(half)
        # the mesh fits the top (1 - bottom) of the height and the whole width
        t_v = max(t / (1.0 - bottom), t / aspect)
        angle = min(math.degrees(2.0 * math.atan(t_v)), 150.0)
        shift = t * bottom / (1.0 - bottom) / t_v if bottom else 0.0
        near = max(dist - 1.5 * radius, 1e-3 * radius)
        far = dist + 1.5 * radius
        camera = Camera(
            tuple(eye),
            tuple(focal),
            tuple(_view_up(forward)),
            False,
            1.0,
            angle,
            (near, far),
            (0.0, -shift),
        )
        return _finite(camera, mesh)
    toward = np.asarray(viewer.to_viewer, np.float64)
    toward = toward / np.linalg.norm(toward)
    forward = -toward
    up = _view_up(forward)
    right = np.cross(forward, up)
    with np.errstate(over="ignore", invalid="ignore"):  # too large: refused below
        rel = mesh.positions - centre
        u, v = rel @ right, rel @ up
        uc, vc = 0.5 * (u.min() + u.max()), 0.5 * (v.min() + v.max())
        hw = 0.5 * (u.max() - u.min()) * FRAME_MARGIN
        hh = 0.5 * (v.max() - v.min()) * FRAME_MARGIN
        scale = max(hh / (1.0 - bottom), hw / aspect, 1e-3 * radius)
        focal = centre + right * uc + up * (vc - scale * bottom)
        dist = 4.0 * radius
        camera = Camera(
            tuple(focal + toward * dist),
            tuple(focal),
            tuple(up),
            True,
            scale,
            30.0,
            (dist - 1.5 * radius, dist + 1.5 * radius),
        )
    return _finite(camera, mesh)


def apply_camera(vtk_camera, cam: Camera) -> None:
    """Set a ``vtkCamera`` to ``cam`` (every field, clipping range and window centre too)."""
    c = vtk_camera
    c.SetPosition(*cam.position)
    c.SetFocalPoint(*cam.focal_point)
    c.SetViewUp(*cam.view_up)
    c.SetParallelProjection(bool(cam.parallel))
    c.SetParallelScale(cam.parallel_scale)
    c.SetViewAngle(cam.view_angle)
    c.SetClippingRange(*cam.clipping_range)
    c.SetWindowCenter(*cam.window_center)


def back_to_front(mesh: Mesh, camera: Camera) -> np.ndarray:
    """Order of the triangles from the farthest to the nearest seen from the camera (by their
    centroids): (m,) int64, stable so ties keep the file order."""
    centre, scale = mesh_frame(mesh)  # in the frame: no overflow of the distances' squares
    camera = in_frame(camera, centre, scale)
    centroids = (mesh.positions / scale - centre / scale)[mesh.faces].mean(axis=1)
    if camera.parallel:
        depth = (centroids - np.asarray(camera.position)) @ camera.direction
    else:
        depth = np.linalg.norm(centroids - np.asarray(camera.position), axis=1)
    return np.argsort(-depth, kind="stable")


# -- the camera ----------------------------------------------------------------------------


def _basis(camera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit forward, right and up vectors of a camera, as VTK builds its view transform."""
    forward = np.subtract(camera.focal_point, camera.position).astype(np.float64)
    forward /= vector_length(forward)
    right = np.cross(forward, np.asarray(camera.view_up, np.float64))
    norm = np.linalg.norm(right)
    if norm < 1e-12:
        raise ExplorerError("camera view-up is parallel to the view direction")
    right /= norm
    up = np.cross(right, forward)
    return forward, right, up


def pixel_ndc(size: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
    """Normalised device coordinates of the pixel centres.

    size : (width, height)
    Returns x : (w,) left to right and y : (h,) top to bottom (image row order), each in
    (-1, 1).
    """
    w, h = (int(v) for v in size)
    x = (2.0 * (np.arange(w) + 0.5)) / w - 1.0
    y = 1.0 - (2.0 * (np.arange(h) + 0.5)) / h
    return x, y


def pixel_rays(
    camera, size: Sequence[int], rect=None, *, pixels=None
) -> tuple[np.ndarray, np.ndarray]:
    """The ray through the centre of every pixel.

    camera : an :class:`explorer.render.camera.Camera`
    size : (width, height) of the picture
    rect : (col0, col1, row0, row1), inclusive: only the rays of these pixels (the same
        numbers as in the whole picture's arrays); None: every pixel
    pixels : (rows, cols), two (k,) int arrays: only the rays of these k pixels, as (k, 3)
        arrays (the same numbers again; instead of ``rect``)
    Returns origins and unit directions, each (h, w, 3) float64 (the rectangle's height and
    width with ``rect``), in image row order (row 0 at the top). A parallel camera's rays start
    on the plane through the camera position; a perspective camera's all start at its position.
    """
    w, h = (int(v) for v in size)
    aspect = w / h
    forward, right, up = _basis(camera)
    nx, ny = pixel_ndc((w, h))
    cx, cy = camera.window_center
    if pixels is not None:
        r, c = pixels
        sx, sy = (nx[c] + cx)[:, None], (ny[r] + cy)[:, None]
        shape: tuple = (len(sx), 3)
    else:
        if rect is not None:
            c0, c1, r0, r1 = (int(v) for v in rect)
            nx, ny = nx[c0 : c1 + 1], ny[r0 : r1 + 1]
        sx = (nx + cx)[None, :, None]
        sy = (ny + cy)[:, None, None]
        shape = (len(ny), len(nx), 3)
    pos = np.asarray(camera.position, np.float64)
    if camera.parallel:
        s = float(camera.parallel_scale)
        origins = pos + sx * (s * aspect) * right + sy * s * up
        directions = np.broadcast_to(forward, shape).copy()
        return origins, directions
    t = math.tan(math.radians(camera.view_angle) / 2.0)
    d = forward + sx * (t * aspect) * right + sy * t * up
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    return np.broadcast_to(pos, shape).copy(), d


def project(camera, points, size: Sequence[int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where world points land in the picture: column, row (pixel units, pixel centres at
    whole numbers + 0, row 0 at the top) and depth along the view direction (> 0 in front of a
    perspective camera).

    points : (n, 3) float
    Returns three (n,) float64 arrays.
    """
    w, h = (int(v) for v in size)
    aspect = w / h
    forward, right, up = _basis(camera)
    rel = np.asarray(points, np.float64) - np.asarray(camera.position, np.float64)
    x, y, z = rel @ right, rel @ up, rel @ forward
    cx, cy = camera.window_center
    if camera.parallel:
        s = float(camera.parallel_scale)
        nx, ny = x / (s * aspect), y / s
    else:
        t = math.tan(math.radians(camera.view_angle) / 2.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            nx, ny = x / (z * t * aspect), y / (z * t)
    nx, ny = nx - cx, ny - cy
    col = (nx + 1.0) * (w / 2.0) - 0.5
    row = (1.0 - ny) * (h / 2.0) - 0.5
    return col, row, z


def camera_from_vtk(vtk_camera, window_center=None):
    """The :class:`explorer.render.camera.Camera` of a live ``vtkCamera`` (a GUI's current view), so
    the per-pixel reference sees exactly what that camera sees."""

    wc = tuple(vtk_camera.GetWindowCenter()) if window_center is None else window_center
    return Camera(
        position=tuple(vtk_camera.GetPosition()),
        focal_point=tuple(vtk_camera.GetFocalPoint()),
        view_up=tuple(vtk_camera.GetViewUp()),
        parallel=bool(vtk_camera.GetParallelProjection()),
        parallel_scale=float(vtk_camera.GetParallelScale()),
        view_angle=float(vtk_camera.GetViewAngle()),
        clipping_range=tuple(vtk_camera.GetClippingRange()),
        window_center=(float(wc[0]), float(wc[1])),
    )


def sphere_camera(scene, aspect: float = 1.0):
    """:func:`explorer.render.camera.camera_for` framing the exact unit sphere at the origin (the
    surface every built-in sphere tessellation approximates): one camera for all of them."""

    if scene.viewer.local:
        pts = np.vstack([np.eye(3), -np.eye(3)])
    else:
        forward = -np.asarray(scene.viewer.to_viewer, np.float64)
        up = _view_up(forward)
        right = np.cross(forward, up)
        pts = np.array([right, -right, up, -up, forward, -forward])
    proxy = Mesh(pts, pts, np.zeros((0, 3), np.int64), "sphere")
    return camera_for(scene, proxy, aspect)
