"""The Shader's cache: each kind of change costs what it should, and nothing stale leaks."""

from __future__ import annotations

import numpy as np
import pytest

import explorer
from explorer.core import tolerances as tol
from explorer.core.hdr import HDR
from explorer.core.lights import DirectionalLight, PointLight
from explorer.core.scene import Viewer, load_scene

SCENE = {
    "material": {
        "ambient": [0.2, 0.1, 0.1],
        "diffuse": [0.6, 0.5, 0.4],
        "specular": [0.7, 0.7, 0.7],
        "shininess": 30,
    },
    "viewer": {"eye": [0, 0, 5]},
    "lights": [
        {
            "type": "point",
            "position": [2, 3, 1],
            "attenuation": [1, 0.1, 0.01],
            "ambient": [0.1, 0.1, 0.1],
        },
        {"type": "directional", "to_light": [-1, 1, 1]},
    ],
}


@pytest.fixture(params=["float32", "float64"])
def shader(request):
    rng = np.random.default_rng(0)
    P, N = rng.normal(size=(2000, 3)), rng.normal(size=(2000, 3))
    return explorer.Shader(SCENE, P, N, precision=request.param)


def fresh(shader):
    return explorer.shade(shader.scene, shader._P, shader._N, precision=shader.precision)


def counts(shader):
    s = shader.stats
    return {
        k: s[k] for k in ("pass", "ambient", "diffuse", "specular", "lobe", "compose", "geometry")
    }


def delta(before, after):
    return {k: after[k] - before[k] for k in before if after[k] != before[k]}


def check(shader):
    n = max(1.0, shader.scene.material.shininess)
    tol_ = 1e-12 if shader.precision == "float64" else tol.FLOAT32_ROUTE_ABS_TOL * n
    assert np.abs(shader.colors - fresh(shader)).max() <= tol_


def test_first_colours_take_one_pass(shader):
    _ = shader.colors
    c = counts(shader)
    assert c["pass"] == 1 and c["diffuse"] == 1 and c["specular"] == 1 and c["geometry"] == 1
    check(shader)


def test_material_colours_only_recompose(shader):
    _ = shader.colors
    before = counts(shader)
    m = shader.scene.material
    shader.set_material(
        m.replace(
            diffuse=(0.1, 0.9, 0.3),
            ambient=(0, 0, 0.4),
            specular=(0.2, 0.2, 0.9),
            emission=(0.1, 0, 0),
        )
    )
    _ = shader.colors
    assert delta(before, counts(shader)) == {"compose": 1}
    check(shader)


def test_shininess_only_reruns_the_lobe(shader):
    _ = shader.colors
    before = counts(shader)
    # the first shininess change recomputes the specular sum once, keeping each light's base
    # and weight; from then on a shininess change only re-runs the lobe
    shader.set_material(shader.scene.material.replace(shininess=5.0))
    _ = shader.colors
    check(shader)
    assert delta(before, counts(shader)) == {"pass": 1, "specular": 1}
    before = counts(shader)
    for n in (120.0, 0.0, 64.0, 1.5):
        shader.set_material(shader.scene.material.replace(shininess=n))
        _ = shader.colors
        check(shader)
    assert delta(before, counts(shader)) == {"lobe": 4, "compose": 4}


def test_a_moving_camera_stops_storing_lobes(shader):
    # lobes (a base and a weight per vertex and light) are stored only while shininess moves:
    # a viewer change makes them invalid, and a camera moves every frame
    _ = shader.colors
    shader.set_material(shader.scene.material.replace(shininess=5.0))
    _ = shader.colors
    assert shader._ws is not None
    for eye in ((1, 2, 6), (0, 1, 5)):
        shader.set_viewer(Viewer(eye=eye))
        _ = shader.colors
        assert shader._ws is None and shader._base is None
        check(shader)
    before = counts(shader)
    for n in (30.0, 60.0):  # one specular pass that stores them again, then the lobe alone
        shader.set_material(shader.scene.material.replace(shininess=n))
        _ = shader.colors
        check(shader)
    assert delta(before, counts(shader)) == {"pass": 1, "specular": 1, "lobe": 1, "compose": 1}


