"""
The models side by side
=======================

One material under each specular model the engine has: OpenGL's Blinn-Phong (``blinn``, the
default), Phong's reflection vector (``phong``) and three.js's ``MeshPhongMaterial``
(``threejs``: a normalised highlight with Schlick's Fresnel, lights of intensity π). Each row is
a preset, each column a model; ``sheet(..., model=[...])`` draws every material once under each.
"""

import explorer
from explorer.core.atomic import write_atomic
from explorer.core.presets import find_preset
from explorer.geometry.meshes import get_mesh
from explorer.render.images import encode_png
from explorer.render.offscreen import sheet

scene = explorer.load_scene(
    {"lights": [{"type": "point", "position": [2.0, 2.0, 3.0]}], "viewer": {"eye": [0, 0, 4]}}
)
sphere = get_mesh("sphere", 48)
presets = [(name, find_preset(name)) for name in ("gold", "chrome", "red_plastic")]
models = ["blinn", "phong", "threejs"]
image = sheet(presets, scene, sphere, tile=(140, 120), columns=3, model=models)
write_atomic("models.png", encode_png(image), overwrite=True)

# %%
# Phong's lobe is wider than Blinn-Phong's at the same exponent (Blinn with 4n matches Phong
# with n), and three.js's highlight peaks ``(n/2 + 1)/4`` times higher and fades toward the
# terminator with N·L. The same comparison for ``jade`` (a gem of the classic table: see-through,
# its alpha is the opacity) on the teapot:

teapot = get_mesh("teapot", 8)
image = sheet(
    [("jade", find_preset("jade"))], scene, teapot, tile=(140, 120), columns=3, model=models
)
write_atomic("models_teapot.png", encode_png(image), overwrite=True)
