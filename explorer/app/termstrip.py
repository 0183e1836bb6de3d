"""The term strip in the explorer's view (docs/terms.md): a row of small views under the main
one, ``emission | ambient | diffuse | specular | sum | overflow``, with the main view's camera.

Both front ends draw it with no code of their own: the tiles are VTK renderers of the view's
own render window (each a viewport of the bottom band, sharing the main renderer's camera), so
the window's Qt interactor and the page's pushed picture show them as they show the view. Each
tile draws the drawn mesh (the full mesh, or its level of detail during a drag) in its term's
bytes, :func:`explorer.shading.strip.shader_strip_bytes` of that drawing's Shader: its kept
light sums recomposed, no light pass; the overflow tile is the sum tile with the vertices the
display clamped in magenta, its label the share of them. Where that share is more than 0 a
caption on a line of its own under the tiles says what the mask is (:func:`overflow_texts`:
``overflow (magenta): 1.3% of the vertices clamped: ...``; the line stays, empty, where
nothing is clamped, so the tiles keep one size). The state's ``strip`` switches it,
``strip_mode`` picks ``weighted`` or ``raw`` tiles (the panel model's rows, :data:`ROWS`).

Per pixel (the view's ``shading: per-pixel``), each tile is a picture instead: the engine lit
at each pixel of the tile (a :class:`~explorer.render.live.LivePixels` of the strip's own at the
tile's size, the main view's camera), its per-pixel shader's kept sums recomposed
(:func:`explorer.shading.strip.compose_strip` on pixel rows); the sum tile is ``render
--per-pixel``'s picture at that size and camera, bit for bit (a mesh file's own materials:
each group's pixels recomposed in its material, as the view's picture is). Made before the
window draws (:meth:`TermStrip.before_pixels`, the render window's StartEvent, as the view's
own per-pixel picture). VTK is imported inside the methods.

In the compare view each pane has a strip of its own (side B's :class:`TermStrip` is made by
side B's SceneView, :attr:`TermStrip.side` ``b``): each shows its side's terms, per pixel when
its side is, under a caption naming the side at its top left. The state's ``strip_side``
(:data:`STRIP_SIDES`) picks the panes that show one: ``both``, or side ``a``'s or ``b``'s alone
(the other pane keeps the strip's band, empty: both views keep one size).

The state's ``strip_lights`` adds a row of tiles per light under the strip (the panel model's
row): each what that light alone adds, emission-free (its ambient, diffuse, specular and their
sum; :func:`explorer.render.strip.scene_rows`' rows, the engine's float64 strip of each,
:func:`explorer.render.strip.mesh_strip`, as ``render --strip --strip-lights`` draws them), named
at its first tile's top left. A light pass per light on each change while the row is on (the
strip's own row recomposes kept sums); the light rows draw the mesh per vertex, also in a
per-pixel view. The strip's height grows with its rows (:func:`strip_fraction`).
"""

from __future__ import annotations

import numpy as np

from explorer.app import model as M
from explorer.app.model import State
from explorer.core.errors import ExplorerError
from explorer.render.images import SIZE_RANGE
from explorer.render.strip import COLUMNS, OVERFLOW_COLOR, mesh_strip, scene_rows
from explorer.shading.display import to_bytes
from explorer.shading.strip import (
    MODES,
    TERMS,
    compose_strip,
    grouped_strip,
    shader_strip_bytes,
)

#: the strip's height as a fraction of the view's (the main view keeps the rest above it)
STRIP_HEIGHT = 0.2
#: the most of the view's height the strip takes with its rows per light (:func:`strip_fraction`)
STRIP_MAX = 0.6
#: the overflow caption's line under the tiles (pixels; :func:`tile_boxes`): 12-pixel text
#: and 2 pixels above and under it
CAPTION_LINE = 16
#: the tiles' label colour and font size (pixels)
LABEL_COLOUR = (0.93, 0.93, 0.93)
LABEL_FONT = 12
#: the smallest font (pixels) a label is drawn at before it is shortened (:func:`label_texts`)
LABEL_MIN_FONT = 9
#: the label's room: the tile's width less this many pixels (4 at its left, 4 at its right)
LABEL_ROOM = 8
#: the compare view's panes that show their side's strip (the state's ``strip_side``)
STRIP_SIDES = ("both", "a", "b")
#: each tile's label shortened, longest first, for narrow tiles (the first that fits is drawn)
SHORT = {
    "emission": ("emis.", "e"),
    "ambient": ("amb.", "a"),
    "diffuse": ("diff.", "d"),
    "specular": ("spec.", "s"),
    "sum": ("sum", "+"),
    "overflow": (),
}


