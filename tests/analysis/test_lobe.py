"""The lobe inset's plot (explorer.analysis.lobe) against closed forms: each model's lobe in
the plane of incidence, its sampling where the lobe is, and every point inside the frame."""

from __future__ import annotations

import math

import numpy as np
import pytest

from explorer.analysis import lobe
from explorer.core.errors import ExplorerError
from explorer.core.lights import DirectionalLight
from explorer.core.material import Material
from explorer.core.scene import Scene, Viewer
from explorer.shading.effects.energy import energy_factor, specular_scale
from explorer.shading.equation import equation_terms


def test_blinn_at_normal_incidence_is_cos_of_half_the_view_angle():
    tv = np.linspace(-0.5 * math.pi, 0.5 * math.pi, 37)
    for n in (1.0, 10.0, 128.0):
        got = lobe.specular_lobe("blinn", n, 0.0, tv)
        assert got == pytest.approx(np.cos(tv / 2) ** n, rel=1e-12)
    phong = lobe.specular_lobe("phong", 10.0, 0.0, tv)
    assert phong == pytest.approx(np.cos(tv) ** 10.0, rel=1e-12)
    assert (lobe.specular_lobe("blinn", 10.0, 0.0, tv) >= phong).all()  # Blinn is broader


@pytest.mark.parametrize("model", ["phong", "blinn", "threejs"])
@pytest.mark.parametrize("theta_deg", [0.0, 25.0, 60.0])
def test_the_peak_is_at_the_mirror_direction(model, theta_deg):
    ti = math.radians(theta_deg)
    tv = lobe.view_angles(model, 80.0, ti)
    values = lobe.specular_lobe(model, 80.0, ti, tv, ks=1.0)
    if model == "threejs":  # Schlick's weight tilts the peak a little toward grazing
        assert abs(tv[np.argmax(values)] - ti) < math.radians(1.0)
    else:
        assert tv[np.argmax(values)] == pytest.approx(ti, abs=1e-12)
        assert values.max() == pytest.approx(1.0)
    plot = lobe.lobe_plot(model, 80.0, ti, 0.5, 0.8)
    assert plot.mirror == pytest.approx([math.sin(ti), math.cos(ti)])
    assert plot.incident == pytest.approx([-math.sin(ti), math.cos(ti)])


@pytest.mark.parametrize("model", ["phong", "blinn", "threejs"])
def test_the_lobe_is_what_the_engine_shades(model):
    """One vertex facing +z, a directional light at incidence 30° in the x-z plane, a viewer
    at each view angle in that plane: the engine's specular sum per unit light is the plot's
    value (before its scale)."""
    ti = math.radians(30.0)
    light = DirectionalLight(to_light=(-math.sin(ti), 0.0, math.cos(ti)), diffuse=(1, 1, 1),
                             specular=(1, 1, 1), ambient=(0, 0, 0))  # fmt: skip
    plain = Material(ambient=(0, 0, 0), diffuse=(0, 0, 0), specular=(0.7, 0.7, 0.7),
                     shininess=20.0)  # fmt: skip
    for m in (plain, plain.replace(fresnel=0.04, energy_conserving=True)):
        scene = Scene(material=m, lights=(light,), model=model)
        three = model == "threejs"
        effects = {"fresnel": None if three else m.fresnel, "energy": specular_scale(scene)}
        assert effects["energy"] == (1.0 if three or m is plain else energy_factor(model, 20.0))
        for tv in np.radians([-60.0, -10.0, 0.0, 20.0, 30.0, 45.0, 80.0]):
            scene = scene.replace(viewer=Viewer(to_viewer=(math.sin(tv), 0.0, math.cos(tv))))
            t = equation_terms(scene, [[0.0, 0.0, 0.0]], [[0.0, 0.0, 1.0]])
            want = 0.7 * t["specular"][0, 0] + (t["specular_f90"][0, 0] if three else 0)
            got = lobe.specular_lobe(model, 20.0, ti, [tv], ks=0.7, **effects)[0]
            assert got == pytest.approx(want)


def test_a_sharp_lobe_is_sampled_where_it_is():
    for model in ("phong", "blinn"):
        ti = math.radians(20.0)
        tv = lobe.view_angles(model, 1000.0, ti)
        values = lobe.specular_lobe(model, 1000.0, ti, tv)
        assert (values > 0.5).sum() >= 20  # a smooth curve, not a bar of two or three points
        assert np.all(np.diff(tv) > 0) and tv[0] == -0.5 * math.pi and tv[-1] == 0.5 * math.pi


@pytest.mark.parametrize("n", [0.0, 0.3, 1.0, 1000.0])
@pytest.mark.parametrize("model", ["phong", "blinn", "threejs"])
def test_every_point_lies_inside_the_frame(model, n):
    box = (20.0, 10.0, 120.0, 54.0)
    for ti in np.radians([0.0, 45.0, 89.0]):
        plot = lobe.lobe_plot(model, n, ti, 0.6, 0.5)
        r = np.hypot(*plot.lobe.T)
        assert r.max() <= 1.0 + 1e-12 and plot.scale > 0
        px = lobe.to_box(np.vstack([plot.lobe, plot.diffuse, [plot.incident, plot.mirror]]), box)
        assert (px[:, 0] >= 20).all() and (px[:, 0] <= 140).all()
        assert (px[:, 1] >= 10).all() and (px[:, 1] <= 64).all()


def test_n_zero_is_a_half_circle_and_the_diffuse_term_a_circle():
    plot = lobe.lobe_plot("phong", 0.0, math.radians(30.0), 0.2, 1.0)
    assert np.hypot(*plot.lobe.T) == pytest.approx(1.0)  # 0^0 = 1: the same everywhere
    d = np.hypot(*plot.diffuse.T)
    assert d == pytest.approx(0.2 * math.cos(math.radians(30.0)))  # kd·(N·L), scale 1


def test_a_light_below_the_surface_draws_no_lobe():
    plot = lobe.lobe_plot("blinn", 10.0, math.radians(120.0), 0.5, 0.5)
    assert not plot.lit and len(plot.lobe) == len(plot.diffuse) == 0


def test_incidence_and_contrast():
    assert lobe.incidence((0, 0, 2), (1, 0, 1)) == pytest.approx(math.radians(45.0))
    assert lobe.contrast_ratio((1, 1, 1), (0, 0, 0)) == pytest.approx(21.0)
    assert lobe.contrast_ratio((0.5, 0.5, 0.5), (0.5, 0.5, 0.5)) == pytest.approx(1.0)
    with pytest.raises(ExplorerError, match="model must be one of"):
        lobe.specular_lobe("cook", 1.0, 0.0, [0.0])


@pytest.mark.parametrize("scale", [1e-200, 1.0, 1e300])
def test_the_incidence_is_the_same_at_every_scale(scale):
    got = lobe.incidence((0.0, 0.0, 2.0 * scale), (scale, 0.0, scale))
    assert got == pytest.approx(math.radians(45.0))
