"""
Accuracy against mesh size
==========================

The engine lights every vertex and VTK interpolates the colours across each triangle (Gouraud
shading), so a highlight smaller than a triangle is blurred or missed. The per-pixel reference
(``render --per-pixel``) lights every pixel at the exact sphere point under it. Here chrome
(shininess 76.8) on UV spheres of growing resolution, each beside its error against the
reference as a heat map (black: within a level; blue, green, yellow, red, white: up to 16
levels of 255).
"""

import numpy as np

import explorer
from explorer.analysis.comparison import compare_view, heat_map
from explorer.core.atomic import write_atomic
from explorer.geometry.meshes import get_mesh
from explorer.render.images import encode_png
from explorer.render.offscreen import render_image
from explorer.render.perpixel import reference

scene = explorer.load_scene(
    {"material": "chrome", "lights": [{"type": "directional", "to_light": [0.5, 0.6, 1.0]}]}
)
size = (128, 128)
rows = []
for resolution in (8, 16, 32, 64):
    sphere = get_mesh("sphere", resolution)
    picture = render_image(scene, sphere, size, label=f"{sphere.n_vertices} vertices")
    result = compare_view(scene, sphere, size)
    print(f"sphere {resolution}: RMSE {result.rmse:.2f} levels, worst pixel {result.max}")
    rows.append(np.concatenate([picture, heat_map(result.levels, result.mask)], axis=1))
grid = np.concatenate([np.concatenate(rows[:2], axis=1), np.concatenate(rows[2:], axis=1)])
write_atomic("accuracy.png", encode_png(grid), overwrite=True)

# %%
# The reference itself, lit at every pixel:

exact = reference(scene, get_mesh("sphere", 8), size).image()
write_atomic("reference.png", encode_png(exact), overwrite=True)