def set_strip(state: State, on: bool) -> State:
    """The term strip under the view on or off."""
    return state.replace(strip=bool(on))


def set_strip_mode(state: State, mode: str) -> State:
    """The strip's tiles: ``weighted`` (k·A, k·D, k·S) or ``raw`` (A, D, S)."""
    if mode not in MODES:
        raise ExplorerError(f"strip_mode must be one of {MODES}, got {mode!r}")
    return state.replace(strip_mode=mode)


def set_strip_side(state: State, side: str) -> State:
    """The compare view's panes that show the strip: ``both``, or side ``a``'s or ``b``'s."""
    if side not in STRIP_SIDES:
        raise ExplorerError(f"strip_side must be one of {STRIP_SIDES}, got {side!r}")
    return state.replace(strip_side=side)


def set_strip_lights(state: State, on: bool) -> State:
    """A row of tiles per light under the strip on or off (a light pass per light while on)."""
    return state.replace(strip_lights=bool(on))


def strip_fraction(rows: int) -> float:
    """The strip's height, a fraction of the view's, with ``rows`` rows of tiles (its own and
    one per light): :data:`STRIP_HEIGHT` a row, at most :data:`STRIP_MAX`."""
    return min(STRIP_HEIGHT * max(rows, 1), STRIP_MAX)


def strip_shown(state: State, side: str = "a") -> bool:
    """Whether the pane of ``side`` (``a``, or ``b`` in the compare view) shows the strip."""
    if not state.strip:
        return False
    return state.compare is None or state.strip_side in ("both", side)


def side_caption(state: State, side: str) -> str:
    """The strip's caption in the compare view: which side's terms it shows ("" outside it)."""
    return "" if state.compare is None else f"side {side.upper()}"


def label_texts(column: str, mode: str, share: float) -> tuple[str, ...]:
    """Tile ``column``'s label and its shorter forms, longest first: ``sum (weighted)``,
    ``sum``, ``+``; ``overflow 1.3%``, ``1.3%`` (``share`` the clamped share, in %)."""
    if column == "overflow":
        return (f"overflow {share:.1f}%", f"{share:.1f}%")
    full = f"{column} ({mode})" if column == "sum" else column
    return (full, *SHORT[column])


def overflow_texts(share: float, per_pixel: bool) -> tuple[str, ...]:
    """The overflow caption and its shorter forms, longest first (the first that fits the
    strip's width is drawn): ``share`` the clamped share of the vertices (or, ``per_pixel``,
    of the surface's pixels) in %; none (``()``) where nothing is clamped."""
    if share <= 0.0:
        return ()
    pct = f"{share:.1f}%" if share >= 0.05 else "< 0.1%"
    unit = "pixels" if per_pixel else "vertices"
    return (
        f"overflow (magenta): {pct} of the {unit} clamped: there the terms add up to more "
        "than 1, the 8-bit tiles to more than the sum tile",
        f"overflow: {pct} of the {unit} clamped (the tiles add up to more than the sum tile)",
        f"overflow: {pct} of the {unit} clamped",
        f"overflow {pct}",
    )


