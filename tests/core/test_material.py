"""Material: the two written forms, validation messages, ka/kd/ks scalars
(explorer.core.material)."""

from __future__ import annotations

import sys

import pytest
from helpers.scenes import materials, unit
from hypothesis import given

from explorer.core.errors import ValidationError
from explorer.core.material import MATERIAL_KEYS, Material, parse_material
from explorer.core.validate import Checker


def parse(mapping):
    checker = Checker("m.yaml")
    material = parse_material(mapping, checker, ())
    return material, checker.problems


def ok(mapping) -> Material:
    material, problems = parse(mapping)
    assert problems == [] and material is not None
    return material


def messages(mapping) -> list[str]:
    material, problems = parse(mapping)
    assert material is None and problems
    return [str(p) for p in problems]


# -- defaults and the RGB form ---------------------------------------------------------------
def test_defaults_are_opengl_glmaterial_defaults():
    m = Material()
    assert m.ambient == (0.2, 0.2, 0.2) and m.diffuse == (0.8, 0.8, 0.8)
    assert m.specular == (0, 0, 0) and m.emission == (0, 0, 0)
    assert m.shininess == 0 and m.opacity == 1 and m.model is None
    assert ok({}) == m


def test_rgb_form_keeps_every_value():
    m = ok(
        {
            "ambient": [0.1, 0.2, 0.3],
            "diffuse": [0.4, 0.5, 0.6],
            "specular": [0.7, 0.8, 0.9],
            "emission": [0.01, 0.02, 0.03],
            "shininess": 76.8,
            "opacity": 0.55,
            "model": "phong",
            "description": "test",
        }
    )
    assert m.ambient == (0.1, 0.2, 0.3) and m.diffuse == (0.4, 0.5, 0.6)
    assert m.specular == (0.7, 0.8, 0.9) and m.emission == (0.01, 0.02, 0.03)
    assert (m.shininess, m.opacity, m.model, m.description) == (76.8, 0.55, "phong", "test")


@given(materials)
def test_to_mapping_parses_back_to_identical_values(m):
    back = ok(m.to_mapping())
    assert back == m and back.description == m.description
    for key in ("ambient", "diffuse", "specular", "emission", "shininess", "opacity"):
        assert getattr(back, key) == getattr(m, key)  # exact, not approximate


# -- the scalar form -------------------------------------------------------------------------
def test_scalar_form_multiplies_color_and_specular_color():
    color, spec = (0.9, 0.5, 0.1), (1.0, 0.8, 0.6)
    m = ok({"color": list(color), "ka": 0.3, "kd": 0.7, "ks": 0.4, "specular_color": list(spec)})
    assert m.ambient == tuple(0.3 * c for c in color)
    assert m.diffuse == tuple(0.7 * c for c in color)
    assert m.specular == tuple(0.4 * c for c in spec)


def test_color_alone_is_the_opengl_default_in_that_colour():
    m = ok({"color": [1, 0, 0.5]})
    assert m.ambient == (0.2, 0.0, 0.1) and m.diffuse == (0.8, 0.0, 0.4)
    assert m.specular == (0, 0, 0)


def test_scalars_without_color_use_white_and_ks_defaults_to_white_highlight():
    m = ok({"ka": 0.1, "kd": 0.6, "ks": 0.5})
    assert m.ambient == (0.1, 0.1, 0.1) and m.diffuse == (0.6, 0.6, 0.6)
    assert m.specular == (0.5, 0.5, 0.5)


def test_forms_can_be_mixed_across_terms():
    m = ok({"color": [0, 1, 0], "kd": 0.5, "ambient": [0.1, 0, 0], "specular": [0.3, 0.3, 0.3]})
    assert m.ambient == (0.1, 0, 0) and m.diffuse == (0, 0.5, 0) and m.specular == (0.3,) * 3


@pytest.mark.parametrize(
    ("scalar", "term"), [("ka", "ambient"), ("kd", "diffuse"), ("ks", "specular")]
)
def test_both_forms_for_one_term_is_an_error(scalar, term):
    (msg,) = messages({scalar: 0.5, term: [0.1, 0.1, 0.1], "color": [1, 1, 1]})
    assert f"m.yaml: {scalar}:" in msg and "not both" in msg and term in msg


