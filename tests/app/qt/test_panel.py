"""The panel shows the truth (issue 30): colour swatches in the colour they hold, a colour
dialog that is not painted in it and takes typed values, a wheel that scrolls the panel, every
control reachable from 640x480 to 1920x1080, typed values refused out loud, controls that show
the state after a refusal, and a message log that keeps every message whole. In-process under
Xvfb (pytest-qt), reading the widgets' real pixels and geometry."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PySide6 import QtCore, QtGui, QtWidgets

from explorer.app import model as M
from explorer.app.colours import contrast_ratio, relative_luminance, text_on
from explorer.core.material import COEFFICIENT_RANGE, SHININESS_RANGE
from explorer.shading.display import to_bytes

pytestmark = pytest.mark.usefixtures("xdisplay")
ROOT = Path(__file__).resolve().parents[3]
#: the sizes the window must lay itself out at (README: from 640x480 to full screen)
SIZES = [(640, 480), (800, 500), (1100, 720), (1920, 1080)]
TABS = ("material", "lights", "view")


def rgb_bytes(rgb) -> tuple[int, int, int]:
    """The 8-bit colour the view draws for ``rgb`` (the engine's rounding)."""
    return tuple(int(v) for v in to_bytes([rgb])[0])


def pixel(widget: QtWidgets.QWidget, point: QtCore.QPoint) -> tuple[int, int, int]:
    """The colour ``widget`` paints at ``point`` (its own coordinates), from ``grab()``."""
    image = widget.grab().toImage()
    ratio = image.devicePixelRatio()
    c = image.pixelColor(round(point.x() * ratio), round(point.y() * ratio))
    return (c.red(), c.green(), c.blue())


def swatch_pixels(button) -> set[tuple[int, int, int]]:
    """The colours painted along the button's left and right quarters at mid height (away
    from the text in the middle)."""
    w, h = button.width(), button.height()
    return {pixel(button, QtCore.QPoint(x, h // 2)) for x in (6, 8, w - 9, w - 7)}


# -- 3. swatches -------------------------------------------------------------------------------
@pytest.mark.parametrize("rgb", [(0.667, 0.0, 0.0), (0.2, 0.5, 0.9), (1.0, 1.0, 1.0)])
def test_a_material_colour_button_is_painted_in_its_value(win, rgb):
    win.controller.act(M.set_colour, "diffuse", rgb)
    button = win.panel.material.colours["diffuse"]
    assert swatch_pixels(button) == {rgb_bytes(rgb)}
    assert rgb_bytes((0.667, 0.0, 0.0)) == (170, 0, 0)  # round(255 v): no transfer function


def test_a_light_colour_button_is_painted_in_its_value(win):
    win.panel.setCurrentIndex(1)
    win.controller.act(M.set_light_colour, (0.0, 0.0, 1.0))
    button = win.panel.lights.colour
    assert swatch_pixels(button) == {(0, 0, 255)}
    assert "(0, 0, 255)" in button.toolTip()


@pytest.mark.parametrize(
    "rgb", [(0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (1.0, 1.0, 0.0), (0.5, 0.5, 0.5), (0.0, 0.4, 0.0)]
)
def test_a_colour_buttons_text_is_written_in_the_colour_of_higher_contrast(win, rgb):
    """The RGB text on a swatch, read from the painted pixels: the text's pixels (those that
    are not the swatch's colour) are the light or dark side that contrasts more with the
    swatch (WCAG 2; black was written on pure blue, 2.4:1)."""
    win.controller.act(M.set_colour, "diffuse", rgb)
    button = win.panel.material.colours["diffuse"]
    image = button.grab().toImage()
    r = button.swatch_rect()
    swatch = rgb_bytes(rgb)
    ratio = image.devicePixelRatio()
    text = [(c.red(), c.green(), c.blue()) for c in (
        image.pixelColor(round(x * ratio), round(y * ratio))
        for x in range(r.left() + 2, r.right() - 1) for y in range(r.top() + 2, r.bottom() - 1))
        if (c.red(), c.green(), c.blue()) != swatch]  # fmt: skip
    assert len(text) > 20  # the text is drawn
    darker = sum(sum(t) < sum(swatch) for t in text) > len(text) / 2
    white_wins = contrast_ratio(relative_luminance(rgb), 1.0) > contrast_ratio(
        relative_luminance(rgb), 0.0
    )
    assert darker != white_wins, (rgb, len(text))


def test_the_text_colour_rule_keeps_at_least_4_5_to_1():
    for v in np.linspace(0.0, 1.0, 256):
        for rgb in ((v, v, v), (0.0, 0.0, v), (v, 0.0, 0.0), (0.0, v, 0.0)):
            y = relative_luminance(rgb)
            t = 1.0 if text_on(rgb) == "#ffffff" else 0.0
            assert contrast_ratio(y, t) >= 4.5, rgb
    assert text_on((0.0, 0.0, 1.0)) == "#ffffff" and text_on((1.0, 1.0, 0.0)) == "#000000"


# -- 4. the colour dialog ----------------------------------------------------------------------
@pytest.mark.parametrize(("preset", "term"), [("jade", "diffuse"), ("jade", "emission")])
def test_the_colour_dialog_is_not_filled_with_the_colour(win, qtbot, preset, term):
    info = next(p for p in win.controller.presets if p.name == preset)
    win.controller.act(M.apply_preset, info.name, info.material)
    button = win.panel.material.colours[term]
    qtbot.mouseClick(button, QtCore.Qt.MouseButton.LeftButton)
    dialog = button.dialog
    qtbot.waitExposed(dialog)
    window_colour = QtWidgets.QApplication.palette().color(QtGui.QPalette.ColorRole.Window)
    want = (window_colour.red(), window_colour.green(), window_colour.blue())
    # the dialog's own background: its margins at the corners
    for p in ((2, 2), (dialog.width() - 3, 2), (2, dialog.height() - 3),
              (dialog.width() - 3, dialog.height() - 3)):  # fmt: skip
        assert pixel(dialog, QtCore.QPoint(*p)) == want, p
    assert button.styleSheet() == "" and dialog.styleSheet() == ""
    dialog.reject()


def test_the_colour_dialog_takes_typed_values(win, qtbot):
    button = win.panel.material.colours["specular"]
    for text, want in (("0.2, 0.4, 0.6", (0.2, 0.4, 0.6)), ("#ff8000", (1.0, 128 / 255, 0.0)),
                       ("0.25 0.5 0.75", (0.25, 0.5, 0.75))):  # fmt: skip
        qtbot.mouseClick(button, QtCore.Qt.MouseButton.LeftButton)
        dialog = button.dialog
        dialog.value.selectAll()
        qtbot.keyClicks(dialog.value, text)
        qtbot.keyClick(dialog.value, QtCore.Qt.Key.Key_Return)  # takes it, then OK
        assert win.controller.state.material.specular == want  # exactly what was typed
        assert not dialog.isVisible()
    before = win.controller.state
    qtbot.mouseClick(button, QtCore.Qt.MouseButton.LeftButton)
    dialog = button.dialog
    dialog.value.selectAll()
    qtbot.keyClicks(dialog.value, "1.5, 0, 0")
    dialog.accept()  # OK with a wrong value: said in the dialog, which stays open
    assert dialog.isVisible() and win.controller.state == before
    assert "specular must be 'r, g, b' with each within 0 .. 1" in dialog.problem.text()
    assert dialog.problem.isVisible()
    dialog.reject()


# -- 8. the wheel ------------------------------------------------------------------------------
def wheel(widget: QtWidgets.QWidget, clicks: int) -> None:
    """A real wheel event (``clicks`` notches, negative: toward the user) at the widget's
    centre, through the application's event delivery (event filters included)."""
    pos = QtCore.QPointF(widget.rect().center())
    glob = QtCore.QPointF(widget.mapToGlobal(widget.rect().center()))
    ev = QtGui.QWheelEvent(pos, glob, QtCore.QPoint(0, 0), QtCore.QPoint(0, 120 * clicks),
                           QtCore.Qt.MouseButton.NoButton, QtCore.Qt.KeyboardModifier.NoModifier,
                           QtCore.Qt.ScrollPhase.NoScrollPhase, False)  # fmt: skip
    QtWidgets.QApplication.sendEvent(widget, ev)


def test_the_wheel_over_a_slider_scrolls_the_panel(open_window, qtbot):
    w = open_window()
    w.resize(800, 500)
    qtbot.waitUntil(lambda: w.panel.widget(0).verticalScrollBar().maximum() > 0)
    bar = w.panel.widget(0).verticalScrollBar()
    ks = w.panel.material.sliders["ks"]
    for widget in (ks.slider, ks.field):
        before, top = w.controller.state, bar.value()
        wheel(widget, -1)
        assert w.controller.state == before and not w.controller.state.edited
        assert bar.value() > top, "the panel did not scroll"
    w.activateWindow()
    qtbot.waitUntil(w.isActiveWindow)
    ks.slider.setFocus()  # clicked into: then the wheel is the slider's
    qtbot.waitUntil(ks.slider.hasFocus)
    wheel(ks.slider, -1)
    assert w.controller.state.material.scalars()[2] != pytest.approx(
        before.material.scalars()[2], abs=1e-9
    )
    assert not w.controller.errors, w.controller.errors


# -- 9. layout at every size -------------------------------------------------------------------
INTERACTIVE = (QtWidgets.QAbstractButton, QtWidgets.QAbstractSlider, QtWidgets.QAbstractSpinBox,
               QtWidgets.QComboBox, QtWidgets.QLineEdit, QtWidgets.QAbstractItemView)  # fmt: skip


def unreachable(window, area: QtWidgets.QScrollArea) -> list[str]:
    """The visible interactive widgets of a tab that are cut: not whole inside the visible
    viewport across, or below / above it with no vertical scroll bar to reach them."""
    viewport = area.viewport()
    vbar = area.verticalScrollBar()
    content = area.widget()
    bad = []
    for w in content.findChildren(QtWidgets.QWidget):
        if not isinstance(w, INTERACTIVE) or not w.isVisibleTo(content):
            continue
        if isinstance(w.parentWidget(), QtWidgets.QAbstractSpinBox | QtWidgets.QComboBox):
            continue  # a spin box's own line edit
        top_left = w.mapTo(viewport, QtCore.QPoint(0, 0))
        r = QtCore.QRect(top_left, w.size())
        across = r.left() >= 0 and r.right() < viewport.width()
        y0 = w.mapTo(content, QtCore.QPoint(0, 0)).y()  # in the scrolled content
        down = y0 >= 0 and y0 + w.height() <= vbar.maximum() + viewport.height()
        inside = r.top() >= 0 and r.bottom() < viewport.height()
        if not across or not (inside or (vbar.isVisible() and down)):
            bad.append(f"{w.objectName() or type(w).__name__} at {r.getRect()} in viewport "
                       f"{viewport.width()}x{viewport.height()}")  # fmt: skip
    return bad


def laid_out(qtbot, w, size):
    w.resize(*size)
    qtbot.waitUntil(lambda: (w.width(), w.height()) == size, timeout=5000)
    QtWidgets.QApplication.processEvents()
    w.render()
    return w


def check_window(w, size, tab: int) -> None:
    w.panel.setCurrentIndex(tab)
    QtWidgets.QApplication.processEvents()
    assert (w.width(), w.height()) == size, "the window did not take the size"
    panel = w.widget_box(w.panel)
    assert panel[0] >= 0 and panel[0] + panel[2] <= w.width(), f"panel {panel} cut"
    for view in (w.plotter, w.plotter_b):
        if view is not None and view.isVisible():
            x, y, vw, vh = w.widget_box(view)
            assert vw >= 100 and vh >= 100 and x >= 0 and x + vw <= panel[0], (x, vw, panel)
    area = w.panel.widget(tab)
    assert not area.horizontalScrollBar().isVisible(), "a tab needs sideways scrolling"
    bad = unreachable(w, area)
    assert not bad, f"{TABS[tab]} at {size[0]}x{size[1]}: cut: {bad}"


@pytest.mark.parametrize("size", SIZES, ids=[f"{a}x{b}" for a, b in SIZES])
@pytest.mark.parametrize("tab", range(3), ids=TABS)
def test_every_tab_is_whole_or_scrolls_at_every_size(open_window, qtbot, size, tab):
    w = laid_out(qtbot, open_window(), size)
    if tab == 1:  # the lights tab with everything a spot shows, and two lights
        w.controller.act(M.add_light)
        w.controller.act(M.set_light_type, "spot")
    check_window(w, size, tab)
    assert not w.controller.errors, w.controller.errors


@pytest.mark.parametrize("size", SIZES, ids=[f"{a}x{b}" for a, b in SIZES])
def test_the_compare_and_difference_views_fit_at_every_size(open_window, qtbot, size):
    w = laid_out(qtbot, open_window(), size)
    w.controller.act(M.set_compare, True)
    qtbot.waitUntil(lambda: w.plotter_b.isVisible() and w.plotter_b.width() > 50)
    w.controller.act(M.set_compare_difference, True)
    for tab in range(3):
        check_window(w, size, tab)
    w.controller.act(M.set_compare, False)
    w.controller.act(M.set_difference, True)
    qtbot.waitUntil(lambda: w.heat.shown, timeout=60_000)
    check_window(w, size, 2)
    assert not w.controller.errors, w.controller.errors


def test_the_preset_list_grows_with_the_window(open_window, qtbot):
    w = laid_out(qtbot, open_window(), (1100, 720))
    presets = w.panel.material.presets
    row = presets.visualItemRect(presets.item(0)).height()
    rows_small = presets.viewport().height() // row
    laid_out(qtbot, w, (1920, 1080))
    rows_big = presets.viewport().height() // row
    assert rows_big >= min(presets.count(), rows_small + 10), (rows_small, rows_big)


# -- 10. typed values --------------------------------------------------------------------------
def type_into(qtbot, field, text: str) -> None:
    field.setFocus()
    field.lineEdit().selectAll()
    qtbot.keyClicks(field.lineEdit(), text)
    qtbot.keyClick(field.lineEdit(), QtCore.Qt.Key.Key_Return)


@pytest.mark.parametrize(
    ("key", "text", "lo", "hi"),
    [("shininess", "5000", *SHININESS_RANGE), ("ka", "2.5", *COEFFICIENT_RANGE),
     ("kd", "-1", *COEFFICIENT_RANGE), ("ks", "abc", *COEFFICIENT_RANGE)],
)  # fmt: skip
def test_a_typed_value_out_of_range_is_refused_out_loud(win, qtbot, key, text, lo, hi):
    before = win.controller.state
    field = win.panel.material.sliders[key].field
    shown = field.text()
    type_into(qtbot, field, text)
    assert win.controller.state == before
    assert field.text() == shown  # the state's value, not a clamped or truncated one
    want = f"{key} must be a number within {lo:g} .. {hi:g}, got '{text}'"
    assert want in win.message and win.statusBar().currentMessage() == win.message
    assert any(want in m.text for m in win.messages.said.messages)
    win.controller.errors.clear()
    logged = len(win.messages.said.messages)
    type_into(qtbot, field, "0.5")  # a value in range is taken
    assert win.controller.state != before
    # and the error goes from the status bar (it stayed through later edits); nothing logged
    assert win.statusBar().currentMessage() == "" and len(win.messages.said.messages) == logged


def test_a_typed_light_value_out_of_range_is_refused_out_loud(win, qtbot):
    win.panel.setCurrentIndex(1)
    before = win.controller.state
    type_into(qtbot, win.panel.lights.sliders["elevation"].field, "120")
    assert win.controller.state == before
    assert "elevation must be a number within -90 .. 90, got '120'" in win.message
    # the log says "error" once: "HH:MM:SS error: elevation ..." (it said "error: error: ...")
    line = win.messages.plain_text().splitlines()[-1]
    assert line.endswith("error: elevation must be a number within -90 .. 90, got '120'"), line
    assert "error: error" not in win.messages.plain_text()
    win.controller.errors.clear()


# -- 11. a control shows the state after a refusal ---------------------------------------------
def test_a_refused_attenuation_leaves_no_stale_field(win, qtbot):
    win.panel.setCurrentIndex(1)
    win.controller.act(M.set_light_field, "attenuation", (1.0, 0.5, 0.0))
    kc, kl, _ = win.panel.lights.attenuation
    type_into(qtbot, kc, "0")
    assert win.controller.state.selected_light.attenuation == (0.0, 0.5, 0.0)
    type_into(qtbot, kl, "0")  # all zero: refused by the light
    assert win.controller.state.selected_light.attenuation == (0.0, 0.5, 0.0)
    assert "all zero" in win.message
    assert kl.value() == 0.5 and kl.text() == "0.500"
    win.controller.errors.clear()


@pytest.mark.parametrize(
    ("action", "control"),
    [("set_light_field", lambda t: t.lights.exponent),
     ("set_light_intensity", lambda t: t.lights.sliders["intensity"]),
     ("place_light", lambda t: t.lights.sliders["azimuth"]),
     ("set_coefficient", lambda t: t.material.sliders["kd"]),
     ("set_shininess", lambda t: t.material.sliders["shininess"])],
)  # fmt: skip
def test_every_control_shows_the_state_after_a_refused_action(win, monkeypatch, action, control):
    """The mechanism: whatever a control sent, a refusal re-reads the state into the panel
    (here every action of the kind is made to refuse)."""
    win.controller.act(M.set_light_type, "spot")
    before = win.controller.state

    def refuse(*_args):
        raise M.ExplorerError(f"{action} refused")

    monkeypatch.setattr(M, action, refuse)
    c = control(win.panel)
    shown = c.value()
    c.field.setValue(shown / 2 + 0.3)  # a value in range the action then refuses
    assert win.controller.state == before and f"{action} refused" in win.message
    assert c.value() == shown and c.slider.value() == c._to_step(shown)
    win.controller.errors.clear()


# -- 12. the message log -----------------------------------------------------------------------
def test_the_obj_warnings_are_whole_in_the_message_log(win, qtbot):
    from explorer.app.start import add_mesh_materials

    obj = ROOT / "docs" / "examples" / "teapot_parts.obj"
    before = win.controller.state
    win.controller.files.open_file(obj)
    qtbot.waitUntil(win.messages.isVisible)  # the log opened by itself
    text = win.messages.plain_text()
    _, expected = add_mesh_materials(before, win.view.mesh)  # the reader's own warnings
    assert len(expected) == 3, expected
    for line in expected:
        assert line in text, f"not whole in the log: {line}"
    assert win.messages_indicator.text() == "1 warning"
    win.messages.copy_all()
    assert QtGui.QGuiApplication.clipboard().text() == text
    win.messages.hide()
    win.menu_actions["messages"].trigger()
    assert win.messages.isVisible()


def test_the_start_meshs_warnings_are_in_the_message_log(open_window, qtbot):
    """`gui --mesh teapot_parts.obj`: the warnings its .mtl's reader printed at the start are
    in the message log as well (whole), not only in the terminal; the log does not open over
    the window at the start (it did: docs/gui_file_menu.png showed it under the File menu)."""
    from explorer.app.start import add_mesh_materials

    obj = ROOT / "docs" / "examples" / "teapot_parts.obj"
    from explorer.cli import build_parser
    from explorer.cli.gui import start_state

    found: list[str] = []
    start_state(build_parser().parse_args(["gui", "--mesh", str(obj)]), found)
    assert len(found) == 3, found
    win = open_window("--mesh", str(obj))
    qtbot.waitUntil(lambda: win.messages_indicator.text() == "1 warning")
    assert not win.messages.isVisible()  # kept, not opened over the window at the start
    text = win.messages.plain_text()
    _, expected = add_mesh_materials(win.controller.state, win.view.mesh)
    for line in expected:
        assert line in text, f"not whole in the log: {line}"
    assert found == expected


# -- 13b. duplicate ----------------------------------------------------------------------------
def test_duplicate_is_an_exact_copy_and_the_list_says_so(win):
    win.panel.setCurrentIndex(1)
    tab = win.panel.lights
    tab.buttons["duplicate"].click()
    lights = win.controller.state.scene.lights
    assert len(lights) == 2 and lights[1] == lights[0] and win.controller.state.light == 1
    assert tab.list.item(1).text().endswith("(same place as 1)")
    assert "same place" not in tab.list.item(0).text()
    tab.sliders["azimuth"].field.setValue(-100.0)  # moved: no longer said
    assert "same place" not in tab.list.item(1).text()


# -- issue 38: the panel model's rows ----------------------------------------------------------
#: the rows of a mesh file's own materials: hidden here (a built-in mesh)
MESH_MATERIALS = ("mesh_materials", "group", "use_mesh_materials")
#: the lobes past the three models' (shown with more lobes in the set: four lights or more)
MORE_LOBES = tuple(f"show_lobe_{i}" for i in range(4, 9))


def every_row_shown(c) -> None:
    """A spot light, the HDR display, Fresnel, the compare view, the strip, the inset's
    several lobes and its incidence on: every row of the panel model is shown."""
    from explorer.app import panelmodel as P

    c.act(M.set_light_type, "spot", label="light type")
    assert c.set_value("compare", True, merge=False)
    assert c.set_value("hdr", True, merge=False)
    assert c.set_value("lobes", "models", merge=False)
    assert c.set_value("strip", True, merge=False)
    assert c.set_value("lobe_incidence", P.row("lobe_incidence").optional, merge=False)
    assert c.set_value("fresnel", P.row("fresnel").optional, merge=False)


def test_every_row_is_drawn_in_its_tab_named_by_its_key(win):
    """Each row of :mod:`explorer.app.panelmodel` is a widget of its tab whose object name and
    accessible name are the row's, and so are its parts' (``rowlayout.names``: a number's
    ``<key>_slider``, an optional number's ``<key>_on``, an image's file, switch, choose and
    clear); the page's test reads the same names in the DOM."""
    from explorer.app import panelmodel as P
    from explorer.app import rowlayout

    every_row_shown(win.controller)
    assert not win.controller.state.mesh_uv
    # the lists, the buttons and the views' toggles are rows too, drawn by no code of the tab's
    assert {"preset", "light", "add_light", "difference", "compare", "swap"} <= set(P.BY_KEY)
    for r in P.ROWS:
        tab = getattr(win.panel, r.tab)
        for name in rowlayout.names(r):
            found = tab.findChildren(QtWidgets.QWidget, name)
            assert len(found) == 1, (r.key, name, found)
            assert found[0].accessibleName() == name, name
            # a mesh file's own materials are shown with an OBJ's groups (test_filemenu.py), the
            # maps with a mesh's (u, v) (test_window_maps.py): the start's icosphere has none
            # (and the line saying the scene has no lights: it has one)
            hidden = r.key in (*MESH_MATERIALS, *MORE_LOBES, "no_lights") or r.kind == "image"
            assert found[0].isVisibleTo(tab) != hidden, name
    win.controller.undo()  # fresnel off: its number hidden, its switch shown and unchecked
    rows = win.panel.material.rows
    assert not rows.sliders["fresnel"].isVisibleTo(win.panel.material)
    assert not rows.switches["fresnel"].isChecked()


#: each effect row worked through its widget: (tab, the click or the value)
EFFECTS = {
    "shadows": ("lights", lambda rows: rows.widgets["shadows"].click()),
    "fresnel_on": ("material", lambda rows: rows.switches["fresnel"].click()),
    "fresnel": ("material", lambda rows: rows.sliders["fresnel"].field.setValue(0.6)),
    "energy_conserving": ("material", lambda rows: rows.widgets["energy_conserving"].click()),
    "two_sided": ("view", lambda rows: rows.widgets["two_sided"].click()),
    "local_viewer": ("view", lambda rows: rows.widgets["local_viewer"].click()),
    "hdr": ("view", lambda rows: rows.widgets["hdr"].click()),
    "exposure": ("view", lambda rows: rows.sliders["exposure"].field.setValue(1.5)),
    "tone_map": ("view", lambda rows: rows.widgets["tone_map"].activated.emit(2)),
}


@pytest.mark.parametrize("effect", list(EFFECTS))
def test_each_effect_row_changes_the_picture_and_undo_restores_it(open_window, effect):
    """Through its widget, each effect changes the colours the view draws (shadows and
    two-sided lighting change the vertices the light does not reach, so those two are read
    from the drawn colours; the others from the view's pixels too), as one undo step."""
    import numpy as np

    w = open_window("--mesh", "teapot", "--resolution", "8", "--preset", "gold")
    c = w.controller
    if effect in ("fresnel", "exposure", "tone_map"):  # their switch first
        c.set_value(
            "fresnel" if effect == "fresnel" else "hdr",
            0.04 if effect == "fresnel" else True,
            merge=False,
        )
    w.render()
    colours = w.view.displayed_colors()
    shot = np.asarray(w.plotter.screenshot(return_img=True)[:, :, :3]).copy()
    tab, work = EFFECTS[effect]
    work(getattr(w.panel, tab).rows)
    w.render()
    assert c.store.undo_label() == effect.removesuffix("_on")
    assert (w.view.displayed_colors() != colours).any(), effect
    if effect not in ("shadows", "two_sided"):
        assert (np.asarray(w.plotter.screenshot(return_img=True)[:, :, :3]) != shot).any()
    c.undo()
    w.render()
    assert (w.view.displayed_colors() == colours).all()
    assert not c.errors, c.errors


def test_a_meshs_own_material_kept_on_another_mesh_is_called_by_its_name(win, qtbot):
    """Open an OBJ with its own materials, then choose a built-in mesh: the material kept
    over the new mesh is called by its .mtl name in the panel, the status bar and the compare
    caption (they said "scene material", which it is not)."""
    win.controller.files.open_file(ROOT / "docs" / "examples" / "teapot_parts.obj")
    name = win.controller.state.scene.material.name
    assert name in ("Porcelain", "Cobalt_Glaze", "Gold_Trim")
    assert win.controller.files.choose_mesh("sphere")
    assert win.controller.state.groups is None and win.controller.state.preset is None
    win.panel.view.compare.click()
    qtbot.waitUntil(lambda: win.plotter_b.width() > 100)
    texts = [
        win.panel.material.preset_label.text(),
        win.status_label.text(),
        win.view.caption.GetInput(),
    ]
    for text in texts:
        assert name in text and "scene material" not in text, texts
    assert win.panel.material.preset_label.text().startswith("material: ")  # not a preset
    win.controller.errors.clear()  # (the .mtl's warnings)


def test_the_lights_tab_says_when_the_scene_has_no_lights(win):
    """The line that says so is the panel model's ``no_lights`` row (the window's own label
    before): shown, in the lights tab, once the last light is removed; hidden again on undo."""
    from explorer.app import panelmodel as P

    tab, c = win.panel.lights, win.controller
    line = tab.findChild(QtWidgets.QLabel, "no_lights")
    assert line is not None and not line.isVisibleTo(tab)
    while c.state.scene.lights:
        assert c.set_value("remove_light", True, merge=False)
    assert line.isVisibleTo(tab) and line.text() == P.NO_LIGHTS
    assert line.accessibleName() == "no_lights"
    assert not tab.rows.widgets["remove_light"].isEnabled()
    c.undo()
    assert not line.isVisibleTo(tab)