def band_height(height: int, rows: int = 1) -> int:
    """The strip's band in a window ``height`` pixels high (pixels): its tiles'
    (:func:`strip_fraction`) and the overflow caption's line under them (:data:`CAPTION_LINE`,
    less in a tiny window: a quarter of the tiles' height at most)."""
    th = int(round(strip_fraction(rows) * height))
    return th + min(CAPTION_LINE, th // 4)


def tile_boxes(
    width: int, height: int, n: int, rows: int = 1, row: int = 0
) -> list[tuple[int, int, int, int]]:
    """The strip's ``n`` tiles in a window of ``width`` x ``height`` pixels: each ``(x, y, w,
    h)`` (pixels, origin bottom-left), all of one width (``width // n``: every tile's per-pixel
    picture is one picture's size), side by side and centred; the strip's band its height, the
    tiles over the overflow caption's line (:data:`CAPTION_LINE` pixels, :func:`band_height`:
    the band takes it from the main view, the tiles keep their size). With ``rows`` rows
    (:func:`strip_fraction`), row ``row`` (0 the strip's own, at the top; then one per light,
    downwards), each row of one height."""
    tw = width // n
    th = int(round(strip_fraction(rows) * height))
    line = band_height(height, rows) - th
    rh = th // max(rows, 1)
    y = line + (rows - 1 - row) * rh
    x0 = (width - n * tw) // 2
    return [(x0 + i * tw, y, tw, rh) for i in range(n)]


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
    draws, :attr:`overflow` the clamped vertices; :attr:`side` the compare view's pane it is
    under (``a``, or ``b`` for side B's), :attr:`caption` the line naming it,
    :attr:`overflow_caption` the line under the tiles saying what the overflow mask is."""

    def __init__(self, plotter, side: str = "a"):
        self.plotter = plotter
        self.side = side
        self.caption = None  # the text actor naming the side (made with the tiles)
        self.overflow_caption = None  # the text actor under the tiles (overflow_texts)
        self._overflow_texts: tuple = ()  # its texts, longest first
        self.renderers: list = []
        self.labels: list = []
        self._texts: list = []  # each label's texts, longest first (label_texts)
        self._band = None  # the renderer under the tiles (the strip's background)
        self._placed = None  # the window size the tiles were placed for
        self._actors: list = []
        self._colours: list = []
        self._key = None
        self._drawing = None
        self.tiles = None
        self.overflow = None
        self.on = False  # the tiles drawn
        self.band = False  # the strip's room under the view taken (the tiles drawn in it, or not)
        self.pixel_tiles = None  # per pixel: each tile's picture (h, w, 3) uint8, else None
        self._live = None  # the per-pixel tiles' LivePixels
        self._pixel_key = None
        self._images: list = []  # per tile: (vtkImageData, its actor)
        self.lights = LightRows(self)  # a row per light under the strip's own (strip_lights)

    def show(self, state: State, drawing) -> None:
        """Show the strip for ``state`` (off: the main view fills the window again), its tiles
        from ``drawing`` (a :class:`~explorer.app.view.MeshDrawing`) when anything they depend
        on changed. A pane whose side the compare view's ``strip_side`` leaves out keeps the
        strip's band, empty: both panes keep one size (the same picture of the shared camera,
        and A − B per pixel needs both pictures of one size)."""
        if not state.strip:
            if self.band:
                self._switch(False)
            return
        if not self.band:
            self._switch(True)
        here = strip_shown(state, self.side)
        if here != self.on:
            for r in self.renderers:
                r.SetDraw(here)  # (left out: the band's background under them)
            self.on, self._key = here, None
        self.lights.sync(state, drawing, here)
        if not here:
            self._set_overflow(0.0, False)
            return
        self.caption.SetInput(side_caption(state, self.side))
        if drawing is not self._drawing:
            self._geometry(drawing)
        self.lights.fill(state, drawing)  # (its own key: rows may come, the strip's the same)
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
        self._texts = [label_texts(c, state.strip_mode, share) for c in COLUMNS]
        self._set_overflow(share, False)

    def before_pixels(self, state: State, per_pixel: bool, mesh) -> None:
        """The render window's StartEvent: with the strip on and the view drawn per pixel
        (``per_pixel``), each tile's per-pixel picture of ``mesh`` for the camera VTK is about
        to draw with (made again when the scene, camera, tile size or mode changed); else the
        tiles draw the mesh per vertex."""
        if self.band:
            self._place()
        small = self.on and min(self.renderers[0].GetSize()) < SIZE_RANGE[0]
        if not (self.on and strip_shown(state, self.side) and per_pixel) or small:
            self._show_pictures(False)  # (tiles under SIZE_RANGE's least side: per vertex)
            return
        from explorer.app.view import view_camera  # (a cycle: the view holds the strip)

        camera = view_camera(self.plotter.camera, state.centre, state.radius)
        scene = M.set_camera(state, camera).shown_scene()
        w, h = (int(v) for v in self.renderers[0].GetSize())
        bg = tuple(self.plotter.renderer.GetBackground())
        groups = state.shown_groups()  # (a mesh file's own materials, group by group)
        key = (repr(scene), camera, (w, h), id(mesh), state.strip_mode, bg, groups)
        if key != self._pixel_key:
            self.pixel_tiles = self._pictures(
                scene, camera, (w, h), mesh, state.strip_mode, bg, groups
            )
            self._pixel_key = key
            for (image, _), rgb in zip(self._images_for(w, h), self.pixel_tiles, strict=True):
                arr = image.GetPointData().GetScalars()
                from vtkmodules.util.numpy_support import vtk_to_numpy

                vtk_to_numpy(arr).reshape(h, w, 3)[:] = rgb[::-1]  # (VTK's rows: bottom up)
                arr.Modified()
                image.Modified()
        self._show_pictures(self.pixel_tiles is not None)

    def _pictures(self, scene, camera, size, mesh, mode, background, groups=None) -> list:
        """The tiles' pictures (:data:`COLUMNS`' order), each (h, w, 3) uint8: the per-pixel
        shader's sums at ``size`` recomposed (each group's pixels in its material of
        ``groups``, as the view's picture is made); the overflow's share in the label."""
        from explorer.render.live import LivePixels  # (VTK, for the G-buffer's rasterisation)

        if self._live is None:
            self._live = LivePixels(mesh)
        self._live.set_mesh(mesh)
        frame = self._live.frame(scene, camera, size, background=background, materials=groups)
        g, _ = self._live.gbuffer(camera, size)
        sh = self._live.shader
        first = len(sh.colors) - len(g.pixels)  # (the mesh's vertices first, with shadows)
        if groups is None:
            strip = compose_strip(scene, sh.terms, sh.colors, mode)
        else:  # (the shader's rows of each group's pixels, as LivePixels lights them)
            rows = self._live._group_rows(g, groups, first)
            strip = grouped_strip(sh, rows, groups, mode)
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
        self._texts[COLUMNS.index("overflow")] = label_texts("overflow", mode, share)
        self._set_overflow(share, True)
        return out

    def _set_overflow(self, share: float, per_pixel: bool) -> None:
        """The overflow caption for ``share`` (in %) of the vertices or pixels clamped (empty
        at 0), and the labels, fitted."""
        self._overflow_texts = overflow_texts(share, per_pixel)
        self._fit_labels()

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
            r.RemoveViewProp(label)  # (the labels drawn over the picture)
            r.AddViewProp(actor)
            r.AddViewProp(label)
            if r is self.renderers[0]:
                r.RemoveViewProp(self.caption)
                r.AddViewProp(self.caption)
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

    def _place(self) -> None:
        """The tiles at :func:`tile_boxes` of the window's present size (again when it changed),
        their labels fitted to them."""
        size = tuple(int(v) for v in self.plotter.window_size)
        if size == self._placed or min(size) <= 0:
            return
        self._placed = size
        W, H = size
        rows = 1 + len(self.lights.rows)
        f = band_height(H, rows) / H
        self.plotter.renderer.SetViewport(0.0, f, 1.0, 1.0)
        self._band.SetViewport(0.0, 0.0, 1.0, f)
        every = [self.renderers] + [row.renderers for row in self.lights.rows]
        for i, renderers in enumerate(every):
            boxes = tile_boxes(W, H, len(COLUMNS), rows, i)
            for r, (x, y, w, h) in zip(renderers, boxes, strict=True):
                r.SetViewport(x / W, y / H, (x + w) / W, (y + h) / H)
        self._fit_labels()

    def _fit_labels(self) -> None:
        """Each label its longest text that fits its tile (:data:`LABEL_ROOM`), at
        :data:`LABEL_FONT` down to :data:`LABEL_MIN_FONT`, else the shortest at that font."""
        for r, label, texts in zip(self.renderers, self.labels, self._texts, strict=False):
            room = int(r.GetSize()[0]) - LABEL_ROOM
            prop = label.GetTextProperty()
            for text in texts:
                label.SetInput(text)
                font = fit_font(label, r, room)
                if font is not None:
                    break
            else:
                font = LABEL_MIN_FONT
            prop.SetFontSize(font)
        if self.overflow_caption is None:
            return
        room = int(self._band.GetSize()[0]) - LABEL_ROOM
        self.overflow_caption.SetInput("")
        for text in self._overflow_texts:  # (the longest that fits the strip's width)
            self.overflow_caption.SetInput(text)
            if fit_font(self.overflow_caption, self._band, room) is not None:
                break
        else:
            self.overflow_caption.GetTextProperty().SetFontSize(LABEL_MIN_FONT)

    def overflow_box(self) -> list[int]:
        """The overflow caption's box ``[x, y, width, height]`` in window pixels (origin
        top-left), as drawn (its position and its text's measured size)."""
        _, wh = self.plotter.window_size
        extent = [0.0, 0.0]
        self.overflow_caption.GetSize(self._band, extent)
        x, y = self._band.GetOrigin()
        lx, ly = self.overflow_caption.GetPosition()
        top = wh - (y + ly + extent[1])
        return [int(x + lx), int(top), int(round(extent[0])), int(round(extent[1]))]

    def label_boxes(self) -> dict:
        """Each tile's label box ``[x, y, width, height]`` in window pixels (origin top-left),
        as drawn (its position and its text's measured size), and its text."""
        _, wh = self.plotter.window_size
        out = {}
        for column, r, label in zip(COLUMNS, self.renderers, self.labels, strict=True):
            extent = [0.0, 0.0]
            label.GetSize(r, extent)
            x, y = r.GetOrigin()
            lx, ly = label.GetPosition()
            top = wh - (y + ly + extent[1])
            out[column] = [int(x + lx), int(top), int(round(extent[0])), int(round(extent[1]))]
        return out

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
            "caption": self.caption.GetInput() or "",
            "labels": self.label_boxes(),
            "texts": {c: t.GetInput() for c, t in zip(COLUMNS, self.labels, strict=True)},
            "overflow_caption": self.overflow_caption.GetInput() or "",
            "overflow_box": self.overflow_box(),
            "lights": self.lights.report(point),
        }

    def _switch(self, on: bool) -> None:
        """Make room for the tiles (or give it back), creating them the first time."""
        main = self.plotter.renderer
        if on and not self.renderers:
            self._make()
        if not on:
            self.lights.drop()
        main.SetViewport(0.0, STRIP_HEIGHT if on else 0.0, 1.0, 1.0)
        window = self.plotter.render_window
        for r in (self._band, *self.renderers):
            if on:
                window.AddRenderer(r)
                r.SetDraw(True)
            else:
                window.RemoveRenderer(r)
        self.on = self.band = on
        self._key = None
        self._placed = None
        if on:
            self._place()

    def _make(self) -> None:
        import vtkmodules.vtkRenderingFreeType  # noqa: F401 - registers the text renderer
        from vtkmodules.vtkRenderingCore import vtkCoordinate, vtkRenderer, vtkTextActor

        main = self.plotter.renderer
        n = len(COLUMNS)
        band = self._band = vtkRenderer()  # (the pixels the equal tiles leave: the background)
        band.SetViewport(0.0, 0.0, 1.0, STRIP_HEIGHT)
        band.SetBackground(main.GetBackground())
        band.InteractiveOff()
        over = self.overflow_caption = vtkTextActor()  # (in the band's line under the tiles)
        prop = over.GetTextProperty()
        prop.SetColor(*LABEL_COLOUR)
        prop.SetFontSize(LABEL_FONT)
        prop.SetFontFamilyToArial()
        prop.ShadowOff()
        over.SetPosition(4, 2)
        band.AddViewProp(over)
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
        caption = self.caption = vtkTextActor()  # the side's name, over the first tile's top
        prop = caption.GetTextProperty()
        prop.SetColor(*LABEL_COLOUR)
        prop.SetFontSize(LABEL_FONT)
        prop.SetFontFamilyToArial()
        prop.BoldOn()
        prop.ShadowOff()
        prop.SetVerticalJustificationToTop()
        corner = vtkCoordinate()  # the tile's top left, whatever its size
        corner.SetCoordinateSystemToNormalizedViewport()
        corner.SetValue(0.0, 1.0)
        at = caption.GetPositionCoordinate()
        at.SetCoordinateSystemToViewport()
        at.SetReferenceCoordinate(corner)
        at.SetValue(4.0, -3.0)  # (pixels from that corner)
        self.renderers[0].AddViewProp(caption)

    def _geometry(self, drawing) -> None:
        """Each tile's actor: the drawing's points and triangles, colours of its own."""
        self._actors, self._colours = _tile_actors(self.renderers, self._actors, drawing)
        self._drawing = drawing
        self._key = None