def test_specular_color_without_ks_and_unused_color_are_errors():
    (msg,) = messages({"specular_color": [1, 1, 1]})
    assert "specular_color" in msg and "ks" in msg
    (msg,) = messages({"color": [1, 1, 1], "ambient": [0, 0, 0], "diffuse": [1, 1, 1]})
    assert "color" in msg and "not used" in msg


# -- validation messages ---------------------------------------------------------------------
def test_unknown_key_suggests_the_right_one():
    (msg,) = messages({"shinyness": 10})
    assert "shinyness" in msg and "did you mean 'shininess'?" in msg
    for key in MATERIAL_KEYS:
        assert key in msg  # the allowed keys are listed


@pytest.mark.parametrize(
    ("mapping", "key", "allowed"),
    [
        ({"diffuse": [0.5, 1.5, 0.5]}, "diffuse[1]", "[0, 1]"),
        ({"ka": 1.2}, "ka", "[0, 1]"),
        ({"kd": -0.1}, "kd", "[0, 1]"),
        ({"ks": 2, "specular_color": [1, 1, 1]}, "ks", "[0, 1]"),
        ({"color": [0, 0, 7]}, "color[2]", "[0, 1]"),
        ({"shininess": 1001}, "shininess", "[0, 1000]"),
        ({"shininess": -1}, "shininess", "[0, 1000]"),
        ({"opacity": 1.01}, "opacity", "[0, 1]"),
        ({"emission": [0, 0, 1.5]}, "emission[2]", "[0, 1]"),
    ],
)
def test_out_of_range_names_key_and_range(mapping, key, allowed):
    (msg,) = messages(mapping)
    assert msg.startswith(f"m.yaml: {key}: ") and allowed in msg


@pytest.mark.parametrize(
    ("mapping", "key", "words"),
    [
        ({"shininess": "shiny"}, "shininess", "must be a number"),
        ({"diffuse": [0.5, 0.5]}, "diffuse", "list of 3 numbers"),
        ({"diffuse": 0.5}, "diffuse", "list of 3 numbers"),
        ({"ka": True}, "ka", "must be a number"),
        ({"model": "gouraud"}, "model", "blinn, phong, threejs"),
        ({"description": ["a"]}, "description", "must be text"),
        ({"opacity": None}, "opacity", "must be a number"),
    ],
)
def test_wrong_types(mapping, key, words):
    (msg,) = messages(mapping)
    assert f"m.yaml: {key}" in msg and words in msg


def test_not_a_mapping():
    (msg,) = messages([0.1, 0.2, 0.3])
    assert "must be a material mapping" in msg


def test_every_problem_reported_at_once():
    msgs = messages(
        {"shinyness": 3, "ambient": [2, 0, 0], "ka": 0.1, "opacity": 3, "model": "x", "kd": 9}
    )
    assert len(msgs) == 6


def test_line_numbers_come_from_the_checker():
    checker = Checker("m.yaml", {(): 1, ("diffuse",): 4, ("diffuse", 2): 4})
    assert parse_material({"diffuse": [0, 0, 2]}, checker, ()) is None
    assert str(checker.problems[0]).startswith("m.yaml:4: diffuse[2]: ")


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"diffuse": (0.1, -0.1, 0.1)}, "diffuse[1]: must be >= 0, got -0.1"),
        ({"emission": (0, 0)}, "emission: must be a list of 3 numbers each >= 0"),
        ({"shininess": -1}, "shininess: must be >= 0, got -1"),
        ({"shininess": float("inf")}, "shininess: must be a finite number >= 0, got inf"),
        ({"opacity": 2}, "opacity: must be in [0, 1], got 2"),
        ({"model": "flat"}, "model: must be one of blinn, phong, threejs, got 'flat'"),
        ({"fresnel": 1.5}, "fresnel: must be in [0, 1], got 1.5"),
        ({"energy_conserving": "yes"}, "energy_conserving: must be true or false"),
        ({"description": 3}, "description: must be text"),
    ],
)
def test_material_constructor_rejects_impossible_values(kwargs, message):
    with pytest.raises(ValidationError) as info:
        Material(**kwargs)
    assert isinstance(info.value, ValueError) and str(info.value).startswith(message)


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("opacity", 2),
        ("model", "flat"),
        ("fresnel", -0.5),
        ("energy_conserving", "yes"),
        ("description", ["a"]),
    ],
)
def test_constructor_and_file_say_the_same(key, value):
    (from_file,) = messages({key: value})
    with pytest.raises(ValidationError) as info:
        Material(**{key: value})
    assert from_file == f"m.yaml: {info.value}"


