"""Off-screen pictures of the engine's colours: PNG renders, the preset sheet, PLY/GLB export.

The engine computes one colour per vertex (:func:`explorer.shade`); VTK only draws them. The
colours go to VTK as RGB point scalars with VTK's lighting off, so VTK adds nothing: no light of
its own, no specular, no ambient (``add_mesh(..., rgb=True, lighting=False)``, see the last
section of the lighting-equation reference). Between vertices VTK interpolates the colours
linearly across each triangle: Gouraud shading, as in OpenGL's fixed-function pipeline. No
multisampling or anti-aliasing, a fixed background, ``render()`` before ``screenshot()``, and
every plotter is closed afterwards: the same scene gives the same pixels every time.

Camera and viewer agree (see :func:`camera_for`):

- a **local viewer** (``viewer: {eye: ...}``) puts a perspective camera at the eye, looking at
  the mesh's centre, with the narrowest field of view that shows the whole mesh;
- an **infinite viewer** (``viewer: {direction: ...}``, the default) is a *parallel*
  projection looking along ``-direction``: every pixel is seen along the same ``V``, exactly
  what the engine assumes. The view is scaled so the mesh's bounding sphere fits.

VTK is imported only inside the functions that draw or read/write PNG files.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import ExplorerError
from .fileio import write_atomic
from .meshes import Mesh

Vec3 = tuple[float, float, float]

#: background colour of every render (linear RGB in [0, 1]): a neutral mid-dark grey on which
#: both black rubber and white plastic read
BACKGROUND: Vec3 = (0.32, 0.32, 0.32)
#: default image size (width, height)
DEFAULT_SIZE = (400, 400)
#: smallest and largest accepted image side in pixels
SIZE_RANGE = (16, 8192)
#: the mesh's bounding sphere spans 1 / FRAME_MARGIN of the image's smaller side
FRAME_MARGIN = 1.08
#: output formats of ``phong-explorer render --out``
OUTPUT_SUFFIXES = (".png", ".ply", ".glb")
#: the light of the preset sheet when no scene is given: OpenGL's directional light from the
#: upper front, as in the classic chart of teapot materials (light position (0, 3, 3, 0))
SHEET_LIGHT_DIRECTION: Vec3 = (0.0, 1.0, 1.0)
#: default preset sheet layout
SHEET_TILE = (200, 150)
SHEET_COLUMNS = 6
#: label text colour and height (fraction of the tile height) on the sheet
LABEL_COLOR: Vec3 = (1.0, 1.0, 1.0)
LABEL_HEIGHT = 0.085


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
        return d / np.linalg.norm(d)


def _view_up(forward: np.ndarray) -> np.ndarray:
    """+y made perpendicular to ``forward``; looking straight down (up) use -z (+z), so +x
    stays on the right."""
    up = np.array([0.0, 1.0, 0.0])
    if abs(float(forward @ up)) > 0.999:
        up = np.array([0.0, 0.0, -1.0 if forward[1] < 0 else 1.0])
    up = up - (up @ forward) * forward
    return up / np.linalg.norm(up)


def camera_for(scene, mesh: Mesh, aspect: float = 1.0, *, bottom: float = 0.0) -> Camera:
    """The camera that sees what the scene's viewer sees, framing the mesh.

    scene : a :class:`~explorer.scene.Scene` (only ``scene.viewer`` is used)
    mesh : the mesh to frame
    aspect : image width / height
    bottom : fraction of the image height kept free at the bottom (for a label), in [0, 0.9]

    Infinite viewer (``viewer.direction``): parallel projection along ``-direction``, so every
    pixel is seen along the engine's constant ``V``; the view is fitted to the mesh's
    projected bounding box (times :data:`FRAME_MARGIN`) and centred on it.

    Local viewer (``viewer.eye``): perspective camera *at the eye* looking at the mesh's
    bounding-box centre; the field of view is the smallest that holds the mesh's bounding
    sphere (times :data:`FRAME_MARGIN`) across both image directions, at most 150 degrees (an
    eye inside the sphere sees what fits).
    """
    bottom = min(max(float(bottom), 0.0), 0.9)
    centre = np.asarray(mesh.centre, np.float64)
    radius = max(float(mesh.radius), 1e-12)
    viewer = scene.viewer
    if viewer.eye is not None:
        eye = np.asarray(viewer.eye, np.float64)
        offset = centre - eye
        dist = float(np.linalg.norm(offset))
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
        return Camera(
            tuple(eye),
            tuple(focal),
            tuple(_view_up(forward)),
            False,
            1.0,
            angle,
            (near, far),
            (0.0, -shift),
        )
    toward = np.asarray(viewer.direction, np.float64)
    toward = toward / np.linalg.norm(toward)
    forward = -toward
    up = _view_up(forward)
    right = np.cross(forward, up)
    rel = mesh.positions - centre
    u, v = rel @ right, rel @ up
    uc, vc = 0.5 * (u.min() + u.max()), 0.5 * (v.min() + v.max())
    hw = 0.5 * (u.max() - u.min()) * FRAME_MARGIN
    hh = 0.5 * (v.max() - v.min()) * FRAME_MARGIN
    scale = max(hh / (1.0 - bottom), hw / aspect, 1e-3 * radius)
    focal = centre + right * uc + up * (vc - scale * bottom)
    dist = 4.0 * radius
    return Camera(
        tuple(focal + toward * dist),
        tuple(focal),
        tuple(up),
        True,
        scale,
        30.0,
        (dist - 1.5 * radius, dist + 1.5 * radius),
    )


# -- colours -------------------------------------------------------------------------------


def vertex_colors(scene, mesh: Mesh, *, precision: str = "float64") -> np.ndarray:
    """Engine colours of the mesh's vertices under the scene: (n, 3) float64 in [0, 1].

    The mesh's triangles go to the engine too (shadows). A scene with ``hdr`` is shaded
    unclamped and shown through its exposure, tone map and the sRGB encoding
    (:func:`explorer.tonemap.display`); the renderer then interpolates the encoded values."""
    import explorer

    hdr = getattr(scene, "hdr", None)
    c = explorer.shade(
        scene,
        mesh.positions,
        mesh.normals,
        precision=precision,
        clamp=hdr is None,
        faces=mesh.faces,
    )
    if hdr is not None:
        from .tonemap import display

        c = display(c, hdr)
    return c


def to_bytes(colors, opacity: float | None = None) -> np.ndarray:
    """Colours in [0, 1] as 8-bit values, rounded to nearest: (n, 3) uint8, or (n, 4) with an
    alpha column of ``opacity`` when given."""
    c = np.clip(np.asarray(colors, np.float64), 0.0, 1.0)
    out = np.rint(c * 255.0).astype(np.uint8)
    if opacity is not None:
        alpha = np.full((len(out), 1), int(round(float(opacity) * 255.0)), np.uint8)
        out = np.hstack([out, alpha])
    return out


# -- the off-screen renderer ---------------------------------------------------------------


_WINDOW_ENV = "VTK_DEFAULT_OPENGL_WINDOW"


def _plotter(size: tuple[int, int], background):
    import pyvista as pv

    # No display: VTK would probe X, log "bad X server connection" and fall back to EGL; ask
    # for EGL directly. Only while the window is created, so nothing else in the process
    # (a GUI started later with a display) inherits the setting.
    headless = not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY")
    added = headless and _WINDOW_ENV not in os.environ
    if added:
        os.environ[_WINDOW_ENV] = "vtkEGLRenderWindow"
    try:
        pl = pv.Plotter(off_screen=True, window_size=list(size), lighting=None)
    finally:
        if added:
            del os.environ[_WINDOW_ENV]
    pl.render_window.SetMultiSamples(0)  # before the first render: no multisampling
    pl.disable_anti_aliasing()
    # translucency: plain "over" blending in the order the triangles are drawn (sorted back to
    # front by the caller); VTK's weighted-average OIT and its depth peeling (wrong layer
    # order on Mesa llvmpipe) are both off
    pl.renderer.SetUseOIT(False)
    pl.renderer.SetUseDepthPeeling(False)
    pl.set_background(background)
    return pl


class OffscreenRenderer:
    """One off-screen VTK window reused for many pictures of the same size (cheap: no new
    OpenGL context per picture). Use as a context manager, or call :meth:`close`.

    size : (width, height) in pixels
    background : RGB in [0, 1]
    """

    def __init__(self, size: Sequence[int] = DEFAULT_SIZE, background=BACKGROUND):
        self.size = check_size(size)
        self.background = tuple(float(c) for c in background)
        self._pl = None
        self._actor = None
        self._mesh = None
        self._poly = None
        self._text = None
        self._sorted = False

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        if self._pl is not None:
            self._pl.close()
            self._pl = None
            self._actor = self._mesh = self._poly = self._text = None

    @property
    def plotter(self):
        if self._pl is None:
            self._pl = _plotter(self.size, self.background)
        return self._pl

    def render(
        self,
        scene,
        mesh: Mesh,
        colors=None,
        *,
        label: str | None = None,
        label_size: int | None = None,
        camera: Camera | None = None,
        backdrop=None,
    ) -> np.ndarray:
        """Draw the mesh in the engine's colours and return the picture.

        scene : a :class:`~explorer.scene.Scene` (its material's opacity is honoured)
        colors : (n, 3) float in [0, 1] to draw instead of shading the scene
        label : text drawn at the bottom centre (the preset sheet's names); the camera then
            keeps the bottom of the picture free for it
        label_size : its font size in pixels (default: the largest that fits)
        camera : overrides :func:`camera_for`
        backdrop : an opaque second object drawn with the mesh, ``(Mesh, colors (k, 3))``; a
            translucent mesh in front of it blends over it (VTK draws opaque geometry first,
            then the translucent triangles back to front with the depth test on)
        Returns (height, width, 3) uint8.
        """
        pl = self.plotter
        if colors is None:
            colors = vertex_colors(scene, mesh)
        rgb = to_bytes(colors)
        if rgb.shape != (mesh.n_vertices, 3):
            raise ExplorerError(
                f"colors must have shape ({mesh.n_vertices}, 3), got {np.shape(colors)}"
            )
        if self._mesh is not mesh:
            if self._actor is not None:
                pl.remove_actor(self._actor)
            self._poly = mesh.to_polydata(rgb)
            self._sorted = False
            self._actor = pl.add_mesh(
                self._poly,
                scalars="colors",
                rgb=True,
                lighting=False,
                show_scalar_bar=False,
                reset_camera=False,
            )
            self._mesh = mesh
        else:
            self._poly.point_data["colors"] = rgb
        opacity = float(scene.material.opacity)
        self._actor.GetProperty().SetOpacity(opacity)
        self._set_label(label, label_size)
        w, h = self.size
        if camera is None:
            band = 0.0
            if label is not None:
                band = 1.5 * self._text.GetTextProperty().GetFontSize() / h
            camera = camera_for(scene, mesh, w / h, bottom=band)
        self._set_camera(camera)
        # translucent: draw the triangles back to front, so each blends over what is behind
        # it; opaque: file order (the depth test decides)
        order = back_to_front(mesh, camera) if opacity < 1.0 else None
        if order is not None or self._sorted:
            faces = mesh.faces if order is None else mesh.faces[order]
            cells = np.hstack([np.full((len(faces), 1), 3, np.int64), faces]).ravel()
            self._poly.faces = cells
            self._sorted = order is not None
        extra = None
        if backdrop is not None:
            bmesh, bcolors = backdrop
            extra = pl.add_mesh(
                bmesh.to_polydata(to_bytes(bcolors)),
                scalars="colors",
                rgb=True,
                lighting=False,
                show_scalar_bar=False,
                reset_camera=False,
            )
        try:
            pl.render()
            img = pl.screenshot(return_img=True)
        finally:
            if extra is not None:
                pl.remove_actor(extra)
        return np.ascontiguousarray(img[:, :, :3])

    def _text_actor(self):
        if self._text is None:
            import vtkmodules.vtkRenderingFreeType  # noqa: F401 - registers the text renderer
            from vtkmodules.vtkRenderingCore import vtkTextActor

            renderer = self.plotter.renderer
            t = vtkTextActor()
            prop = t.GetTextProperty()
            prop.SetColor(*LABEL_COLOR)
            prop.SetJustificationToCentered()
            prop.SetVerticalJustificationToBottom()
            prop.SetFontFamilyToArial()
            prop.ShadowOff()
            prop.BoldOff()
            renderer.AddActor(t)
            self._text = t
        return self._text

    def label_font_size(self, labels: Iterable[str]) -> int:
        """The largest font size (pixels, at most ``LABEL_HEIGHT`` of the height) at which
        every label fits the width."""
        t = self._text_actor()
        w, h = self.size
        size = max(6, int(round(LABEL_HEIGHT * h)))
        for label in labels:
            while size > 6:
                t.SetInput(str(label))
                t.GetTextProperty().SetFontSize(size)
                extent = [0.0, 0.0]
                t.GetSize(self.plotter.renderer, extent)
                if extent[0] <= w - 6:
                    break
                size -= 1
        return size

    def _set_label(self, label: str | None, font_size: int | None) -> None:
        if label is None:
            if self._text is not None:
                self._text.SetVisibility(False)
            return
        if font_size is None:
            font_size = self.label_font_size([label])
        t = self._text_actor()
        t.SetInput(str(label))
        t.GetTextProperty().SetFontSize(int(font_size))
        w, _ = self.size
        t.SetPosition(w / 2.0, max(2.0, 0.25 * font_size))
        t.SetVisibility(True)

    def _set_camera(self, cam: Camera) -> None:
        self.plotter.camera_set = True
        apply_camera(self.plotter.camera, cam)


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
    centroids = mesh.positions[mesh.faces].mean(axis=1)
    if camera.parallel:
        depth = (centroids - np.asarray(camera.position)) @ camera.direction
    else:
        depth = np.linalg.norm(centroids - np.asarray(camera.position), axis=1)
    return np.argsort(-depth, kind="stable")


def render_image(
    scene,
    mesh: Mesh,
    size: Sequence[int] = DEFAULT_SIZE,
    *,
    background=BACKGROUND,
    colors=None,
    label: str | None = None,
    camera: Camera | None = None,
    backdrop=None,
) -> np.ndarray:
    """One off-screen picture of the mesh under the scene: (height, width, 3) uint8.

    See :meth:`OffscreenRenderer.render`; the window is closed before returning.
    """
    with OffscreenRenderer(size, background) as r:
        return r.render(scene, mesh, colors, label=label, camera=camera, backdrop=backdrop)


def sheet(
    materials: Iterable,
    scene,
    mesh: Mesh,
    *,
    tile: Sequence[int] = SHEET_TILE,
    columns: int = SHEET_COLUMNS,
    background=BACKGROUND,
    gap: int = 2,
    model: str | None = None,
) -> np.ndarray:
    """Every material on the same mesh, in a labelled grid: (H, W, 3) uint8.

    materials : (label, Material) pairs, drawn left to right, top to bottom
    scene : lights, viewer, model; each tile replaces its material
    model : specular model of every tile; None: the material's own model when it has one,
        else the scene's
    tile : (width, height) of one cell; gap : pixels between cells (background colour)
    """
    items = list(materials)
    if not items:
        raise ExplorerError("no materials to put on the sheet")
    tw, th = check_size(tile)
    columns = max(1, min(int(columns), len(items)))
    rows = -(-len(items) // columns)
    bg = np.rint(np.asarray(background) * 255.0).astype(np.uint8)
    out = np.empty((rows * th + (rows + 1) * gap, columns * tw + (columns + 1) * gap, 3), np.uint8)
    out[:] = bg
    with OffscreenRenderer((tw, th), background) as r:
        font = r.label_font_size(str(label) for label, _ in items)
        for i, (label, material) in enumerate(items):
            s = scene.replace(material=material, model=model or material.model or scene.model)
            img = r.render(s, mesh, label=str(label), label_size=font)
            y0 = gap + (i // columns) * (th + gap)
            x0 = gap + (i % columns) * (tw + gap)
            out[y0 : y0 + th, x0 : x0 + tw] = img
    return out


# -- sizes and files -----------------------------------------------------------------------


def check_size(size) -> tuple[int, int]:
    """(width, height) as ints in :data:`SIZE_RANGE`, or an :class:`ExplorerError`."""
    lo, hi = SIZE_RANGE
    try:
        w, h = (int(v) for v in size)
        ok = all(float(v) == int(v) for v in size)
    except (TypeError, ValueError):
        ok = False
    if not ok or not (lo <= w <= hi and lo <= h <= hi):
        raise ExplorerError(
            f"image size must be two whole numbers of pixels, each in [{lo}, {hi}], got {size!r}"
        )
    return w, h


_SIZE_RE = re.compile(r"^\s*(\d+)\s*[xX×]\s*(\d+)\s*$")


def parse_size(text: str) -> tuple[int, int]:
    """``"400x300"`` -> (400, 300) (width x height), checked against :data:`SIZE_RANGE`."""
    m = _SIZE_RE.match(str(text))
    if not m:
        raise ExplorerError(f"size must look like WIDTHxHEIGHT, e.g. 400x400, got {text!r}")
    return check_size((int(m.group(1)), int(m.group(2))))


def encode_png(image) -> bytes:
    """PNG file contents of an (h, w, 3|4) uint8 image (VTK's PNG writer)."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkPNGWriter

    img = np.asarray(image)
    if img.dtype != np.uint8 or img.ndim != 3 or img.shape[2] not in (3, 4):
        raise ValueError(f"image must be (h, w, 3|4) uint8, got {img.shape} {img.dtype}")
    h, w, c = img.shape
    data = vtkImageData()
    data.SetDimensions(w, h, 1)
    flat = np.ascontiguousarray(img[::-1].reshape(-1, c))  # VTK rows go bottom-up
    arr = numpy_to_vtk(flat, deep=True)
    arr.SetNumberOfComponents(c)
    data.GetPointData().SetScalars(arr)
    writer = vtkPNGWriter()
    writer.SetWriteToMemory(True)
    writer.SetInputData(data)
    writer.Write()
    result = writer.GetResult()
    return bytes(memoryview(result))


def read_png(path) -> np.ndarray:
    """An (h, w, 3|4) uint8 image from a PNG file."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOImage import vtkPNGReader

    path = os.fspath(path)
    reader = vtkPNGReader()
    if not os.path.isfile(path) or not reader.CanReadFile(path):
        raise ExplorerError(f"{path}: not a readable PNG file")
    reader.SetFileName(path)
    reader.Update()
    img = reader.GetOutput()
    w, h, _ = img.GetDimensions()
    arr = vtk_to_numpy(img.GetPointData().GetScalars())
    c = arr.shape[1] if arr.ndim == 2 else 1
    return np.ascontiguousarray(arr.reshape(h, w, c)[::-1]).astype(np.uint8)


def mesh_file_bytes(mesh: Mesh, colors, suffix: str, opacity: float = 1.0) -> bytes:
    """A PLY or GLB file (by ``suffix``) holding the mesh, its normals and its per-vertex
    colours as 8-bit RGBA (alpha = opacity). The colours are the engine's display values, as
    in the PNG; a viewer that lights the mesh again adds its own shading on top."""
    import trimesh

    rgba = to_bytes(colors, opacity)
    tm = trimesh.Trimesh(
        vertices=np.array(mesh.positions),
        faces=np.array(mesh.faces),
        vertex_normals=np.array(mesh.normals),
        vertex_colors=rgba,
        process=False,
    )
    kind = suffix.lower().lstrip(".")
    if kind not in ("ply", "glb"):
        raise ExplorerError(f"mesh export writes .ply or .glb, got {suffix!r}")
    return tm.export(file_type=kind)


def write_file_atomic(path, data: bytes, *, force: bool = False) -> Path:
    """Write bytes to ``path`` atomically (:func:`explorer.fileio.write_atomic`). An existing
    file is replaced only with ``force``; the directory must exist."""
    return write_atomic(path, data, overwrite=force, make_dirs=False)
