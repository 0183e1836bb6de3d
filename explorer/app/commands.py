"""The explorer window's menus, shortcuts, dialogs and files (a mix-in of
:class:`explorer.app.window.ExplorerWindow`).

Dialogs go through :meth:`Commands.ask_text`, :meth:`Commands.ask_yes` and
:meth:`Commands.ask_path`, so that scripts and tests can answer them programmatically.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

from PySide6 import QtCore, QtGui, QtWidgets

from explorer.app import model as M
from explorer.app.messages import open_log
from explorer.app.session import last_session_path, load_session, save_session
from explorer.app.start import add_mesh_materials, free_name, load_mesh_choice
from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError
from explorer.core.material import MODELS
from explorer.core.mtl import MtlError
from explorer.core.presets import MAX_NAME_LENGTH, check_name, save_preset, user_dir
from explorer.core.scene import load_scene
from explorer.core.yamlio import load_yaml
from explorer.geometry.meshes import MESH_SUFFIXES

log = logging.getLogger(__name__)

#: keys of the 3D view (active while it has the keyboard focus): key -> (what, method name)
VIEW_KEYS = {
    "h": ("show / hide this help", "toggle_help"),
    "r": ("reset the camera (the material and lights stay)", "reset_camera"),
    "q": ("quit (the session is kept for 'gui --last')", "close"),
    "d": ("show / hide the per-pixel difference", "toggle_difference"),
    "b": (f"next specular model ({' / '.join(MODELS)})", "toggle_model"),
    "1": ("show / hide the ambient term", "toggle_ambient"),
    "2": ("show / hide the diffuse term", "toggle_diffuse"),
    "3": ("show / hide the specular term", "toggle_specular"),
    "n": ("next preset", "next_preset"),
    "p": ("previous preset", "previous_preset"),
    "t": ("next light type (directional / point / spot)", "next_light_type"),
    "l": ("control the next light", "next_light"),
    "i": ("save a screenshot of the view (never over a file)", "screenshot"),
    "c": ("compare A | B on / off (two panes, linked cameras)", "toggle_compare"),
    "x": ("swap A and B", "swap_sides"),
}
#: mouse controls of the view, for the help
MOUSE = (
    ("drag the yellow sphere", "move the light (the lights tab follows)"),
    ("left drag", "rotate the camera; the camera is the viewer, so highlights move"),
    ("right drag / wheel", "zoom"),
    ("middle drag / shift + left drag", "pan"),
)
#: file types File > Open takes
OPEN_FILTER = "meshes, scenes and sessions (*{} *.yaml *.yml *.json);;all files (*)".format(
    " *".join(MESH_SUFFIXES)
)


def help_text() -> str:
    """Every key and mouse control, one per line."""
    lines = ["Keys in the 3D view (VTK's own keys are switched off):"]
    lines += [f"  {key}   {what}" for key, (what, _) in VIEW_KEYS.items()]
    lines += ["", "Window shortcuts:", "  Ctrl+Z / Ctrl+Shift+Z   undo / redo",
              "  Ctrl+O   open a mesh, scene or session",
              "  Ctrl+I / Ctrl+E   import materials (.mtl) / export the material",
              "  Ctrl+Shift+E / Ctrl+T   export the view (PNG) / a turntable (GIF, MP4)",
              "  Ctrl+S   save the session",
              "  Ctrl+Shift+S   save the material as a preset", "  Ctrl+Q   quit",
              "  F1   this help", "", "Mouse in the 3D view:"]  # fmt: skip
    lines += [f"  {how}: {what}" for how, what in MOUSE]
    return "\n".join(lines)


class ViewKeys(QtCore.QObject):
    """The 3D view's keys: :data:`VIEW_KEYS` run their commands; every other plain key is
    kept from VTK and PyVista, whose own keys (w wireframe, s surface, 3 stereo, ...) would
    change the picture behind the state's back. Keys with Ctrl or Alt go on to the menus."""

    def __init__(self, window):
        super().__init__(window)
        self.window = window
        self.calls = {
            key: window._guard(getattr(window, method), f"key {key}")
            for key, (_, method) in VIEW_KEYS.items()
        }

    def eventFilter(self, obj, event) -> bool:  # noqa: N802 - Qt's name
        kind = event.type()
        if kind not in (QtCore.QEvent.Type.KeyPress, QtCore.QEvent.Type.KeyRelease):
            return False
        mods = QtCore.Qt.KeyboardModifier
        if event.modifiers() & (mods.ControlModifier | mods.AltModifier | mods.MetaModifier):
            return False
        if kind == QtCore.QEvent.Type.KeyPress and event.text() in self.calls:
            self.calls[event.text()]()
        return True


