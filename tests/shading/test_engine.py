"""The engine against the OpenGL 2.1 equation, closed forms, the full-generality reference, and
its own policies for the hard cases."""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.gl21_oracle import gl_vertex_color
from helpers.scenes import check_oracle, random_gl_scene

import explorer
from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError, ValidationError
from explorer.core.lights import DirectionalLight, PointLight, SpotLight
from explorer.core.material import Material
from explorer.core.scene import Scene, Viewer, load_scene
from explorer.shading.equation import equation_shade

PRECISIONS = ("float64", "float32")


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def one_vertex(scene, p=(0, 0, 0), n=(0, 0, 1), precision="float64", clamp=True):
    return explorer.shade(scene, [p], [n], precision=precision, clamp=clamp)[0]


# --- 3. correctness against an independent OpenGL 2.1 implementation ----------------------------


@pytest.mark.parametrize("seed", range(12))
def test_blinn_equals_opengl_21_on_random_scenes(seed):
    rng = np.random.default_rng(seed)
    check_oracle(random_gl_scene(rng), gl_vertex_color, rng, 300)


# --- closed forms --------------------------------------------------------------------------

MAT = {
    "ambient": [0.1, 0.2, 0.3],
    "diffuse": [0.4, 0.5, 0.6],
    "specular": [0.7, 0.6, 0.5],
    "emission": [0.01, 0.02, 0.03],
    "shininess": 40,
}
LIGHT_COLOURS = {
    "ambient": [0.2, 0.1, 0.05],
    "diffuse": [0.9, 0.8, 0.7],
    "specular": [0.6, 0.7, 0.8],
}


@pytest.mark.parametrize("precision", PRECISIONS)
@pytest.mark.parametrize("model", ["blinn", "phong"])
@pytest.mark.parametrize("viewer", [{"to_viewer": [0, 0, 1]}, {"eye": [0, 0, 7]}])
def test_light_and_viewer_along_the_normal(precision, model, viewer):
    scene = {
        "material": MAT,
        "model": model,
        "ambient": [0.3, 0.3, 0.3],
        "viewer": viewer,
        "lights": [{"type": "directional", "to_light": [0, 0, 1], **LIGHT_COLOURS}],
    }
    m = {k: np.array(v) for k, v in MAT.items()}
    want = (
        m["emission"]
        + m["ambient"] * 0.3
        + m["ambient"] * LIGHT_COLOURS["ambient"]
        + m["diffuse"] * LIGHT_COLOURS["diffuse"]
        + m["specular"] * LIGHT_COLOURS["specular"]
    )
    got = one_vertex(scene, precision=precision, clamp=False)
    assert got == pytest.approx(want, abs=1e-12 if precision == "float64" else 1e-6)


@pytest.mark.parametrize("precision", PRECISIONS)
def test_attenuation_at_a_known_distance(precision):
    kc, kl, kq, d = 1.0, 0.5, 0.25, 2.0
    scene = {
        "material": {**MAT, "specular": [0, 0, 0], "emission": [0, 0, 0]},
        "ambient": [0, 0, 0],
        "lights": [
            {"type": "point", "position": [0, 0, d], "attenuation": [kc, kl, kq], **LIGHT_COLOURS}
        ],
    }
    att = 1.0 / (kc + kl * d + kq * d * d)
    want = att * (
        np.array(MAT["ambient"]) * LIGHT_COLOURS["ambient"]
        + np.array(MAT["diffuse"]) * LIGHT_COLOURS["diffuse"]
    )
    assert one_vertex(scene, precision=precision) == pytest.approx(want, abs=1e-6)


@pytest.mark.parametrize("precision", PRECISIONS)
def test_spot_cone_edge(precision):
    # spot at the origin pointing along -z; vertices on a plane z = -1 at angles around 30°
    cutoff = 30.0
    scene = {
        "material": {"ambient": [0, 0, 0], "diffuse": [1, 1, 1]},
        "ambient": [0, 0, 0],
        "lights": [
            {
                "type": "spot",
                "position": [0, 0, 0],
                "aim": [0, 0, -1],
                "cutoff": cutoff,
                "exponent": 0,
            }
        ],
    }
    angles = np.radians([cutoff - 0.01, cutoff + 0.01])
    P = np.stack([np.tan(angles), np.zeros(2), -np.ones(2)], axis=1)
    N = np.tile([0.0, 0.0, 1.0], (2, 1))
    inside, outside = explorer.shade(scene, P, N, precision=precision)
    assert inside[0] == pytest.approx(math.cos(angles[0]), abs=1e-6)  # N·L at that angle
    assert np.all(outside == 0.0)


