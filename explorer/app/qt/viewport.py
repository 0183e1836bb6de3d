"""The Qt window's :class:`~explorer.app.viewport.Pictures`: how the window's view port (an
:class:`~explorer.app.viewport.PlotterView` over the window's ``QtInteractor``) reaches the
person: a frame drawn in the window now, the controls and the status bar's summary, the
difference view's legend and advice in the panel; after each frame, the state file."""

from __future__ import annotations

import json

from explorer.app import captions
from explorer.app import model as M
from explorer.app.session import session_mapping
from explorer.core.atomic import write_atomic


class QtPictures:
    """The pictures of ``window`` (an :class:`explorer.app.qt.window.ExplorerWindow`: its
    ``plotter``, ``view``, ``panel``, ``status_label``, ``state_file``)."""

    def __init__(self, window):
        self.w = window

    def send(self) -> None:
        """Draw a frame now (Qt shows it)."""
        self.w.plotter.render_window.Render()

    def show_controls(self, state: M.State) -> None:
        """The controls and the status bar's summary (:func:`~explorer.app.captions.summary`)
        show ``state``."""
        w = self.w
        w.panel.show_state(state, w.view.mesh.n_vertices)
        w.status_label.setText(captions.summary(state))

    def show_legend(self, legend: str, advice: str) -> None:
        """The panel's legend and advice (hidden while the difference is off)."""
        self.w.panel.view.legend.setText(legend)
        self.w.panel.view.advice.setText(advice)

    def after_frame(self) -> None:
        """The state file written (after the frame, so a reader never races the pixels)."""
        w = self.w
        if w.state_file is not None:
            data = {**session_mapping(w.controller.state), "window": w.report_state()}
            write_atomic(w.state_file, json.dumps(data).encode(), overwrite=True)
