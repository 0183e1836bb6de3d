"""Fixtures of the window tests: a private Xvfb server for Qt (its xcb platform is the only
one that hosts the VTK view, so in-process widget tests need an X server too)."""

from __future__ import annotations

import os
import shutil
import sys

import pytest
from helpers.processes import end_process

from explorer.app.start import start_xvfb

#: the private server's screen: room for the largest window size tested (1920x1080)
SCREEN = (1920, 1200)


def pytest_collection_modifyitems(session, config, items):
    """The in-process Qt tests run last: after a Qt window has existed in the process, VTK's
    off-screen pictures of translucent meshes no longer match between a reused and a fresh
    window (tests/render/test_render.py::test_reused_window_matches_fresh_one), so the other
    tests run before any Qt window is made. Every module of ``tests/app/qt`` runs last (a list
    of the modules that open windows missed a new one, test_window_strip, and 20 off-screen
    tests after it drew blank or failed)."""
    qt = [i for i in items if i.path.parent.name == "qt" and i.path.parent.parent.name == "app"]
    if qt:
        rest = [i for i in items if i not in set(qt)]
        items[:] = rest + qt


@pytest.fixture(scope="session")
def xserver():
    """One Xvfb for the session's in-process Qt tests, ended and waited for at the session's
    end (tests/conftest.py's ``no_child_left``) after the process's X clients are closed
    (:func:`close_x_clients`: Qt and VTK keep their connections until then, and an X server
    gone under one ended the process with exit status 1). Left running, its Popen warned at
    the process's end: "ResourceWarning: subprocess N is still running"."""
    if sys.platform in ("darwin", "win32") or shutil.which("Xvfb") is None:
        pytest.skip("needs Xvfb for the Qt window (apt-get install -y xvfb)")
    pytest.importorskip("PySide6")
    pytest.importorskip("pyvistaqt")
    proc, display = start_xvfb(size=SCREEN)
    yield display
    close_x_clients()
    end_process(proc)


def close_x_clients() -> None:
    """Close this process's connections to the X server before it ends: every PyVista
    plotter's render window (the Qt views' and the off-screen ones made under DISPLAY), every
    Qt window, then the QApplication (PySide6's ``shutdown``). A server ended while one is
    open ends the process at its next X request ("XIO: fatal IO error", "The X11 connection
    broke"; Xlib and Qt exit 1)."""
    if "pyvista" in sys.modules:
        import pyvista

        pyvista.close_all()
    if "PySide6.QtWidgets" in sys.modules:
        from PySide6 import QtCore, QtWidgets

        app = QtWidgets.QApplication.instance()
        if app is not None:
            for w in app.topLevelWidgets():
                w.close()
                w.deleteLater()
            app.sendPostedEvents(None, QtCore.QEvent.Type.DeferredDelete)
            app.processEvents()
            app.shutdown()


@pytest.fixture
def xdisplay(xserver, monkeypatch):
    """DISPLAY and Qt's xcb platform for one test (VTK's window class left to VTK)."""
    monkeypatch.setenv("DISPLAY", xserver)
    monkeypatch.setenv("QT_QPA_PLATFORM", "xcb")
    monkeypatch.delenv("VTK_DEFAULT_OPENGL_WINDOW", raising=False)
    return xserver


@pytest.fixture(scope="session")
def qapp(xserver):
    """pytest-qt's QApplication, made on the private Xvfb (a session fixture is made before
    any test's own fixtures, so the display is given here). The environment is restored
    afterwards: Qt keeps its connection, and later tests see the machine's own."""
    saved = {k: os.environ.get(k) for k in ("DISPLAY", "QT_QPA_PLATFORM")}
    os.environ.update(DISPLAY=xserver, QT_QPA_PLATFORM="xcb")
    try:
        from PySide6 import QtWidgets

        app = QtWidgets.QApplication.instance() or QtWidgets.QApplication(["pytest-qt"])
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    yield app


@pytest.fixture
def open_window(xdisplay, qtbot, tmp_path, monkeypatch):
    """``open_window(*gui_args, size=(1000, 700))``: the explorer window (default: ``gui
    --mesh icosphere --resolution 3``), shown at ``size`` and drawn once; presets are saved in
    ``tmp_path/presets``, screenshots and the ``--state-file`` go to ``tmp_path``, and the
    last session is kept in ``tmp_path/last.yaml``."""
    from explorer.app.qt.window import ExplorerWindow
    from explorer.cli import build_parser
    from explorer.cli.gui import start_state

    monkeypatch.setenv("PHONG_EXPLORER_MATERIALS", str(tmp_path / "presets"))

    def make(*argv, size=(1000, 700)):
        argv = argv or ("--mesh", "icosphere", "--resolution", "3")
        warnings: list[str] = []  # as `gui` starts it: the start mesh's warnings in the log
        state, mesh = start_state(build_parser().parse_args(["gui", *argv]), warnings)
        w = ExplorerWindow(
            state,
            mesh,
            output_dir=tmp_path,
            state_file=tmp_path / "state.json",
            last_session=tmp_path / "last.yaml",
            size=size,
            start_warnings=tuple(warnings),
        )
        qtbot.addWidget(w)
        w.show()
        qtbot.waitExposed(w)
        w.render()
        return w

    return make


@pytest.fixture
def win(open_window):
    """The default window; the test fails if any error was shown and not cleared."""
    w = open_window()
    yield w
    assert not w.controller.errors, w.controller.errors
