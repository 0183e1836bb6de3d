"""The view port of the controller (:class:`explorer.app.controller.ports.View`) over any PyVista
plotter, for both front ends (no toolkit here): the Qt window's ``QtInteractor`` and the web
page's off-screen plotter are each one :class:`PlotterView`, and differ only in a small
collaborator, their :class:`Pictures`: how a new picture reaches the person (Qt draws its widget;
the page's server pushes the picture to the browser), the controls shown and the difference
view's legend written in the front end's widgets, and what it does after each frame.

:class:`PlotterView` holds the plotter, the scene drawn in it
(:class:`~explorer.app.view.SceneView`), the difference view's heat map, the light handles'
drag (:class:`~explorer.app.handledrag.HandleDragger`), side B of the compare view
(:class:`~explorer.app.sides.SideB`) and the frame plumbing: before each frame the camera goes
into the state (the camera is the viewer), after it side B follows and the frame is counted
and timed.
"""

from __future__ import annotations

import time
from typing import Protocol

import numpy as np

from explorer.app import model as M
from explorer.app.difference import PENDING, HeatMap, advice_lines
from explorer.app.handledrag import HandleDragger
from explorer.app.litsphere import SphereDrag
from explorer.app.pixellayer import PixelLayer
from explorer.app.view import LOD_TARGET, LOD_VERTICES, SceneView, view_camera
from explorer.render.images import encode_png
from explorer.render.vtk import DRAW_LOCK


class Pictures(Protocol):
    """What a front end gives its :class:`PlotterView`: ``send()`` a new picture to the person
    (drawn now, or pushed to the page); ``show_controls(state)`` the controls show ``state``;
    ``show_legend(legend, advice)`` the difference view's legend and advice (both "" when the
    difference is off); ``after_frame()`` after each frame of the view (side B is drawn and
    the frame counted before it)."""

    def send(self) -> None: ...

    def show_controls(self, state: M.State) -> None: ...

    def show_legend(self, legend: str, advice: str) -> None: ...

    def after_frame(self) -> None: ...


def controls_changed(old: M.State, new: M.State) -> bool:
    """Whether the controls show something new from ``old`` to ``new``: anything but the camera
    (and the viewer, which is the camera) changed, or the preset's material was replaced."""
    viewer = old.scene.replace(viewer=new.scene.viewer)
    return (
        old.replace(camera=None, scene=viewer) != new.replace(camera=None)
        or new.preset_material is not old.preset_material
    )


