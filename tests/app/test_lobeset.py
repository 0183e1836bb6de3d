"""The lobe inset's several lobes (explorer.app.lobeinset, issue 41), on an off-screen plotter as
both front ends draw it: which lobes, and each curve where its values put it in its colour."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.views import sphere_view

from explorer.analysis import lobes as many
from explorer.app import lobeinset as LI
from explorer.app import model as M
from explorer.cli import build_parser
from explorer.cli.gui import start_state
from explorer.shading.display import to_bytes

SIZE = (700, 520)


@pytest.fixture
def view():
    v = sphere_view("chrome", SIZE)
    yield v
    v.plotter.close()


def test_the_lobe_sets():
    state, _ = start_state(build_parser().parse_args(["gui", "--mesh", "sphere"]))
    models = LI.lobe_set(state.replace(lobes="models"))
    assert [lb.model for lb in models] == ["phong", "blinn", "threejs"]
    two = state.replace(scene=state.scene.replace(lights=state.scene.lights * 2), lobes="lights")
    assert [lb.label.split(" (")[0] for lb in LI.lobe_set(two)] == ["light 1", "light 2"]
    sides = state.replace(lobes="sides")
    assert [lb.label for lb in LI.lobe_set(sides)] == ["A"]
    b = M.set_compare_model(M.set_compare(sides, True), "phong")
    assert [(lb.label, lb.model) for lb in LI.lobe_set(b)] == [("A", "blinn"), ("B", "phong")]
    with pytest.raises(ValueError, match="lobe_view must be one of"):
        LI.set_lobe_option(state, "lobe_view", "radial")


@pytest.mark.parametrize(
    ("plot", "quantity", "log"),
    [("polar", "intensity", False), ("cartesian", "brdf", True), ("cartesian", "albedo", False)],
)
def test_each_lobe_is_drawn_where_its_values_are_in_its_colour(view, plot, quantity, log):
    state = view.state.replace(lobes="models", lobe_view=plot, lobe_quantity=quantity, lobe_log=log)
    view.show_state(state)
    view.plotter.render()
    img = view.plotter.screenshot(return_img=True)[:, :, :3].astype(int)
    chart = view.lobe.chart
    assert chart is not None and [c.lobe.model for c in chart.curves] == list(many.MODEL_LABELS)
    title = chart.title
    for greek, latin in LI.LATIN.items():  # (the inset writes Greek letters out: VTK's fonts)
        title = title.replace(greek, latin)
    assert view.lobe.caption.GetInput().startswith(title)
    h = SIZE[1]
    for curve in chart.curves[-1:]:  # (drawn last: nothing over it)
        colour = to_bytes([curve.lobe.colour])[0]
        px = np.rint(view.lobe.to_pixels(curve.points)).astype(int)
        hits = 0
        for x, y in px:
            r = h - 1 - y
            patch = img[max(r - 1, 0) : r + 2, max(x - 1, 0) : x + 2].reshape(-1, 3)
            hits += bool(np.all(np.abs(patch - colour) <= 1, axis=1).any())
        assert hits >= 0.9 * len(px)
    view.show_state(state.replace(lobes="selected"))
    assert view.lobe.chart is None


@pytest.mark.parametrize("size", [(600, 440), SIZE])
def test_the_legend_stays_left_of_the_lit_sphere(size):
    """The three models' legend (``three.js (n/2+1)/4 (N·H)^n`` the longest) beside the lit
    sphere, in a small inset (600x440: its least side, 130 pixels) and a larger one: each
    entry's box ends inside the plot, and the panel's pixels between the plot and the sphere,
    over the legend's rows, are the panel's colour (the three.js line ran across them into the
    sphere)."""
    view = sphere_view("chrome", size)
    try:
        _legend_left_of_the_sphere(view)
    finally:
        view.plotter.close()


def _legend_left_of_the_sphere(view) -> None:
    state = view.state.replace(lobes="models")
    view.show_state(state)
    view.plotter.render()
    img = view.plotter.screenshot(return_img=True)[:, :, :3].astype(int)
    rep = view.lobe.report()
    sphere = view.lobe.sphere_report()
    assert sphere is not None  # (the sphere is drawn beside the plot at this size)
    sx = sphere["box"][0]
    x, _, w, _ = view.lobe._plot_box
    assert [e[0] + e[2] <= x + w for e in rep["legend"]] == [True] * 3
    assert rep["legend"][2][2] > 12  # (an entry, not an empty line)
    panel = to_bytes([LI.LOBE_PANEL_COLOR])[0].astype(int)
    top, bottom = rep["legend"][0][1], rep["legend"][-1][1] + rep["legend"][-1][3]
    gap = img[top:bottom, int(x + w) + 1 : sx - 1]
    assert gap.size and (np.abs(gap - panel).max(axis=2) <= 2).all()
