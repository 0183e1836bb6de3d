"""
The compare view
================

The window's ``compare A | B``: two panes under one camera and the same lights, two materials
or one material under two models, and their difference ``A − B`` as a heat map of the largest
channel difference (in 1/255 levels). Here gold against brass, then gold under Blinn-Phong
against Phong.
"""

import numpy as np

import explorer
from explorer.analysis.comparison import channel_max, heat_map
from explorer.core.atomic import write_atomic
from explorer.core.presets import find_preset
from explorer.geometry.meshes import get_mesh
from explorer.render.images import encode_png, side_by_side
from explorer.render.offscreen import OffscreenRenderer

scene = explorer.load_scene(
    {"lights": [{"type": "point", "position": [2.0, 2.0, 3.0]}], "viewer": {"eye": [0, 0.5, 4]}}
)
teapot = get_mesh("teapot", 10)
GAP = (40, 40, 40)  # the colour between the panes


def compare(a, b, labels):
    """A | B | A − B: the two pictures and the heat map of their difference."""
    with OffscreenRenderer((160, 130)) as renderer:
        left = renderer.render(a, teapot)
        right = renderer.render(b, teapot)
        shown = [renderer.render(s, teapot, label=t) for s, t in zip((a, b), labels, strict=True)]
    diff = channel_max(np.abs(left.astype(np.int16) - right.astype(np.int16)))
    pair = side_by_side(shown[0], shown[1], gap=2, fill=GAP)
    return side_by_side(pair, heat_map(diff), gap=2, fill=GAP)


gold = scene.replace(material=find_preset("gold"))
brass = scene.replace(material=find_preset("brass"))
picture = compare(gold, brass, ("gold", "brass"))
write_atomic("compare_materials.png", encode_png(picture), overwrite=True)

# %%
# One material under two models: Phong's lobe is wider at the same shininess.

phong = gold.replace(model="phong")
picture = compare(gold, phong, ("blinn", "phong"))
write_atomic("compare_models.png", encode_png(picture), overwrite=True)
