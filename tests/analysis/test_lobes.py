"""The plot of several lobes (explorer.analysis.lobes): each sample is the engine's value, the
albedo's quadrature against closed forms, what energy_conserving does and does not do."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from explorer.analysis import lobes as L
from explorer.core.lights import DirectionalLight
from explorer.core.material import Material
from explorer.core.scene import Scene, Viewer
from explorer.shading.effects.energy import energy_factor
from explorer.shading.shader import shade

TI = math.radians(35.0)


def _scene(model, **material):
    light = DirectionalLight(
        to_light=(-math.sin(TI), 0.0, math.cos(TI)),
        diffuse=(1, 1, 1),
        specular=(1, 1, 1),
        ambient=(0, 0, 0),
    )
    m = Material(ambient=(0, 0, 0), diffuse=(0.3,) * 3, specular=(0.8,) * 3, shininess=25.0)
    return Scene(material=m.replace(**material), lights=(light,), model=model, ambient=(0, 0, 0))


@pytest.mark.parametrize("tier", ["compiled", "numpy"])
@pytest.mark.parametrize("quantity", ["intensity", "brdf"])
def test_every_lobe_sample_is_the_engine_at_that_direction(quantity, tier):
    """One vertex facing +z, the light at 35° in the x-z plane, the viewer at each sampled view
    angle: the engine's colour (unclamped, per unit light) is the plot's value, for every lobe
    of the three models, with and without fresnel and energy_conserving."""
    scenes = [_scene(m) for m in ("blinn", "phong")]
    scenes += [_scene(m, fresnel=0.1, energy_conserving=True) for m in ("blinn", "phong")]
    lobes = [L.scene_lobe(s, TI, f"lobe {i}") for i, s in enumerate(scenes)]
    lobes += [L.scene_lobe(_scene("threejs"), TI, "three.js")]
    scenes.append(_scene("threejs"))
    plot = L.chart(lobes, view="cartesian", quantity=quantity)
    assert len(plot.curves) == len(lobes)
    for scene, curve in zip(scenes, plot.curves, strict=True):
        three = scene.model == "threejs"
        picks = np.linspace(0, len(curve.x) - 1, 9).astype(int)
        for k in picks:
            tv = curve.x[k]
            s = scene.replace(viewer=Viewer(to_viewer=(math.sin(tv), 0.0, math.cos(tv))))
            got = shade(
                s,
                [[0.0, 0.0, 0.0]],
                [[0.0, 0.0, 1.0]],
                clamp=False,
                tier="numpy" if three else tier,
            )[0, 0]
            if quantity == "brdf":
                got /= math.pi * math.cos(TI)
            assert curve.values[k] == pytest.approx(got, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("theta", [0.0, 30.0, 60.0, 85.0])
def test_the_albedo_of_a_lambert_term_is_kd(theta):
    lobe = L.Lobe("lambert", "blinn", 10.0, kd=0.6, ks=0.0, theta_i=math.radians(theta))
    assert L.albedo(lobe) == pytest.approx(0.6, rel=1e-9)


@pytest.mark.parametrize("theta", [0.0, 40.0, 75.0])
def test_the_albedo_of_a_flat_gl_lobe_is_ks_over_cos_theta_i(theta):
    """n = 0: the lobe is ks everywhere, BRDF ks/(π cos θ_i), albedo ks/cos θ_i: above 1 for
    any incidence but 0 (GL's specular has no N·L: it reflects more than it receives)."""
    ti = math.radians(theta)
    lobe = L.Lobe("flat", "phong", 0.0, kd=0.0, ks=0.9, theta_i=ti)
    assert L.albedo(lobe) == pytest.approx(0.9 / math.cos(ti), rel=1e-6)


@pytest.mark.parametrize("n", [1.0, 10.0, 100.0, 1000.0])
def test_the_albedo_of_three_js_and_of_energy_conserving_lobes(n):
    ti = np.radians([0.0, 20.0, 40.0, 55.0, 65.0, 70.0, 75.0, 80.0, 85.0, 88.0])
    three = L.Lobe("three.js", "threejs", n, kd=0.0, ks=1.0)
    _, rho = L.albedo_curve(three, ti)
    assert rho.max() <= 1.0  # three.js's lobe has its N·L: at every θ_i
    for model in ("phong", "blinn"):
        lobe = L.Lobe(model, model, n, kd=0.0, ks=1.0, energy=energy_factor(model, n))
        _, rho = L.albedo_curve(lobe, ti)
        assert rho[ti <= math.radians(70.0)].max() <= 1.0
        if model == "phong":  # the constant's aim: ks/π at normal incidence, whatever n
            assert rho[0] == pytest.approx(1.0 / math.pi, rel=1e-4)
    # GL's missing N·L is not a constant: energy_conserving still exceeds 1 at grazing light
    grazing = L.Lobe(
        "phong",
        "phong",
        1.0,
        kd=0.0,
        ks=1.0,
        theta_i=math.radians(88.0),
        energy=energy_factor("phong", 1.0),
    )
    assert L.albedo(grazing) > 1.0


def test_the_chart_legend_visibility_log_and_n_dot_l():
    scene = _scene("blinn")
    lobes = L.model_lobes(scene, TI)
    lobes[1] = replace(lobes[1], visible=False)
    plot = L.chart(lobes, view="polar")
    assert [e[0] for e in plot.legend] == [lb.label for lb in lobes]
    assert [e[2] for e in plot.legend] == [True, False, True]
    assert [c.lobe.label for c in plot.curves] == [lobes[0].label, lobes[2].label]
    for view in L.VIEWS:
        for quantity in L.QUANTITIES:
            p = L.chart(lobes, view=view, quantity=quantity, log=True, nodes=(24, 24))
            pts = np.vstack([c.points for c in p.curves])
            assert pts[:, 0].min() >= -1.0 and pts[:, 0].max() <= 1.0
            assert pts[:, 1].min() >= 0.0 and pts[:, 1].max() <= 1.0 + 1e-12
            assert p.floor == pytest.approx(p.top * 1e-4)
    times = L.chart(lobes, quantity="brdf", times_ndl=True)
    plain = L.chart(lobes, quantity="brdf")
    np.testing.assert_allclose(times.curves[0].values, plain.curves[0].values * math.cos(TI))
    assert times.title == "BRDF (1/sr) × N·L"
    with pytest.raises(ValueError, match="view must be one of"):
        L.chart(lobes, view="radial")
    with pytest.raises(ValueError, match="quantity must be one of"):
        L.chart(lobes, quantity="radiance")
