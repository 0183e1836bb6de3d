"""The lit sphere beside the lobe plot, as Disney's BRDF Explorer shows one: a unit sphere seen
from far along +z, drawn in a scene's material and model under one white directional light at
the plot's incidence θ_i, each pixel the engine's colour at that pixel's point of the sphere
(:func:`explorer.shading.display.display_colors`: the display effects of the scene included).

Directions follow :mod:`explorer.analysis.lobes`: the plane of incidence is x-z, the light
comes from the left, toward ``(-sin θ_i, 0, cos θ_i)``, so the sphere's middle (its point
facing the viewer, where the lobe plot is measured) is lit at θ_i and the light's own point of
the sphere (its normal toward the light) is at ``(-sin θ_i, 0)`` of the disc. A press at disc
point ``(u, v)`` asks for the incidence whose light point lies at that distance from the middle:
``θ_i = asin(min(hypot(u, v), 1))`` (:func:`incidence_at`; the BRDF is isotropic, so only the
distance counts). Plain numpy and the engine: no VTK.
"""

from __future__ import annotations

import math

import numpy as np

from explorer.analysis.lobes import to_light
from explorer.core.lights import DirectionalLight
from explorer.core.scene import Viewer
from explorer.shading.display import display_colors, to_bytes

#: the light's colour: a white light of colour 1, the lobe plot's unit light
SPHERE_LIGHT = DirectionalLight(
    ambient=(0.0, 0.0, 0.0), diffuse=(1.0, 1.0, 1.0), specular=(1.0, 1.0, 1.0)
)


def sphere_scene(scene, theta_i: float):
    """``scene`` with the sphere's light at incidence ``theta_i`` (radians) and its viewer far
    along +z: the material, model, scene ambient and display effects kept."""
    light = SPHERE_LIGHT.replace(to_light=to_light(theta_i))
    return scene.replace(lights=(light,), viewer=Viewer(to_viewer=(0.0, 0.0, 1.0)))


def disc(size: int) -> tuple[np.ndarray, np.ndarray]:
    """The sphere's pixels in a ``size`` x ``size`` picture (rows top to bottom): ``inside``
    (size, size) bool, the pixels whose centre falls on the disc, and ``normals`` (k, 3) the
    sphere's unit normal (and point) under each of them, in row order."""
    c = (np.arange(size) + 0.5) * (2.0 / size) - 1.0
    u, v = np.meshgrid(c, -c)  # (v: up, rows go down)
    r2 = u * u + v * v
    inside = r2 <= 1.0
    normals = np.column_stack([u[inside], v[inside], np.sqrt(1.0 - r2[inside])])
    return inside, normals


def sphere_picture(scene, theta_i: float, size: int, background=(0.0, 0.0, 0.0)) -> np.ndarray:
    """(size, size, 3) uint8, rows top to bottom: the sphere in ``scene``'s material and model
    lit at ``theta_i`` (radians), each pixel the engine's display colour at its point; the
    pixels off the disc ``background`` (RGB in [0, 1])."""
    inside, normals = disc(size)
    out = np.empty((size, size, 3), np.uint8)
    out[:] = to_bytes(np.asarray([background], np.float64))[0]
    if len(normals):
        out[inside] = to_bytes(display_colors(sphere_scene(scene, theta_i), normals, normals))
    return out


def light_point(theta_i: float) -> tuple[float, float]:
    """Where the light's mark sits on the disc (u right, v up, each in [-1, 1]): the sphere's
    point whose normal is toward the light."""
    return to_light(theta_i)[:2]


def incidence_at(u: float, v: float) -> float:
    """The incidence (degrees, 0 to 90) a press at disc point ``(u, v)`` asks for: the light's
    point at that distance from the middle (see the module docstring)."""
    return math.degrees(math.asin(min(math.hypot(u, v), 1.0)))
