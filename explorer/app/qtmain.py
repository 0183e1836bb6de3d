"""Opening the explorer window: the Qt application, the window, the event loop."""

from __future__ import annotations

import logging
import os
import sys

from PySide6 import QtCore, QtWidgets

from explorer.app.qt.window import ExplorerWindow
from explorer.app.start import NoDisplayError

log = logging.getLogger(__name__)


def application() -> QtWidgets.QApplication:
    """The process's QApplication (made once; Qt's xcb platform on Linux, which hosts VTK)."""
    if sys.platform.startswith("linux"):
        os.environ.setdefault("QT_QPA_PLATFORM", "xcb")
    app = QtWidgets.QApplication.instance()
    return app if app is not None else QtWidgets.QApplication(["phong-explorer"])


def run_window(state, mesh, *, exit_after: float | None = None, last_session=True,
               **options) -> int:  # fmt: skip
    """Open the window on ``state`` / ``mesh`` and run until it is closed (or for
    ``exit_after`` seconds); the session is kept for ``gui --last``. ``options`` go to
    :class:`~explorer.app.qt.window.ExplorerWindow`. Returns the exit status (0)."""
    app = application()
    window = ExplorerWindow(state, mesh, last_session=last_session, **options)
    name = window.plotter.render_window.GetClassName()
    if "OpenGL" not in name or "EGL" in name or "OSMesa" in name:
        window.close()
        raise NoDisplayError(f"VTK opened a {name}, which cannot show a window")
    window.show()
    window.plotter.setFocus()
    if exit_after is not None:

        def expire():
            log.warning("closing after %g s (--exit-after)", exit_after)
            window.close()

        QtCore.QTimer.singleShot(max(1, int(float(exit_after) * 1000)), expire)
    app.exec()
    return 0
