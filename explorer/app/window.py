"""The explorer window: a Qt main window with the 3D view (pyvistaqt's ``QtInteractor``)
beside the control panel (:mod:`explorer.app.panel`), over a :class:`~explorer.app.model.Store`.

The window holds no state of its own: the panel and the view show the store's state, and every
control sends an action (:meth:`ExplorerWindow.act`). The camera is the viewer: before each
frame the view's camera goes into the state (:meth:`Store.set_camera`, no undo step), so moving
the camera moves the highlights and recomputes the specular sum only. The difference view is
computed in a worker thread (:class:`~explorer.app.difference.DifferenceWorker`) and shown only
when it matches the view.

Menus, shortcuts, dialogs and files are in :mod:`explorer.app.commands`.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import time
from pathlib import Path

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

from explorer.app import model as M
from explorer.app.commands import Commands
from explorer.app.compare import ComparePane, DifferencePane
from explorer.app.difference import DifferenceWorker, HeatMap
from explorer.app.filemenu import FileCommands
from explorer.app.handledrag import HandleDrag
from explorer.app.lightpanel import Panel
from explorer.app.messages import Messages
from explorer.app.panel import ValueSlider
from explorer.app.session import session_mapping
from explorer.app.start import MESH_CHOICES, TITLE, WINDOW_SIZE
from explorer.app.view import (
    LOD_TARGET,
    LOD_VERTICES,
    SceneView,
    framed_camera,
    view_camera,
)
from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError
from explorer.core.presets import list_presets
from explorer.geometry.meshes import Mesh
from explorer.render.camera import Camera
from explorer.render.offscreen import BACKGROUND
from explorer.render.vtk import plain_blending
from explorer.shading import tiers

log = logging.getLogger(__name__)

#: the panel's share of the window's width at the start (the view takes the rest)
PANEL_FRACTION = 0.34
#: how often the status bar asks whether the compiled kernels are ready yet (ms)
ENGINE_POLL_MS = 500


class ExplorerWindow(Commands, FileCommands, ComparePane, DifferencePane, HandleDrag, Messages,
                     QtWidgets.QMainWindow):  # fmt: skip
    """The explorer window.

    state, mesh : the start (``mesh`` is the mesh ``state.mesh`` names)
    materials_dirs : extra preset directories; preset_dir : where presets are saved (default:
        the user's preset directory); output_dir : where screenshots go (default: the current
        directory); state_file : write the session and a report as JSON after every frame;
        last_session : the file the session is kept in on quit (None: not kept)
    size : (width, height) of the window; lod_vertices, lod_target : see
        :mod:`explorer.app.view`; background : RGB in [0, 1]
    """

    difference_ready = QtCore.Signal(object)

    def __init__(self, state: M.State, mesh: Mesh, *, materials_dirs=(), preset_dir=None,
                 output_dir=None, state_file=None, last_session=None, size=WINDOW_SIZE,
                 lod_vertices: int = LOD_VERTICES, lod_target: int = LOD_TARGET,
                 background=None):  # fmt: skip
        from pyvistaqt import QtInteractor

        super().__init__()
        self.setWindowTitle(TITLE)
        self.materials_dirs = tuple(materials_dirs)
        self.preset_dir = preset_dir
        self.output_dir = Path(output_dir) if output_dir else Path.cwd()
        self.state_file = Path(state_file) if state_file else None
        self.last_session = last_session
        self.session_path: Path | None = None
        self.errors: list[str] = []
        self.message = ""
        self.frames = 0
        self.frame_ms = float("nan")
        self._t0: float | None = None
        self._in_frame = False
        self._holding_handle = False
        self._grab = None
        self._requested = None
        self.meshes: dict[str, Mesh] = {state.mesh: mesh}
        self.mesh_choices = dict(MESH_CHOICES)
        if state.mesh not in self.mesh_choices:
            self.mesh_choices = {state.mesh: None, **self.mesh_choices}
        w, h = (int(v) for v in size)
        self.resize(w, h)
        self.splitter = QtWidgets.QSplitter(QtCore.Qt.Orientation.Horizontal)
        self.views = QtWidgets.QSplitter(QtCore.Qt.Orientation.Horizontal)
        self.views.setChildrenCollapsible(False)
        self.plotter = QtInteractor(self.views, multi_samples=0, auto_update=False)
        self.plotter.setObjectName("view")
        self.plotter.setMinimumSize(120, 120)
        self.plotter.setFocusPolicy(QtCore.Qt.FocusPolicy.StrongFocus)
        self.plotter.disable_anti_aliasing()
        plain_blending(self.plotter.renderer)  # translucency drawn as the off-screen renders
        self.plotter.set_background(BACKGROUND if background is None else background)
        self.panel = Panel(self.act, self.choose_mesh)
        self.views.addWidget(self.plotter)
        self.splitter.addWidget(self.views)
        self.splitter.addWidget(self.panel)
        self.splitter.setStretchFactor(0, 1)
        self.splitter.setStretchFactor(1, 0)
        self.splitter.setChildrenCollapsible(False)
        self.splitter.setSizes([round(w * (1 - PANEL_FRACTION)), round(w * PANEL_FRACTION)])
        self.setCentralWidget(self.splitter)
        self.status_label = QtWidgets.QLabel("")
        self.status_label.setObjectName("status")
        self.statusBar().addPermanentWidget(self.status_label)
        self.build_messages()
        self._watch_engine()
        self.view_aspect = max(w * (1 - PANEL_FRACTION), 1.0) / max(h - 60, 1.0)
        self._frame_on_show = state.camera is None  # framed again for the view's real shape
        if state.camera is None:
            state = M.set_camera(state, self._framed(state, mesh))
        self.start_state = state
        self.store = M.Store(state)
        self.view = SceneView(self.plotter, mesh, state, lod_vertices=lod_vertices,
                              lod_target=lod_target)  # fmt: skip
        self.view.apply_camera(state.camera)
        self.view.add_handles(self._guard(self._grab_handle, "light handle"),
                              self._guard(self._drag_handle, "light handle"),
                              self._guard(self._release_handle, "light handle"))  # fmt: skip
        self.heat = HeatMap(self.plotter.renderer)
        self.worker = DifferenceWorker(self.difference_ready.emit)
        self.difference_ready.connect(self._guard(self._on_difference, "difference view"))
        self.plotter_b = self.view_b = None  # the compare view's side B, made when first shown
        self._syncing = False
        self.presets = []
        self.reload_presets()
        self._set_mesh_choices()
        self._observe()
        self.build_menus()
        self.store.subscribe(self._on_change)
        self._show_compare(None, state)
        self._show_panel(state)
        self._update_difference()

    # -- building ------------------------------------------------------------------------------
    def _framed(self, state: M.State, mesh: Mesh) -> Camera:
        cam = framed_camera(state, mesh, self.view_aspect)
        return dataclasses.replace(cam, window_center=(0.0, 0.0))

    def _observe(self) -> None:
        pl = self.plotter
        pl.renderer.AddObserver("StartEvent", self._guard(self._before_frame, "frame"))
        pl.render_window.AddObserver("EndEvent", self._guard(self._after_frame, "frame"))
        iren = pl.iren.interactor
        style = iren.GetInteractorStyle()
        if style is not None:
            style.AddObserver("StartInteractionEvent", self._guard(self._begin_drag, "camera"))
            style.AddObserver("EndInteractionEvent", self._guard(self._end_drag, "camera"))
        for s in self.panel.findChildren(ValueSlider):
            s.pressed.connect(self._guard(self._begin_drag, s.objectName()))
            s.released.connect(self._guard(self._end_drag_if_dragging, s.objectName()))
        # VTK's and PyVista's own keys (w wireframe, s surface, 3 stereo, v isometric...) would
        # change the picture behind the state's back: the window's shortcuts are the only keys
        for key in list(getattr(pl, "_key_press_event_callbacks", {})):
            pl.clear_events_for_key(key)

        def block(obj, _event):
            obj.GetCommand(self._char_tag).SetAbortFlag(1)

        self._char_tag = iren.AddObserver("CharEvent", block, 10.0)

    def reload_presets(self) -> None:
        notices: list[str] = []
        self.presets = list_presets(self.materials_dirs, notices=notices)
        for text in notices:
            log.warning("%s", text)
        self.panel.material.set_presets(self.presets)
        self.panel.view.set_presets(self.presets)

    def _set_mesh_choices(self) -> None:
        labels = {n: (Path(n).name if n not in MESH_CHOICES else n) for n in self.mesh_choices}
        self.panel.view.set_meshes(labels)

    # -- errors and messages -------------------------------------------------------------------
    def _guard(self, fn, where: str):
        """``fn`` made safe for Qt's and VTK's callbacks: an error is shown on the status bar
        and logged, never lost and never a traceback in the user's face."""

        def call(*args):
            try:
                return fn(*args)
            except Exception as exc:  # noqa: BLE001 - every error is shown, none is lost
                self.report(exc, where)
                return None

        return call

    def report(self, exc: BaseException, where: str) -> None:
        if isinstance(exc, ExplorerError):
            text = str(exc)
            log.error("%s: %s", where, text)
        else:
            text = f"{type(exc).__name__}: {exc}"
            log.error("%s failed", where, exc_info=exc)
        lines = text.splitlines() or [type(exc).__name__]
        self.errors.append(f"{where}: {text}")
        self.show_status(f"error ({where}): {lines[0]}", error=True, details=lines[1:])

    def _watch_engine(self) -> None:
        """Load the compiled kernels in a thread as soon as numba's cache holds them (the numpy
        tier draws meanwhile; :func:`explorer.shading.tiers.preload`), and say so in the
        status bar while it lasts."""
        tiers.preload()
        self.engine_label = QtWidgets.QLabel("")
        self.engine_label.setObjectName("engine")
        self.engine_label.setContentsMargins(0, 0, 16, 0)  # apart from the preset and model
        self.statusBar().insertPermanentWidget(0, self.engine_label)
        self._engine_timer = QtCore.QTimer(self)
        self._engine_timer.timeout.connect(self._show_engine)
        self._engine_timer.start(ENGINE_POLL_MS)
        self._show_engine()

    def _show_engine(self) -> None:
        tiers.preload()  # looks for the ready marker (a stat at most every tiers.POLL seconds)
        text = tiers.status() or ""
        if text != self.engine_label.text():
            self.engine_label.setText(text)
        if not text and (tiers.loaded() or tiers.mode() != "auto"):
            self._engine_timer.stop()

    # -- actions --------------------------------------------------------------------------------
    def act(self, action, *args, label: str | None = None, merge=None) -> bool:
        """Apply ``action(state, *args)`` as one undo step (steps with the same ``merge`` key
        join until the next seal); ``act(None)`` seals (a slider's release). Errors are shown."""
        if action is None:
            self.store.seal()
            return False
        if self._t0 is None:
            self._t0 = time.perf_counter()
        try:
            return self.store.apply(action, *args, label=label, merge=merge)
        except ExplorerError as exc:
            self.report(exc, label or action.__name__)
            self._show_panel(self.store.state)  # the control that sent it shows the state again
            return False

    def _on_change(self, old: M.State, new: M.State) -> None:
        if new.mesh != old.mesh:
            self.view.set_mesh(self.meshes[new.mesh], new)
        else:
            self.view.show_state(new)
        self._show_compare(old, new)
        only_camera = dataclasses.replace(old, camera=None, scene=old.scene.replace(
            viewer=new.scene.viewer)) == dataclasses.replace(new, camera=None)  # fmt: skip
        if new.camera is not None and not self._in_frame:
            live = view_camera(self.plotter.camera, new.centre, new.radius)
            if live != new.camera:
                self.view.apply_camera(new.camera)
        if not only_camera or new.preset_material is not old.preset_material:
            self._show_panel(new)
        self._update_difference()
        if not self._in_frame:
            self.render()

    def _show_panel(self, state: M.State) -> None:
        self.panel.show_state(state, self.view.mesh.n_vertices)
        self.update_edit_actions()
        what = state.preset or "(scene material)"
        if state.groups is not None:
            what = f"{state.mesh_materials.source}'s materials"
        parts = [what, state.scene.model]
        if state.hidden:
            parts.append("hidden: " + ", ".join(t for t in M.TERMS if t in state.hidden))
        self.status_label.setText(";  ".join(parts))

    def render(self) -> None:
        """Draw a frame now."""
        if self._t0 is None:
            self._t0 = time.perf_counter()
        self.plotter.render_window.Render()

    # -- frames ---------------------------------------------------------------------------------
    def _before_frame(self, *_) -> None:
        """Renderer StartEvent: the camera is the viewer; translucent triangles sorted."""
        if self._t0 is None:
            self._t0 = time.perf_counter()
        s = self.store.state
        cam = view_camera(self.plotter.camera, s.centre, s.radius)
        self._in_frame = True
        try:
            self.store.set_camera(cam)
        finally:
            self._in_frame = False
        self.view.before_frame(cam)
        self._update_difference()  # the view's size may have changed (a resize)
        self.plotter.renderer.ResetCameraClippingRange()

    def _after_frame(self, *_) -> None:
        """Render window EndEvent: count and time the frame, draw side B of the compare view
        (same camera), then write the state file (after the frame, so a reader never races
        the pixels)."""
        self.frames += 1
        if self.plotter_b is not None and self.plotter_b.isVisible() and not self._syncing:
            self._syncing = True
            try:
                self.plotter_b.render_window.Render()
            finally:
                self._syncing = False
        if self._t0 is not None:
            self.frame_ms = 1000.0 * (time.perf_counter() - self._t0)
            self._t0 = None
        if self.state_file is not None:
            data = json.dumps({**session_mapping(self.store.state), "window": self.report_state()})
            write_atomic(self.state_file, data.encode(), overwrite=True)

    def _begin_drag(self, *_) -> None:
        self.view.begin_drag()
        self._update_difference()

    def _end_drag(self, *_) -> None:
        self.view.end_drag()
        self.store.seal()
        self._update_difference()
        self.render()

    def _end_drag_if_dragging(self, *_) -> None:
        if self.view.dragging:
            self._end_drag()
        else:
            self.store.seal()

    # -- reporting ------------------------------------------------------------------------------
    def widget_box(self, widget: QtWidgets.QWidget) -> list[int]:
        """``[x, y, width, height]`` of a widget in the window's pixels (top-left origin)."""
        p = widget.mapTo(self, QtCore.QPoint(0, 0))
        return [p.x(), p.y(), widget.width(), widget.height()]

    def report_state(self) -> dict:
        """What a test or a script may want to know beyond the session (plain JSON values)."""
        s = self.store.state
        probe = self.view.probe_vertex()
        origin = self.widget_box(self.plotter)[:2]

        def in_window(px):
            return [px[0] + origin[0], px[1] + origin[1]]

        handle = None
        if s.selected_light is not None:
            handle = in_window(self.view.world_to_window(M.handle_point(s)))
        handles = [in_window(self.view.world_to_window(M.handle_point(s, i)))
                   for i in range(len(s.scene.lights))]  # fmt: skip
        _, h = self.plotter.window_size
        arrows = {str(i): in_window([round(float(t[0, 0])), round(h - 1 - float(t[0, 1]))])
                  for i, t in self.view.marker_triangles.items()}  # fmt: skip
        widgets = {
            w.objectName(): self.widget_box(w)
            for w in self.findChildren(QtWidgets.QWidget)
            if w.objectName() and not w.objectName().startswith("qt_") and w.isVisible()
        }
        return {
            "frame": self.frames,
            "frame_ms": None if not np.isfinite(self.frame_ms) else self.frame_ms,
            "window_size": [self.width(), self.height()],
            "view_box": self.widget_box(self.plotter),
            "n_vertices": self.view.mesh.n_vertices,
            "edited": s.edited,
            "dragging": self.view.dragging > 0,
            "lod": self.view.lod_active,
            "handle_px": handle,
            "handles_px": handles,
            "arrows_px": arrows,
            "glyph": self.view.glyph_kind,
            "probe": {"vertex": probe,
                      "px": in_window(self.view.world_to_window(self.view.mesh.positions[probe]))},
            "difference": self.heat.state(),
            "widgets": widgets,
            "can_undo": self.store.can_undo,
            "can_redo": self.store.can_redo,
            "message": self.message,
            "errors": list(self.errors),
        }  # fmt: skip

    def showEvent(self, event: QtGui.QShowEvent) -> None:  # noqa: N802 - Qt's name
        super().showEvent(event)
        if self._frame_on_show:
            self._frame_on_show = False
            w, h = self.plotter.width(), self.plotter.height()
            if w > 1 and h > 1:
                self.view_aspect = w / h
                cam = self._framed(self.store.state, self.view.mesh)
                self.start_state = M.set_camera(self.start_state, cam)
                self.store.set_camera(cam)

    # -- closing --------------------------------------------------------------------------------
    def closeEvent(self, event: QtGui.QCloseEvent) -> None:  # noqa: N802 - Qt's name
        self.keep_last_session()
        if self.turntable is not None:
            self.turntable.cancel()  # nothing written
        self.worker.close()
        self.plotter.close()
        super().closeEvent(event)