def _tile_actors(renderers, actors, drawing) -> tuple[list, list]:
    """The tiles' actors of ``drawing`` (:func:`_mesh_actor`, one a renderer) in place of
    ``actors``, which leave their renderers: ``(actors, colours)``."""
    for r, a in zip(renderers, actors, strict=False):
        r.RemoveActor(a)
    made = [_mesh_actor(r, drawing) for r in renderers]
    return [a for a, _ in made], [c for _, c in made]


def _mesh_actor(renderer, drawing) -> tuple:
    """An actor in ``renderer`` of the drawing's points and triangles, in colours of its own:
    ``(actor, (colours (n, 3) uint8 view, the VTK array, its polydata))``."""
    from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
    from vtkmodules.vtkCommonDataModel import vtkPolyData
    from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper

    poly = vtkPolyData()
    poly.SetPoints(drawing.poly.GetPoints())
    poly.SetPolys(drawing.poly.GetPolys())
    arr = numpy_to_vtk(np.zeros((drawing.mesh.n_vertices, 3), np.uint8), deep=True)
    arr.SetName("colors")
    poly.GetPointData().SetScalars(arr)
    mapper = vtkPolyDataMapper()
    mapper.SetInputData(poly)
    mapper.SetColorModeToDirectScalars()
    mapper.SetScalarModeToUsePointData()
    actor = vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().LightingOff()
    renderer.AddActor(actor)
    return actor, (vtk_to_numpy(arr), arr, poly)