def test_constructor_takes_what_the_engine_can_shade():
    # files hold coefficients in [0, 1] and shininess in [0, 1000]; the engine any value >= 0
    m = Material(diffuse=(1.5, 0, 0), shininess=4000)
    assert m.diffuse == (1.5, 0.0, 0.0) and m.shininess == 4000.0
    (msg,) = messages({"shininess": 4000})
    assert "[0, 1000]" in msg
    assert Material(model=None, fresnel=None) == Material()  # None: not given


# -- scalars (ka / kd / ks sliders) ----------------------------------------------------------
def representable(hue, k) -> bool:
    """True when hue * k keeps full precision (no channel falls into the subnormals)."""
    return all(h == 0 or h * k >= sys.float_info.min * 2**53 for h in hue)


def test_scalars_are_the_largest_channel_of_each_term():
    m = Material(ambient=(0.1, 0.3, 0.2), diffuse=(0.5, 0.4, 0.9), specular=(0, 0, 0.25))
    assert m.scalars() == (0.3, 0.9, 0.25)


@given(materials, unit, unit, unit)
def test_with_scalars_sets_exactly_and_keeps_the_hue(m, ka, kd, ks):
    new = m.with_scalars(ka=ka, kd=kd, ks=ks)
    assert new.scalars() == (ka, kd, ks)
    for term, k in (("ambient", ka), ("diffuse", kd), ("specular", ks)):
        old = getattr(m, term)
        if max(old) > 0 and representable(m.hue(term), k):
            assert new.hue(term) == pytest.approx(m.hue(term), rel=1e-12, abs=1e-300)
            for c_new, c_old in zip(getattr(new, term), old, strict=True):
                assert c_new == pytest.approx(c_old / max(old) * k, rel=1e-12, abs=1e-300)
    assert (new.emission, new.shininess, new.opacity, new.model) == (
        m.emission,
        m.shininess,
        m.opacity,
        m.model,
    )


@given(materials, unit)
def test_with_scalars_is_invertible_where_the_term_is_non_zero(m, kd):
    if max(m.diffuse) == 0 or not representable(m.hue("diffuse"), kd):
        return
    back = m.with_scalars(kd=kd).with_scalars(kd=max(m.diffuse))
    assert back.scalars()[1] == max(m.diffuse)
    assert back.diffuse == pytest.approx(m.diffuse, rel=1e-12, abs=1e-300)


def test_with_scalars_same_value_or_none_changes_nothing():
    m = Material(diffuse=(0.3, 0.1, 0.7))
    assert m.with_scalars() is m
    assert m.with_scalars(kd=0.7).diffuse == (0.3, 0.1, 0.7)


def test_black_terms_borrow_a_hue():
    plastic = Material(ambient=(0, 0, 0), diffuse=(0.5, 0.0, 0.25), specular=(0, 0, 0))
    assert plastic.with_scalars(ka=0.2).ambient == (0.2, 0.0, 0.1)  # diffuse hue
    assert plastic.with_scalars(ks=0.5).specular == (0.5, 0.5, 0.5)  # white highlight
    lamp = Material(ambient=(0.0, 0.3, 0.3), diffuse=(0, 0, 0))
    assert lamp.with_scalars(kd=0.5).diffuse == (0.0, 0.5, 0.5)  # ambient hue
    black = Material(ambient=(0, 0, 0), diffuse=(0, 0, 0))
    assert black.with_scalars(kd=0.5).diffuse == (0.5, 0.5, 0.5)


@pytest.mark.parametrize("bad", [-0.1, 1.5, float("nan"), "0.5", True])
def test_with_scalars_rejects_out_of_range(bad):
    with pytest.raises(ValidationError, match=r"^kd: must be (a (finite )?number )?in \[0, 1\]"):
        Material().with_scalars(kd=bad)