class Commands:
    """Menus, shortcuts and the commands behind them (needs the window's ``store``, ``view``,
    ``plotter``, ``act``, ``report`` and ``show_status``)."""

    # -- dialogs (replaceable by scripts and tests) -------------------------------------------
    def ask_text(self, title: str, label: str, default: str = "") -> str | None:
        text, ok = QtWidgets.QInputDialog.getText(self, title, label, text=default)
        return text.strip() if ok else None

    def ask_yes(self, question: str) -> bool:
        answer = QtWidgets.QMessageBox.question(self, "phong-explorer", question)
        return answer == QtWidgets.QMessageBox.StandardButton.Yes

    def ask_path(self, title: str, *, save: bool = False, default: str = "",
                 filter: str = "") -> str | None:  # fmt: skip
        """A file name from Qt's file dialog, or None. Saving, the dialog does not ask about
        an existing file: the command asks (:meth:`ask_yes`), whoever gave the name."""
        if save:
            path, _ = QtWidgets.QFileDialog.getSaveFileName(
                self, title, default, filter,
                options=QtWidgets.QFileDialog.Option.DontConfirmOverwrite,
            )  # fmt: skip
        else:
            path, _ = QtWidgets.QFileDialog.getOpenFileName(self, title, default, filter)
        return path or None

    # -- menus and keys -------------------------------------------------------------------------
    def add_action(self, menu, name: str, text: str, slot, shortcut: str | None = None):
        """A menu entry named ``name`` (``menu_actions[name]``) running ``slot()`` with its
        errors shown; ``shortcut``: key sequences separated by ``|``."""
        a = QtGui.QAction(text, self)
        a.setObjectName(name)
        if shortcut:
            a.setShortcuts([QtGui.QKeySequence(s) for s in shortcut.split("|")])
        a.triggered.connect(self._guard(lambda _=False: slot(), name))
        menu.addAction(a)
        self.menu_actions[name] = a
        return a

    def build_menus(self) -> None:
        bar = self.menuBar()
        self.menu_actions: dict[str, QtGui.QAction] = {}
        add = self.add_action
        self.build_file_menu(bar.addMenu("&File"))
        e = bar.addMenu("&Edit")
        add(e, "undo", "&Undo", self.undo, "Ctrl+Z")
        add(e, "redo", "&Redo", self.redo, "Ctrl+Shift+Z|Ctrl+Y")
        e.addSeparator()
        add(e, "reset_all", "Reset &all (undoable)", self.reset_all)
        v = bar.addMenu("&View")
        add(v, "reset_camera", "Reset &camera (r)", self.reset_camera)
        add(v, "toggle_difference", "&Difference view (d)", self.toggle_difference)
        add(v, "toggle_compare", "&Compare A | B (c)", self.toggle_compare)
        add(v, "swap_sides", "&Swap A and B (x)", self.swap_sides)
        v.addSeparator()
        add(v, "messages", "&Messages", lambda: open_log(self.messages), "Ctrl+M")
        h = bar.addMenu("&Help")
        add(h, "help", "&Keys and mouse", self.toggle_help, "F1")
        self.panel.material.save.clicked.connect(self._guard(self.save_preset_as, "save preset"))
        self._view_keys = ViewKeys(self)
        self.plotter.installEventFilter(self._view_keys)
        self.help = None

    def update_edit_actions(self) -> None:
        s = self.store
        for name, can, label in (("undo", s.can_undo, s.undo_label()),
                                 ("redo", s.can_redo, s.redo_label())):  # fmt: skip
            a = self.menu_actions.get(name) if hasattr(self, "menu_actions") else None
            if a is not None:
                a.setEnabled(can)
                a.setText(f"&{name.title()} {label}" if label else f"&{name.title()}")

    # -- edit -------------------------------------------------------------------------------------
    def undo(self) -> None:
        if not self.store.undo():
            self.show_status("nothing to undo")

    def redo(self) -> None:
        if not self.store.redo():
            self.show_status("nothing to redo")

    def reset_all(self) -> None:
        """Back to the start (material, lights, mesh, terms, camera): one undo step."""
        self.store.commit(self.start_state, "reset all")
        self.show_status("reset to the start (Ctrl+Z brings your changes back)")

    def reset_camera(self) -> None:
        """The start camera (this mesh framed from the start's viewer); no undo step."""
        s = self.store.state
        if s.mesh == self.start_state.mesh:
            cam = self.start_state.camera
        else:
            start = s.replace(scene=s.scene.replace(viewer=self.start_state.scene.viewer))
            cam = self._framed(start, self.view.mesh)
        self.store.set_camera(cam)
        self.show_status("camera reset")

    # -- keys -------------------------------------------------------------------------------------
    def toggle_difference(self) -> None:
        self.act(M.set_difference, not self.store.state.difference, label="difference")

    def toggle_compare(self) -> None:
        self.act(M.set_compare, self.store.state.compare is None, label="compare")

    def swap_sides(self) -> None:
        self.act(M.swap_compare, label="swap A and B")

    def toggle_model(self) -> None:
        """The next specular model of :data:`explorer.core.material.MODELS`."""
        self.act(M.set_model, M.next_model(self.store.state.scene.model), label="model")

    def _toggle_term(self, term: str) -> None:
        shown = term not in self.store.state.hidden
        self.act(M.set_term, term, not shown, label=f"{term} term")

    def toggle_ambient(self) -> None:
        self._toggle_term("ambient")

    def toggle_diffuse(self) -> None:
        self._toggle_term("diffuse")

    def toggle_specular(self) -> None:
        self._toggle_term("specular")

    def _step_preset(self, step: int) -> None:
        if not self.presets:
            raise ExplorerError("no presets found")
        names = [p.name for p in self.presets]
        s = self.store.state
        i = names.index(s.preset) if s.preset in names else (-1 if step > 0 else 0)
        p = self.presets[(i + step) % len(names)]
        self.act(M.apply_preset, p.name, p.material, label=f"preset {p.name}")

    def next_preset(self) -> None:
        self._step_preset(1)

    def previous_preset(self) -> None:
        self._step_preset(-1)

    def next_light_type(self) -> None:
        light = self.store.state.selected_light
        if light is None:
            raise ExplorerError("the scene has no lights: add one in the lights tab")
        kinds = ("directional", "point", "spot")
        nxt = kinds[(kinds.index(light.type) + 1) % 3]
        self.act(M.set_light_type, nxt, label="light type")

    def next_light(self) -> None:
        s = self.store.state
        n = len(s.scene.lights)
        if n < 2:
            self.show_status(f"the scene has {n} light{'s' if n != 1 else ''}: nothing to switch"
                             " to (add one in the lights tab)")  # fmt: skip
            return
        self.act(M.select_light, (s.light + 1) % n, label="select light")
        self.show_status(f"controlling light {self.store.state.light + 1} of {n}")

    def toggle_help(self) -> None:
        if self.help is not None and self.help.isVisible():
            self.help.hide()
            return
        if self.help is None:
            self.help = QtWidgets.QMessageBox(self)
            self.help.setObjectName("help")
            self.help.setWindowTitle("phong-explorer: keys and mouse")
            self.help.setText(help_text())
            self.help.setModal(False)
        self.help.show()

    # -- files ------------------------------------------------------------------------------------
    def screenshot(self) -> Path:
        """Save the 3D view as a PNG in the output directory (a new file every time)."""
        stem = self.picture_stem()
        taken = {p.stem for p in self.output_dir.glob(f"{stem}_*.png")}
        path = self.output_dir / f"{free_name(stem, taken)}.png"
        write_atomic(path, self.view_png())
        self.show_status(f"saved screenshot {path}")
        return path

    def save_preset_as(self, name: str | None = None) -> Path | None:
        """Save the material (with the current specular model) as a preset: asks for a name,
        checks it, asks before replacing a file or hiding another preset. The preset is then
        shown clean; while the mesh shows its own materials the edited group's is saved, and
        the groups stay."""
        s = self.store.state
        stem = (s.preset or self.material_name())[: MAX_NAME_LENGTH - 8]
        taken = {p.name for p in self.presets}
        if name is None:
            name = self.ask_text(
                "Save preset as",
                "preset name (lowercase letters, digits, _):",
                free_name(stem, taken) if s.edited else (s.preset or stem),
            )
            if not name:
                return None
        check_name(name)
        directory = Path(self.preset_dir) if self.preset_dir else user_dir()
        path = directory / f"{name}.yaml"
        overwrite = path.exists()
        if overwrite and not self.ask_yes(f"Replace the preset file {path}?"):
            return None
        if (
            not overwrite
            and name in taken
            and not self.ask_yes(
                f"A preset named '{name}' exists; yours will hide it. Save anyway?"
            )
        ):
            return None
        material = s.material.replace(
            model=s.scene.model, description=s.material.description
            or f"{stem} as edited in phong-explorer",
        )  # fmt: skip
        written = save_preset(material, name, directory, overwrite=overwrite)
        self.reload_presets()
        info = next((p for p in self.presets if p.name == name), None)
        if info is not None and s.groups is None:
            self.act(M.apply_preset, name, info.material, label=f"save preset {name}")
        self.show_status(f"saved preset '{name}' to {written}")
        return written

    def save_session_as(self, path=None) -> Path | None:
        if path is None:
            default = str(self.session_path or Path.cwd() / "session.yaml")
            path = self.ask_path("Save session", save=True, default=default,
                                 filter="sessions (*.yaml *.yml *.json)")  # fmt: skip
            if not path:
                return None
        path = Path(path)
        overwrite = path.exists()
        if overwrite and not self.ask_yes(f"Replace the session file {path}?"):
            return None
        written = save_session(path, self.store.state, overwrite=overwrite)
        self.session_path = written
        self.remember_recent(written)
        self.show_status(f"saved session {written}")
        return written

    def open_file(self, path=None) -> None:
        """Open a mesh file, a scene file or a session (File > Open)."""
        if path is None:
            path = self.ask_path("Open mesh, scene or session", filter=OPEN_FILTER)
            if not path:
                return
        path = os.fspath(path)
        if not os.path.lexists(path):  # anything else is read, or refused, by the checked open
            raise ExplorerError(f"{path}: no such file")
        if path.lower().endswith(MESH_SUFFIXES):
            if self.choose_mesh(os.path.abspath(path)):
                self.remember_recent(path)
            return
        doc = load_yaml(path, what="scene or session")
        if isinstance(doc.data, dict) and "session" in doc.data:
            self.open_session(path)
        else:
            scene = load_scene(path, materials_dirs=self.materials_dirs)
            self._open_scene(scene, path)
        self.remember_recent(path)

    def _open_scene(self, scene, path: str) -> None:
        M.check_window_lights(len(scene.lights), path)
        s = self.store.state  # the scene's material covers the mesh (groups=None)
        new = s.replace(scene=scene.replace(mesh=s.mesh), preset=scene.material.name,
                        preset_material=None, light=0, held_azimuth=None,
                        groups=None)  # fmt: skip
        if scene.mesh is not None and scene.mesh != s.mesh:
            mesh = load_mesh_choice(scene.mesh)
            self.meshes[scene.mesh] = mesh
            if scene.mesh not in self.mesh_choices:
                self.mesh_choices[scene.mesh] = None
                self._set_mesh_choices()
            new = M.set_mesh(new, scene.mesh, mesh.centre, mesh.radius)
            new = new.replace(scene=new.scene.replace(lights=scene.lights))
            try:
                new, _ = add_mesh_materials(new, mesh, use=False)
            except MtlError as exc:
                self.report(exc, "mesh materials")
        new = M.set_camera(new, self._framed(new, self.meshes[new.mesh]))
        self.store.commit(new, f"open {Path(path).name}")
        self.show_status(f"opened scene {path}")

    def open_session(self, path) -> None:
        state, mesh = load_session(path, materials_dirs=self.materials_dirs)
        self.meshes[state.mesh] = mesh
        if state.mesh not in self.mesh_choices:
            self.mesh_choices[state.mesh] = None
            self._set_mesh_choices()
        if state.camera is None:
            state = M.set_camera(state, self._framed(state, mesh))
        self.store.commit(state, f"open {Path(path).name}")
        self.session_path = Path(path)
        self.show_status(f"opened session {path}")

    def keep_last_session(self) -> None:
        """Write the session to the last-session file (``gui --last`` reopens it)."""
        if self.last_session is None:
            return
        try:
            path = Path(self.last_session) if self.last_session is not True else None
            save_session(path or last_session_path(), self.store.state, overwrite=True)
        except ExplorerError as exc:
            log.warning("could not keep the last session: %s", exc)
