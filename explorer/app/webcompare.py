"""The web page's A / B compare view: side B's view beside side A's, rendered on the server by a
second off-screen plotter with the same camera (one ``vtkCamera`` for both), the same lights and
mesh, and side B's material and model, or A − B (:func:`explorer.app.sides.show_side_b`, as the
desktop's :mod:`explorer.app.qt.compare`).
"""

from __future__ import annotations

from explorer.app import model as M
from explorer.app.sides import show_side_b
from explorer.app.view import SceneView, view_camera


class WebCompare:
    """Side B of ``app`` (a :class:`~explorer.app.web.WebExplorer`: its ``plotter``, ``view``,
    ``controller``, ``server`` and ``guard``): :attr:`plotter` is made with the page (its remote
    view needs it), :attr:`view` when the compare view is first shown."""

    def __init__(self, app, size):
        from explorer.render.vtk import plotter  # VTK only once a server is made

        self.app = app
        self.plotter = plotter(size, app.plotter.renderer.GetBackground())
        self.plotter.renderer.camera = app.plotter.renderer.camera  # the camera is shared
        self.plotter.camera_set = True
        self.view: SceneView | None = None
        self.plotter.renderer.AddObserver("StartEvent", app.guard(self._before_frame, "B"))

    @property
    def shown(self) -> bool:
        return self.view is not None and self.app.controller.state.compare is not None

    def _before_frame(self, *_) -> None:
        if self.view is not None:
            s = self.app.controller.state
            self.view.before_frame(view_camera(self.plotter.camera, s.centre, s.radius))

    def show(self, old: M.State | None, new: M.State) -> None:
        """Side B given side B's state (or A − B); the captions say which side is which."""
        app = self.app
        if new.compare is None:
            app.view.set_caption("")
            return
        if self.view is None:
            self.view = SceneView(self.plotter, app.view.mesh, M.side_b(new))
        show_side_b(app.view, self.view, old, new)

    def probe(self) -> dict:
        """Side B's probe vertex and its pixel (origin top-left), its picture's size."""
        i = self.view.probe_vertex()
        return {"vertex": i, "px": self.view.world_to_window(self.view.mesh.positions[i]),
                "size": list(self.plotter.window_size)}  # fmt: skip
