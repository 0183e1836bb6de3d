"""
Every preset
============

Every built-in preset on the Utah teapot under the preset sheet's light (one directional light
from the upper front, as in the classic chart of OpenGL teapot materials): the picture
``phong-explorer sheet`` draws, at a small tile size.
"""

import explorer
from explorer.core.atomic import write_atomic
from explorer.core.presets import builtin_dir, load_material_file
from explorer.geometry.meshes import get_mesh
from explorer.render.images import encode_png
from explorer.render.offscreen import SHEET_LIGHT_DIRECTION, sheet

scene = explorer.load_scene(
    {"lights": [{"type": "directional", "to_light": list(SHEET_LIGHT_DIRECTION)}]}
)
teapot = get_mesh("teapot", 6)
files = sorted(builtin_dir().glob("*.yaml"))  # the built-in library, not the user's own
presets = [(path.stem, load_material_file(path)) for path in files]
image = sheet(presets, scene, teapot, tile=(120, 90), columns=7)
write_atomic("presets.png", encode_png(image), overwrite=True)
print(f"{len(presets)} presets, {image.shape[1]}x{image.shape[0]} pixels")
