"""
Effects
=======

The effects beyond the local model, each switched on in the scene (every one is off by
default): hard shadows on a light, Schlick's Fresnel and energy-conserving specular on the
material, HDR exposure and tone mapping on the scene, translucency through the material's
opacity. The same teapot, light and viewer in every picture; only the named key changes.
"""

import numpy as np

import explorer
from explorer.core.atomic import write_atomic
from explorer.geometry.meshes import get_mesh
from explorer.render.images import encode_png
from explorer.render.offscreen import OffscreenRenderer

base = {
    "material": {"diffuse": [0.2, 0.3, 0.6], "specular": [0.6, 0.6, 0.6], "shininess": 60},
    "lights": [{"type": "directional", "to_light": [-1.0, 0.7, 0.4]}],
    "viewer": {"eye": [0.0, 1.0, 3.2]},
}
effects = {
    "none": {},
    "shadows": {"lights": [{"type": "directional", "to_light": [-1.0, 0.7, 0.4], "shadows": True}]},
    "fresnel": {"material": {**base["material"], "fresnel": 0.04}},
    "energy": {"material": {**base["material"], "energy_conserving": True}},
    "hdr aces": {"hdr": {"exposure": -0.5, "tone_map": "aces"}},
    "opacity 0.5": {"material": {**base["material"], "opacity": 0.5}},
}
teapot = get_mesh("teapot", 10)
with OffscreenRenderer((180, 150)) as renderer:
    tiles = [
        renderer.render(explorer.load_scene({**base, **change}), teapot, label=name)
        for name, change in effects.items()
    ]
strip = np.concatenate([np.concatenate(tiles[:3], axis=1), np.concatenate(tiles[3:], axis=1)])
write_atomic("effects.png", encode_png(strip), overwrite=True)

# %%
# A shadow on the teapot is small (the spout's, the handle's). A torus lit from the side at a
# low angle shows one clearly: without shadows the inside of the far side of the ring is lit
# through the near side; with ``shadows: true`` the near side blocks the light.

torus = get_mesh("torus", 48)
light = {"type": "directional", "to_light": [1.0, 0.5, 0.0]}
scene = {**base, "viewer": {"eye": [0.0, 2.5, 2.5]}}
with OffscreenRenderer((180, 150)) as renderer:
    pair = [
        renderer.render(
            explorer.load_scene({**scene, "lights": [{**light, "shadows": on}]}),
            torus,
            label=f"shadows: {str(on).lower()}",
        )
        for on in (False, True)
    ]
write_atomic("shadows.png", encode_png(np.concatenate(pair, axis=1)), overwrite=True)
