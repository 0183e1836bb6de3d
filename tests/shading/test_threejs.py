"""The ``threejs`` specular model: three.js's MeshPhongMaterial (normalised Blinn-Phong with
Schlick's Fresnel on the specular colour), against closed forms and an independent scalar
transcription of three.js's GLSL (tests/helpers/threejs_oracle.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.scenes import check_oracle, random_gl_scene
from helpers.threejs_oracle import threejs_vertex_color
from hypothesis import given, settings
from hypothesis import strategies as st

import explorer
from explorer.app.model import State, next_model, set_term
from explorer.core.material import MODELS
from explorer.core.presets import find_preset
from explorer.geometry import meshes as M
from explorer.shading.equation import THREEJS_FRESNEL, equation_shade, threejs_fresnel
from explorer.shading.plan import make_plan
from explorer.shading.shader import Shader

Z = [0.0, 0.0, 1.0]


def head_on(material: dict, light: dict | None = None) -> dict:
    """Light and viewer along the normal (0, 0, 1): N·L = N·H = V·H = 1."""
    light = light or {"type": "directional", "to_light": Z}
    return {"material": material, "model": "threejs", "ambient": [0.1, 0.2, 0.3],
            "viewer": {"to_viewer": Z}, "lights": [light]}  # fmt: skip


@pytest.mark.parametrize("precision", ["float64", "float32"])
def test_head_on_closed_form(precision):
    """N = L = V: colour = e + a_m·a + d_m·d_i + (n/2 + 1)/4·(s_m·(1 - g) + g)·s_i with
    g = 2^(A + B) (three.js's F at V·H = 1)."""
    n = 12.0
    mat = {"ambient": [0.2, 0.1, 0.0], "diffuse": [0.3, 0.2, 0.1], "specular": [0.05, 0.1, 0.0],
           "emission": [0.01, 0.0, 0.02], "shininess": n}  # fmt: skip
    light = {"type": "directional", "to_light": Z, "diffuse": [0.5, 0.6, 0.7],
             "specular": [0.4, 0.3, 0.2], "ambient": [0, 0, 0]}  # fmt: skip
    got = explorer.shade(head_on(mat, light), [[0, 0, 0]], [Z], precision=precision, clamp=False)
    g = 2.0 ** sum(THREEJS_FRESNEL)
    want = [
        mat["emission"][j]
        + mat["ambient"][j] * [0.1, 0.2, 0.3][j]
        + mat["diffuse"][j] * light["diffuse"][j]
        + (n / 2 + 1) / 4 * (mat["specular"][j] * (1 - g) + g) * light["specular"][j]
        for j in range(3)
    ]
    np.testing.assert_allclose(got[0], want, rtol=0, atol=1e-12 if precision == "float64" else 1e-6)


def test_black_specular_still_has_the_grazing_highlight():
    """F = s_m + (1 - s_m)·g: with s_m = 0 the highlight is g·D·G·π·(N·L), rising toward
    grazing angles, and the plan keeps the specular term (saying why)."""
    mat = {"diffuse": [0, 0, 0], "ambient": [0, 0, 0], "specular": [0, 0, 0], "shininess": 1}
    angles = np.radians([0.0, 45.0, 80.0])
    # light and viewer mirrored about the normal at angle t: N·H = 1, V·H = cos t
    views = [[math.sin(t), 0, math.cos(t)] for t in angles]
    out = []
    for t, v in zip(angles, views, strict=True):
        scene = head_on(mat, {"type": "directional", "to_light": [-v[0], 0, v[2]]})
        scene["viewer"] = {"to_viewer": v}
        c = explorer.shade(scene, [[0, 0, 0]], [Z], clamp=False)[0]
        want = float(threejs_fresnel([math.cos(2 * t)])[0]) * 1.5 / 4 * math.cos(t)
        np.testing.assert_allclose(c, want, rtol=1e-12)
        out.append(c[0])
    assert out[0] < out[1] < out[2]
    plan = make_plan(explorer.load_scene(head_on(mat)))
    assert plan.specular
    assert any("grazing" in why for item, _, why in plan.reasons if item == "specular")
    assert not make_plan(explorer.load_scene(dict(head_on(mat), model="blinn"))).specular


def test_fresnel_weight_is_three_js_form():
    """g(1) = 2^(A + B), g(0) = 1 (also where L = -V), and within 0.01 of (1 - V·H)^5
    (Epic's fit, as three.js's comment says)."""
    c = np.linspace(0, 1, 101)
    v_dot_l = 2 * c * c - 1  # V·H = sqrt((1 + V·L) / 2)
    g = threejs_fresnel(v_dot_l)
    assert g[0] == 1.0 and g[-1] == pytest.approx(2.0 ** sum(THREEJS_FRESNEL))
    assert np.abs(g - (1 - c) ** 5).max() < 0.01
    assert np.all(np.diff(g) < 0)


@pytest.mark.parametrize("seed", range(8))
def test_equals_three_js_glsl_on_random_scenes(seed):
    """Random scenes (directional, point and spot lights; local and infinite viewers) against
    the scalar transcription of three.js's shader; float32 within 1/255 of float64."""
    rng = np.random.default_rng(100 + seed)
    check_oracle(dict(random_gl_scene(rng), model="threejs"), threejs_vertex_color, rng, 200)


@settings(max_examples=40, deadline=None)
@given(
    shininess=st.floats(0, 1000),
    spec=st.floats(0, 1),
    seed=st.integers(0, 2**16),
)
def test_finite_and_non_negative(shininess, spec, seed):
    """Any shininess in the file range, any specular: finite, >= 0 unclamped, and the same
    whether the shader pins the compiled tier or not (threejs always runs on the equation)."""
    rng = np.random.default_rng(seed)
    scene = dict(random_gl_scene(rng), model="threejs")
    scene["material"] = dict(scene["material"], shininess=shininess, specular=[spec] * 3)
    P, N = rng.normal(size=(50, 3)), rng.normal(size=(50, 3))
    c = explorer.shade(scene, P, N, clamp=False)
    assert np.isfinite(c).all() and (c >= 0).all()
    pinned = explorer.shade(scene, P, N, clamp=False, tier="compiled")
    np.testing.assert_array_equal(c, pinned)
    np.testing.assert_array_equal(c, equation_shade(explorer.load_scene(scene), P, N, clamp=False))


def test_fresnel_and_energy_do_not_apply():
    """The model has its own Fresnel and normalisation: the material's are planned out, with
    the reason, and change nothing."""
    mesh = M.sphere(12)
    base = {"material": "chrome", "model": "threejs"}
    plain = explorer.shade(base, mesh.positions, mesh.normals)
    mat = find_preset("chrome").replace(fresnel=0.5, energy_conserving=True)
    scene = explorer.load_scene(base).replace(material=mat)
    np.testing.assert_array_equal(explorer.shade(scene, mesh.positions, mesh.normals), plain)
    rows = {item: (state, why) for item, state, why in make_plan(scene).reasons}
    assert rows["fresnel"][0] == "out" and "threejs" in rows["fresnel"][1]
    assert rows["energy"][0] == "out" and "threejs" in rows["energy"][1]


def test_shader_caches_and_switches_models():
    """On a Shader: a material change only recomposes; blinn -> threejs -> blinn gives the
    one-shot colours each time; terms compose to the colours (specular_f90 added)."""
    mesh = M.teapot(6)
    P, N = mesh.positions, mesh.normals
    scene = explorer.load_scene({"material": "bronze", "model": "threejs"})
    s = Shader(scene, P, N, precision="float64")
    _ = s.colors
    assert s.stats["numpy"] == 1
    s.set_material(scene.material.replace(diffuse=(0.1, 0.5, 0.9), specular=(0.9, 0.1, 0.0)))
    np.testing.assert_array_equal(s.colors, explorer.shade(s.scene, P, N))
    assert s.stats["numpy"] == 1 and s.stats["compose"] == 1  # the change composed only
    for model in ("blinn", "threejs", "phong", "threejs"):
        s.set_model(model)
        np.testing.assert_allclose(s.colors, explorer.shade(s.scene, P, N), atol=1e-12)
    t = s.terms
    m = s.scene.material
    c = m.emission + m.ambient * t["ambient"] + m.diffuse * t["diffuse"]
    c = np.clip(c + m.specular * t["specular"] + t["specular_f90"], 0, 1)
    np.testing.assert_allclose(c, s.colors, atol=1e-12)


def test_window_model_choices():
    """The window cycles through every model; hiding the specular term under threejs hides
    its Fresnel part too (drawn as blinn, identical without specular)."""
    assert [next_model(m) for m in MODELS] == [*MODELS[1:], MODELS[0]]
    grazing = {"material": "bronze", "model": "threejs", "viewer": {"to_viewer": [1, 0, 0.3]},
               "lights": [{"type": "directional", "to_light": [-1, 0, 0.3]}]}  # fmt: skip
    state = State(scene=explorer.load_scene(grazing), mesh="sphere")
    hidden = set_term(state, "specular", False).shown_scene()
    assert hidden.model == "blinn" and hidden.material.specular == (0, 0, 0)
    mesh = M.sphere(16)
    shown = explorer.shade(hidden, mesh.positions, mesh.normals)
    no_spec = explorer.shade(hidden.replace(model="threejs"), mesh.positions, mesh.normals)
    assert np.abs(shown - no_spec).max() > 0.05  # the f90 part is really there under threejs