def test_viewer_change_recomputes_specular_not_diffuse(shader):
    _ = shader.colors
    before = counts(shader)
    shader.set_viewer(Viewer(eye=(1, 2, 6)))
    _ = shader.colors
    assert delta(before, counts(shader)) == {"pass": 1, "specular": 1}
    check(shader)
    shader.set_model("phong")
    _ = shader.colors
    assert delta(before, counts(shader)) == {"pass": 2, "specular": 2}
    check(shader)


def test_effect_settings_cost_what_their_effect_declares(shader):
    # Fresnel's F is stored in each light's lobe weight: a new F0 recomputes the specular sum;
    # the energy-conserving factor is a constant: it only re-runs the lobe, as shininess does
    _ = shader.colors
    shader.set_material(shader.scene.material.replace(shininess=5.0))  # lobes stored from now
    _ = shader.colors
    before = counts(shader)
    shader.set_material(shader.scene.material.replace(energy_conserving=True))
    _ = shader.colors
    check(shader)
    assert delta(before, counts(shader)) == {"lobe": 1, "compose": 1}
    before = counts(shader)
    for f0 in (0.04, 0.5, None):
        shader.set_material(shader.scene.material.replace(fresnel=f0))
        _ = shader.colors
        check(shader)
    assert delta(before, counts(shader)) == {"pass": 3, "specular": 3}
    before = counts(shader)
    shader.set_scene(shader.scene.replace(hdr=HDR()))  # a display effect: compose only
    _ = shader.colors
    check(shader)
    assert delta(before, counts(shader)) == {"compose": 1}


def test_two_sided_viewer_change_recomputes_everything(shader):
    shader.set_scene(shader.scene.replace(two_sided=True))
    _ = shader.colors
    before = counts(shader)
    shader.set_viewer(Viewer(to_viewer=(0, 1, 0)))
    _ = shader.colors
    assert delta(before, counts(shader)) == {"pass": 1, "ambient": 1, "diffuse": 1, "specular": 1}
    check(shader)


def test_light_change_invalidates(shader):
    _ = shader.colors
    before = counts(shader)
    shader.set_lights([PointLight(position=(0, 0, 3)), DirectionalLight(to_light=(1, 0, 0))])
    _ = shader.colors
    assert delta(before, counts(shader))["pass"] == 1
    check(shader)


def test_geometry_change_invalidates(shader):
    _ = shader.colors
    rng = np.random.default_rng(1)
    shader.set_geometry(rng.normal(size=(700, 3)), rng.normal(size=(700, 3)))
    assert shader.colors.shape == (700, 3)
    assert counts(shader)["geometry"] == 2 and counts(shader)["pass"] == 2
    check(shader)


def test_terms_are_computed_only_when_the_material_needs_them(shader):
    shader.set_material(shader.scene.material.replace(specular=(0, 0, 0)))
    _ = shader.colors
    assert counts(shader)["specular"] == 0
    before = counts(shader)
    shader.set_material(shader.scene.material.replace(specular=(1, 1, 1)))
    _ = shader.colors
    assert delta(before, counts(shader)) == {"pass": 1, "specular": 1}
    check(shader)


def test_cached_arrays_are_read_only_and_never_rewritten(shader):
    first = shader.colors
    kept = first.copy()
    with pytest.raises(ValueError):
        first[0, 0] = 1.0
    for term in shader.terms.values():
        with pytest.raises(ValueError):
            term[0, 0] = 1.0
    shader.set_material(shader.scene.material.replace(diffuse=(0, 0, 0)))
    _ = shader.colors
    assert np.array_equal(first, kept)  # colours handed out earlier did not change


def test_sums_reuse_memory_only_when_nothing_views_it(shader):
    # a light change recomputes the sums into the memory of the invalidated ones (no page
    # faults at 1M vertices) unless an array handed out (terms) still views that memory
    lights = [PointLight(position=(0, 0, 3)), DirectionalLight(to_light=(1, 0, 0))]
    _ = shader.colors

    def addresses():  # not references: holding the arrays would keep them from reuse
        return {a.__array_interface__["data"][0] for a in (shader._A, shader._D, shader._S)
                if a is not None}  # fmt: skip

    old = addresses()
    shader.set_lights(lights)
    _ = shader.colors
    new = addresses()
    assert new and new <= old  # the sums the new lights need, in the old sums' memory
    check(shader)
    held = shader.terms
    kept = {k: v.copy() for k, v in held.items()}
    shader.set_lights(lights[::-1])
    _ = shader.colors
    check(shader)
    for k, v in held.items():
        assert np.array_equal(v, kept[k])  # what was handed out never changes
    assert not any(np.shares_memory(v, shader._D) for v in held.values())


