"""The explorer window's extra panes (mix-ins of :class:`explorer.app.window.ExplorerWindow`).

:class:`DifferencePane`: the difference view's heat map, requested from the worker thread and
shown only when it matches the view. :class:`ComparePane`: the A / B compare view, side B's
pane beside the 3D view, with the same
camera (one ``vtkCamera`` for both), the same lights and mesh, and side B's material and model;
or, as "A − B", the difference of the two sides' colours per vertex, largest channel in 1/255
levels, in the difference view's colours (interpolated across each triangle, like the colours).
"""

from __future__ import annotations

import numpy as np

from explorer.app import model as M
from explorer.app.commands import ViewKeys
from explorer.app.difference import PENDING, Job, advice_lines
from explorer.app.view import SceneView, view_camera
from explorer.render.vtk import plain_blending
from explorer.shading.display import to_bytes


class ComparePane:
    """Side B (needs the window's ``views`` splitter, ``plotter``, ``view``, ``render``,
    ``_guard``, ``_begin_drag`` and ``_end_drag``)."""

    def _make_side_b(self, state: M.State) -> None:
        from pyvistaqt import QtInteractor

        pl = QtInteractor(self.views, multi_samples=0, auto_update=False)
        pl.setObjectName("view_b")
        pl.setMinimumSize(120, 150)
        pl.disable_anti_aliasing()
        plain_blending(pl.renderer)
        pl.set_background(self.plotter.renderer.GetBackground())
        self.views.addWidget(pl)
        # linked cameras: one vtkCamera, A's, which PyVista's ``camera`` names too (after
        # SetActiveCamera alone it named B's own unused camera, and B's translucent triangles
        # were sorted for that one)
        pl.renderer.camera = self.plotter.renderer.camera
        pl.camera_set = True
        self.plotter_b = pl
        self.view_b = SceneView(pl, self.view.mesh, M.side_b(state),
                                lod_vertices=self.view.lod_vertices,
                                lod_target=self.view.lod_target)  # fmt: skip
        pl.installEventFilter(ViewKeys(self))
        for key in list(getattr(pl, "_key_press_event_callbacks", {})):
            pl.clear_events_for_key(key)
        style = pl.iren.interactor.GetInteractorStyle()
        if style is not None:
            style.AddObserver("StartInteractionEvent", self._guard(self._begin_drag, "camera"))
            style.AddObserver("EndInteractionEvent", self._guard(self._end_drag, "camera"))

        def draw_a(*_):  # B's camera is A's: a frame of B draws A too (and A records it)
            if not self._syncing:
                self._syncing = True
                try:
                    self.render()
                finally:
                    self._syncing = False

        pl.render_window.AddObserver("EndEvent", self._guard(draw_a, "compare"))

        def before_frame(*_):
            s = self.store.state
            self.view_b.before_frame(view_camera(pl.camera, s.centre, s.radius))

        pl.renderer.AddObserver("StartEvent", self._guard(before_frame, "compare"))

    def _show_compare(self, old: M.State | None, new: M.State) -> None:
        """Side B's pane: made, shown, hidden, and given side B's state (or A − B)."""
        if new.compare is None:
            if self.plotter_b is not None:
                self.plotter_b.hide()
            self.view.set_caption("")
            return
        if self.view_b is None:
            self._make_side_b(new)
        b = M.side_b(new)
        if self.view_b.mesh is not self.view.mesh:
            self.view_b.set_mesh(self.view.mesh, b)
        else:
            self.view_b.show_state(b)
        if new.compare_difference:
            a = self.view.displayed_colors().astype(np.int16)
            other = to_bytes(self.view_b.drawings[0].colors()).astype(np.int16)
            self.view_b.paint_levels(np.abs(a - other).max(axis=1))
        elif old is not None and old.compare_difference:
            self.view_b.drawings[0].upload()
        self.view.set_caption(f"A: {new.preset or 'scene material'} ({new.scene.model})")
        self.view_b.set_caption("A − B (levels, as the difference view)" if new.compare_difference
                                else f"B: {new.compare_preset or 'material'} "
                                f"({new.compare_model})")  # fmt: skip
        if not self.plotter_b.isVisible():
            self.plotter_b.show()
            half = max(self.views.width() // 2, 1)
            self.views.setSizes([half, half])


class DifferencePane:
    """The difference view (needs the window's ``store``, ``plotter``, ``view``, ``heat``,
    ``worker``, ``panel``, ``act`` and ``render``)."""

    # -- the difference view --------------------------------------------------------------------
    def _difference_key(self) -> tuple:
        s = self.store.state
        return (repr(s.shown_scene()), repr(s.shown_groups()), s.mesh, s.camera,
                tuple(self.plotter.window_size))  # fmt: skip

    def _update_difference(self) -> None:
        """The heat map when it matches the view; else the live view, and a request for the
        map unless something is being dragged (then it waits for the release)."""
        s = self.store.state
        legend, advice = self.panel.view.legend, self.panel.view.advice
        if not s.difference:
            self.worker.cancel()
            self._requested = None
            self.heat.show(False)
            self.view.show_mesh(True)
            return
        key = self._difference_key()
        current = self.heat.result is not None and self.heat.result.job.key == key
        self.heat.show(current)
        self.view.show_mesh(not current)
        legend.setText(self.heat.legend() if current else PENDING)
        advice.setText(advice_lines(self.heat.result.advice) if current else "")
        size = tuple(int(v) for v in self.plotter.window_size)
        if current or self.view.dragging or key == self._requested or min(size) < 16:
            return  # (a view not laid out yet asks at its first frame)
        self._requested = key
        self.worker.submit(Job(
            key, s.shown_scene(), self.view.mesh, self.view.drawings[0].colors().copy(),
            s.camera, size,
            tuple(self.plotter.renderer.GetBackground()), s.shown_groups(),
        ))  # fmt: skip

    def _on_difference(self, result) -> None:
        """A comparison is done (in the GUI thread now): shown if it is still the view's."""
        if result.error is not None:
            self._requested = None
            self.act(M.set_difference, False, label="difference")
            raise result.error
        if result.job.key != self._difference_key():
            return  # stale: a newer request is on its way
        self.heat.set(result)
        self._update_difference()
        self.render()
