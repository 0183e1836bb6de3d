"""The lit sphere beside the lobe plot (explorer.analysis.litsphere): each pixel is the engine's
colour at that pixel's point of the sphere, the light's point is where the sphere faces the
light, and a press at a disc point asks for the incidence whose light point lies there."""

from __future__ import annotations

import math

import numpy as np
import pytest

from explorer.analysis import litsphere as LS
from explorer.core.material import Material
from explorer.core.scene import Scene
from explorer.shading.display import to_bytes
from explorer.shading.shader import shade


def _scene(model="phong"):
    m = Material(
        ambient=(0.1, 0.1, 0.1), diffuse=(0.5, 0.3, 0.2), specular=(0.8,) * 3, shininess=40.0
    )
    return Scene(material=m, model=model)


@pytest.mark.parametrize("model", ["phong", "blinn", "threejs"])
@pytest.mark.parametrize("degrees", [0.0, 30.0, 75.0])
def test_each_pixel_is_the_engine_at_its_point_of_the_sphere(model, degrees):
    """A vertex at each disc pixel's point of the unit sphere (its normal the point), the light
    at the incidence from the left, the viewer far along +z: the engine's colour, per pixel."""
    t = math.radians(degrees)
    size = 33
    img = LS.sphere_picture(_scene(model), t, size, background=(0.2, 0.2, 0.2))
    inside, normals = LS.disc(size)
    want = to_bytes(shade(LS.sphere_scene(_scene(model), t), normals, normals))
    assert np.array_equal(img[inside], want)
    assert (img[~inside] == to_bytes([(0.2, 0.2, 0.2)])[0]).all()
    # the brightest diffuse point faces the light: the light's mark there
    lit = LS.sphere_scene(
        _scene(model).replace(material=_scene().material.replace(specular=(0.0,) * 3)), t
    )
    d = shade(lit, normals, normals)[:, 0]
    u, v = LS.light_point(t)
    best = normals[np.argmax(d)]
    assert math.hypot(best[0] - u, best[1] - v) < 2.5 * 2.0 / size


@pytest.mark.parametrize("degrees", [0.0, 10.0, 45.0, 80.0, 90.0])
def test_a_press_on_the_light_point_asks_for_its_incidence(degrees):
    t = math.radians(degrees)
    u, v = LS.light_point(t)
    assert LS.incidence_at(u, v) == pytest.approx(degrees, abs=1e-9)
    # anywhere at that distance from the middle (the BRDF is isotropic), beyond the rim 90
    assert LS.incidence_at(0.0, -math.sin(t)) == pytest.approx(degrees, abs=1e-9)
    assert LS.incidence_at(0.9, 0.9) == 90.0
