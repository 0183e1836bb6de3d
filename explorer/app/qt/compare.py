"""The A / B compare view's pane in the Qt window (the :class:`~explorer.app.sides.Pane` of
:class:`~explorer.app.sides.SideB`): side B's ``QtInteractor`` beside the 3D view in the views
splitter, with the window's keys and camera drags, the light handles drawn and dragged in both
panes; a frame of either pane draws the other (one camera)."""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore

from explorer.app.qt.menus import ViewKeys
from explorer.render.images import side_by_side
from explorer.render.vtk import draw_as_the_engine


class CompareView:
    """Side B's pane in ``window`` (its ``views`` splitter, ``plotter``, ``render``,
    ``_guard`` and ``watch_camera``); sets ``window.plotter_b`` and ``window.view_b`` when
    side B is first shown."""

    handles = True  # B's handles are drawn and dragged too

    def __init__(self, window):
        self.w = window
        window.plotter_b = window.view_b = None
        self._syncing = False

    def make_plotter(self):
        from pyvistaqt import QtInteractor

        w = self.w
        pl = QtInteractor(w.views, multi_samples=0, auto_update=False)
        draw_as_the_engine(pl, w.plotter.renderer.GetBackground())  # as side A's
        pl.setObjectName("view_b")
        pl.setMinimumSize(120, 150)
        w.views.addWidget(pl)
        w.plotter_b = pl
        return pl

    def made(self, pl, view) -> None:
        """Side B's keys and camera drags as the view's; a frame of B draws A too."""
        w = self.w
        w.view_b = view
        pl.installEventFilter(ViewKeys(w))
        w.watch_camera(pl)

        def draw_a(*_):  # B's camera is A's: a frame of B draws A too (and A records it)
            if not self._syncing:
                self._syncing = True
                try:
                    w.render()
                finally:
                    self._syncing = False

        w.viewport.observe(pl.render_window, "EndEvent", draw_a, "compare")

    def show_pane(self, visible: bool) -> None:
        """Side B's pane shown (half the views' width, when it appears) or hidden."""
        w = self.w
        if not visible:
            w.plotter_b.hide()
        elif not w.plotter_b.isVisible():
            w.plotter_b.show()
            half = max(w.views.width() // 2, 1)
            w.views.setSizes([half, half])

    def follow(self) -> None:
        """After a frame of side A: side B drawn too (same camera)."""
        pl = self.w.plotter_b
        if pl.isVisible() and not self._syncing:
            self._syncing = True
            try:
                pl.render_window.Render()
            finally:
                self._syncing = False

    def beside(self, img: np.ndarray) -> np.ndarray:
        """``img`` (h, w, 3), side A's pixels, with side B's beside it when B is shown (the
        gap between them in the splitter's place and colour)."""
        w = self.w
        pl_b = w.plotter_b
        if not pl_b.isVisible():
            return img
        pl_b.render_window.Render()  # drawn at its present size before it is read
        b = pl_b.screenshot(return_img=True)[:, :, :3]
        a_x = w.plotter.mapTo(w, QtCore.QPoint(0, 0)).x()
        gap = max(pl_b.mapTo(w, QtCore.QPoint(0, 0)).x() - a_x - img.shape[1], 0)
        fill = w.views.palette().window().color().getRgb()[:3]  # the splitter's
        return side_by_side(img, b, gap, fill)