class PlotterView:
    """The view port over ``plotter`` (a PyVista plotter), with ``pictures`` the front end's
    :class:`Pictures`. Made before the controller (which asks the view's :meth:`aspect` to frame
    its start), then :meth:`attach`-ed to it. ``fixed_aspect``: the aspect :meth:`aspect`
    gives instead of the plotter's (a window not shown yet has no size of its own)."""

    def __init__(self, plotter, pictures: Pictures, *, fixed_aspect: float | None = None):
        self.plotter = plotter
        self.pictures = pictures
        self.fixed_aspect = fixed_aspect
        self.heat = HeatMap(plotter.renderer)
        self.controller = None
        self.view: SceneView | None = None
        self.side_b = None  # an explorer.app.sides.SideB, when the front end has a pane B
        self.handles: HandleDragger | None = None
        self.pixels: PixelLayer | None = None  # the per-pixel picture (shading: per-pixel)
        self.frames = 0
        self.frame_ms = float("nan")  # from the change (or redraw) to its frame's end
        self._t0: float | None = None
        self._mesh: str | None = None
        self._observers: list = []  # (VTK object, tag) of every observer :meth:`observe` added

    def attach(
        self,
        controller,
        mesh,
        *,
        side_b=None,
        lod_vertices: int = LOD_VERTICES,
        lod_target: int = LOD_TARGET,
    ) -> SceneView:
        """Draw ``controller``'s state (``mesh`` the mesh it names) with its camera, the light
        handles (dragged as :meth:`begin_drag` / :meth:`end_drag` say), side B ``side_b`` (an
        :class:`~explorer.app.sides.SideB`), and watch the frames. Returns the scene drawn."""
        self.controller = controller
        state = controller.state
        self.view = SceneView(
            self.plotter, mesh, state, lod_vertices=lod_vertices, lod_target=lod_target
        )
        self._mesh = state.mesh
        self.view.apply_camera(state.camera)
        self.handles = HandleDragger(self)
        self.sphere_drag = SphereDrag(self)  # (the lobe inset's lit sphere)
        self.pixels = PixelLayer(self.view)
        window = self.plotter.render_window  # (before VTK makes its context current)
        self.observe(window, "StartEvent", self._pixels_before, "per-pixel view")
        self.observe(self.plotter.renderer, "StartEvent", self._before_frame, "frame")
        self.observe(window, "EndEvent", self._after_frame, "frame")
        self.side_b = side_b
        return self.view

    def show_start(self, state: M.State) -> None:
        """The start shown whole (after :meth:`attach` and the controller's start): side B (a
        session may start in the compare view) and the controls."""
        if self.side_b is not None:
            self.side_b.show(None, state)
        self.pictures.show_controls(state)

    # -- errors and drags (the handles' dragger and the front ends' widgets call these) ---------
    def guard(self, fn, where: str):
        """``fn`` made safe for the toolkit's, trame's and VTK's callbacks: an error is said and
        logged (:meth:`Controller.report`), never lost and never a traceback in the user's
        face."""

        def call(*args, **kw):
            try:
                return fn(*args, **kw)
            except Exception as exc:  # noqa: BLE001 - every error is shown, none is lost
                self.controller.report(exc, where)
                return None

        return call

    def observe(self, obj, event: str, fn, where: str, priority: float = 0.0) -> int:
        """``fn`` (made safe: :meth:`guard`) observes VTK's ``event`` on ``obj`` until
        :meth:`close`; returns the observer's tag. Every observer of the view port and its
        parts is added here, so that :meth:`close` removes them all."""
        tag = obj.AddObserver(event, self.guard(fn, where), priority)
        self._observers.append((obj, tag))
        return tag

    def close(self) -> None:
        """The view port's end (its front end closes): every observer :meth:`observe` added is
        removed, the handles and the per-pixel quads of both sides let go of VTK
        (:meth:`SceneView.release_handles`, :meth:`PixelLayer.release`), then side B's plotter
        and this one are closed (under ``DRAW_LOCK``: no other thread draws meanwhile).

        A Python callback given to VTK is held by a C++ command the garbage collector does not
        see: one left would keep this view port, its controller and its front end (a closed
        window, its engine and its VTK view) alive for the rest of the process."""
        for obj, tag in self._observers:
            obj.RemoveObserver(tag)
        self._observers.clear()
        b = self.side_b
        for part in (self, b) if b is not None else (self,):
            if part.view is not None:
                part.view.release_handles()
            if part.pixels is not None:
                part.pixels.release()
        with DRAW_LOCK:
            if b is not None:
                b.close()
            self.plotter.close()

    def watch_drags(self, plotter) -> None:
        """``plotter``'s camera drags are drags (:meth:`begin_drag`, :meth:`end_drag`: the level
        of detail; in per-pixel mode the drag fallback): its interactor's style starts and ends
        each camera interaction (Qt's mouse, or the page's pointer passed on by its remote
        view). Side A's plotter and side B's are watched alike."""
        style = plotter.iren.interactor.GetInteractorStyle()
        if style is not None:
            self.observe(style, "StartInteractionEvent", self.begin_drag, "camera")
            self.observe(style, "EndInteractionEvent", self.end_drag, "camera")

    def begin_drag(self, *_) -> None:
        """A drag starts (a slider, the camera, a handle): the level of detail is drawn, and
        the difference waits for the end."""
        self.view.begin_drag()
        self.controller.begin_drag()

    def end_drag(self, *_) -> None:
        self.view.end_drag()
        self.controller.end_drag()

    def let_go(self, *_) -> None:
        """A control let go: the drag it began ends, or (a click, a key: no drag) its steps so
        far are one undo step."""
        if self.dragging():
            self.end_drag()
        else:
            self.controller.release()

    # -- the View port ---------------------------------------------------------------------------
    def show(self, old: M.State | None, new: M.State) -> None:
        """One change drawn: the mesh (switched, or one engine update and one upload), side B,
        the camera when it did not come from the view, the controls unless only the camera
        moved. ``old`` None: a value was refused; the controls show the state again."""
        if self._t0 is None:
            self._t0 = time.perf_counter()
        if old is None:
            self.pictures.show_controls(new)
            return
        if self.view is None:
            return
        if new.mesh != self._mesh:
            self.view.set_mesh(self.controller.meshes[new.mesh], new)
            self._mesh = new.mesh
        else:
            self.view.show_state(new)
        if self.side_b is not None:
            self.side_b.show(old, new)
        if new.camera is not None and not self.controller.in_frame:
            if view_camera(self.plotter.camera, new.centre, new.radius) != new.camera:
                self.view.apply_camera(new.camera)
        if controls_changed(old, new):
            self.pictures.show_controls(new)

    def redraw(self) -> None:
        """A new picture, sent as the front end sends one (side B's follows side A's frame)."""
        if self._t0 is None:
            self._t0 = time.perf_counter()
        self.pictures.send()

    def size(self) -> tuple[int, int]:
        w, h = self.plotter.window_size
        return int(w), int(h)

    def aspect(self) -> float:
        if self.fixed_aspect is not None:
            return self.fixed_aspect
        w, h = self.size()
        return w / max(h, 1)

    def background(self) -> tuple[float, float, float]:
        return tuple(self.plotter.renderer.GetBackground())

    def colors(self) -> np.ndarray:
        return self.view.drawings[0].colors()

    def dragging(self) -> bool:
        return self.view is not None and self.view.dragging > 0

    def show_difference(self, result, *, on: bool) -> None:
        """The heat map of ``result`` in place of the mesh, or the live view (``result`` None:
        the map is being computed, the legend says so), or the plain view (``on`` False)."""
        current = on and result is not None
        if current and self.heat.result is not result:
            self.heat.set(result)
        self.heat.show(current)
        if self.view is not None:
            self.view.show_mesh(not current)
        legend = "" if not on else (self.heat.legend() if current else PENDING)
        self.pictures.show_legend(legend, advice_lines(result.advice) if current else "")

    def png(self) -> bytes:
        """The view as drawn now (a frame is drawn first), PNG-encoded; in the compare view
        with side B as the front end shows it beside (:meth:`SideB.beside`)."""
        self.plotter.render_window.Render()
        img = np.ascontiguousarray(self.plotter.screenshot(return_img=True)[:, :, :3])
        if self.side_b is not None:
            img = self.side_b.beside(img)
        return encode_png(np.ascontiguousarray(img))

    # -- what a test or a script reads ----------------------------------------------------------
    def report(self, at=None) -> dict:
        """What either front end reports of its view (plain JSON values): the frames drawn and
        the last change's time to its frame's end (ms; None before one), the mesh's vertices,
        the probe vertex and its pixel, each light handle's pixel, undo and redo, the errors
        said, the difference view, whether a drag is under way, and the per-pixel picture
        (its pictures made, whether a drag draws per vertex now, the last per-pixel picture's
        and per-vertex frame's times in ms, None before one, the frames drawn per vertex, the
        camera drags decided and the last one's decision: ``drag``, the two times it compared,
        unrounded, and whether it fell back, None before one). ``at``: a pixel of the view
        (origin top-left) -> the pixel the front end reports (the window's own; default the
        view's)."""
        c, view = self.controller, self.view
        s = c.state

        def px(world):
            p = view.world_to_window(world)
            return p if at is None else at(p)

        def ms(v: float):
            return None if np.isnan(v) else round(float(v), 2)

        probe = view.probe_vertex()
        p = self.pixels
        drag = None
        if p.drag_decision is not None:
            pixel_ms, vertex_ms, fallback = p.drag_decision
            drag = {
                "ms": None if np.isnan(pixel_ms) else float(pixel_ms),
                "vertex_ms": None if np.isnan(vertex_ms) else float(vertex_ms),
                "fallback": bool(fallback),
            }
        return {
            "frame": self.frames,
            "frame_ms": None if np.isnan(self.frame_ms) else self.frame_ms,
            "n_vertices": view.mesh.n_vertices,
            "probe": {"vertex": probe, "px": px(view.mesh.positions[probe])},
            "handles_px": [px(M.handle_point(s, i)) for i in range(len(s.scene.lights))],
            "can_undo": c.store.can_undo,
            "can_redo": c.store.can_redo,
            "errors": list(c.errors),
            "difference": self.heat.state(),
            "dragging": self.dragging(),
            "pixels": {
                "frames": p.frames,
                "fallback": p.fallback,
                "ms": ms(p.ms),
                "vertex_ms": ms(p.vertex_ms),
                "vertex_frames": p.vertex_frames,
                "drags": p.drags,
                "drag": drag,
            },
        }

    # -- frames ----------------------------------------------------------------------------------
    def _pixels_before(self, *_) -> None:
        """The render window's StartEvent: in per-pixel mode the picture for the camera VTK
        draws with (:meth:`PixelLayer.before`), side B's (:meth:`SideB.before_a_frame`); a drag
        that falls back to per vertex says so."""
        if self._t0 is None:  # (a camera frame: its time starts here, its picture's too)
            self._t0 = time.perf_counter()
        was = self.pixels.fallback
        self.pixels.before(self.controller.state)
        state = self.controller.state  # the term strip's tiles per pixel as the view is drawn
        per_pixel = self.pixels.wanted(state) and not self.pixels.fallback
        self.view.strip.before_pixels(state, per_pixel, self.view.mesh)
        if self.side_b is not None:  # (side B's work is not side A's frame time)
            t0 = time.perf_counter()
            self.side_b.before_a_frame(self.controller.state)
            self.pixels.set_aside(time.perf_counter() - t0)
        if self.pixels.fallback and not was:
            p = self.pixels
            self.controller.say(
                f"camera drag drawn per vertex: a per-pixel frame takes {p.ms:.0f} ms, a "
                f"per-vertex one {p.vertex_ms:.0f} ms; per pixel again on release",
                open_log=False,
            )

    def _before_frame(self, *_) -> None:
        """The renderer's StartEvent: the camera is the viewer, it goes into the state (no undo
        step); translucent triangles sorted, the inset and the handles' ring laid out."""
        if self._t0 is None:
            self._t0 = time.perf_counter()
        self.view.frame_camera(self.controller.state, self.controller.camera_moved)

    def _after_frame(self, *_) -> None:
        """The render window's EndEvent: the frame counted and timed, side B follows (the same
        camera), then the front end's own step."""
        self.frames += 1
        self.pixels.after()
        if self.side_b is not None:
            self.side_b.after_frame()
        if self._t0 is not None:
            self.frame_ms = 1000.0 * (time.perf_counter() - self._t0)
            self._t0 = None
        self.pictures.after_frame()
