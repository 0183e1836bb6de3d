"""The A / B compare view of the Qt window: side B's pane beside the 3D view, with the same
camera (one ``vtkCamera`` for both), the same lights (their handles drawn and dragged in both
panes) and mesh, and side B's material and model;
or, as "A − B", the difference of the two sides' colours per vertex, largest channel in 1/255
levels, in the difference view's colours (interpolated across each triangle, like the colours).
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore

from explorer.app import model as M
from explorer.app.handledrag import HandleDragger
from explorer.app.qt.menus import ViewKeys
from explorer.app.sides import show_side_b
from explorer.app.view import SceneView, view_camera
from explorer.render.images import side_by_side
from explorer.render.vtk import plain_blending


class CompareView:
    """Side B of ``window`` (its ``views`` splitter, ``plotter``, ``view``, ``render``,
    ``controller``, ``_guard`` and ``watch_camera``); sets ``window.plotter_b`` and
    ``window.view_b`` when first shown."""

    def __init__(self, window):
        self.w = window
        window.plotter_b = window.view_b = None
        self._syncing = False

    def _make_side_b(self, state: M.State) -> None:
        from pyvistaqt import QtInteractor

        w = self.w
        pl = QtInteractor(w.views, multi_samples=0, auto_update=False)
        pl.setObjectName("view_b")
        pl.setMinimumSize(120, 150)
        pl.disable_anti_aliasing()
        plain_blending(pl.renderer)
        pl.set_background(w.plotter.renderer.GetBackground())
        w.views.addWidget(pl)
        # linked cameras: one vtkCamera, A's, which PyVista's ``camera`` names too (after
        # SetActiveCamera alone it named B's own unused camera, and B's translucent triangles
        # were sorted for that one)
        pl.renderer.camera = w.plotter.renderer.camera
        pl.camera_set = True
        w.plotter_b = pl
        w.view_b = SceneView(pl, w.view.mesh, M.side_b(state), lod_vertices=w.view.lod_vertices,
                             lod_target=w.view.lod_target)  # fmt: skip
        pl.installEventFilter(ViewKeys(w))
        w.watch_camera(pl)
        self.handles = HandleDragger(w, pl, w.view_b)  # the lights are shared: B's move them too

        def draw_a(*_):  # B's camera is A's: a frame of B draws A too (and A records it)
            if not self._syncing:
                self._syncing = True
                try:
                    w.render()
                finally:
                    self._syncing = False

        pl.render_window.AddObserver("EndEvent", w._guard(draw_a, "compare"))

        def before_frame(*_):
            s = w.controller.state
            w.view_b.before_frame(view_camera(pl.camera, s.centre, s.radius))

        pl.renderer.AddObserver("StartEvent", w._guard(before_frame, "compare"))

    def after_frame(self) -> None:
        """After a frame of side A: side B drawn too (same camera)."""
        pl = self.w.plotter_b
        if pl is not None and pl.isVisible() and not self._syncing:
            self._syncing = True
            try:
                pl.render_window.Render()
            finally:
                self._syncing = False

    def show(self, old: M.State | None, new: M.State) -> None:
        """Side B's pane: made, shown, hidden, and given side B's state (or A − B)."""
        w = self.w
        if new.compare is None:
            if w.plotter_b is not None:
                w.plotter_b.hide()
            w.view.set_caption("")
            return
        if w.view_b is None:
            self._make_side_b(new)
        show_side_b(w.view, w.view_b, old, new)
        if not w.plotter_b.isVisible():
            w.plotter_b.show()
            half = max(w.views.width() // 2, 1)
            w.views.setSizes([half, half])

    def beside(self, img: np.ndarray) -> np.ndarray:
        """``img`` (h, w, 3), side A's pixels, with side B's beside it when B is shown (the
        gap between them in the splitter's place and colour)."""
        w = self.w
        pl_b = w.plotter_b
        if pl_b is None or not pl_b.isVisible():
            return img
        pl_b.render_window.Render()  # drawn at its present size before it is read
        b = pl_b.screenshot(return_img=True)[:, :, :3]
        a_x = w.plotter.mapTo(w, QtCore.QPoint(0, 0)).x()
        gap = max(pl_b.mapTo(w, QtCore.QPoint(0, 0)).x() - a_x - img.shape[1], 0)
        fill = w.views.palette().window().color().getRgb()[:3]  # the splitter's
        return side_by_side(img, b, gap, fill)
