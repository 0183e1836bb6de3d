"""Extreme finite input (issue 19 items 1 and 2): far lights, tiny and huge attenuation, tiny
meshes, HDR display of huge sums. Every accepted scene gives finite colours in [0, 1]; a far
positional light lights the mesh like a directional light toward it (tolerances.FAR_LIGHT)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.scenes import vertices
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import explorer
from explorer.core import tolerances as tol
from explorer.shading.effects.hdr import display, tone_map
from explorer.shading.equation import equation_shade

PRECISIONS = ("float64", "float32")
TONES = ("clamp", "reinhard", "aces")
MATERIAL = {
    "ambient": [0.1, 0.1, 0.1],
    "diffuse": [0.6, 0.5, 0.4],
    "specular": [0.5, 0.5, 0.5],
    "shininess": 20.0,
}


def scene(*lights, **extra) -> dict:
    return {"material": MATERIAL, "viewer": {"to_viewer": [0, 0, 1]}, "lights": list(lights)}


def point(position, attenuation=(1, 0, 0), **extra) -> dict:
    return {"type": "point", "position": list(position), "attenuation": list(attenuation), **extra}


def directional(to_light, **extra) -> dict:
    return {"type": "directional", "to_light": list(to_light), **extra}


def sphere(scale=1.0):
    P, N = vertices(7, 200)
    return P * scale, N


def shaded(s, P, N, precision, **kw):
    c = explorer.shade(s, P, N, precision=precision, **kw)
    assert c.shape == (len(P), 3)
    assert np.isfinite(c).all(), f"non-finite colours ({precision})"
    return c


def close(a, b, precision) -> bool:
    limit = tol.FLOAT32_MAX_ABS_ERROR if precision == "float32" else 1e-9
    return np.abs(a - b).max() <= limit


# -- item 1: NaN colours ---------------------------------------------------------------------
@pytest.mark.parametrize("precision", PRECISIONS)
def test_light_too_far_for_its_distance_squared_gives_finite_colours(precision):
    P, N = sphere()
    s = scene(point([0, 0, 4e154], [0, 1, 0]))
    c = shaded(s, P, N, precision)
    # 1 / 4e154 of a light: ambient of the material only (the scene ambient is 0.2)
    assert close(c, shaded(scene(), P, N, precision), precision)


@pytest.mark.parametrize("precision", PRECISIONS)
@pytest.mark.parametrize("kc", [1e-320, 1e-300, 1e-39, 1e-7])
def test_tiny_constant_attenuation_is_capped_at_the_floor(precision, kc):
    P, N = sphere()
    c = shaded(scene(point([0, 0, 3], [kc, 0, 0])), P, N, precision)
    floor = shaded(scene(point([0, 0, 3], [tol.ATTENUATION_FLOOR, 0, 0])), P, N, precision)
    assert close(c, floor, precision)
    ref = equation_shade(explorer.load_scene(scene(point([0, 0, 3], [kc, 0, 0]))), P, N)
    assert close(c, ref, precision)


@pytest.mark.parametrize("precision", PRECISIONS)
@pytest.mark.parametrize("distance", [1e13, 1e19, 1e20, 1e38, 1e200, 1e308])
def test_far_point_light_lights_like_a_directional_light(precision, distance):
    P, N = sphere()
    c = shaded(scene(point([0, distance, 0])), P, N, precision)
    d = shaded(scene(directional([0, 1, 0])), P, N, precision)
    assert close(c, d, precision)
    assert c.max() > 0.5  # lit, not ambient only
    ref = equation_shade(explorer.load_scene(scene(point([0, distance, 0]))), P, N)
    assert close(c, ref, precision)


@pytest.mark.parametrize("precision", PRECISIONS)
def test_far_light_is_attenuated_at_its_distance(precision):
    P, N = sphere()
    far = point([1e30, 0, 0], [1, 1e-30, 0])  # 1 / (1 + 1e-30·1e30) = 1/2
    c = shaded(scene(far), P, N, precision)
    half = shaded(
        scene(directional([1, 0, 0], diffuse=[0.5] * 3, specular=[0.5] * 3)), P, N, precision
    )
    assert close(c, half, precision)


@pytest.mark.parametrize("precision", PRECISIONS)
def test_far_spot_light_uses_its_cone_toward_the_mesh(precision):
    P, N = sphere()
    inside = {"type": "spot", "position": [0, 0, 1e100], "aim": [0, 0, -1], "cutoff": 10.0}
    outside = {**inside, "aim": [0, 0, 1]}
    lit = shaded(scene(inside), P, N, precision)
    assert close(lit, shaded(scene(directional([0, 0, 1])), P, N, precision), precision)
    assert close(
        shaded(scene(outside), P, N, precision), shaded(scene(), P, N, precision), precision
    )


@pytest.mark.parametrize("precision", PRECISIONS)
def test_light_near_a_tiny_mesh_is_far_in_its_frame(precision):
    P, N = sphere(1e-300)
    c = shaded(scene(point([0, 2, 0], [1, 0.5, 0])), P, N, precision)  # 1 / (1 + 0.5·2) = 1/2
    half = shaded(
        scene(directional([0, 1, 0], diffuse=[0.5] * 3, specular=[0.5] * 3)), P, N, precision
    )
    assert close(c, half, precision)


@pytest.mark.parametrize("precision", PRECISIONS)
def test_huge_attenuation_coefficients_in_a_huge_frame_stay_finite(precision):
    P, N = sphere(1e200)
    # kl·scale and kq·scale² overflow; the light sits on a vertex (distance 0)
    s = scene(point(P[0], [0, 1e300, 1e300]), point([0, 0, 3e200], [0, 0, 1e-300]))
    c = shaded(s, P, N, precision)
    assert (c >= 0).all() and (c <= 1).all()


def test_far_light_shadow_rays_point_at_it():
    from explorer.core.lights import PointLight

    P, _ = sphere()
    D, tmax = PointLight(position=(0.0, 1e200, 0.0)).shadow_ray(P, np.zeros(3), 1.0)
    assert np.isfinite(D).all() and np.allclose(D, [0, 1, 0])
    assert (tmax > 1e6).all()


def test_toward_in_the_world_keeps_the_light_where_it_is():
    from explorer.core.lights import PointLight

    P = np.array([[1e13, 0.0, 0.0], [3e13, 0.0, 0.0]])
    D = PointLight(position=(2e13, 0.0, 0.0)).toward(P)  # no frame: no far-light policy
    assert D[:, 0].tolist() == [1e13, -1e13]


# -- HDR display -----------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["clamp", "reinhard", "aces"])
def test_tone_maps_send_huge_and_inf_to_one(name):
    x = np.array([[1e17, 1e200, np.inf]])
    with np.errstate(all="raise"):
        assert tone_map(x, name).tolist() == [[1.0, 1.0, 1.0]]


@pytest.mark.parametrize("precision", PRECISIONS)
@pytest.mark.parametrize("tone", ["reinhard", "aces"])
def test_hdr_display_of_a_blinding_light_is_finite(precision, tone):
    P, N = sphere()
    light = point([0, 0, 3], [1e-300, 0, 0], diffuse=[1e6] * 3, specular=[1e6] * 3)
    s = {**scene(light), "hdr": {"exposure": 16, "tone_map": tone}}
    c = explorer.shade(s, P, N, precision=precision, clamp=False)
    out = display(c, explorer.load_scene(s).hdr)
    assert np.isfinite(out).all() and (out >= 0).all() and (out <= 1).all()


# -- fuzz: extreme finite values everywhere ---------------------------------------------------
def extreme(lo=-308, hi=308):
    """Finite floats from 1e-320 to 1e308 in size, either sign, and 0."""
    mag = st.one_of(
        st.just(0.0),
        st.just(1e-320),
        st.builds(lambda e, m: m * 10.0**e, st.integers(lo, hi), st.floats(1.0, 1.79)),
    )
    return st.builds(lambda s, m: s * m, st.sampled_from([1.0, -1.0]), mag)


def triple(values):
    return st.lists(values, min_size=3, max_size=3)


colour = triple(st.one_of(st.floats(0, 1), st.sampled_from([0.0, 1e-320, 1e-200, 1e3, 1e6])))
attenuation = triple(st.one_of(st.just(0.0), extreme(-308, 308).map(abs)))


@st.composite
def extreme_lights(draw):
    kind = draw(st.sampled_from(["directional", "point", "spot"]))
    light = {"type": kind, "ambient": draw(colour), "diffuse": draw(colour)}
    light["specular"] = draw(colour)
    if kind == "directional":  # huge and tiny directions: another item (unit vectors)
        light["to_light"] = draw(triple(st.floats(-3, 3)).filter(lambda v: max(map(abs, v)) > 0.1))
        return light
    light["position"] = draw(triple(extreme()))
    light["attenuation"] = draw(attenuation.filter(any))
    if kind == "spot":
        light["aim"] = [0.0, 0.0, -1.0]
        light["cutoff"] = draw(st.sampled_from([180.0, 60.0, 5.0]))
        light["exponent"] = draw(st.sampled_from([0.0, 10.0, 128.0]))
    return light


@settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    lights=st.lists(extreme_lights(), min_size=1, max_size=3),
    exponent=st.integers(-320, 300),
    shift=triple(extreme(-300, 300)),
    precision=st.sampled_from(PRECISIONS),
    seed=st.integers(0, 2**16),
    hdr=st.one_of(
        st.none(),
        st.fixed_dictionaries(
            {"exposure": st.sampled_from([-16, 0, 16]), "tone_map": st.sampled_from(TONES)}
        ),
    ),
)
def test_extreme_finite_scenes_give_finite_colours_or_a_clean_error(
    lights, exponent, shift, precision, seed, hdr
):
    P, N = vertices(seed, 12)
    with np.errstate(over="ignore"):
        P = P * 10.0**exponent + np.asarray(shift)
    if not np.isfinite(P).all():
        return
    s = {**scene(), "lights": lights, **({"hdr": hdr} if hdr else {})}
    try:
        c = explorer.shade(s, P, N, precision=precision, clamp=hdr is None)
    except ValueError as exc:  # refused: the message names what is wrong
        assert any(k in str(exc) for k in ("position", "attenuation", "degenerate", "vertices"))
        return
    assert c.shape == (len(P), 3)
    assert np.isfinite(c).all() and (c >= 0).all()
    loaded = explorer.load_scene(s)
    shown = display(c, loaded.hdr)
    assert np.isfinite(shown).all() and (shown >= 0).all() and (shown <= 1).all()
    ref = equation_shade(loaded, P, N, clamp=hdr is None)
    assert np.isfinite(ref).all()


# -- hostile types ---------------------------------------------------------------------------

#: where a hostile value goes: a key path in a valid scene mapping
_PATHS = [
    ("material",),
    ("material", "diffuse"),
    ("material", "shininess"),
    ("material", "opacity"),
    ("model",),
    ("ambient",),
    ("two_sided",),
    ("viewer",),
    ("viewer", "eye"),
    ("lights",),
    ("lights", 0),
    ("lights", 0, "type"),
    ("lights", 0, "position"),
    ("lights", 0, "attenuation"),
    ("lights", 0, "aim"),
    ("lights", 0, "cutoff"),
    ("hdr",),
    ("hdr", "exposure"),
]
_HOSTILE = st.one_of(
    st.none(),
    st.booleans(),
    st.text(max_size=8),
    st.integers(min_value=-(10**400), max_value=10**400),
    st.floats(allow_nan=True, allow_infinity=True),
    st.lists(st.one_of(st.text(max_size=3), st.none(), st.floats()), max_size=4),
    st.dictionaries(st.text(max_size=4), st.integers(), max_size=2),
)


def _base_scene() -> dict:
    return {
        "material": {"diffuse": [0.8, 0.2, 0.1], "specular": [1, 1, 1], "shininess": 20},
        "model": "blinn",
        "ambient": [0.2, 0.2, 0.2],
        "two_sided": False,
        "viewer": {"eye": [0, 0, 5]},
        "lights": [
            {"type": "spot", "position": [2, 2, 2], "aim": [-1, -1, -1], "cutoff": 45,
             "attenuation": [1, 0.1, 0]}
        ],
        "hdr": {"exposure": 0, "tone_map": "reinhard"},
    }  # fmt: skip


@given(path=st.sampled_from(_PATHS), value=_HOSTILE, precision=st.sampled_from(PRECISIONS))
@settings(max_examples=60)
def test_hostile_types_give_finite_colours_or_an_error_naming_the_key(path, value, precision):
    """Any value of any type at any key: finite colours in [0, 1], or a ValueError / TypeError
    whose message names the key (never an AttributeError, OverflowError or NaN)."""
    scene = _base_scene()
    node = scene
    for part in path[:-1]:
        node = node[part]
    node[path[-1]] = value
    P, N = vertices(7, 32)
    try:
        c = explorer.shade(scene, P, N, precision=precision)
    except (ValueError, TypeError) as exc:
        named = [p for p in path if isinstance(p, str)]
        assert named[-1] in str(exc) or named[0] in str(exc), (path, str(exc))
        return
    assert c.shape == (len(P), 3) and np.isfinite(c).all()
    assert c.min() >= 0.0 and c.max() <= 1.0


@pytest.mark.parametrize("precision", PRECISIONS)
@pytest.mark.parametrize("exponent", [-309, -315, -323])
def test_a_mesh_of_subnormal_size_gives_finite_colours(precision, exponent):
    """A mesh whose extent is below float64's smallest normal number (found by the fuzz at
    1e-309): the frame's scale is floored at MIN_FRAME_SCALE, so its reciprocal stays finite."""
    P, N = vertices(0, 12)
    scene = {
        "lights": [
            {"type": "point", "diffuse": [0, 0, 1], "position": [0, 0, 0],
             "attenuation": [0, 0, 1e-320]}
        ]
    }  # fmt: skip
    c = explorer.shade(scene, P * 10.0**exponent, N, precision=precision)
    assert np.isfinite(c).all() and c.min() >= 0.0 and c.max() <= 1.0
