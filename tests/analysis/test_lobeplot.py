"""The lobe plots as a picture (explorer.analysis.lobeplot) and ``render --lobes``: each curve
is where its values put it, in its colour; a hidden lobe is drawn nowhere."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from explorer.analysis import lobes as L
from explorer.analysis.lobeplot import chart_pixels, draw_chart, lobe_picture
from explorer.cli import main
from explorer.core.presets import find_preset
from explorer.core.scene import Scene
from explorer.render.images import read_png
from explorer.shading.display import to_bytes


@pytest.mark.parametrize(
    ("view", "quantity", "log"),
    [("polar", "intensity", False), ("cartesian", "brdf", True), ("cartesian", "albedo", False)],
)
def test_each_curve_is_drawn_where_its_values_are_in_its_colour(view, quantity, log):
    scene = Scene(material=find_preset("jade"))
    lobes = L.model_lobes(scene, math.radians(40.0))
    lobes[0] = replace(lobes[0], visible=False)
    c = L.chart(lobes, view=view, quantity=quantity, log=log, nodes=(32, 32))
    img = draw_chart(c)
    last = c.curves[-1]  # (drawn last: nothing over it)
    colour = to_bytes([last.lobe.colour])[0]
    px = np.rint(chart_pixels(c, last.points)).astype(int)
    hits = 0
    for x, y in px:
        patch = img[max(y - 1, 0) : y + 2, max(x - 1, 0) : x + 2].reshape(-1, 3)
        hits += bool(np.all(patch == colour, axis=1).any())
    assert hits >= 0.95 * len(px)
    hidden = to_bytes([lobes[0].colour])[0]
    assert not np.all(img == hidden, axis=2).any()  # the hidden lobe: in no pixel


def test_render_lobes_writes_the_panels(tmp_path, capsys):
    out = tmp_path / "lobes.png"
    argv = [
        "render",
        "--preset",
        "gold",
        "--light-type",
        "point",
        "--light-position",
        "2",
        "2",
        "2",
        "--lobes",
        "--out",
        str(out),
    ]
    assert main(argv) == 0
    assert "lobe plots (gold, incidence 55°)" in capsys.readouterr().out
    image = read_png(out)
    assert image.shape == lobe_picture([L.chart(L.model_lobes(Scene(), 0.0))] * 3).shape
    assert main(["render", "--lobes", "--out", str(tmp_path / "x.ply")]) == 2
    assert "error: --lobes draws one picture" in capsys.readouterr().err
