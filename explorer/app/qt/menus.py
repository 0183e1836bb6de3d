"""The explorer window's menus, shortcuts and the 3D view's keys (in
:class:`explorer.app.qt.window.ExplorerWindow`): each entry sends an intent to the window's
:class:`~explorer.app.controller.Controller`."""

from __future__ import annotations

from pathlib import Path

from PySide6 import QtCore, QtGui, QtWidgets

from explorer.app.qt.messages import open_log
from explorer.core.material import MODELS

#: keys of the 3D view (active while it has the keyboard focus): key -> (what, method name);
#: the methods are the controller's intents, but for the help (the menus') and quit (the window's)
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

    def eventFilter(self, obj, event) -> bool:  # noqa: N802 - Qt's name
        kind = event.type()
        if kind not in (QtCore.QEvent.Type.KeyPress, QtCore.QEvent.Type.KeyRelease):
            return False
        mods = QtCore.Qt.KeyboardModifier
        if event.modifiers() & (mods.ControlModifier | mods.AltModifier | mods.MetaModifier):
            return False
        if kind == QtCore.QEvent.Type.KeyPress and event.text() in VIEW_KEYS:
            key = event.text()
            w, method = self.window, VIEW_KEYS[key][1]
            target = {"toggle_help": w.menus.toggle_help, "close": w.close}.get(method)
            w._guard(target or getattr(w.controller, method), f"key {key}")()
        return True


class Menus:
    """The menu bar of ``window`` (sets ``window.menu_actions``, ``window.recent_menu`` and
    ``window.help``), the 3D view's keys, the Save button of the material tab; the
    controller's choices port shows undo / redo and the recent files here."""

    def __init__(self, window):
        self.window = w = window
        c = w.controller
        bar = w.menuBar()
        self.actions = w.menu_actions = {}
        f = bar.addMenu("&File")
        add = self.add_action
        add(f, "open", "&Open mesh, scene or session…", c.open_file, "Ctrl+O")
        self.recent = w.recent_menu = f.addMenu("Open &recent")
        self.recent.setObjectName("recent")
        f.addSeparator()
        add(f, "import_materials", "&Import materials (.mtl)…", c.import_materials, "Ctrl+I")
        add(f, "export_material", "&Export material…", c.export_material, "Ctrl+E")
        add(f, "export_render", "Export &view as PNG…", c.export_render, "Ctrl+Shift+E")
        add(f, "export_turntable", "Export &turntable (GIF, MP4)…", c.export_turntable, "Ctrl+T")
        f.addSeparator()
        add(f, "save_session", "&Save session…", c.save_session_as, "Ctrl+S")
        add(f, "save_preset", "Save &preset as…", c.save_preset_as, "Ctrl+Shift+S")
        add(f, "screenshot", "Save screens&hot", c.screenshot)
        f.addSeparator()
        add(f, "quit", "&Quit", w.close, "Ctrl+Q")
        e = bar.addMenu("&Edit")
        add(e, "undo", "&Undo", c.undo, "Ctrl+Z")
        add(e, "redo", "&Redo", c.redo, "Ctrl+Shift+Z|Ctrl+Y")
        e.addSeparator()
        add(e, "reset_all", "Reset &all (undoable)", c.reset_all)
        v = bar.addMenu("&View")
        add(v, "reset_camera", "Reset &camera (r)", c.reset_camera)
        add(v, "toggle_difference", "&Difference view (d)", c.toggle_difference)
        add(v, "toggle_compare", "&Compare A | B (c)", c.toggle_compare)
        add(v, "swap_sides", "&Swap A and B (x)", c.swap_sides)
        v.addSeparator()
        add(v, "messages", "&Messages", lambda: open_log(w.messages), "Ctrl+M")
        h = bar.addMenu("&Help")
        add(h, "help", "&Keys and mouse", self.toggle_help, "F1")
        w.panel.material.save.clicked.connect(w._guard(c.save_preset_as, "save preset"))
        self._view_keys = ViewKeys(w)
        w.plotter.installEventFilter(self._view_keys)
        w.help = None

    def add_action(self, menu, name: str, text: str, slot, shortcut: str | None = None):
        """A menu entry named ``name`` (``menu_actions[name]``) running ``slot()`` with its
        errors shown; ``shortcut``: key sequences separated by ``|``."""
        a = QtGui.QAction(text, self.window)
        a.setObjectName(name)
        if shortcut:
            a.setShortcuts([QtGui.QKeySequence(s) for s in shortcut.split("|")])
        a.triggered.connect(self.window._guard(lambda _=False: slot(), name))
        menu.addAction(a)
        self.actions[name] = a
        return a

    def show_history(self, undo: str | None, redo: str | None) -> None:
        """Undo and redo enabled when there is something to undo or redo, named after it."""
        for name, label in (("undo", undo), ("redo", redo)):
            a = self.actions[name]
            a.setEnabled(label is not None)
            a.setText(f"&{name.title()} {label}" if label else f"&{name.title()}")

    def show_recent(self, items: list[str]) -> None:
        menu, c = self.recent, self.window.controller
        menu.clear()
        for i, path in enumerate(items):
            a = menu.addAction(f"&{i + 1} {Path(path).name}   ({Path(path).parent})")
            a.setObjectName(f"recent_{i + 1}")
            a.triggered.connect(self.window._guard(lambda _=False, p=path: c.open_recent(p),
                                                   "open recent"))  # fmt: skip
        if items:
            menu.addSeparator()
            clear = menu.addAction("&Clear the list")
            clear.triggered.connect(self.window._guard(lambda _=False: c.keep_recent([]),
                                                       "recent"))  # fmt: skip
        menu.setEnabled(bool(items))

    def toggle_help(self) -> None:
        w = self.window
        if w.help is not None and w.help.isVisible():
            w.help.hide()
            return
        if w.help is None:
            w.help = QtWidgets.QMessageBox(w)
            w.help.setObjectName("help")
            w.help.setWindowTitle("phong-explorer: keys and mouse")
            w.help.setText(help_text())
            w.help.setModal(False)
        w.help.show()
