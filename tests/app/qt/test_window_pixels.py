"""The window's per-pixel mode read from its real pixels (pytest-qt on a private Xvfb): the view
tab's shading radio turns it on; the window's pixels equal the engine's per-pixel picture
(explorer.render.perpixel.reference, what ``render --per-pixel`` writes) for the window's camera
and size within 1 level on every interior pixel, silhouette pixels counted; the 24-vertex cube
lit near a face shows its highlight per pixel and none per vertex; "Gouraud vs per-pixel" puts
the line of each side's time and the error in both panes."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.probes import interior
from PySide6 import QtCore, QtGui, QtWidgets

from explorer.app import view as V
from explorer.render.perpixel import reference

pytestmark = pytest.mark.usefixtures("xdisplay")
#: the viewer of the cube test: the +z face in front, a little from above and the right
CUBE_EYE = ("--viewer-eye", "0.4", "0.6", "6")


def pixels(pl) -> np.ndarray:
    """(h, w, 3) int: what the pane shows now (origin top-left)."""
    pl.render()
    return np.asarray(pl.screenshot(return_img=True)[:, :, :3]).astype(int)


def rings(view, size) -> np.ndarray:
    """(h, w) bool: the pixels of every light's ring (drawn with its handle off too)."""
    w, h = size
    yy, xx = np.mgrid[0:h, 0:w]
    out = np.zeros((h, w), bool)
    s = view.state
    for i, (x, y, _ahead) in enumerate(view.handle_pixels()):
        size = V.HANDLE_RADIUS * V.SELECTED_SCALE * s.radius / view.frame[1]
        r = view._pixel_radius(view.to_view(V.handle_point(s, i)), size)
        out |= np.abs(np.hypot(xx - x, (h - 1 - yy) - y) - (r + V.RING_GAP)) <= 3
    return out


def click_shading(w, qtbot, name: str) -> None:
    """Click the view tab's shading radio ``name`` as a person does."""
    w.panel.setCurrentIndex(2)
    radio = w.panel.findChild(QtWidgets.QRadioButton, name)
    assert radio is not None and radio.isVisible()
    qtbot.mouseClick(radio, QtCore.Qt.MouseButton.LeftButton)


def bare_view(w):
    """The view's pixels with the handles, their ring and the inset's caption left out, and
    the reference of the window's state for its camera and size; the inset's panel masked."""
    for handle in w.view.handles:
        handle.Off()
    w.view.lobe_caption.SetVisibility(False)
    got = pixels(w.plotter)
    s = w.controller.state
    size = tuple(int(v) for v in w.plotter.window_size)
    cam = V.view_camera(w.plotter.camera, s.centre, s.radius)
    ref = reference(s.shown_scene(), w.view.mesh, size, camera=cam)
    free = ~rings(w.view, size)
    x0, y0, bw, bh = w.view.lobe.box
    free[size[1] - (y0 + bh) - 2 :, : x0 + bw + 3] = False
    return got, ref, free


def test_the_window_draws_the_engines_per_pixel_picture(open_window, qtbot):
    w = open_window("--mesh", "torus", "--preset", "glossy_plastic")
    before = pixels(w.plotter)
    click_shading(w, qtbot, "per-pixel")
    assert w.controller.state.scene.shading == "per-pixel"
    got, ref, free = bare_view(w)
    bg = (np.asarray(w.plotter.renderer.GetBackground()) * 255).round()
    d = np.abs(got - ref.image(bg / 255.0).astype(int)).max(axis=2)
    inner = interior(ref.mask) & free
    edge = ref.mask & ~interior(ref.mask) & free
    assert inner.sum() > 20000 and edge.sum() > 500
    assert d[inner].max() <= 1  # every interior pixel within 1 level
    assert (d[edge] > 1).sum() <= 0.05 * edge.sum()  # silhouette pixels, counted
    assert np.abs(before - got).max(axis=2)[inner].max() > 4  # per vertex it differs
    assert not w.controller.errors


def test_the_cube_lit_near_a_face_shows_its_highlight_per_pixel_only(open_window, qtbot):
    light = ("--light-type", "point", "--light-position", "0.2", "0.3", "1.6")
    w = open_window("--mesh", "cube", "--preset", "glossy_plastic", *light, *CUBE_EYE)
    vertex, ref, free = bare_view(w)
    click_shading(w, qtbot, "per-pixel")
    pixel, ref, free = bare_view(w)
    peak = ref.peak_index()
    assert peak is not None and free[peak]
    want = ref.image()[peak].astype(int)
    assert np.abs(pixel[peak] - want).max() <= 1  # the peak where the engine puts it
    white = want.min()  # (the highlight is whiter than the blue plastic)
    assert white > 150 and vertex[peak].min() < white - 100
    face = interior(ref.mask) & free
    assert vertex[face].min(axis=1).max() < white - 100  # no highlight per vertex anywhere
    assert not w.controller.errors


def test_gouraud_vs_per_pixel_shows_the_line_in_both_panes(open_window, qtbot):
    w = open_window("--mesh", "torus", "--preset", "glossy_plastic")
    entry = w.findChild(QtGui.QAction, "gouraud_vs_per_pixel")  # View > Gouraud vs per-pixel
    assert entry is not None and entry.isEnabled()
    entry.trigger()
    qtbot.waitUntil(lambda: w.viewport.side_b.figures is not None, timeout=20000)
    pixels(w.plotter)
    f = w.viewport.side_b.figures
    line = f.line()
    assert w.view.caption.GetInput().endswith(line)
    assert w.viewport.side_b.view.caption.GetInput().endswith(line)
    errors, _ = w.viewport.side_b.errors
    assert f.max_levels == errors.max() and f.share == pytest.approx(np.mean(errors > 2))
    assert not w.controller.errors
