"""The compare view's side B, for both front ends (no toolkit): :class:`SideB`, side B's pane
beside side A's :class:`~explorer.app.viewport.PlotterView`, with the same camera (one
``vtkCamera`` for both), lights and mesh, and side B's material and model, or "A − B" (the
difference of what the two panes show, largest channel in 1/255 levels, in the difference
view's colours: the colours per vertex, or with both sides lit per pixel their two per-pixel
pictures, pixel by pixel), and both sides' captions. The front end's :class:`Pane` makes
side B's plotter and shows it (Qt: a second ``QtInteractor`` beside the view; the page: a
second off-screen plotter in its own remote view)."""

from __future__ import annotations

from typing import Protocol

import numpy as np

from explorer.app import captions
from explorer.app import model as M
from explorer.app import pixelcompare as PC
from explorer.app.handledrag import HandleDragger
from explorer.app.pixellayer import PER_PIXEL, PixelLayer
from explorer.app.view import SceneView, view_camera
from explorer.shading.display import to_bytes


class Pane(Protocol):
    """What a front end gives :class:`SideB`: ``handles`` whether side B draws the light
    handles (dragged there too); ``make_plotter()`` side B's plotter (called once, when side B
    is first shown); ``made(plotter, view)`` once side B's scene is drawn in it;
    ``show_pane(visible)``; ``follow()`` after each frame of side A while side B is shown (side
    B's picture follows); ``beside(img)`` side A's picture (h, w, 3) with side B's beside it as
    the front end shows them."""

    handles: bool

    def make_plotter(self): ...

    def made(self, plotter, view: SceneView) -> None: ...

    def show_pane(self, visible: bool) -> None: ...

    def follow(self) -> None: ...

    def beside(self, img: np.ndarray) -> np.ndarray: ...


