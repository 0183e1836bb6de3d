"""Lights and the viewer: one check per key (file and constructor), old key names, placement."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import explorer
from explorer.cli import build_parser
from explorer.cli.options import light_from_options
from explorer.core.errors import DeprecatedName, ExplorerError, Notice, ValidationError
from explorer.core.lights import (
    LIGHT_CLASSES,
    DirectionalLight,
    PointLight,
    SpotLight,
    angles_of,
    direction_of,
)
from explorer.core.presets import PresetNotice
from explorer.core.scene import Viewer, load_scene

# -- one check per key: the file parser and the constructor say the same -----------------------

BAD = [
    ("directional", "to_light", [0, 0, 0], "must be a non-zero direction, got [0, 0, 0]"),
    ("directional", "diffuse", [2e6, 0, 0], "must be in [0, 1e+06], got 2e+06"),
    ("directional", "shadows", "yes", "must be true or false"),
    ("point", "position", [0, float("nan"), 0], "must be a finite number"),
    ("point", "attenuation", [0, 0, 0], "must not be all zero"),
    ("point", "attenuation", [1, -1, 0], "must be >= 0, got -1"),
    ("spot", "cutoff", 120, "must be in [0, 90] or exactly 180, got 120"),
    ("spot", "cutoff", 200, "must be in [0, 180], got 200"),
    ("spot", "exponent", 129, "must be in [0, 128], got 129"),
    ("spot", "aim", [0, 0], "must be a list of 3 numbers"),
]


@pytest.mark.parametrize("kind, key, value, message", BAD)
def test_file_and_constructor_report_a_bad_key_alike(tmp_path, kind, key, value, message):
    with pytest.raises(ValidationError) as from_mapping:
        load_scene({"lights": [{"type": kind, key: value}]})
    (p,) = from_mapping.value.problems
    assert p.key.startswith(f"lights[0].{key}") and message in p.message
    with pytest.raises(ValidationError) as from_code:
        LIGHT_CLASSES[kind](**{key: value})
    (q,) = from_code.value.problems
    assert q.message == p.message and q.key == p.key.removeprefix("lights[0].")
    assert isinstance(from_code.value, ValueError)


def test_a_file_reports_every_light_problem_with_file_and_line(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text(
        "lights:\n"
        "  - {type: spot, cutoff: 120, exponent: 200}\n"
        "  - type: point\n"
        "    attenuation: [0, 0, 0]\n"
    )
    with pytest.raises(ValidationError) as err:
        load_scene(str(f))
    text = str(err.value).splitlines()
    assert f"{f}:2: lights[0].cutoff: must be in [0, 90] or exactly 180, got 120" in text
    assert f"{f}:2: lights[0].exponent: must be in [0, 128], got 200" in text
    assert any(t.startswith(f"{f}:4: lights[1].attenuation: must not be all zero") for t in text)


def test_constructor_reports_every_problem_at_once():
    with pytest.raises(ValidationError) as err:
        SpotLight(aim=(0, 0, 0), cutoff=120, exponent=-1)
    assert [p.key for p in err.value.problems] == ["aim", "cutoff", "exponent"]


def test_viewer_checks_alike():
    with pytest.raises(ValidationError) as err:
        load_scene({"viewer": {"to_viewer": [0, 0, 0]}})
    (p,) = err.value.problems
    assert p.key == "viewer.to_viewer"
    with pytest.raises(ValidationError) as err:
        Viewer(to_viewer=(0, 0, 0))
    assert err.value.problems[0].message == p.message
    for kw in ({}, {"eye": (0, 0, 1), "to_viewer": (0, 0, 1)}):
        with pytest.raises(ValidationError, match="exactly one of eye"):
            Viewer(**kw)
    with pytest.raises(ValidationError, match=r"viewer: needs exactly one of eye"):
        load_scene({"viewer": {}})


# -- names that say which way they point -------------------------------------------------------


def test_new_names_are_stored_unit_length_and_written_back():
    d = DirectionalLight(to_light=(0, 0, 2))
    s = SpotLight(position=(0, 1, 0), aim=(0, -3, 0), cutoff=30)
    v = Viewer(to_viewer=(2, 0, 0))
    assert d.to_light == (0, 0, 1) and s.aim == (0, -1, 0) and v.to_viewer == (1, 0, 0)
    scene = explorer.Scene(lights=(d, s), viewer=v)
    m = scene.to_mapping()
    assert m["viewer"] == {"to_viewer": [1.0, 0.0, 0.0]}
    assert m["lights"][0]["to_light"] == [0.0, 0.0, 1.0] and "aim" in m["lights"][1]
    assert "direction'" not in str(m)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the new names give no notice
        assert load_scene(m) == scene


def test_old_key_direction_still_loads_with_one_notice_each(tmp_path):
    f = tmp_path / "scene.yaml"
    f.write_text(
        "viewer: {direction: [0, 0, 1]}\n"
        "lights:\n"
        "  - type: directional\n"
        "    direction: [1, 1, 1]\n"
        "  - {type: spot, position: [0, 4, 0], direction: [0, -1, 0], cutoff: 30}\n"
    )
    with pytest.warns(DeprecatedName) as notes:
        old = load_scene(str(f))
    text = [str(n.message) for n in notes]
    assert text == [
        f"{f}:1: viewer.direction is now to_viewer (the direction toward the viewer); "
        "the old name still works",
        f"{f}:4: lights[0].direction is now to_light (the direction toward the light); "
        "the old name still works",
        f"{f}:5: lights[1].direction is now aim (the axis the spot shines along); "
        "the old name still works",
    ]
    new = load_scene(
        {
            "viewer": {"to_viewer": [0, 0, 1]},
            "lights": [
                {"type": "directional", "to_light": [1, 1, 1]},
                {"type": "spot", "position": [0, 4, 0], "aim": [0, -1, 0], "cutoff": 30},
            ],
        }
    )
    assert old == new


def test_old_key_keeps_its_line_in_problems_and_both_names_are_a_problem(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text("lights:\n  - type: directional\n    direction: [0, 0, 0]\n")
    with pytest.warns(DeprecatedName), pytest.raises(ValidationError) as err:
        load_scene(str(f))
    want = f"{f}:3: lights[0].to_light: must be a non-zero direction, got [0, 0, 0]"
    assert str(err.value) == want
    with pytest.raises(ValidationError, match=r"lights\[0\]\.direction: is the old name of aim"):
        load_scene({"lights": [{"type": "spot", "direction": [0, 0, -1], "aim": [0, 0, -1]}]})
    with pytest.raises(ValidationError, match="unknown key"):  # a point light never had one
        load_scene({"lights": [{"type": "point", "direction": [0, 0, -1]}]})


def test_old_keyword_direction_still_works_with_a_notice():
    with pytest.warns(DeprecatedName, match=r"DirectionalLight\(direction=...\) is now to_light"):
        assert DirectionalLight(direction=(1, 2, 3)) == DirectionalLight(to_light=(1, 2, 3))
    with pytest.warns(DeprecatedName, match=r"SpotLight\(direction=...\) is now aim"):
        assert SpotLight(direction=(0, 0, 1)) == SpotLight(aim=(0, 0, 1))
    with pytest.warns(DeprecatedName, match="is now aim"):
        assert SpotLight().replace(direction=(1, 0, 0)).aim == (1, 0, 0)
    with pytest.warns(DeprecatedName, match=r"Viewer\(direction=...\) is now to_viewer"):
        assert Viewer(direction=(0, 0, 2)) == Viewer(to_viewer=(0, 0, 1))
    with pytest.raises(ValidationError, match="old name of to_light"):
        DirectionalLight(direction=(1, 0, 0), to_light=(1, 0, 0))


def test_notices_share_one_base():
    assert issubclass(DeprecatedName, Notice) and issubclass(PresetNotice, Notice)
    assert issubclass(Notice, UserWarning)


# -- what each light says of itself -------------------------------------------------------------


def test_a_spot_is_positional_without_being_a_point_light():
    s = SpotLight(position=(0, 0, 2), cutoff=30, exponent=4)
    assert not isinstance(s, PointLight)
    w = s.work()
    assert w.positional and w.spot == "cone+exponent" and w.attenuation == "none"
    assert [r[0] for r in w.reasons] == ["distance", "attenuation", "spot"]
    assert DirectionalLight().work().positional is False
    c = PointLight(attenuation=(2, 0, 0)).work()
    assert c.attenuation == "constant" and c.factor == 0.5


def test_incident_light_of_each_type():
    P = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    N = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    L, d, w = DirectionalLight(to_light=(0, 0, 1)).incident(P, N, np.zeros(3), 1.0)
    assert np.allclose(L, [[0, 0, 1], [0, 0, 1]]) and np.all(np.isinf(d)) and np.all(w == 1)
    L, d, w = PointLight(position=(0, 0, 2), attenuation=(1, 1, 0)).incident(P, N, np.zeros(3), 1.0)
    assert np.allclose(d, [2, np.sqrt(5)]) and np.allclose(w, 1 / (1 + d))
    # a 30° cone around -z from (0, 0, 2): the vertex below is inside, the other outside
    _, _, w = SpotLight(position=(0, 0, 2), aim=(0, 0, -1), cutoff=20).incident(
        P, N, np.zeros(3), 1.0
    )
    assert w[0] == 1.0 and w[1] == 0.0


def test_shadow_rays_point_at_the_light():
    P = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    D, tmax = PointLight(position=(0, 0, 2)).shadow_ray(P)
    assert np.allclose(D[0], [0, 0, 1]) and np.allclose(tmax, [2, np.sqrt(5)])
    D, tmax = DirectionalLight(to_light=(0, 1, 0)).shadow_ray(P)
    assert np.allclose(D, [[0, 1, 0]] * 2) and np.all(np.isinf(tmax))


@pytest.mark.parametrize("az", [-170.0, -90.0, -30.0, 0.0, 45.0, 135.0, 180.0])
@pytest.mark.parametrize("el", [-80.0, -10.0, 0.0, 35.0, 89.0])
def test_placement_round_trips_for_every_light_type(az, el):
    centre = np.array([0.5, -1.0, 2.0])
    for light in (DirectionalLight(), PointLight(), SpotLight(cutoff=30.0)):
        placed = light.placed(az, el, 3.0, centre)
        a, e, d = placed.placement(centre)
        assert (a - az + 180.0) % 360.0 - 180.0 == pytest.approx(0.0, abs=1e-9)
        assert e == pytest.approx(el, abs=1e-9)
        if placed.type == "directional":
            assert d is None
        else:
            assert d == pytest.approx(3.0)
        if placed.type == "spot":  # a spot aims at the centre
            to_centre = centre - np.asarray(placed.position)
            assert np.allclose(placed.aim, to_centre / np.linalg.norm(to_centre))
            assert placed.cutoff == 30.0


def test_direction_of_convention():
    assert np.allclose(direction_of(0, 0), [0, 0, 1])  # the front (default viewer)
    assert np.allclose(direction_of(90, 0), [1, 0, 0])
    assert np.allclose(direction_of(0, 90), [0, 1, 0])


def test_as_type_keeps_colours_and_attenuation():
    p = PointLight(diffuse=(1, 0.5, 0.2), specular=(0.3, 0.3, 0.3), attenuation=(1, 0.1, 0.01))
    s = p.as_type("spot").placed(20, 10, 4.0, (0, 0, 0))
    assert isinstance(s, SpotLight) and s.cutoff == SpotLight.LIKE_DEFAULTS["cutoff"]
    assert s.diffuse == p.diffuse and s.specular == p.specular and s.attenuation == p.attenuation
    d = s.as_type("directional").placed(20, 10, 4.0, (0, 0, 0))
    assert isinstance(d, DirectionalLight) and d.diffuse == p.diffuse
    assert np.allclose(d.to_light, direction_of(20, 10))
    back = d.as_type("point").placed(20, 10, 4.0, (0, 0, 0))
    assert np.allclose(back.position, 4.0 * direction_of(20, 10))
    assert p.as_type("point") is p
    with pytest.raises(ExplorerError):
        p.as_type("area")


# -- scale-safe unit vectors (issue 19, item 3) -------------------------------------------------

EXTREME_DIRECTIONS = [
    (1e-200, 0, 0),
    (1e-320, 0, 0),
    (0, -5e-324, 0),
    (1e-320, 1e-320, 0),
    (1e200, 1e200, 0),
    (1e308, 1e308, 1e308),
    (-1.7e308, 1.7e308, 1.7e308),
]


@pytest.mark.parametrize("v", EXTREME_DIRECTIONS)
def test_any_finite_nonzero_direction_becomes_a_unit_vector(v):
    want = np.asarray(v, dtype=np.float64) / np.max(np.abs(v))
    want /= np.linalg.norm(want)
    for got in (
        DirectionalLight(to_light=v).to_light,
        SpotLight(aim=v).aim,
        Viewer(to_viewer=v).to_viewer,
    ):
        assert np.linalg.norm(got) == pytest.approx(1.0, abs=1e-15)
        np.testing.assert_allclose(got, want, atol=1e-15)


def test_tiny_and_huge_directions_load_from_a_scene_file(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text(
        "viewer: {to_viewer: [1e308, 1e308, 1e308]}\n"
        "lights:\n"
        "  - {type: directional, to_light: [1e-320, 0, 0]}\n"
        "  - {type: spot, position: [0, 4, 0], aim: [0, -1e-300, 0]}\n"
    )
    scene = load_scene(f)
    assert scene.lights[0].to_light == (1.0, 0.0, 0.0)
    assert scene.lights[1].aim == (0.0, -1.0, 0.0)
    np.testing.assert_allclose(scene.viewer.to_viewer, [3**-0.5] * 3)


def test_tiny_light_direction_on_the_command_line_is_not_a_traceback():
    for flag in ("--light-direction", "--light-to-light"):
        args = build_parser().parse_args(["render", flag, "1e-200", "0", "0", "--out", "x.png"])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecatedName)
            assert light_from_options(args).to_light == (1.0, 0.0, 0.0)


@pytest.mark.parametrize("scale", [1e-200, 1.0, 1e300])
def test_angles_of_a_vector_at_every_scale(scale):
    az, el, length = angles_of((0.0, 3.0 * scale, 4.0 * scale))
    assert (az, length / scale) == pytest.approx((0.0, 5.0)) and el == pytest.approx(36.8699, 1e-5)


def test_as_type_keeps_the_lights_shadows():
    """A shadowing light turned into another type (the panel's ``type`` row) still casts
    shadows: the panel's ``shadows`` row does not switch off behind the user's back."""
    p = PointLight(shadows=True)
    for kind in ("spot", "directional", "point"):
        p = p.as_type(kind)
        assert p.type == kind and p.shadows