@pytest.mark.parametrize("model", ["blinn", "phong"])
def test_highlight_peak_on_the_mirror_direction(model):
    # normals sweep a half circle; light and viewer fixed: the specular maximum is where N
    # bisects L and V, i.e. V is L's mirror image
    L, V = unit([1, 0, 1]), unit([-0.3, 0, 1])
    t = np.linspace(-np.pi / 2, np.pi / 2, 20001)
    N = np.stack([np.sin(t), np.zeros_like(t), np.cos(t)], axis=1)
    scene = {
        "material": {
            "ambient": [0, 0, 0],
            "diffuse": [0, 0, 0],
            "specular": [1, 1, 1],
            "shininess": 60,
        },
        "model": model,
        "ambient": [0, 0, 0],
        "viewer": {"to_viewer": V.tolist()},
        "lights": [{"type": "directional", "to_light": L.tolist()}],
    }
    c = explorer.shade(scene, np.zeros_like(N), N)[:, 0]
    peak = N[np.argmax(c)]
    assert np.allclose(peak, unit(L + V), atol=2e-4)


def test_phong_and_blinn_agree_where_R_equals_V():
    L = unit([1, 2, 3])
    N = unit([0.2, 0.1, 1])
    R = 2 * (N @ L) * N - L  # V = R: the viewer sits on the mirror direction
    base = {
        "material": {**MAT, "shininess": 77},
        "viewer": {"to_viewer": R.tolist()},
        "lights": [{"type": "directional", "to_light": L.tolist(), **LIGHT_COLOURS}],
    }
    blinn = one_vertex({**base, "model": "blinn"}, n=N)
    phong = one_vertex({**base, "model": "phong"}, n=N)
    assert blinn == pytest.approx(phong, abs=1e-12)


def test_phong_uses_the_reflection_vector():
    # R·V with R = 2(N·L)N - L, against a hand computation
    N, L, V = unit([0, 0, 1]), unit([1, 0, 1]), unit([0, 0.3, 1])
    R = 2 * (N @ L) * N - L
    n = 10.0
    scene = {
        "material": {
            "ambient": [0, 0, 0],
            "diffuse": [0, 0, 0],
            "specular": [1, 1, 1],
            "shininess": n,
        },
        "model": "phong",
        "ambient": [0, 0, 0],
        "viewer": {"to_viewer": V.tolist()},
        "lights": [{"type": "directional", "to_light": L.tolist()}],
    }
    assert one_vertex(scene)[0] == pytest.approx(max(R @ V, 0) ** n, abs=1e-12)


# --- scenes --------------------------------------------------------------------------------


def test_scene_defaults_follow_opengl():
    s = load_scene({})
    assert s.ambient == (0.2, 0.2, 0.2)
    assert s.material == Material()
    assert s.viewer == Viewer(to_viewer=(0, 0, 1))
    assert s.model == "blinn" and s.two_sided is False
    p = load_scene({"lights": [{"type": "point"}]}).lights[0]
    assert p.attenuation == (1.0, 0.0, 0.0)
    assert (p.ambient, p.diffuse, p.specular) == ((0, 0, 0), (1, 1, 1), (1, 1, 1))
    s = load_scene({"lights": [{"type": "spot"}]}).lights[0]
    assert (s.cutoff, s.exponent) == (180.0, 0.0)


def test_color_intensity_shorthand():
    light = load_scene(
        {"lights": [{"type": "directional", "color": [1, 0.5, 0.25], "intensity": 2}]}
    ).lights[0]
    assert light.diffuse == light.specular == (2.0, 1.0, 0.5)


def test_every_problem_in_a_scene_is_reported_at_once():
    bad = {
        "material": {"diffuse": [2, 0, 0], "shinyness": 3},
        "viewer": {"eye": [0, 0, 1], "to_viewer": [0, 0, 1]},
        "lights": [
            {"type": "point", "attenuation": [0, 0, 0]},
            {"type": "spot", "cutoff": 120},
            {"type": "lamp"},
        ],
        "two_sided": "yes",
        "colour": 1,
    }
    with pytest.raises(ValidationError) as err:
        load_scene(bad)
    text = str(err.value)
    for needle in [
        "material.diffuse[0]",
        "did you mean 'shininess'",
        "viewer",
        "lights[0].attenuation",
        "must not be all zero",
        "lights[1].cutoff",
        "lights[2].type",
        "two_sided",
        "colour",
    ]:
        assert needle in text, needle
    assert len(err.value.problems) >= 8


