"""Off-screen pictures of the engine's colours: PNG renders, the preset sheet, PLY/GLB export.

The engine computes one colour per vertex (:func:`explorer.shade`); VTK only draws them. The
colours go to VTK as RGB point scalars with VTK's lighting off, so VTK adds nothing: no light of
its own, no specular, no ambient (:func:`explorer.render.vtk.add_unlit`, see the last section of
the lighting-equation reference). Between vertices VTK interpolates the colours linearly across
each triangle: Gouraud shading, as in OpenGL's fixed-function pipeline. No multisampling or
anti-aliasing (:func:`explorer.render.vtk.plotter`), a fixed background, ``render()`` before
``screenshot()``, and every plotter is closed afterwards: the same scene gives the same pixels
every time.

Camera and viewer agree (see :func:`camera_for`):

- a **local viewer** (``viewer: {eye: ...}``) puts a perspective camera at the eye, looking at
  the mesh's centre, with the narrowest field of view that shows the whole mesh;
- an **infinite viewer** (``viewer: {to_viewer: ...}``, the default) is a *parallel*
  projection looking along ``-to_viewer``: every pixel is seen along the same ``V``, exactly
  what the engine assumes. The view is scaled so the mesh's bounding sphere fits.

VTK is imported only inside the functions that draw or read/write PNG files.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from explorer.core.errors import ExplorerError
from explorer.geometry.meshes import Mesh
from explorer.render.camera import Camera, Vec3, back_to_front, camera_for, mesh_frame
from explorer.render.images import DEFAULT_SIZE, check_picture_pixels, check_size
from explorer.render.textured import Textured, add_textured, texture_arrays, textured
from explorer.render.vtk import DRAW_LOCK, add_unlit, cells, plotter, polydata, set_camera
from explorer.shading.display import group_vertex_colors, to_bytes, vertex_colors

#: background colour of every render (linear RGB in [0, 1]): a neutral mid-dark grey on which
#: both black rubber and white plastic read
BACKGROUND: Vec3 = (0.32, 0.32, 0.32)
#: the light of the preset sheet when no scene is given: OpenGL's directional light from the
#: upper front, as in the classic chart of teapot materials (light position (0, 3, 3, 0))
SHEET_LIGHT_DIRECTION: Vec3 = (0.0, 1.0, 1.0)
#: default preset sheet layout
SHEET_TILE = (200, 150)
SHEET_COLUMNS = 6
#: label text colour and height (fraction of the tile height) on the sheet
LABEL_COLOR: Vec3 = (1.0, 1.0, 1.0)
LABEL_HEIGHT = 0.085


# -- the off-screen renderer ---------------------------------------------------------------


class OffscreenWindow:
    """One off-screen VTK window of a fixed size, opened on first use and reused for many
    pictures (no new OpenGL context per picture). Use as a context manager, or call
    :meth:`close`.

    size : (width, height) in pixels
    background : RGB in [0, 1]
    """

    def __init__(self, size: Sequence[int], background):
        self.size = check_size(size)
        self.background = tuple(float(c) for c in background)
        self._pl = None
        self._forget()

    def _forget(self) -> None:
        """Drop what the subclass keeps of the closed window's contents."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        """Close the window (its OpenGL context goes) while no other thread draws
        (:data:`~explorer.render.vtk.DRAW_LOCK`: the difference worker closes its windows in
        its own thread)."""
        if self._pl is not None:
            with DRAW_LOCK:
                self._pl.close()
            self._pl = None
            self._forget()

    @property
    def plotter(self):
        """The window's plotter, made on first use (while no other thread draws)."""
        if self._pl is None:
            with DRAW_LOCK:
                self._pl = plotter(self.size, self.background)
        return self._pl


