"""The material tab's texture maps in the real window (pytest-qt on a private Xvfb): each map a
row of the panel model (explorer.app.panelmodel's ``image`` rows) with its thumbnail, its file's
name, on / off, choose-file and clear, read from the widgets' pixels and the view's pixels."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from PySide6 import QtGui, QtWidgets

from explorer.app.session import load_session, save_session

pytestmark = pytest.mark.usefixtures("xdisplay")

TEAPOT = Path(__file__).resolve().parents[3] / "docs" / "examples" / "textured_teapot.obj"


def view_pixels(w) -> np.ndarray:
    w.plotter.render()
    return np.asarray(w.plotter.screenshot(return_img=True)[:, :, :3]).astype(int)


def widget_pixels(widget) -> np.ndarray:
    """(h, w, 3): the widget as drawn (its own grab, device pixels)."""
    image = widget.grab().toImage().convertToFormat(QtGui.QImage.Format.Format_RGB888)
    h, wd = image.height(), image.width()
    data = np.frombuffer(image.constBits(), np.uint8, count=image.bytesPerLine() * h)
    return data.reshape(h, image.bytesPerLine())[:, : 3 * wd].reshape(h, wd, 3).astype(int)


def child(w, cls, name):
    found = w.panel.material.findChild(cls, name)
    assert found is not None, name
    return found


def click(qtbot, widget):
    """A click as the user's (the button's own click: its signals, then the events)."""
    assert widget.isVisible() and widget.isEnabled()
    widget.click()
    qtbot.wait(20)


def show_maps(w, qtbot):
    """The material tab scrolled to the diffuse map's row."""
    w.panel.setCurrentIndex(0)
    w.panel.areas[0].ensureWidgetVisible(child(w, QtWidgets.QWidget, "diffuse_map"))
    qtbot.wait(50)


def test_the_diffuse_maps_thumbnail_shows_the_image_and_its_name(open_window, qtbot):
    """The thumbnail's pixels (the label as drawn) have the tiles' mean colour, its file's name
    is beside it, and a map the material has not shows no picture and ``(none)``."""
    w = open_window("--mesh", str(TEAPOT))
    show_maps(w, qtbot)
    tiles = np.asarray(Image.open(TEAPOT.parent / "tiles.png").convert("RGB"), np.float64)
    thumb = child(w, QtWidgets.QLabel, "diffuse_map_thumbnail")
    assert thumb.isVisible() and thumb.width() == 48
    pix = thumb.pixmap()
    assert not pix.isNull() and (pix.width(), pix.height()) == (32, 32)  # tiles.png's own
    got = widget_pixels(thumb)
    ph, pw = pix.height(), pix.width()
    top, left = (thumb.height() - ph) // 2, (thumb.width() - pw) // 2
    inner = got[top + 2 : top + ph - 2, left + 2 : left + pw - 2].reshape(-1, 3)
    assert np.abs(inner.mean(0) - tiles.reshape(-1, 3).mean(0)).max() < 8
    assert child(w, QtWidgets.QLabel, "diffuse_map_file").text() == "tiles.png"
    assert child(w, QtWidgets.QLabel, "specular_map_thumbnail").pixmap().isNull()
    assert child(w, QtWidgets.QLabel, "specular_map_file").text() == "(none)"
    assert not child(w, QtWidgets.QCheckBox, "specular_map_on").isEnabled()


def test_turning_the_map_off_draws_the_untextured_mesh_and_on_again_the_texture(open_window, qtbot):
    """Clicking ``diffuse_map_on`` off gives the view's pixels of the material without the map
    (the same picture as after a clear), on again the textured picture; each click one undo
    step, and undo gives the map back on."""
    w = open_window("--mesh", str(TEAPOT))
    show_maps(w, qtbot)
    on = child(w, QtWidgets.QCheckBox, "diffuse_map_on")
    textured = view_pixels(w)
    assert on.isChecked()
    click(qtbot, on)
    off = view_pixels(w)
    assert not on.isChecked() and "diffuse_map" in w.controller.state.hidden
    assert "hidden: diffuse_map" in w.status_label.text()  # the status bar names it
    assert np.abs(off - textured).max() > 100
    assert w.controller.state.material.diffuse_map is not None  # kept
    w.controller.undo()
    np.testing.assert_array_equal(view_pixels(w), textured)
    assert on.isChecked()
    click(qtbot, on)  # off
    click(qtbot, child(w, QtWidgets.QPushButton, "diffuse_map_clear"))
    np.testing.assert_array_equal(view_pixels(w), off)
    assert child(w, QtWidgets.QLabel, "diffuse_map_file").text() == "(none)"
    w.controller.undo()  # the clear
    w.controller.undo()  # the off
    np.testing.assert_array_equal(view_pixels(w), textured)


