"""The term strip in the explorer's view (docs/terms.md): a row of small views under the main
one, ``emission | ambient | diffuse | specular | sum | overflow``, with the main view's camera.

Both front ends draw it with no code of their own: the tiles are VTK renderers of the view's
own render window (each a viewport of the bottom band, sharing the main renderer's camera), so
the window's Qt interactor and the page's pushed picture show them as they show the view. Each
tile draws the drawn mesh (the full mesh, or its level of detail during a drag) in its term's
bytes, :func:`explorer.shading.strip.shader_strip_bytes` of that drawing's Shader: its kept
light sums recomposed, no light pass; the overflow tile is the sum tile with the vertices the
display clamped in magenta, its label the share of them. The state's ``strip`` switches it,
``strip_mode`` picks ``weighted`` or ``raw`` tiles (the panel model's rows, :data:`ROWS`).

Per pixel (the view's ``shading: per-pixel``), each tile is a picture instead: the engine lit
at each pixel of the tile (a :class:`~explorer.render.live.LivePixels` of the strip's own at the
tile's size, the main view's camera), its per-pixel shader's kept sums recomposed
(:func:`explorer.shading.strip.compose_strip` on pixel rows); the sum tile is ``render
--per-pixel``'s picture at that size and camera, bit for bit. Made before the window draws
(:meth:`TermStrip.before_pixels`, the render window's StartEvent, as the view's own per-pixel
picture). VTK is imported inside the methods.
"""

from __future__ import annotations

import numpy as np

from explorer.app import model as M
from explorer.app.model import State
from explorer.core.errors import ExplorerError
from explorer.render.strip import COLUMNS, OVERFLOW_COLOR
from explorer.shading.display import to_bytes
from explorer.shading.strip import MODES, compose_strip, shader_strip_bytes

#: the strip's height as a fraction of the view's (the main view keeps the rest above it)
STRIP_HEIGHT = 0.2
#: the tiles' label colour and font size (pixels)
LABEL_COLOUR = (0.93, 0.93, 0.93)
LABEL_FONT = 12


def set_strip(state: State, on: bool) -> State:
    """The term strip under the view on or off."""
    return state.replace(strip=bool(on))


def set_strip_mode(state: State, mode: str) -> State:
    """The strip's tiles: ``weighted`` (k·A, k·D, k·S) or ``raw`` (A, D, S)."""
    if mode not in MODES:
        raise ExplorerError(f"strip_mode must be one of {MODES}, got {mode!r}")
    return state.replace(strip_mode=mode)


def _drawing_strip_bytes(drawing, mode: str) -> tuple:
    """:func:`~explorer.shading.strip.shader_strip_bytes` of a drawing's Shader, each group of
    the mesh in its own material when the drawing shows a mesh file's materials (the sums kept
    once, each material recomposing them, as the drawing's own colours are made)."""
    shader = drawing.shader
    if drawing.groups is None:
        return shader_strip_bytes(shader, mode)
    own = shader.scene.material
    groups = drawing.mesh.groups
    tiles, over = None, None
    try:
        for i, material in enumerate(drawing.groups):
            rows = groups.vertices(i)
            if not len(rows):
                continue
            shader.set_material(material)
            t, o = shader_strip_bytes(shader, mode)
            if tiles is None:
                tiles, over = [np.array(x) for x in t], np.array(o)
            for out, x in zip(tiles, t, strict=True):
                out[rows] = x[rows]
            over[rows] = o[rows]
    finally:
        shader.set_material(own)
    return (tiles, over) if tiles is not None else shader_strip_bytes(shader, mode)