def test_scene_objects_and_mappings_give_the_same_colours():
    mapping = random_gl_scene(np.random.default_rng(3))
    scene = load_scene(mapping)
    P = np.random.default_rng(0).normal(size=(50, 3))
    assert np.array_equal(explorer.shade(mapping, P, P), explorer.shade(scene, P, P))


def test_scene_file(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text(
        "material: {diffuse: [1, 0, 0], ambient: [0, 0, 0]}\nambient: [0, 0, 0]\n"
        "lights:\n  - {type: directional, to_light: [0, 0, 1]}\n"
    )
    assert one_vertex(str(f)) == pytest.approx([1, 0, 0])
    f.write_text("lights:\n  - {type: point, attenuation: [0, 0, 0]}\n")
    with pytest.raises(ValidationError, match=r"s\.yaml:2: lights\[0\]\.attenuation"):
        load_scene(str(f))


# --- 7. numerical stability ----------------------------------------------------------------

HARD = {
    "material": {**MAT, "shininess": 30},
    "model": "blinn",
    "viewer": {"eye": [0, 0, 3]},
    "lights": [
        {
            "type": "point",
            "position": [0.5, 0.5, 1],
            "attenuation": [0.5, 0.2, 0.1],
            **LIGHT_COLOURS,
        },
        {
            "type": "spot",
            "position": [0, 2, 0],
            "aim": [0, -1, 0],
            "cutoff": 40,
            "exponent": 10,
        },
        {"type": "directional", "to_light": [1, 1, 1]},
    ],
}


def check_finite_in_range(c):
    assert np.all(np.isfinite(c))
    assert np.all((c >= 0) & (c <= 1))


@pytest.mark.parametrize("precision", PRECISIONS)
def test_zero_and_non_unit_normals(precision):
    P = np.zeros((4, 3))
    N = np.array([[0, 0, 0], [0, 0, 1e-30], [0, 0, 5], [0, 0, 1]], float)
    c = explorer.shade(HARD, P, N, precision=precision)
    check_finite_in_range(c)
    dark = [{**lt, "diffuse": [0, 0, 0], "specular": [0, 0, 0]} for lt in HARD["lights"]]
    no_normal = explorer.shade({**HARD, "lights": dark}, P[:1], N[:1], precision=precision)
    assert np.allclose(c[0], no_normal[0])  # emission + ambient only
    assert np.allclose(c[1], c[3], atol=1e-6)  # a tiny normal is a direction (NORMAL_RANGE)
    assert np.allclose(c[2], c[3], atol=1e-6)  # length does not matter
    assert not np.allclose(c[0], c[3])


@pytest.mark.parametrize("precision", PRECISIONS)
@pytest.mark.parametrize("length", [1e-310, 1e-200, 1e-20, 1e-15, 1e-7, 1e7, 1e20, 1e300])
def test_normals_of_any_finite_length_are_directions(precision, length):
    direction = unit([0.3, -0.2, 1.0])
    N = np.array([direction, direction * length, [0.0, 0.0, 0.0]])
    c = explorer.shade(HARD, np.zeros((3, 3)), N, precision=precision)
    check_finite_in_range(c)
    assert np.allclose(c[1], c[0], atol=1e-6), length  # same direction, same colour
    assert not np.allclose(c[2], c[0])  # an all-zero normal is still absent
    ref = equation_shade(load_scene(HARD), np.zeros((3, 3)), N)  # the spec agrees
    assert np.allclose(ref[1], ref[0], atol=1e-9) and np.allclose(ref[:2], c[:2], atol=1e-4)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_nan_or_inf_input_names_the_vertex(bad):
    P = np.zeros((5, 3))
    P[3, 1] = bad
    with pytest.raises(ValueError, match=r"positions\[3\] is not finite"):
        explorer.shade(HARD, P, np.ones((5, 3)))
    with pytest.raises(ExplorerError, match=r"normals\[3\]"):
        explorer.shade(HARD, np.zeros((5, 3)), P)


@pytest.mark.parametrize("precision", PRECISIONS)
def test_light_exactly_at_a_vertex(precision):
    scene = {
        "material": MAT,
        "lights": [{"type": "point", "position": [1, 2, 3], "attenuation": [0, 1, 0]}],
    }
    c = explorer.shade(
        scene, [[1, 2, 3], [1, 2, 4]], [[0, 0, 1], [0, 0, 1]], precision=precision, clamp=False
    )
    assert np.all(np.isfinite(c))  # kc = 0, d = 0: attenuation capped by ATTENUATION_FLOOR
    check_finite_in_range(np.clip(c, 0, 1))


def test_all_zero_attenuation_is_rejected():
    with pytest.raises(ValidationError, match="must not be all zero"):
        load_scene({"lights": [{"type": "point", "attenuation": [0, 0, 0]}]})
    with pytest.raises(ValueError):
        PointLight(attenuation=(0, 0, 0))


@pytest.mark.parametrize("shininess", [0.0, 1e-6, 1e-3])
@pytest.mark.parametrize("sign", [1, -1])
def test_grazing_light_never_flips_a_highlight_in_float32(shininess, sign):
    # N·L = ±1e-8 with the viewer facing the light: with a tiny exponent the specular term is
    # about s_m·s_l when N·L > 0 and 0 otherwise; float32 must decide as float64 does
    eps = sign * 1e-8
    L = np.array([math.sqrt(1 - eps * eps), 0.0, eps])
    scene = {
        "material": {
            "ambient": [0, 0, 0],
            "diffuse": [0, 0, 0],
            "specular": [1, 1, 1],
            "shininess": shininess,
        },
        "ambient": [0, 0, 0],
        "viewer": {"to_viewer": L.tolist()},
        "lights": [{"type": "directional", "to_light": L.tolist()}],
    }
    rng = np.random.default_rng(1)
    P = rng.normal(size=(64, 3)) * 1e3 + 1e4
    N = np.tile([0.0, 0.0, 1.0], (64, 1))
    c64 = explorer.shade(scene, P, N)
    c32 = explorer.shade(scene, P, N, precision="float32")
    assert np.abs(c32 - c64).max() <= tol.FLOAT32_MAX_ABS_ERROR
    if sign < 0:
        assert np.all(c64 == 0)


@pytest.mark.parametrize("shininess", [0.0, 1e-6, 128.0, 1e4])
@pytest.mark.parametrize("precision", PRECISIONS)
def test_extreme_shininess(shininess, precision):
    rng = np.random.default_rng(2)
    P, N = rng.normal(size=(500, 3)), rng.normal(size=(500, 3))
    # files cap shininess at 1000 (SHININESS_RANGE); the engine takes any finite n >= 0
    scene = load_scene(HARD).replace(material=Material(**{**MAT, "shininess": shininess}))
    c = explorer.shade(scene, P, N, precision=precision)
    check_finite_in_range(c)
    ref = equation_shade(scene, P, N)
    assert np.abs(c - ref).max() <= (1e-9 if precision == "float64" else tol.FLOAT32_MAX_ABS_ERROR)


@pytest.mark.parametrize("precision", PRECISIONS)
def test_blinn_with_light_opposite_the_viewer(precision):
    # L = -V: H is undefined; the policy takes N·H = 0
    scene = {
        "material": {**MAT, "shininess": 10},
        "viewer": {"to_viewer": [0, 0, -1]},
        "lights": [{"type": "directional", "to_light": [0, 0, 1]}],
    }
    c = one_vertex(scene, precision=precision, clamp=False)
    m = {k: np.array(v) for k, v in MAT.items()}
    assert c == pytest.approx(m["emission"] + 0.2 * m["ambient"] + m["diffuse"], abs=1e-6)
    # same through a local viewer and a point light on opposite sides
    scene = {
        **scene,
        "viewer": {"eye": [0, 0, -5]},
        "lights": [{"type": "point", "position": [0, 0, 5]}],
    }
    assert np.all(np.isfinite(one_vertex(scene, precision=precision)))


@pytest.mark.parametrize("offset, size", [(1e8, 1.0), (0.0, 1e-8), (1e8, 1e3), (-1e8, 1e-3)])
def test_large_and_tiny_coordinates(offset, size):
    rng = np.random.default_rng(4)
    P0 = rng.normal(size=(400, 3))
    N = rng.normal(size=(400, 3))
    base = HARD
    c_unit = explorer.shade(base, P0, N)

    def moved(v):
        return (np.asarray(v) * size + offset).tolist()

    scene = {
        **base,
        "viewer": {"eye": moved(base["viewer"]["eye"])},
        "lights": [
            {
                **lt,
                "position": moved(lt["position"]),
                "attenuation": [
                    lt["attenuation"][0],
                    lt["attenuation"][1] / size,
                    lt["attenuation"][2] / size**2,
                ],
            }
            if "position" in lt and "attenuation" in lt
            else ({**lt, "position": moved(lt["position"])} if "position" in lt else lt)
            for lt in base["lights"]
        ],
    }
    P = P0 * size + offset
    for precision in PRECISIONS:
        c = explorer.shade(scene, P, N, precision=precision)
        check_finite_in_range(c)
        assert np.abs(c - c_unit).max() <= tol.FLOAT32_MAX_ABS_ERROR


@pytest.mark.parametrize("precision", PRECISIONS)
def test_empty_mesh(precision):
    c = explorer.shade(HARD, np.zeros((0, 3)), np.zeros((0, 3)), precision=precision)
    assert c.shape == (0, 3)


def test_bad_shapes_are_clear_errors():
    with pytest.raises(ExplorerError, match=r"shape \(n, 3\)"):
        explorer.shade(HARD, np.zeros((4, 2)), np.zeros((4, 2)))
    with pytest.raises(ExplorerError, match="same length"):
        explorer.shade(HARD, np.zeros((4, 3)), np.zeros((3, 3)))
    with pytest.raises(ExplorerError, match="precision"):
        explorer.shade(HARD, np.zeros((1, 3)), np.zeros((1, 3)), precision="half")


def test_float32_matches_float64_on_hard_scenes():
    # every hard case at once, on many vertices, including exact grazing and cone edges
    rng = np.random.default_rng(5)
    n = 4000
    N = rng.normal(size=(n, 3))
    P = rng.normal(size=(n, 3))
    L = unit([0.3, 0.2, 1])
    N[:500] = np.cross(L, rng.normal(size=(500, 3)))  # N ⟂ L: N·L = 0 up to rounding
    scene = {
        "material": {**MAT, "shininess": 1e-6},
        "two_sided": True,
        "viewer": {"to_viewer": L.tolist()},
        "lights": [
            {"type": "directional", "to_light": L.tolist()},
            {
                "type": "spot",
                "position": [0, 0, 3],
                "aim": [0, 0, -1],
                "cutoff": 20,
                "exponent": 0,
            },
        ],
    }
    for model in ("blinn", "phong"):
        s = {**scene, "model": model}
        c64 = explorer.shade(s, P, N)
        c32 = explorer.shade(s, P, N, precision="float32")
        assert np.abs(c32 - c64).max() <= tol.FLOAT32_MAX_ABS_ERROR


def test_unclamped_output_keeps_hdr_sums():
    scene = {
        "material": {"diffuse": [1, 1, 1], "ambient": [0, 0, 0]},
        "ambient": [0, 0, 0],
        "lights": [{"type": "directional", "to_light": [0, 0, 1], "intensity": 3}],
    }
    assert one_vertex(scene, clamp=False) == pytest.approx([3, 3, 3])
    assert one_vertex(scene) == pytest.approx([1, 1, 1])


def test_python_objects_work_as_scenes():
    scene = Scene(
        material=Material(diffuse=(1, 0, 0), ambient=(0, 0, 0)),
        ambient=(0, 0, 0),
        lights=(
            SpotLight(position=(0, 0, 2), aim=(0, 0, -1), cutoff=45),
            DirectionalLight(to_light=(0, 0, 1), diffuse=(0, 0, 0)),
        ),
    )
    assert one_vertex(scene) == pytest.approx([1 / 1, 0, 0])


@pytest.mark.parametrize("model", ["blinn", "phong"])
def test_grey_and_coloured_point_lights_together(model):
    # the float32 kernel sums grey lights (r = g = b) in one channel and coloured ones in three,
    # inline or through the pre-pass rows (a spot); every mix must give the reference colours
    rng = np.random.default_rng(11)
    n = 3000
    P = rng.normal(size=(n, 3))
    N = rng.normal(size=(n, 3))
    P[0] = [2.0, 3.0, 1.0]  # a vertex exactly at the first light
    scene = {
        "material": {**MAT, "shininess": 40.0},
        "model": model,
        "viewer": {"eye": [0.0, 0.5, 4.0]},
        "lights": [
            {"type": "point", "position": [2, 3, 1], "attenuation": [1, 0.1, 0.01]},
            {"type": "point", "position": [-2, 1, 2], "diffuse": [1, 0.5, 0.2]},
            {"type": "point", "position": [0, -3, 1], "color": [0.4, 0.4, 0.4], "intensity": 2},
            {"type": "spot", "position": [0, 4, 0], "aim": [0, -1, 0], "cutoff": 40},
            {"type": "directional", "to_light": [1, 1, 1], "specular": [0.2, 0.9, 0.3]},
        ],
    }
    ref = equation_shade(load_scene(scene), P, N)
    c64 = explorer.shade(scene, P, N)
    c32 = explorer.shade(scene, P, N, precision="float32")
    assert np.abs(c64 - ref).max() <= 1e-9
    assert np.abs(c32 - ref).max() <= tol.FLOAT32_MAX_ABS_ERROR
    assert np.abs(c32 - ref).mean() <= 1e-5