class _LightRow:
    """One light's row of tiles under the strip (:data:`COLUMNS`' order, per vertex): its
    renderers in the strip's render window (the main camera), its name at the first tile's top
    left, :attr:`tiles` the bytes each draws."""

    def __init__(self, strip: TermStrip):
        from vtkmodules.vtkRenderingCore import vtkRenderer, vtkTextActor

        main = strip.plotter.renderer
        self.renderers, self._actors, self._colours = [], [], []
        self._drawing = None
        self.tiles = None
        for _ in COLUMNS:
            r = vtkRenderer()
            r.SetBackground(main.GetBackground())
            r.SetActiveCamera(main.GetActiveCamera())
            r.InteractiveOff()
            strip.plotter.render_window.AddRenderer(r)
            self.renderers.append(r)
        self.caption = vtkTextActor()
        prop = self.caption.GetTextProperty()
        prop.SetColor(*LABEL_COLOUR)
        prop.SetFontSize(LABEL_MIN_FONT + 1)
        prop.SetFontFamilyToArial()
        prop.ShadowOff()
        prop.SetVerticalJustificationToTop()
        at = self.caption.GetPositionCoordinate()
        at.SetCoordinateSystemToNormalizedViewport()
        at.SetValue(0.02, 0.97)
        self.renderers[0].AddViewProp(self.caption)

    def show(self, drawing, name: str, tiles) -> None:
        """Draw ``drawing``'s mesh in each tile's bytes of ``tiles``, the row named ``name``."""
        if drawing is not self._drawing:
            self._actors, self._colours = _tile_actors(self.renderers, self._actors, drawing)
            self._drawing = drawing
        self.tiles = tiles
        for colours, rgb in zip(self._colours, tiles, strict=True):
            colours[0][:] = rgb
            colours[1].Modified()
        self.caption.SetInput(name)

    def tile_box(self, column: str) -> list[int]:
        """Tile ``column``'s box ``[x, y, width, height]`` in window pixels (origin top-left)."""
        r = self.renderers[COLUMNS.index(column)]
        x, y = r.GetOrigin()
        w, h = r.GetSize()
        _, wh = r.GetRenderWindow().GetSize()
        return [int(x), int(wh - y - h), int(w), int(h)]

    def tile_pixel(self, column: str, point) -> list[int]:
        """Window pixel (origin top-left) of ``point`` (3,) in the view's coordinates in tile
        ``column`` (as :meth:`TermStrip.tile_pixel`)."""
        r = self.renderers[COLUMNS.index(column)]
        r.SetWorldPoint(*point, 1.0)
        r.WorldToDisplay()
        x, y, _ = r.GetDisplayPoint()
        _, h = r.GetRenderWindow().GetSize()
        return [int(round(x)), int(round(h - 1 - y))]

    def remove(self, window) -> None:
        """Take the row's renderers out of ``window``."""
        for r in self.renderers:
            window.RemoveRenderer(r)


