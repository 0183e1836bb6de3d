"""The explorer window's menus, shortcuts, the 3D view's keys and the help (in
:class:`explorer.app.qt.window.ExplorerWindow`), all built from the intent registry
(:data:`explorer.app.intents.INTENTS`): each entry and key runs an intent, a method of the
window's :class:`~explorer.app.controller.Controller` or one of the window's own (quit, the
help, the message log)."""

from __future__ import annotations

from PySide6 import QtCore, QtGui, QtWidgets

from explorer.app import captions
from explorer.app import intents as intents_
from explorer.app.intents import BY_ID, INTENTS, MENUS
from explorer.app.qt.messages import open_log
from explorer.app.start import TITLE

#: keys of the 3D view (active while it has the keyboard focus): key -> intent id (from the
#: registry, :data:`explorer.app.intents.INTENTS`)
VIEW_KEYS = {i.view_key: i.id for i in INTENTS if i.view_key}


def help_text() -> str:
    """Every key and mouse control, one per line (from the registry)."""
    return "\n".join(intents_.help_lines())


class ViewKeys(QtCore.QObject):
    """The 3D view's keys: :data:`VIEW_KEYS` run their intents; every other plain key is
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
            self.window._guard(self.window.menus.run, f"key {key}")(VIEW_KEYS[key])
        return True


class Menus:
    """The menu bar of ``window`` (sets ``window.menu_actions``, ``window.recent_menu`` and
    ``window.help``) and the 3D view's keys, both from the intent registry
    (:data:`explorer.app.intents.INTENTS`), and the Save button of the material tab; the
    controller's choices port shows undo / redo and the recent files here."""

    def __init__(self, window):
        self.window = w = window
        c = w.controller
        #: the window's own callbacks of the registry's ``front:NAME`` intents
        self.front = {
            "quit": w.close,
            "help": self.toggle_help,
            "messages": lambda: open_log(w.messages),
        }
        bar = w.menuBar()
        self.actions = w.menu_actions = {}
        for name in MENUS:
            menu = bar.addMenu(f"&{name}")
            for n, group in enumerate(intents_.menu(name)):
                if n:
                    menu.addSeparator()
                for intent in group:
                    self.add_action(menu, intent)
                if intent.id == "open":  # the recent files follow File > Open
                    self.recent = w.recent_menu = menu.addMenu("Open &recent")
                    self.recent.setObjectName("recent")
        w.panel.material.save.clicked.connect(w._guard(c.files.save_preset_as, "save preset"))
        self._view_keys = ViewKeys(w)
        w.plotter.installEventFilter(self._view_keys)
        w.help = None

    def run(self, intent_id: str):
        """Run intent ``intent_id`` (:func:`explorer.app.intents.run`)."""
        return intents_.run(intent_id, self.window.controller, self.front)

    def add_action(self, menu, intent) -> QtGui.QAction:
        """The menu entry of ``intent`` (``menu_actions[intent.id]``): its title (and view
        key), its shortcuts, running the intent with its errors shown."""
        key = f" ({intent.view_key})" if intent.view_key and not intent.keys else ""
        a = QtGui.QAction(intent.title + key, self.window)
        a.setObjectName(intent.id)
        a.setShortcuts([QtGui.QKeySequence(s) for s in intent.keys])
        a.triggered.connect(self.window._guard(lambda _=False: self.run(intent.id), intent.id))
        menu.addAction(a)
        self.actions[intent.id] = a
        return a

    def refresh(self) -> None:
        """Each entry enabled when its intent can run now."""
        for name, on in intents_.enabled(self.window.controller).items():
            if name in self.actions:
                self.actions[name].setEnabled(on)

    def show_history(self, undo: str | None, redo: str | None) -> None:
        """Undo and redo named after what they undo or redo; every entry enabled when its
        intent can run (undo and redo: when there is something to undo or redo)."""
        for name, label in (("undo", undo), ("redo", redo)):
            self.actions[name].setText(intents_.history_title(name, label))
        self.refresh()

    def show_recent(self, items: list[str]) -> None:
        menu, c = self.recent, self.window.controller
        menu.clear()
        for i, path in enumerate(items):
            a = menu.addAction(captions.recent_entry(i, path))
            a.setObjectName(f"recent_{i + 1}")
            a.triggered.connect(
                self.window._guard(lambda _=False, p=path: c.files.open_recent(p), "open recent")
            )
        if items:
            menu.addSeparator()
            clear = menu.addAction("&Clear the list")
            clear.triggered.connect(
                self.window._guard(lambda _=False: c.files.keep_recent([]), "recent")
            )
        menu.setEnabled(bool(items))

    def toggle_help(self) -> None:
        w = self.window
        if w.help is not None and w.help.isVisible():
            w.help.hide()
            return
        if w.help is None:
            w.help = QtWidgets.QMessageBox(w)
            w.help.setObjectName("help")
            w.help.setWindowTitle(f"{TITLE}: {BY_ID['help'].label.lower()}")
            w.help.setText(help_text())
            w.help.setModal(False)
        w.help.show()