class TermStrip:
    """The strip in ``plotter``'s render window under its main renderer (see the module
    docstring): :meth:`show` draws it for a state and a drawing, :attr:`renderers` its tiles'
    renderers in :data:`~explorer.render.strip.COLUMNS`' order, :attr:`tiles` the bytes each
    draws, :attr:`overflow` the clamped vertices."""

    def __init__(self, plotter):
        self.plotter = plotter
        self.renderers: list = []
        self.labels: list = []
        self._actors: list = []
        self._colours: list = []
        self._key = None
        self._drawing = None
        self.tiles = None
        self.overflow = None
        self.on = False
        self.pixel_tiles = None  # per pixel: each tile's picture (h, w, 3) uint8, else None
        self._live = None  # the per-pixel tiles' LivePixels
        self._pixel_key = None
        self._images: list = []  # per tile: (vtkImageData, its actor)

    def show(self, state: State, drawing) -> None:
        """Show the strip for ``state`` (off: the main view fills the window again), its tiles
        from ``drawing`` (a :class:`~explorer.app.view.MeshDrawing`) when anything they depend
        on changed."""
        if not state.strip:
            if self.on:
                self._switch(False)
            return
        if not self.on:
            self._switch(True)
        if drawing is not self._drawing:
            self._geometry(drawing)
        key = (id(drawing), drawing.shader.scene, state.strip_mode, drawing.groups)
        if key == self._key:
            return
        self._key = key
        tiles, over = _drawing_strip_bytes(drawing, state.strip_mode)
        mask = tiles[4].copy()
        mask[over] = to_bytes([OVERFLOW_COLOR])[0]
        self.tiles, self.overflow = (*tiles, mask), over
        for colours, rgb in zip(self._colours, self.tiles, strict=True):
            colours[0][:] = rgb
            colours[1].Modified()
        share = 100.0 * float(over.mean()) if over.size else 0.0
        for name, label in zip(COLUMNS, self.labels, strict=True):
            text = f"{name} {share:.1f}%" if name == "overflow" else name
            label.SetInput(f"{text} ({state.strip_mode})" if name == "sum" else text)

    def before_pixels(self, state: State, per_pixel: bool, mesh) -> None:
        """The render window's StartEvent: with the strip on and the view drawn per pixel
        (``per_pixel``), each tile's per-pixel picture of ``mesh`` for the camera VTK is about
        to draw with (made again when the scene, camera, tile size or mode changed); else the
        tiles draw the mesh per vertex."""
        if not (self.on and state.strip and per_pixel):
            self._show_pictures(False)
            return
        from explorer.app.view import view_camera  # (a cycle: the view holds the strip)

        camera = view_camera(self.plotter.camera, state.centre, state.radius)
        scene = M.set_camera(state, camera).shown_scene()
        w, h = (int(v) for v in self.renderers[0].GetSize())
        bg = tuple(self.plotter.renderer.GetBackground())
        key = (repr(scene), camera, (w, h), id(mesh), state.strip_mode, bg)
        if key != self._pixel_key and min(w, h) > 0:
            self.pixel_tiles = self._pictures(scene, camera, (w, h), mesh, state.strip_mode, bg)
            self._pixel_key = key
            for (image, _), rgb in zip(self._images_for(w, h), self.pixel_tiles, strict=True):
                arr = image.GetPointData().GetScalars()
                from vtkmodules.util.numpy_support import vtk_to_numpy

                vtk_to_numpy(arr).reshape(h, w, 3)[:] = rgb[::-1]  # (VTK's rows: bottom up)
                arr.Modified()
                image.Modified()
        self._show_pictures(self.pixel_tiles is not None)

    def _pictures(self, scene, camera, size, mesh, mode, background) -> list:
        """The tiles' pictures (:data:`COLUMNS`' order), each (h, w, 3) uint8: the per-pixel
        shader's sums at ``size`` recomposed; the overflow's share in the label."""
        from explorer.render.live import LivePixels  # (VTK, for the G-buffer's rasterisation)

        if self._live is None:
            self._live = LivePixels(mesh)
        self._live.set_mesh(mesh)
        frame = self._live.frame(scene, camera, size, background=background)
        g, _ = self._live.gbuffer(camera, size)
        sh = self._live.shader
        strip = compose_strip(scene, sh.terms, sh.colors, mode)
        first = len(sh.colors) - len(g.pixels)  # (the mesh's vertices first, with shadows)
        out = []
        for name in COLUMNS:
            rgb = np.array(frame.rgb)
            flat = rgb.reshape(-1, 3)
            if name == "overflow":
                flat[g.pixels] = to_bytes(strip.tiles["sum"][first:])
                flat[g.pixels[strip.overflow[first:]]] = to_bytes([OVERFLOW_COLOR])[0]
            else:
                flat[g.pixels] = to_bytes(strip.tiles[name][first:])
            out.append(rgb)
        over = strip.overflow[first:]
        share = 100.0 * float(over.mean()) if over.size else 0.0
        self.labels[COLUMNS.index("overflow")].SetInput(f"overflow {share:.1f}%")
        return out

    def _images_for(self, w: int, h: int) -> list:
        """Each tile's picture actor (made, or remade for a new size), under its label."""
        from vtkmodules.util.numpy_support import numpy_to_vtk
        from vtkmodules.vtkCommonDataModel import vtkImageData
        from vtkmodules.vtkRenderingCore import vtkActor2D, vtkImageMapper

        if self._images and self._images[0][0].GetDimensions()[:2] == (w, h):
            return self._images
        for r, (_, actor) in zip(self.renderers, self._images, strict=False):
            r.RemoveViewProp(actor)
        self._images = []
        for r, label in zip(self.renderers, self.labels, strict=True):
            image = vtkImageData()
            image.SetDimensions(w, h, 1)
            arr = numpy_to_vtk(np.zeros((w * h, 3), np.uint8), deep=True)
            arr.SetName("pixels")
            image.GetPointData().SetScalars(arr)
            mapper = vtkImageMapper()
            mapper.SetInputData(image)
            mapper.SetColorWindow(255.0)
            mapper.SetColorLevel(127.5)
            actor = vtkActor2D()
            actor.SetMapper(mapper)
            r.RemoveViewProp(label)  # (the label drawn over the picture)
            r.AddViewProp(actor)
            r.AddViewProp(label)
            self._images.append((image, actor))
        return self._images

    def _show_pictures(self, on: bool) -> None:
        """The tiles show their per-pixel pictures (on) or draw the mesh per vertex."""
        if not on:
            self.pixel_tiles = None
            self._pixel_key = None
        for _, actor in self._images:
            actor.SetVisibility(on)
        for actor in self._actors:
            actor.SetVisibility(not on)

    def tile_box(self, column: str) -> list[int]:
        """Tile ``column``'s box ``[x, y, width, height]`` in window pixels (origin top-left)."""
        r = self.renderers[COLUMNS.index(column)]
        x, y = r.GetOrigin()
        w, h = r.GetSize()
        _, wh = self.plotter.window_size
        return [int(x), int(wh - y - h), int(w), int(h)]

    def tile_pixel(self, column: str, point) -> list[int]:
        """Window pixel (origin top-left) of ``point`` (3,) in the view's coordinates (as
        the mesh is drawn, :meth:`explorer.app.view.SceneView.to_view`) in tile ``column``."""
        r = self.renderers[COLUMNS.index(column)]
        r.SetWorldPoint(*point, 1.0)
        r.WorldToDisplay()
        x, y, _ = r.GetDisplayPoint()
        _, h = self.plotter.window_size
        return [int(round(x)), int(round(h - 1 - y))]

    def report(self, point) -> dict | None:
        """What a test of a front end reads (plain JSON values): each tile's window pixel of
        ``point`` (3,) in the view's coordinates (:meth:`tile_pixel`), and the overflow's
        share; None while the strip is off."""
        if not self.on:
            return None
        share = float(self.overflow.mean()) if self.overflow is not None else 0.0
        return {
            "px": {c: self.tile_pixel(c, point) for c in COLUMNS},
            "overflow": share,
            "boxes": {c: self.tile_box(c) for c in COLUMNS},
            "per_pixel": self.pixel_tiles is not None,
        }

    def _switch(self, on: bool) -> None:
        """Make room for the tiles (or give it back), creating them the first time."""
        main = self.plotter.renderer
        if on and not self.renderers:
            self._make()
        main.SetViewport(0.0, STRIP_HEIGHT if on else 0.0, 1.0, 1.0)
        window = self.plotter.render_window
        for r in self.renderers:
            if on:
                window.AddRenderer(r)
            else:
                window.RemoveRenderer(r)
        self.on = on
        self._key = None

    def _make(self) -> None:
        import vtkmodules.vtkRenderingFreeType  # noqa: F401 - registers the text renderer
        from vtkmodules.vtkRenderingCore import vtkRenderer, vtkTextActor

        main = self.plotter.renderer
        n = len(COLUMNS)
        for i in range(n):
            r = vtkRenderer()
            r.SetViewport(i / n, 0.0, (i + 1) / n, STRIP_HEIGHT)
            r.SetBackground(main.GetBackground())
            r.SetActiveCamera(main.GetActiveCamera())
            r.SetUseOIT(False)
            r.SetUseDepthPeeling(False)
            r.InteractiveOff()  # (a drag on a tile turns the main view's camera)
            label = vtkTextActor()
            prop = label.GetTextProperty()
            prop.SetColor(*LABEL_COLOUR)
            prop.SetFontSize(LABEL_FONT)
            prop.SetFontFamilyToArial()
            prop.ShadowOff()
            label.SetPosition(4, 3)
            r.AddViewProp(label)
            self.renderers.append(r)
            self.labels.append(label)

    def _geometry(self, drawing) -> None:
        """Each tile's actor: the drawing's points and triangles, colours of its own."""
        from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
        from vtkmodules.vtkCommonDataModel import vtkPolyData
        from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper

        for r, a in zip(self.renderers, self._actors, strict=False):
            r.RemoveActor(a)
        self._actors, self._colours = [], []
        n = drawing.mesh.n_vertices
        for r in self.renderers:
            poly = vtkPolyData()
            poly.SetPoints(drawing.poly.GetPoints())
            poly.SetPolys(drawing.poly.GetPolys())
            arr = numpy_to_vtk(np.zeros((n, 3), np.uint8), deep=True)
            arr.SetName("colors")
            poly.GetPointData().SetScalars(arr)
            mapper = vtkPolyDataMapper()
            mapper.SetInputData(poly)
            mapper.SetColorModeToDirectScalars()
            mapper.SetScalarModeToUsePointData()
            actor = vtkActor()
            actor.SetMapper(mapper)
            actor.GetProperty().LightingOff()
            r.AddActor(actor)
            self._actors.append(actor)
            self._colours.append((vtk_to_numpy(arr), arr, poly))
        self._drawing = drawing
        self._key = None
