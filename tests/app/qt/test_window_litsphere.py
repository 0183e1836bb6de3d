"""The lobe inset's lit sphere in the real window (pytest-qt on a private Xvfb, issue 41): its
pixels are the engine's colours, and a drag on it with real mouse events sets the lobe plot's
incidence; the plot's pixels follow (its lobe peaks where the engine's does)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.peaks import engine_peak
from PySide6 import QtCore, QtGui, QtWidgets

from explorer.analysis import litsphere as LS
from explorer.app import model as M

pytestmark = pytest.mark.usefixtures("xdisplay")


def _pixels(pl) -> np.ndarray:
    pl.render()
    return np.asarray(pl.screenshot(return_img=True)[:, :, :3]).astype(int)


def _mouse(pl, kind, x, y, buttons) -> None:
    left = QtCore.Qt.MouseButton.LeftButton
    ev = QtGui.QMouseEvent(
        kind,
        QtCore.QPointF(x, y),
        QtCore.QPointF(x, y),
        left,
        buttons,
        QtCore.Qt.KeyboardModifier.NoModifier,
    )
    QtWidgets.QApplication.sendEvent(pl, ev)


def sphere_matches(img, rep, scene) -> float:
    """The share of the sphere's disc pixels (away from the light's mark) that are the
    engine's bytes exactly."""
    x, y, size = rep["box"]
    theta = math.radians(rep["theta"])
    want = LS.sphere_picture(scene, theta, size)
    inside, _ = LS.disc(size)
    yy, xx = np.mgrid[0:size, 0:size]
    mx, my = rep["mark"]
    away = np.hypot(xx + x - mx, yy + y - my) > 8
    got = img[y : y + size, x : x + size]
    same = (got == want).all(axis=2)
    return float(same[inside & away].mean())


def plot_peak(img, rep) -> float:
    """The angle from the plot's normal (degrees, toward the mirror side positive) of the lobe
    colour's pixel farthest from the plot's origin, read from the window's pixels."""
    ox, oy = rep["origin"]
    x, y, size = rep["box"]
    left = int(2 * ox - x)  # (the plot's box: as wide each side of its origin)
    part = img[int(y - 2) : int(oy) + 1, left : x - 4]
    yellow = (part[..., 0] > 200) & (part[..., 1] > 160) & (part[..., 2] < 120)
    rows, cols = np.nonzero(yellow)
    assert len(rows) > 10
    dx, dy = cols + left - ox, oy - (rows + y - 2)
    k = int(np.argmax(np.hypot(dx, dy)))
    return math.degrees(math.atan2(dx[k], dy[k]))


def test_a_drag_on_the_lit_sphere_sets_the_incidence_and_the_lobe_follows(open_window, tmp_path):
    w = open_window("--mesh", "icosphere", "--resolution", "3")
    w.controller.act(M.set_shininess, 30.0)
    pl = w.plotter
    lobe = w.view.lobe
    rep = lobe.sphere_report()
    state = w.controller.state
    assert state.lobe_incidence is None
    img = _pixels(pl)
    assert sphere_matches(img, rep, state.shown_scene()) >= 0.99
    t0 = rep["theta"]
    assert plot_peak(img, rep) == pytest.approx(
        engine_peak(state.shown_scene(), math.radians(t0)), abs=3.0
    )
    camera = state.camera
    # press on the sphere's middle, drag up and right to sin(62°) of its radius, let go
    x, y, size = rep["box"]
    cx, cy = x + size / 2 - 0.5, y + size / 2 - 0.5
    Type, left = QtCore.QEvent.Type, QtCore.Qt.MouseButton.LeftButton
    _mouse(pl, Type.MouseButtonPress, cx, cy, left)
    want = 62.0
    r = math.sin(math.radians(want)) * size / 2
    steps = 6
    for i in range(1, steps + 1):
        _mouse(
            pl,
            Type.MouseMove,
            round(cx + 0.6 * r * i / steps),
            round(cy - 0.8 * r * i / steps),
            left,
        )
    ex, ey = round(cx + 0.6 * r), round(cy - 0.8 * r)
    _mouse(pl, Type.MouseButtonRelease, ex, ey, QtCore.Qt.MouseButton.NoButton)
    state = w.controller.state
    # the pointer's own pixel asks for asin(its distance / the radius): within a pixel of 62°
    got = LS.incidence_at((ex + 0.5 - x) * 2 / size - 1, (y + size - ey - 0.5) * 2 / size - 1)
    assert state.lobe_incidence == pytest.approx(round(got, 1), abs=0.051)
    assert abs(state.lobe_incidence - want) < 3.0
    assert state.camera == camera  # the press was the sphere's: the camera did not turn
    assert w.controller.store.can_undo
    img = _pixels(pl)
    rep = lobe.sphere_report()
    assert rep["theta"] == pytest.approx(state.lobe_incidence)
    assert sphere_matches(img, rep, state.shown_scene()) >= 0.99
    peak = plot_peak(img, rep)
    want_peak = engine_peak(state.shown_scene(), math.radians(state.lobe_incidence))
    assert peak == pytest.approx(want_peak, abs=3.0)
    assert abs(peak - t0) > 10  # the lobe moved
    assert f"incidence {state.lobe_incidence:.0f}°" in w.view.lobe_caption.GetInput()
    # the panel's row shows it, and switched off the plot follows the light again
    field = w.findChild(QtWidgets.QCheckBox, "lobe_incidence_on")
    assert field is not None and field.isChecked()
    field.click()
    assert w.controller.state.lobe_incidence is None
    assert lobe.sphere_report()["theta"] == pytest.approx(t0)
    w.grab().save(str(tmp_path / "window_litsphere.png"))


