"""The A / B compare view's pane in the web page (the :class:`~explorer.app.sides.Pane` of
:class:`~explorer.app.sides.SideB`, as :mod:`explorer.app.qt.compare` is the desktop's): side
B rendered on the server by a second off-screen plotter, shown by its own remote view; its
picture is sent after each of side A's frames.
"""

from __future__ import annotations

import numpy as np


class WebCompare:
    """Side B's pane of ``app`` (a :class:`~explorer.app.web.WebExplorer`: its ``plotter``,
    ``viewport``, ``server``, ``loop``, ``guard`` and ``_send``): :attr:`plotter` is made with
    the page (its remote view needs it). The page shows or hides side B's view itself (state
    ``compare``). Side B draws the light handles, the selected one's ring and the arrows at
    its edge toward handles out of it, as the window's pane B does: a drag on B's handle moves
    the light in both panes (the remote view passes the page's pointer to B's interactor)."""

    handles = True

    def __init__(self, app, size):
        from explorer.render.vtk import plotter  # VTK only once a server is made

        self.app = app
        self.plotter = plotter(size, app.plotter.renderer.GetBackground())

    def make_plotter(self):
        return self.plotter

    def made(self, plotter, view) -> None:
        """Side B's camera drags are drags too (one camera: B's drag moves A's)."""
        self.app.viewport.watch_drags(plotter)

    def show_pane(self, visible: bool) -> None:
        pass

    def follow(self) -> None:
        """Side B's picture sent after side A's (from the server's loop, once A's is sent)."""
        app = self.app
        if app.loop is not None:
            app.loop.call_soon(app.guard(app._send, "B"), app.server.controller.view_b_update,
                               self.plotter.render_window)  # fmt: skip

    def beside(self, img: np.ndarray) -> np.ndarray:
        """The page's PNG is side A's alone."""
        return img
