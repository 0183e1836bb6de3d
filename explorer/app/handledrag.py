"""Dragging the light handles with the mouse, for either front end (the Qt window and the web
page: no toolkit here, only the VTK interactor's event positions): a press on a handle selects
its light, a drag keeps the handle under the pointer (:func:`explorer.app.model.point_on_ray`),
whatever the camera's distance and zoom."""

from __future__ import annotations

import numpy as np

from explorer.app import model as M


class HandleDragger:
    """The handles of ``window`` (an :class:`explorer.app.viewport.PlotterView`: its
    ``controller``, ``plotter``, ``view``, ``begin_drag``, ``end_drag`` and ``guard``), or of
    another pane of it (``plotter`` and ``view``: the compare view's side B, which shows the
    same lights): :meth:`_grab_handle`,
    :meth:`_drag_handle` and :meth:`_release_handle` are the handles' callbacks
    (:meth:`explorer.app.view.SceneView.add_handles`)."""

    def __init__(self, window, plotter=None, view=None):
        self.window = w = window
        self.store = w.controller.store
        self.act = w.controller.act
        self.plotter = w.plotter if plotter is None else plotter
        self.view = w.view if view is None else view
        self._grab = None
        self._holding_handle = False
        self._begin_drag, self._end_drag = w.begin_drag, w.end_drag
        g = w.guard
        self.view.add_handles(g(self._grab_handle, "light handle"),
                           g(self._drag_handle, "light handle"),
                           g(self._release_handle, "light handle"))  # fmt: skip

    def _grab_handle(self, index: int) -> None:
        """Light ``index``'s handle is pressed: its light is selected, and the drag starts
        with the pointer's offset from the handle's centre (kept to the end, so the handle
        does not jump) and the side of the mesh centre it is on (see :func:`M.point_on_ray`)."""
        if index != self.store.state.light:
            self.act(M.select_light, index, label="select light")
        s = self.store.state
        x, y = self._pointer()
        hx, hy, _ = self.view.handle_pixels()[index]
        origin, direction = self._pointer_ray(hx, hy)
        to_view = self.view.to_view
        near = float((to_view(M.handle_point(s)) - origin) @ direction) <= float(
            (to_view(s.centre) - origin) @ direction)  # fmt: skip
        self._grab = (hx - x, hy - y, near, (x, y))  # the last pointer position handled
        self._holding_handle = True
        self._begin_drag()

    def _drag_handle(self, index: int) -> None:
        """Handle ``index`` dragged: the light goes where the pointer is (on the pointer's ray,
        at the light's distance from the mesh centre), so the handle stays under the pointer
        (VTK's sphere widget moves its sphere at the focal point's depth, not the handle's:
        ahead of the pointer when the handle is nearer than the focal point)."""
        s = self.store.state
        if s.selected_light is None or index != s.light or self._grab is None:
            return
        dx, dy, near, _ = self._grab
        x, y = self._pointer()
        self._grab = (dx, dy, near, (x, y))
        origin, direction = self._pointer_ray(x + dx, y + dy)
        d = s.placement()[2] / self.view.frame[1]  # in the view's frame: any mesh scale
        at = M.point_on_ray(origin, direction, self.view.to_view(s.centre), d, near)
        self._on_handle(self.view.from_view(at))

    def _release_handle(self, index: int) -> None:
        """The handle let go: the release's position is the drag's last step (a front end may
        drop moves while the view is busy, as the web page's does: the handle still ends under
        the pointer), then the drag ends."""
        if self._grab is not None and self._pointer() != self._grab[3]:  # a click moves nothing
            self._drag_handle(index)
        self._grab = None
        self._holding_handle = False
        self._end_drag()

    def _pointer(self) -> tuple[int, int]:
        """The pointer's display pixel of the event being handled (origin bottom-left)."""
        x, y = self.plotter.iren.interactor.GetEventPosition()
        return int(x), int(y)

    def _pointer_ray(self, x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
        """The ray under display pixel ``(x, y)`` (origin bottom-left): its start on the near
        clipping plane and its unit direction, each (3,), in the coordinates VTK draws in
        (the view's frame: :meth:`explorer.app.view.SceneView.to_view`)."""
        ren = self.plotter.renderer
        ends = []
        for z in (0.0, 1.0):
            ren.SetDisplayPoint(float(x), float(y), z)
            ren.DisplayToWorld()
            p = np.asarray(ren.GetWorldPoint(), np.float64)
            ends.append(p[:3] / p[3])
        u = ends[1] - ends[0]
        return ends[0], u / max(float(np.linalg.norm(u)), 1e-300)

    def _on_handle(self, centre) -> None:
        """Move the selected light to where its handle is put (``centre`` (3,), world)."""
        s = self.store.state
        if s.selected_light is None:
            return
        az, el, d = M.angles_from_point(s, centre)
        if d > 0:
            self.act(M.place_light, az, el, d, label="light handle", merge="handle")