class OffscreenRenderer(OffscreenWindow):
    """An :class:`OffscreenWindow` that draws the engine's colours on a mesh.

    size : (width, height) in pixels
    background : RGB in [0, 1]
    """

    def __init__(self, size: Sequence[int] = DEFAULT_SIZE, background=BACKGROUND):
        super().__init__(size, background)

    def _forget(self) -> None:
        self._actor = self._mesh = self._poly = self._text = self._frame = None
        self._sorted = False
        self._texture = None

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
        texture: Textured | None = None,
    ) -> np.ndarray:
        """Draw the mesh in the engine's colours and return the picture.

        scene : a :class:`~explorer.core.scene.Scene` (its material's opacity is honoured)
        colors : (n, 3) float in [0, 1] to draw instead of shading the scene
        label : text drawn at the bottom centre (the preset sheet's names); the camera then
            keeps the bottom of the picture free for it
        label_size : its font size in pixels (default: the largest that fits)
        camera : overrides :func:`camera_for`
        backdrop : an opaque second object drawn with the mesh, ``(Mesh, colors (k, 3))``; a
            translucent mesh in front of it blends over it (VTK draws opaque geometry first,
            then the translucent triangles back to front with the depth test on)
        texture : what a textured picture draws (:func:`explorer.render.textured.textured`);
            None: the scene's own ``diffuse_map`` when it has one and ``colors`` is None
        Returns (height, width, 3) uint8.
        """
        if texture is None and colors is None:
            texture = textured(scene, mesh)
        if texture is not None:
            rgb = texture.primary
        else:
            rgb = to_bytes(vertex_colors(scene, mesh) if colors is None else colors)
        if rgb.shape != (mesh.n_vertices, 3):
            raise ExplorerError(
                f"colors must have shape ({mesh.n_vertices}, 3), got {np.shape(colors)}"
            )
        # the window changed, drawn and read with no other thread drawing (actors added and
        # removed make and free OpenGL buffers: DRAW_LOCK covers them too)
        with DRAW_LOCK:
            pl = self.plotter
            if self._mesh is not mesh or texture is not None or self._texture is not None:
                if self._actor is not None:
                    pl.remove_actor(self._actor)
                self._frame = mesh_frame(mesh)  # VTK draws in the mesh's frame: any scale
                self._poly = polydata(mesh, rgb, frame=self._frame)
                self._sorted = False
                if texture is None:
                    self._actor = add_unlit(pl, self._poly)
                else:
                    texture_arrays(self._poly, mesh, texture)
                    self._actor = add_textured(pl, self._poly, texture)
                self._mesh, self._texture = mesh, texture
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
            set_camera(pl, camera, self._frame)
            # translucent: draw the triangles back to front, so each blends over what is behind
            # it; opaque: file order (the depth test decides)
            order = back_to_front(mesh, camera) if opacity < 1.0 else None
            if order is not None or self._sorted:
                self._poly.faces = cells(mesh.faces if order is None else mesh.faces[order])
                self._sorted = order is not None
            extra = None
            if backdrop is not None:
                bmesh, bcolors = backdrop
                extra = add_unlit(pl, polydata(bmesh, to_bytes(bcolors), frame=self._frame))
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
    texture: Textured | None = None,
) -> np.ndarray:
    """One off-screen picture of the mesh under the scene: (height, width, 3) uint8.

    See :meth:`OffscreenRenderer.render`; the window is closed before returning.
    """
    with OffscreenRenderer(size, background) as r:
        return r.render(
            scene, mesh, colors, label=label, camera=camera, backdrop=backdrop, texture=texture
        )


def sheet(
    materials: Iterable,
    scene,
    mesh: Mesh,
    *,
    tile: Sequence[int] = SHEET_TILE,
    columns: int = SHEET_COLUMNS,
    background=BACKGROUND,
    gap: int = 2,
    model: str | Sequence[str] | None = None,
) -> np.ndarray:
    """Every material on the same mesh, in a labelled grid: (H, W, 3) uint8.

    materials : (label, Material) pairs, drawn left to right, top to bottom; a tuple of
        Materials instead of one gives each group of ``mesh.groups`` its own (the mesh
        file's own materials; the tile's opacity is the first one's)
    scene : lights, viewer, model; each tile replaces its material
    model : specular model of every tile; None: the material's own model when it has one,
        else the scene's; several models: each material once under each, side by side,
        labelled "label · model"
    tile : (width, height) of one cell; gap : pixels between cells (background colour)
    """
    items = list(materials)
    if model is not None and not isinstance(model, str):
        items = [(f"{label} · {m}", mat, m) for label, mat in items for m in model]
    else:
        items = [(label, mat, model) for label, mat in items]
    if not items:
        raise ExplorerError("no materials to put on the sheet")
    tw, th = check_size(tile)
    columns = max(1, min(int(columns), len(items)))
    rows = -(-len(items) // columns)
    height, width = rows * th + (rows + 1) * gap, columns * tw + (columns + 1) * gap
    check_picture_pixels(
        width, height, f"sheet of {len(items)} tiles of {tw}x{th} in {columns} columns"
    )
    bg = to_bytes([background])[0]
    out = np.empty((height, width, 3), np.uint8)
    out[:] = bg
    with OffscreenRenderer((tw, th), background) as r:
        font = r.label_font_size(str(label) for label, _, _ in items)
        for i, (label, material, model) in enumerate(items):
            per_group = isinstance(material, tuple)
            first = material[0] if per_group else material
            s = scene.replace(material=first, model=model or first.model or scene.model)
            colors = group_vertex_colors(s, mesh, material) if per_group else None
            img = r.render(s, mesh, colors, label=str(label), label_size=font)
            y0 = gap + (i // columns) * (th + gap)
            x0 = gap + (i % columns) * (tw + gap)
            out[y0 : y0 + th, x0 : x0 + tw] = img
    return out