def test_terms_recompose_to_the_colours(shader):
    t = shader.terms
    m = shader.scene.material
    c = (
        np.asarray(m.emission)
        + np.asarray(m.ambient) * t["ambient"]
        + np.asarray(m.diffuse) * t["diffuse"]
        + np.asarray(m.specular) * t["specular"]
    )
    assert np.abs(np.clip(c, 0, 1) - shader.colors).max() <= 1e-6


def test_setting_the_same_scene_costs_nothing(shader):
    _ = shader.colors
    before = counts(shader)
    shader.set_scene(load_scene(SCENE))
    _ = shader.colors
    assert delta(before, counts(shader)) == {}


def test_float32_shader_stays_within_one_level_of_float64():
    rng = np.random.default_rng(2)
    P, N = rng.normal(size=(3000, 3)), rng.normal(size=(3000, 3))
    s32 = explorer.Shader(SCENE, P, N, precision="float32")
    s64 = explorer.Shader(SCENE, P, N, precision="float64")
    for n in (1.0, 30.0, 200.0):
        for s in (s32, s64):
            s.set_material(s.scene.material.replace(shininess=n))
        assert np.abs(s32.colors - s64.colors).max() <= tol.FLOAT32_MAX_ABS_ERROR


@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_lobes_of_plain_point_lights(precision):
    # plain point lights (no cone, no light ambient) take the float32 inline loops, which also
    # store the lobe rows when a pass starts a shininess drag (one grey light, one coloured)
    scene = dict(SCENE)
    scene["lights"] = [
        {"type": "point", "position": [2, 3, 1], "attenuation": [1, 0.1, 0.01]},
        {"type": "point", "position": [-3, 1, 2], "diffuse": [1, 0.5, 0.2]},  # coloured
    ]
    rng = np.random.default_rng(3)
    P, N = rng.normal(size=(3000, 3)), rng.normal(size=(3000, 3))
    shader = explorer.Shader(scene, P, N, precision=precision)
    _ = shader.colors
    before = counts(shader)
    for n in (5.0, 120.0, 0.0, 64.0):
        shader.set_material(shader.scene.material.replace(shininess=n))
        _ = shader.colors
        check(shader)
    assert delta(before, counts(shader)) == {"pass": 1, "specular": 1, "lobe": 3, "compose": 3}


def test_grey_only_pass_stores_sums_a_recolour_reuses():
    # white plain point lights only: the float32 pass keeps the diffuse and specular sums in one
    # grey row each and stores them as grey (n, 1) sums, which must still recompose a new
    # material exactly, and serve the passes that recompute the specular sum alone
    scene = dict(SCENE)
    scene["lights"] = [
        {"type": "point", "position": [2, 3, 1], "attenuation": [1, 0.1, 0.01]},
        {"type": "point", "position": [-3, 1, 2]},
    ]
    rng = np.random.default_rng(4)
    P, N = rng.normal(size=(3000, 3)), rng.normal(size=(3000, 3))
    # and a few vertices lit exactly edge-on (N·L = 0): ambiguous, redone in float64
    P[:4] = 0.0
    N[:4] = np.cross([2.0, 3.0, 1.0], rng.normal(size=(4, 3)))
    shader = explorer.Shader(scene, P, N, precision="float32")
    _ = shader.colors
    assert shader._D.shape == shader._S.shape == (3000, 1)
    assert shader.stats["fixup_vertices"] >= 4
    check(shader)
    t = shader.terms
    for name in ("diffuse", "specular"):  # grey lights: every channel alike, and not all zero
        assert np.array_equal(t[name][:, 0], t[name][:, 1])
        assert np.array_equal(t[name][:, 0], t[name][:, 2])
        assert t[name].max() > 0
    before = counts(shader)
    shader.set_material(shader.scene.material.replace(diffuse=(0.1, 0.8, 0.3)))
    _ = shader.colors
    assert delta(before, counts(shader)) == {"compose": 1}
    check(shader)
    ref = explorer.shade(shader.scene, P, N, precision="float64")
    assert np.abs(shader.colors - ref).max() <= tol.FLOAT32_MAX_ABS_ERROR
    # the specular sum alone (a viewer change) is a grey pass too, on the grey diffuse sum
    before = counts(shader)
    shader.set_viewer(Viewer(eye=(1.0, 2.0, 6.0)))
    _ = shader.colors
    assert delta(before, counts(shader)) == {"pass": 1, "specular": 1}
    assert shader._D.shape == shader._S.shape == (3000, 1)
    check(shader)
    # a shininess drag: one grey specular pass that keeps the lobes, then the lobe alone,
    # which writes an (n, 3) sum; a viewer change then reads it no more (recomputed grey)
    for n, shape in ((5.0, (3000, 1)), (60.0, (3000, 3))):
        shader.set_material(shader.scene.material.replace(shininess=n))
        _ = shader.colors
        assert shader._S.shape == shape
        check(shader)
    shader.set_viewer(Viewer(eye=(0.0, 1.0, 5.0)))
    _ = shader.colors
    assert shader._S.shape == (3000, 1)
    check(shader)