def _hits(img, curve) -> int:
    """How many of ``curve``'s reported points have a pixel of its colour within one pixel."""
    n = 0
    for x, y in curve["px"]:
        patch = img[max(y - 1, 0) : y + 2, max(x - 1, 0) : x + 2].reshape(-1, 3)
        n += bool((np.abs(patch - curve["colour"]) <= 1).all(axis=1).any())
    return n


def _near(patch, colour, within: int = 40) -> int:
    """How many pixels of ``patch`` (h, w, 3) lie within ``within`` levels of ``colour``."""
    return int((np.abs(patch.reshape(-1, 3) - colour) <= within).all(axis=1).sum())


def test_a_lobe_is_hidden_from_its_row_and_shown_again_by_a_click_on_its_legend(open_window):
    """The three models' lobes: ``show_lobe_3`` off, three.js's curve leaves the window's
    pixels and its legend entry turns grey; a real click on that entry draws it again (the
    camera unturned)."""
    from explorer.app import lobeinset as LI

    w = open_window("--mesh", "sphere", "--preset", "chrome")
    combo = w.findChild(QtWidgets.QComboBox, "lobes")
    combo.setCurrentIndex(combo.findText("models"))
    combo.activated.emit(combo.currentIndex())  # (what a pick in the list sends)
    pl = w.plotter
    rep = w.view.lobe.report()
    three = rep["curves"][-1]
    assert three["label"].startswith("three.js") and rep["shown"] == [True] * 3
    img = _pixels(pl)
    assert _hits(img, three) >= 0.9 * len(three["px"])
    x, y, bw, bh = rep["legend"][2]
    assert _near(img[y : y + bh, x : x + bw], three["colour"]) >= 5  # its text in its colour
    box = w.findChild(QtWidgets.QCheckBox, "show_lobe_3")
    assert box is not None and box.isChecked()
    box.click()
    assert w.controller.state.lobe_hidden == frozenset({2})
    img = _pixels(pl)
    assert _hits(img, three) <= 0.2 * len(three["px"])
    rep = w.view.lobe.report()
    assert rep["shown"] == [True, True, False] and len(rep["curves"]) == 2
    assert rep["legend"][2] == [x, y, bw, bh]
    entry = img[y : y + bh, x : x + bw]
    assert _near(entry, three["colour"]) == 0  # its text grey now
    frame = np.rint(np.asarray(LI.LOBE_FRAME_COLOR) * 255)
    text = (
        (entry.max(axis=2) > 60)
        & (np.ptp(entry, axis=2) <= 6)
        & (np.abs(entry - frame).max(axis=2) > 6)
    )
    assert text.sum() >= 5
    camera = w.controller.state.camera
    Type, left = QtCore.QEvent.Type, QtCore.Qt.MouseButton.LeftButton
    _mouse(pl, Type.MouseButtonPress, x + bw // 2, y + bh // 2, left)
    _mouse(pl, Type.MouseButtonRelease, x + bw // 2, y + bh // 2, QtCore.Qt.MouseButton.NoButton)
    assert w.controller.state.lobe_hidden == frozenset() and box.isChecked()
    assert w.controller.state.camera == camera
    assert _hits(_pixels(pl), three) >= 0.9 * len(three["px"])