def test_choose_file_puts_the_image_on_the_mesh_and_a_bad_file_is_one_line(
    open_window, qtbot, tmp_path, monkeypatch
):
    """``diffuse_map_choose`` asks the window's file dialog: a red PNG turns the mesh red (the
    view's pixels) and its thumbnail red; a file that is not an image, a missing one and a
    truncated PNG each say one line naming the file and change nothing; undo gives the tiles
    back."""
    w = open_window("--mesh", str(TEAPOT))
    show_maps(w, qtbot)
    red = tmp_path / "red.png"
    Image.fromarray(np.full((8, 8, 3), (255, 0, 0), np.uint8)).save(red)
    answers = []
    monkeypatch.setattr(w, "ask_path", lambda *a, **k: answers.pop(0))
    choose = child(w, QtWidgets.QPushButton, "diffuse_map_choose")
    before = view_pixels(w)
    answers.append(str(red))
    click(qtbot, choose)
    got = view_pixels(w)
    mesh = np.abs(got - before).max(axis=2) > 30
    assert mesh.sum() > 500
    assert (got[mesh][:, 1:] <= got[mesh][:, :1]).all()  # no texel brighter in green or blue
    assert w.controller.state.material.diffuse_map.file == str(red)
    thumb = widget_pixels(child(w, QtWidgets.QLabel, "diffuse_map_thumbnail"))
    assert ((thumb == (255, 0, 0)).all(axis=2)).sum() > 48 * 40
    assert w.controller.store.undo_label() == "diffuse_map file"
    text = tmp_path / "notes.png"
    text.write_text("not an image\n")
    truncated = tmp_path / "cut.png"
    noise = np.random.default_rng(0).integers(0, 256, (64, 64, 3), np.uint8)
    Image.fromarray(noise).save(truncated)
    truncated.write_bytes(truncated.read_bytes()[:6000])
    for bad, words in (
        (text, "not a PNG or JPEG"),
        (tmp_path / "gone.png", "does not exist"),
        (truncated, "damaged or truncated"),
    ):
        state = w.controller.state
        answers.append(str(bad))
        click(qtbot, choose)
        assert w.controller.state == state
        assert words in w.message and bad.name in w.message and "\n" not in w.message
    w.controller.undo()
    assert w.controller.state.material.diffuse_map.file.endswith("tiles.png")
    np.testing.assert_array_equal(view_pixels(w), before)


def test_a_mesh_without_texture_coordinates_says_so(open_window, tmp_path):
    """An OBJ with no ``vt``: no map row, one line saying why."""
    obj = tmp_path / "flat.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    w = open_window("--mesh", str(obj))
    w.panel.setCurrentIndex(0)
    note = child(w, QtWidgets.QLabel, "maps_note")
    assert note.isVisible() and "no texture coordinates" in note.text()
    assert not child(w, QtWidgets.QWidget, "diffuse_map").isVisible()


def test_a_session_keeps_the_maps_and_their_off_state(open_window, qtbot, tmp_path):
    """A map turned off and another chosen are kept by a session saved and opened again."""
    w = open_window("--mesh", str(TEAPOT))
    c = w.controller
    c.set_value("diffuse_map", False, merge=False)
    c.set_value("emission_map", str(TEAPOT.parent / "tiles.png"), merge=False)
    path = save_session(tmp_path / "s.yaml", c.state)
    state, _ = load_session(path)
    assert "diffuse_map" in state.hidden and "emission_map" not in state.hidden
    assert state.material.diffuse_map == c.state.material.diffuse_map
    assert state.material.emission_map.file == str(TEAPOT.parent / "tiles.png")
    assert state.mesh_uv


@pytest.mark.parametrize("size", [(640, 480), (1000, 700)])
def test_the_status_bar_names_the_hidden_maps_whole_beside_the_engine_word(
    open_window, qtbot, monkeypatch, size
):
    """While the status bar also says the numpy engine serves (its longest word), the summary
    still names every map turned off, whole and unclipped (docs/maps_window.png read "hidden:"
    with nothing after it; at 640x480 the label was squeezed below its text: "hidden: diffuse_"),
    and its tooltip says the whole summary; the labels sit side by side in the bar."""
    from explorer.app import captions
    from explorer.shading import tiers

    w = open_window("--mesh", str(TEAPOT))
    c = w.controller
    c.set_value("emission_map", str(TEAPOT.parent / "tiles.png"), merge=False)
    c.set_value("emission_map", False, merge=False)
    c.set_value("diffuse_map", False, merge=False)
    monkeypatch.setattr(tiers, "status", lambda: f"numpy engine; {tiers.PREPARING}")
    w.engine.show()
    w.resize(*size)
    qtbot.waitUntil(lambda: w.width() == size[0])
    qtbot.wait(50)
    label, engine, bar = w.status_label, w.engine_label, w.statusBar()
    shown = label.shown()  # (drawn at the label's width)
    assert label.text() == label.toolTip() == captions.summary(c.state)
    assert "hidden: diffuse_map, emission_map" in shown, shown
    assert label.fontMetrics().horizontalAdvance(shown) <= label.contentsRect().width(), shown
    assert engine.text().startswith("numpy engine")
    boxes = [w.widget_box(x) for x in (engine, label, w.messages_indicator)]
    for (x0, _, w0, _), (x1, _, _, _) in zip(boxes, boxes[1:], strict=False):
        assert x0 + w0 <= x1, boxes  # side by side, none over the next
    x, _, width, _ = w.widget_box(bar)
    assert x <= boxes[0][0] and boxes[-1][0] + boxes[-1][2] <= x + width, boxes
