"""The intent registry (explorer.app.intents) and the Qt window built from it: every intent is
in the menus (same title) or the view's keys, its shortcuts fire it in a real window under
Xvfb, the help lists every key, and each entry is enabled when its intent can run."""

from __future__ import annotations

import pytest

from explorer.app import intents as X
from explorer.app.controller import Controller
from explorer.app.controller.files import FileFlows


def test_the_registry_names_real_callbacks_unique_ids_and_keys():
    assert len(X.BY_ID) == len(X.INTENTS)
    for i in X.INTENTS:
        if i.run.startswith("front:"):
            assert i.run.removeprefix("front:") in X.FRONT, i.id
        elif i.run.startswith("act:"):
            assert callable(X.ACTIONS.get(i.run.removeprefix("act:"))), i.id
        else:
            owner, _, name = i.run.rpartition(".")
            cls = {"": Controller, "files": FileFlows}[owner]
            assert callable(getattr(cls, name, None)), f"{i.id}: no Controller.{i.run}"
        assert i.menu in (None, *X.MENUS), i.id
        assert i.menu or i.view_key or i.keys, f"{i.id}: neither in a menu nor on a key"
    desktop = [X.key_name(k) for i in X.INTENTS for k in i.all_keys()]
    page = [X.key_name(k) for i in X.INTENTS for k in i.web_keys()]
    assert len(desktop) == len(set(desktop)) and len(page) == len(set(page))
    assert not set(page) & X.BROWSER_KEYS
    # Ctrl+T (the turntable) is the browser's new tab: the page has its own key for it
    assert X.BY_ID["export_turntable"].web_keys() == ("Alt+T",)


def test_key_names_are_the_page_listeners():
    assert X.key_name("Ctrl+Shift+Z") == "ctrl+shift+z"
    assert X.key_name("Shift+Ctrl+z") == "ctrl+shift+z"
    assert X.key_name("F1") == "f1" and X.key_name("r") == "r" and X.key_name("Alt+T") == "alt+t"


def test_run_calls_the_method_or_the_front_ends_and_skips_a_disabled_intent():
    class Store:
        can_undo = False

    class C:
        store = Store()

        def undo(self):
            return "undone"

        def reset_camera(self):
            return "reset"

    c = C()
    assert X.run("reset_camera", c, {}) == "reset"
    assert X.run("undo", c, {}) is False  # nothing to undo: not run
    Store.can_undo = True
    assert X.run("undo", c, {}) == "undone"
    assert X.run("help", c, {"help": lambda: "helped"}) == "helped"
    with pytest.raises(ValueError, match="no intent named 'nope'"):
        X.run("nope", c, {})


@pytest.mark.usefixtures("xdisplay")
def test_every_intent_is_in_the_menus_with_its_title_or_on_a_view_key(win):
    from explorer.app.qt.menus import VIEW_KEYS

    titles = {}
    for bar_entry in win.menuBar().actions():
        for a in bar_entry.menu().actions():
            if a.objectName():
                titles[a.objectName()] = (bar_entry.text(), a.text())
    for i in X.INTENTS:
        if i.menu:
            key = f" ({i.view_key})" if i.view_key and not i.keys else ""  # shown once
            assert titles[i.id] == (f"&{i.menu}", i.title + key), i.id
            shortcuts = [s.toString() for s in win.menu_actions[i.id].shortcuts()]
            assert shortcuts == list(i.keys), i.id
        else:
            assert VIEW_KEYS[i.view_key] == i.id


@pytest.mark.usefixtures("xdisplay")
def test_the_window_shortcuts_fire_their_intents(win, qtbot, monkeypatch):
    """Each window shortcut pressed in the shown window runs its intent (the controller's
    method, or the window's own), through Qt's shortcut machinery."""
    from PySide6 import QtGui

    c = win.controller
    c.set_value("kd", 0.25)
    c.set_value("ks", 0.5)
    c.store.undo()  # something to undo and to redo: both enabled
    ran = []
    for i in X.INTENTS:
        if i.run.startswith("act:"):  # (a model action: no key of the window's)
            assert not i.keys, i.id
        elif not i.run.startswith("front:"):
            owner, _, name = i.run.rpartition(".")
            target = c.files if owner else c
            monkeypatch.setattr(target, name, lambda n=i.id: ran.append(n))
    for name in X.FRONT:
        monkeypatch.setitem(win.menus.front, name, lambda n=name: ran.append(n))
    active(win, qtbot)
    for i in X.INTENTS:
        for key in i.keys:
            seq = QtGui.QKeySequence(key)[0]
            qtbot.keyClick(win.plotter, seq.key(), seq.keyboardModifiers())
            assert ran[-1:] == [
                i.run.removeprefix("front:") if i.run.startswith("front:") else i.id
            ], key
            ran.clear()
    qtbot.keyClick(win.plotter, "r")  # a view key: the same registry
    assert ran == ["reset_camera"]


@pytest.mark.usefixtures("xdisplay")
def test_the_help_lists_every_key_of_the_registry(win, qtbot):
    from PySide6 import QtCore

    active(win, qtbot)
    qtbot.keyClick(win.plotter, QtCore.Qt.Key.Key_F1)
    said = set()  # (key, what) of each line "  KEY / KEY   what"
    for line in win.help.text().splitlines():
        keys, _, what = line.strip().partition("   ")
        said |= {(k, what) for k in keys.split(" / ")}
    for i in X.INTENTS:
        for key in i.all_keys():
            assert (key, i.what) in said, (key, i.id)


@pytest.mark.usefixtures("xdisplay")
def test_undo_and_redo_are_enabled_when_they_can_run(win):
    undo, redo = win.menu_actions["undo"], win.menu_actions["redo"]
    assert not undo.isEnabled() and not redo.isEnabled() and undo.text() == "&Undo"
    win.controller.set_value("kd", 0.25)
    assert undo.isEnabled() and not redo.isEnabled() and undo.text() == "&Undo kd"
    win.controller.undo()
    assert not undo.isEnabled() and redo.isEnabled()


@pytest.mark.usefixtures("xdisplay")
def test_the_save_preset_button_says_its_intents_title_and_keys(win):
    """The material tab's Save button runs the registry's ``save_preset``: its text and its
    tooltip are the registry's (:func:`explorer.app.intents.tooltip`)."""
    save = win.panel.material.save
    assert save.text() == X.BY_ID["save_preset"].label
    assert save.toolTip() == X.tooltip("save_preset") == "Save preset as… (Ctrl+Shift+S)"


def active(win, qtbot) -> None:
    """The window made the active one (a window shortcut reaches only the active window)."""
    from PySide6 import QtWidgets

    win.activateWindow()
    qtbot.waitUntil(lambda: QtWidgets.QApplication.activeWindow() is win, timeout=10_000)
