"""The term strip in the real window (pytest-qt on a private Xvfb, issue 41): the panel's
``strip`` check box and ``strip_mode`` radios, and the tiles under the view read from the
window's pixels at the probe vertex, each the engine's term."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.probes import in_ring, one_ring
from PySide6 import QtWidgets

from explorer.render.strip import COLUMNS
from explorer.shading.strip import shader_strip

pytestmark = pytest.mark.usefixtures("xdisplay")


def _pixels(pl) -> np.ndarray:
    pl.render()
    return np.asarray(pl.screenshot(return_img=True)[:, :, :3]).astype(int)


def _tab_with(w, widget) -> None:
    """Show the panel tab that holds ``widget`` (a click reaches shown widgets only)."""
    tabs = w.findChild(QtWidgets.QTabWidget)
    for i in range(tabs.count()):
        if tabs.widget(i).isAncestorOf(widget):
            tabs.setCurrentIndex(i)


def test_the_strip_is_drawn_under_the_view_from_the_panel(open_window, qtbot, tmp_path):
    w = open_window("--mesh", "sphere", "--preset", "gold")
    box = w.findChild(QtWidgets.QCheckBox, "strip")
    _tab_with(w, box)
    box.click()  # (the widget's own click: it may lie below the panel's scrolled part)
    assert w.controller.state.strip and w.view.strip.on
    for mode in ("raw", "weighted"):
        radio = w.findChild(QtWidgets.QRadioButton, mode)
        radio.click()
        assert w.controller.state.strip_mode == mode
        img = _pixels(w.plotter)
        view = w.view
        strip = view.strip
        i = view.probe_vertex()
        ring = one_ring(view.mesh, i)
        point = view.to_view(view.mesh.positions[i])
        terms = shader_strip(view.drawings[0].shader, mode)
        for k, column in enumerate(COLUMNS):
            x, y = strip.tile_pixel(column, point)
            want = strip.tiles[k][i].astype(int)
            if column in terms.tiles:
                assert np.abs(want - np.rint(terms.tiles[column][i] * 255)).max() <= 1
            assert in_ring(img[y, x], strip.tiles[k], ring), column
    w.grab().save(str(tmp_path / "window_strip.png"))
    box.click()
    assert not w.view.strip.on


def test_the_inset_plots_the_three_models_lobes_from_the_panel(open_window, tmp_path):
    w = open_window("--mesh", "sphere", "--preset", "chrome")
    combo = w.findChild(QtWidgets.QComboBox, "lobes")
    _tab_with(w, combo)
    combo.setCurrentIndex(combo.findText("models"))
    combo.activated.emit(combo.currentIndex())  # (what a pick in the list sends)
    assert w.controller.state.lobes == "models"
    rep = w.view.lobe.report()
    assert [c["label"].split()[0] for c in rep["curves"]] == ["Phong", "Blinn", "three.js"]
    img = _pixels(w.plotter)
    last = rep["curves"][-1]  # (drawn last: nothing over it)
    hits = 0
    for x, y in last["px"]:
        patch = img[max(y - 1, 0) : y + 2, max(x - 1, 0) : x + 2].reshape(-1, 3)
        hits += bool((np.abs(patch - last["colour"]) <= 1).all(axis=1).any())
    assert hits >= 0.9 * len(last["px"])
    w.grab().save(str(tmp_path / "window_lobes.png"))
