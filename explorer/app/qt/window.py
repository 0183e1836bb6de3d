"""The explorer window: a Qt main window with the 3D view (pyvistaqt's ``QtInteractor``)
beside the control panel (:mod:`explorer.app.qt.panel`), a thin binding of
:class:`explorer.app.controller.Controller`.

The window holds no state and no flow of its own: the controls send intents to the controller,
which changes the store and tells the window (its ports: :class:`ExplorerWindow` implements the
dialogs, messages, choices and progress ports; the view port is the
:class:`~explorer.app.viewport.PlotterView` both front ends share, over the window's
``QtInteractor``, drawing through :class:`~explorer.app.qt.viewport.QtPictures`) what to
show. The camera is the viewer: before each frame the view's camera goes into the state
(:meth:`Controller.camera_moved`, no undo step). The difference view is computed in a worker thread
(:class:`~explorer.app.difference.DifferenceWorker`) whose results come back through a Qt
signal to :meth:`Controller.on_difference`.

Menus, shortcuts and keys are in :mod:`explorer.app.qt.menus`.
"""

from __future__ import annotations

from pathlib import Path

from PySide6 import QtCore, QtGui, QtWidgets

from explorer.app import model as M
from explorer.app import panelmodel
from explorer.app.controller import Controller, Ports
from explorer.app.difference import DifferenceWorker
from explorer.app.qt.compare import CompareView
from explorer.app.qt.lightpanel import Panel
from explorer.app.qt.menus import Menus
from explorer.app.qt.messages import MessageBar
from explorer.app.qt.panel import ValueSlider
from explorer.app.qt.progress import EngineStatus, run_steps
from explorer.app.qt.viewport import QtPictures
from explorer.app.sides import SideB
from explorer.app.start import TITLE, WINDOW_SIZE
from explorer.app.view import LOD_TARGET, LOD_VERTICES
from explorer.app.viewport import PlotterView
from explorer.render.offscreen import BACKGROUND
from explorer.render.vtk import draw_as_the_engine

#: the panel's share of the window's width at the start (the view takes the rest)
PANEL_FRACTION = 0.34