def test_an_rgb_diffuse_sum_keeps_a_specular_pass_rgb():
    # grey lights, but no specular at first (material specular 0): that pass is not a grey
    # pass, so its diffuse sum is (n, 3); the specular-only pass that follows, when the
    # material gains a specular colour, cannot keep its sums in the grey rows alone
    scene = dict(SCENE)
    scene["material"] = dict(SCENE["material"], specular=[0, 0, 0])
    scene["lights"] = [
        {"type": "point", "position": [2, 3, 1], "attenuation": [1, 0.1, 0.01]},
        {"type": "point", "position": [-3, 1, 2]},
    ]
    rng = np.random.default_rng(6)
    P, N = rng.normal(size=(2000, 3)), rng.normal(size=(2000, 3))
    shader = explorer.Shader(scene, P, N, precision="float32")
    _ = shader.colors
    assert shader._D.shape == (2000, 3) and shader._S is None
    before = counts(shader)
    shader.set_material(shader.scene.material.replace(specular=(0.5, 0.5, 0.5)))
    _ = shader.colors
    assert delta(before, counts(shader)) == {"pass": 1, "specular": 1}
    assert shader._S.shape == (2000, 3)
    check(shader)


def test_redone_lanes_keep_their_float64_lobes_for_a_shininess_drag():
    # vertices a hair off a plane, a light far away in that plane (N·L = ±1e-9): float32 gets
    # the sign of N·L wrong on about half of them, so the float64 redo must also replace the
    # lobe rows (base, weight) a shininess drag re-runs from, not only the colours
    rng = np.random.default_rng(7)
    n_hat = np.array([1.0, 1.0, 1.0]) / np.sqrt(3.0)
    u = np.cross(n_hat, [0.0, 0.0, 1.0])
    u /= np.linalg.norm(u)
    v = np.cross(n_hat, u)
    a, b = rng.uniform(-1, 1, size=(2, 2000))
    off = rng.choice([-1e-6, 1e-6], size=2000)
    P = a[:, None] * u + b[:, None] * v + off[:, None] * n_hat
    N = np.tile(n_hat, (2000, 1))
    q = (1e3 * u).tolist()  # in the plane: N·(q - P) = -off
    scene = {
        "material": {"ambient": [0, 0, 0], "diffuse": [0, 0, 0], "specular": [1, 1, 1]},
        "ambient": [0, 0, 0],
        "viewer": {"eye": q},  # V = L: N·H = N·L, and a tiny exponent makes the lobe ~1
        "lights": [{"type": "point", "position": q}],
    }
    s32 = explorer.Shader(scene, P, N, precision="float32")
    s64 = explorer.Shader(scene, P, N, precision="float64")
    for shininess in (1e-3, 1e-6, 2e-6):  # a pass that keeps the lobes, then the lobe alone
        for s in (s32, s64):
            s.set_material(s.scene.material.replace(shininess=shininess))
        assert np.abs(s32.colors - s64.colors).max() <= tol.FLOAT32_MAX_ABS_ERROR
        assert (s64.colors > 0.5).any() and (s64.colors == 0).any()  # both signs occur
    assert s32.stats["lobe"] == 2 and s32.stats["fixup_vertices"] >= 1000