class LightRows:
    """The strip's rows per light (the state's ``strip_lights``), under the strip's own:
    :attr:`rows` each a :class:`_LightRow`, made or dropped as the count of lights changes
    (:meth:`sync`), their tiles the engine's strip of each light alone (:meth:`fill`)."""

    def __init__(self, strip: TermStrip):
        self.strip = strip
        self.rows: list = []
        self._key = None

    def sync(self, state: State, drawing, here: bool) -> None:
        """A row per light of ``drawing``'s scene while ``state.strip_lights`` (none else),
        the strip placed again when their count changed; drawn where the pane shows the strip
        (``here``: a pane the compare view leaves out keeps their room, empty, as the
        strip's)."""
        want = len(drawing.shader.scene.lights) if state.strip_lights else 0
        if want != len(self.rows):
            self.drop()
            self.rows = [_LightRow(self.strip) for _ in range(want)]
            self.strip._placed = None
            self.strip._place()
        for row in self.rows:
            for r in row.renderers:
                r.SetDraw(here)

    def fill(self, state: State, drawing) -> None:
        """Each row's tiles: the engine's float64 strip of its light alone (a light pass each;
        :func:`~explorer.render.strip.scene_rows`, :func:`~explorer.render.strip.mesh_strip`),
        again when the drawing, scene, mode or groups changed."""
        scene = drawing.shader.scene
        key = (id(drawing), scene, state.strip_mode, drawing.groups)
        if not self.rows or key == self._key:
            return
        self._key = key
        rows = scene_rows(scene, lights=True, materials=drawing.groups)[1:]
        for row, (name, light_scene, materials) in zip(self.rows, rows, strict=True):
            strip = mesh_strip(light_scene, drawing.mesh, state.strip_mode, materials)
            tiles = [to_bytes(strip.tiles[t]) for t in TERMS]
            mask = tiles[4].copy()
            mask[strip.overflow] = to_bytes([OVERFLOW_COLOR])[0]
            row.show(drawing, name, (*tiles, mask))

    def drop(self) -> None:
        """No rows: their renderers out of the window."""
        for row in self.rows:
            row.remove(self.strip.plotter.render_window)
        self.rows, self._key = [], None

    def report(self, point) -> list[dict]:
        """Each row's name, tile boxes and window pixels of ``point`` (as the strip's)."""
        return [
            {
                "name": row.caption.GetInput() or "",
                "boxes": {c: row.tile_box(c) for c in COLUMNS},
                "px": {c: row.tile_pixel(c, point) for c in COLUMNS},
            }
            for row in self.rows
        ]


def fit_font(label, renderer, room: float) -> int | None:
    """The largest font from :data:`LABEL_FONT` down to :data:`LABEL_MIN_FONT` at which the
    text actor ``label``'s text is at most ``room`` pixels wide in ``renderer``, or None."""
    prop = label.GetTextProperty()
    for font in range(LABEL_FONT, LABEL_MIN_FONT - 1, -1):
        prop.SetFontSize(font)
        extent = [0.0, 0.0]
        label.GetSize(renderer, extent)
        if extent[0] <= room:
            return font
    return None