class ExplorerWindow(QtWidgets.QMainWindow):
    """The explorer window.

    state, mesh : the start (``mesh`` is the mesh ``state.mesh`` names)
    materials_dirs, preset_dir, output_dir, last_session : see
        :class:`~explorer.app.controller.Controller`; state_file : write the session and a
        report as JSON after every frame
    size : (width, height) of the window; lod_vertices, lod_target : see
        :mod:`explorer.app.view`; background : RGB in [0, 1]; start_warnings : the warnings
        of the start mesh's materials (printed at the start; the message log lists them too)
    """

    difference_ready = QtCore.Signal(object)

    def __init__(self, state: M.State, mesh, *, materials_dirs=(), preset_dir=None,
                 output_dir=None, state_file=None, last_session=None, size=WINDOW_SIZE,
                 lod_vertices: int = LOD_VERTICES, lod_target: int = LOD_TARGET,
                 background=None, start_warnings=()):  # fmt: skip
        super().__init__()
        self.setWindowTitle(TITLE)
        self.state_file = Path(state_file) if state_file else None
        self.message = ""
        w, h = (int(v) for v in size)
        self.resize(w, h)
        self._build_views(w, background)
        aspect = max(w * (1 - PANEL_FRACTION), 1.0) / max(h - 60, 1.0)  # until it is shown
        self.viewport = PlotterView(self.plotter, QtPictures(self), fixed_aspect=aspect)
        self._frame_on_show = state.camera is None  # framed again for the view's real shape
        self.worker = DifferenceWorker(self.difference_ready.emit)
        ports = Ports.of(self, worker=self.worker, view=self.viewport)
        self.controller = c = Controller(state, mesh, ports, materials_dirs=materials_dirs,
                                         preset_dir=preset_dir, output_dir=output_dir,
                                         last_session=last_session)  # fmt: skip
        self.panel = Panel(c.files.choose_mesh, c.set_value)
        self.splitter.addWidget(self.panel)
        self.splitter.setSizes([round(w * (1 - PANEL_FRACTION)), round(w * PANEL_FRACTION)])
        self.bar = MessageBar(self)
        self.panel.rejected.connect(self._guard(c.reject_input, "typed value"))
        self.engine = EngineStatus(self)
        self.compare = CompareView(self)
        side_b = SideB(self.viewport, self.compare)
        self.view = self.viewport.attach(c, mesh, side_b=side_b, lod_vertices=lod_vertices,
                                         lod_target=lod_target)  # fmt: skip
        self.heat = self.viewport.heat
        self.difference_ready.connect(self._guard(c.on_difference, "difference view"))
        self._observe()
        self.menus = Menus(self)
        c.start()
        c.files.say_mesh_warnings(mesh.name, start_warnings, logged=True)  # printed at start too
        self.viewport.show_start(c.state)

    # -- building ------------------------------------------------------------------------------
    def _build_views(self, w: int, background) -> None:
        from pyvistaqt import QtInteractor

        self.splitter = QtWidgets.QSplitter(QtCore.Qt.Orientation.Horizontal)
        self.views = QtWidgets.QSplitter(QtCore.Qt.Orientation.Horizontal)
        self.views.setChildrenCollapsible(False)
        self.plotter = QtInteractor(self.views, multi_samples=0, auto_update=False)
        # the engine's colours, translucency drawn as the off-screen renders draw it
        draw_as_the_engine(self.plotter, BACKGROUND if background is None else background)
        self.plotter.setObjectName("view")
        self.plotter.setMinimumSize(120, 120)
        self.plotter.setFocusPolicy(QtCore.Qt.FocusPolicy.StrongFocus)
        self.views.addWidget(self.plotter)
        self.splitter.addWidget(self.views)
        self.splitter.setStretchFactor(0, 1)
        self.splitter.setStretchFactor(1, 0)
        self.splitter.setChildrenCollapsible(False)
        self.setCentralWidget(self.splitter)

    def _observe(self) -> None:
        self.watch_camera(self.plotter)
        for s in self.panel.findChildren(ValueSlider):
            s.pressed.connect(self._guard(self.viewport.begin_drag, s.objectName()))
            s.released.connect(self._guard(self.viewport.let_go, s.objectName()))

    def watch_camera(self, pl) -> None:
        """``pl``'s camera drags are drags (the level of detail, one undo step); VTK's and
        PyVista's own keys (w wireframe, s surface, ...) would change the picture behind the
        state's back: the window's keys are the only keys."""
        self.viewport.watch_drags(pl)
        iren = pl.iren.interactor
        for key in list(getattr(pl, "_key_press_event_callbacks", {})):
            pl.clear_events_for_key(key)

        def block(obj, _event):
            obj.GetCommand(tag).SetAbortFlag(1)

        tag = iren.AddObserver("CharEvent", block, 10.0)

    # -- errors --------------------------------------------------------------------------------
    def _guard(self, fn, where: str):
        """``fn`` made safe for Qt's and VTK's callbacks (:meth:`PlotterView.guard`)."""
        return self.viewport.guard(fn, where)

    # -- ports: dialogs (replaceable by scripts and tests), messages, progress ------------------
    def ask_text(self, title: str, label: str, default: str = "") -> str | None:
        text, ok = QtWidgets.QInputDialog.getText(self, title, label, text=default)
        return text.strip() if ok else None

    def ask_yes(self, question: str) -> bool:
        answer = QtWidgets.QMessageBox.question(self, "phong-explorer", question)
        return answer == QtWidgets.QMessageBox.StandardButton.Yes

    def ask_path(self, title: str, *, save: bool = False, default: str = "",
                 filter: str = "") -> str | None:  # fmt: skip
        """A file name from Qt's file dialog, or None. Saving, the dialog does not ask about
        an existing file: the controller asks (:meth:`ask_yes`), whoever gave the name."""
        if save:
            path, _ = QtWidgets.QFileDialog.getSaveFileName(
                self, title, default, filter,
                options=QtWidgets.QFileDialog.Option.DontConfirmOverwrite,
            )  # fmt: skip
        else:
            path, _ = QtWidgets.QFileDialog.getOpenFileName(self, title, default, filter)
        return path or None

    def ask_number(self, title: str, label: str, default: int, lo: int, hi: int) -> int | None:
        value, ok = QtWidgets.QInputDialog.getInt(self, title, label, default, lo, hi)
        return int(value) if ok else None

    def tell(self, title: str, text: str, *, details: str = "", error: bool = False) -> None:
        """A message box (``details`` behind its Show Details button)."""
        box = QtWidgets.QMessageBox(self)
        box.setIcon(QtWidgets.QMessageBox.Icon.Warning if error
                    else QtWidgets.QMessageBox.Icon.Information)  # fmt: skip
        box.setWindowTitle(f"phong-explorer: {title}")
        box.setText(text)
        if details:
            box.setDetailedText(details)
        box.exec()

    def show_message(self, text, level="info", details=(), msecs=None, open_log=True) -> None:
        self.bar.show(text, level, details, msecs, open_log)

    def show_status(self, text: str, *, error: bool = False, warning: bool = False,
                    details=(), **kw) -> None:  # fmt: skip
        level = "error" if error else "warning" if warning else "info"
        self.bar.show(text, level, details, kw.get("msecs"), kw.get("open_log_", True))

    def run_steps(self, title, text, total, step, cancel):
        return run_steps(self, title, text, total, step, cancel)

    # -- ports: choices ------------------------------------------------------------------------
    def show_presets(self, presets) -> None:
        self.panel.show_items("presets", panelmodel.preset_items(presets))

    def show_meshes(self, labels) -> None:
        self.panel.view.set_meshes(labels)

    def show_recent(self, paths) -> None:
        self.menus.show_recent(paths)

    def show_history(self, undo, redo) -> None:
        self.menus.show_history(undo, redo)

    def render(self) -> None:
        """Draw a frame now."""
        self.viewport.redraw()

    # -- reporting ------------------------------------------------------------------------------
    def widget_box(self, widget: QtWidgets.QWidget) -> list[int]:
        """``[x, y, width, height]`` of a widget in the window's pixels (top-left origin)."""
        p = widget.mapTo(self, QtCore.QPoint(0, 0))
        return [p.x(), p.y(), widget.width(), widget.height()]

    def report_state(self) -> dict:
        """What a test or a script may want to know beyond the session (plain JSON values): the
        view port's report (:meth:`PlotterView.report`, its pixels in the window's), and the
        window's own: its size, the view's box, the selected light's handle and the arrows
        toward handles out of the view, the handle's glyph, the drag and the level of detail,
        every named widget's box, the last message."""
        s, view = self.controller.state, self.view
        origin = self.widget_box(self.plotter)[:2]

        def in_window(px):
            return [px[0] + origin[0], px[1] + origin[1]]

        handle = None
        if s.selected_light is not None:
            handle = in_window(view.world_to_window(M.handle_point(s)))
        _, h = self.plotter.window_size
        arrows = {str(i): in_window([round(float(t[0, 0])), round(h - 1 - float(t[0, 1]))])
                  for i, t in view.marker_triangles.items()}  # fmt: skip
        widgets = {
            w.objectName(): self.widget_box(w)
            for w in self.findChildren(QtWidgets.QWidget)
            if w.objectName() and not w.objectName().startswith("qt_") and w.isVisible()
        }
        return {
            **self.viewport.report(at=in_window),
            "window_size": [self.width(), self.height()],
            "view_box": self.widget_box(self.plotter),
            "edited": s.edited,
            "dragging": view.dragging > 0,
            "lod": view.lod_active,
            "handle_px": handle,
            "arrows_px": arrows,
            "glyph": view.glyph_kind,
            "widgets": widgets,
            "message": self.message,
        }

    def showEvent(self, event: QtGui.QShowEvent) -> None:  # noqa: N802 - Qt's name
        super().showEvent(event)
        if self._frame_on_show:
            self._frame_on_show = False
            w, h = self.plotter.width(), self.plotter.height()
            if w > 1 and h > 1:
                self.viewport.fixed_aspect = w / h
                self.controller.frame_start()

    def closeEvent(self, event: QtGui.QCloseEvent) -> None:  # noqa: N802 - Qt's name
        self.controller.files.keep_last_session()
        if self.controller.turntable is not None:
            self.controller.turntable.cancel()  # nothing written
        self.worker.close()  # (joined: its off-screen windows closed, under DRAW_LOCK)
        # VTK's observers removed, the handles released, side B's plotter and the view's
        # closed under DRAW_LOCK: nothing of VTK keeps the window, its controller or its view
        self.viewport.close()
        super().closeEvent(event)