class SideB:
    """Side B beside ``main`` (side A's :class:`~explorer.app.viewport.PlotterView`), in the
    front end's ``pane``: :attr:`plotter` and :attr:`view` (its SceneView) are made when side
    B is first shown."""

    def __init__(self, main, pane: Pane):
        self.main = main
        self.pane = pane
        self.plotter = None
        self.view: SceneView | None = None
        self.pixels: PixelLayer | None = None  # side B's per-pixel picture
        self.figures: PC.Figures | None = None  # Gouraud vs per-pixel: this frame's line
        self._heat = False  # side B's per-pixel pane draws the heat map
        self.errors = None  # the errors (k,) and the mask (h, w) of the figures

    @property
    def shown(self) -> bool:
        return self.view is not None and self.main.controller.state.compare is not None

    def _make(self, state: M.State) -> None:
        main = self.main
        pl = self.plotter = self.pane.make_plotter()
        # linked cameras: one vtkCamera, A's, which PyVista's ``camera`` names too (after
        # SetActiveCamera alone it named B's own unused camera, and B's translucent triangles
        # were sorted for that one)
        pl.renderer.camera = main.plotter.renderer.camera
        pl.camera_set = True
        a = main.view
        self.view = SceneView(pl, a.mesh, M.side_b(state), lod_vertices=a.lod_vertices,
                              lod_target=a.lod_target, side="b")  # fmt: skip
        if self.pane.handles:  # the lights are shared: B's handles move them too
            self.handles = HandleDragger(main, pl, self.view)
        main.observe(pl.renderer, "StartEvent", self._before_frame, "compare")
        self.pixels = PixelLayer(self.view)
        window = pl.render_window  # (before VTK makes its context current: see pixellayer)
        main.observe(window, "StartEvent", self._pixels_before, "compare")
        main.observe(window, "EndEvent", lambda *_: self.pixels.after(), "compare")
        self.pane.made(pl, self.view)

    def close(self) -> None:
        """Side B's plotter closed, when it was made (side A's :meth:`PlotterView.close`
        removed its observers and released its handles first)."""
        if self.plotter is not None:
            self.plotter.close()

    def _before_frame(self, *_) -> None:
        """Before a frame of side B: its triangles sorted and its inset laid out for the shared
        camera, whose clipping range is set around what B draws (A's frame set it around
        what A draws: no mesh while A shows the heat map)."""
        s = self.main.controller.state
        self.view.before_frame(view_camera(self.plotter.camera, s.centre, s.radius))
        self.plotter.renderer.ResetCameraClippingRange()

    def _pixels_before(self, *_) -> None:
        """Side B's render window's StartEvent: its per-pixel picture (made already when side
        A's frame came first: :meth:`before_a_frame`), and its term strip's tiles per pixel
        while side B is drawn per pixel."""
        state = self.main.controller.state
        if state.compare is not None:
            b = M.side_b(state)
            self.pixels.before(b)
            per_pixel = self.pixels.wanted(b) and not self.pixels.fallback
            self.view.strip.before_pixels(b, per_pixel, self.view.mesh)

    def before_a_frame(self, state: M.State) -> None:
        """Side A's render window's StartEvent, after side A's picture: side B's per-pixel
        picture for the shared camera, and with one side per vertex and the other per pixel
        the line of both panes (so both show the same line in the same frame) and, with the
        difference on, the heat map in side B's pane."""
        if not self.shown:
            return
        self.pixels.update(M.side_b(state))
        self.figures = self._compare(state)
        self._captions()

    def _compare(self, state: M.State) -> PC.Figures | None:
        """The figures of Gouraud vs per-pixel (:mod:`explorer.app.pixelcompare`), or None
        when both sides are lit alike (or the per-pixel side draws per vertex: a drag)."""
        b_pp = M.side_b(state).scene.shading == PER_PIXEL
        if (state.scene.shading == PER_PIXEL) == b_pp:
            self._pixel_difference(state if b_pp else None)
            return None
        layer, other = (self.pixels, self.main.view) if b_pp else (self.main.pixels, self.view)
        if layer.last is None or not layer.shown:
            return None
        g, _ = layer.live.gbuffer(layer.camera, layer.size)
        vertex = PC.gouraud(other.mesh, g.hits, to_bytes(other.drawings[0].colors()))
        errors = PC.levels(vertex, layer.last.rgb[g.hits.mask])
        self.errors = (errors, g.hits.mask)  # (what the line and the heat map are made of)
        if b_pp and state.compare_difference:
            self.pixels.draw(PC.heat_picture(errors, g.hits.mask))
        elif b_pp and self._heat:
            self.pixels.draw(self.pixels.rgb)
        self._heat = b_pp and state.compare_difference
        if b_pp:  # side A's last frame, from its change to its picture, side B's work left out
            vertex_ms = self.main.frame_ms - self.main.pixels.aside_ms
        else:
            vertex_ms = self.pixels.vertex_ms
        return PC.figures(errors, vertex_ms, layer.ms)

    def _pixel_difference(self, state: M.State | None) -> None:
        """A − B with both sides lit per pixel (``state``; None: they are not): side B's pane
        draws the difference of the two pictures, the largest channel in 8-bit levels at the
        pixels both cover (what each pane shows; the per-vertex colours' A − B of
        :func:`show_side_b` lies under B's picture), in the difference view's colours;
        :attr:`errors` holds it. Turned off, or a side not drawn per pixel (a drag's
        fallback): side B's picture again."""
        a, b = self.main.pixels, self.pixels
        both = (
            state is not None
            and a is not None
            and state.compare_difference
            and a.shown
            and b.shown
            and a.last is not None
            and b.last is not None
            and a.camera == b.camera
            and a.size == b.size
        )
        if both:
            mask = a.last.mask & b.last.mask
            errors = PC.levels(a.last.rgb[mask], b.last.rgb[mask])
            self.errors = (errors, mask)
            b.draw(PC.heat_picture(errors, mask))
        elif self._heat and b.shown and b.rgb is not None:
            b.draw(b.rgb)
        self._heat = both

    def _captions(self) -> None:
        """Both panes' captions with the figures' line under them (none without figures)."""
        for view in (self.main.view, self.view):
            caption = getattr(view, "caption", None)
            first = (caption.GetInput() or "") if caption is not None else ""
            first = first.split("\n")[0]
            view.set_caption(first if self.figures is None else f"{first}\n{self.figures.line()}")

    def show(self, old: M.State | None, new: M.State) -> None:
        """Side B made, shown, hidden, and given side B's state (or A − B)."""
        if new.compare is None:
            if self.view is not None:
                self.pane.show_pane(False)
            self.main.view.set_caption("")
            return
        if self.view is None:
            self._make(new)
        show_side_b(self.main.view, self.view, old, new)
        self._captions()
        self.pane.show_pane(True)

    def after_frame(self) -> None:
        """After a frame of side A: side B's picture follows (the same camera)."""
        if self.shown:
            self.pane.follow()

    def beside(self, img: np.ndarray) -> np.ndarray:
        """``img`` (h, w, 3), side A's pixels, with side B's beside it while side B is shown."""
        return self.pane.beside(img) if self.shown else img

    def probe(self) -> dict:
        """Side B's probe vertex and its pixel (origin top-left), its picture's size, each
        light's handle pixel (origin top-left) and the arrows at its edge (light -> the
        triangle's corners, origin top-left) while its handles are drawn, and its term strip's
        report (:meth:`~explorer.app.termstrip.TermStrip.report`; None while it has none)."""
        v = self.view
        i = v.probe_vertex()
        s = self.main.controller.state
        h = self.plotter.window_size[1]
        drawn = self.pane.handles
        return {"vertex": i, "px": v.world_to_window(v.mesh.positions[i]),
                "size": list(self.plotter.window_size),
                "handles_px": [v.world_to_window(M.handle_point(s, k))
                               for k in range(len(s.scene.lights))] if drawn else [],
                "arrows_px": {str(k): [[float(x), float(h - 1 - y)] for x, y in t]
                              for k, t in v.marker_triangles.items()} if drawn else {},
                "strip": v.strip.report(v.to_view(v.mesh.positions[i])),
                }  # fmt: skip


def show_side_b(view_a, view_b, old: M.State | None, new: M.State) -> None:
    """``view_b`` (side B's SceneView beside ``view_a``, side A's) shows ``new``'s side B, or
    A − B; the captions say which side is which. ``new.compare`` must be set."""
    b = M.side_b(new)
    if view_b.mesh is not view_a.mesh:
        view_b.set_mesh(view_a.mesh, b)
    else:
        view_b.show_state(b)
    if new.compare_difference:
        a = view_a.displayed_colors().astype(np.int16)
        other = to_bytes(view_b.drawings[0].colors()).astype(np.int16)
        view_b.paint_levels(np.abs(a - other).max(axis=1))
    elif old is not None and old.compare_difference:
        view_b.drawings[0].upload()
    b_shading = b.scene.shading
    how_a = f", {new.scene.shading}" if b_shading != new.scene.shading else ""
    how_b = f", {b_shading}" if how_a else ""
    view_a.set_caption(f"A: {captions.material_title(new)} ({new.scene.model}{how_a})")
    view_b.set_caption("A − B (levels, as the difference view)" if new.compare_difference
                       else f"B: {new.compare_preset or 'material'} "
                       f"({new.compare_model}{how_b})")  # fmt: skip
