"""Random scenes for property tests (hypothesis strategies), in the scene-file schema."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

import explorer
from explorer.core import tolerances as tol
from explorer.core.material import SHININESS_RANGE, Material

unit_float = st.floats(0, 1, allow_nan=False, allow_infinity=False)
maybe_zero_rgb = st.one_of(st.just([0.0, 0.0, 0.0]), st.lists(unit_float, min_size=3, max_size=3))
vec = st.lists(st.floats(-3, 3, allow_nan=False), min_size=3, max_size=3).filter(
    lambda v: sum(c * c for c in v) > 1e-2
)
#: materials a preset file can hold (every coefficient in [0, 1], shininess in its file range)
unit = st.floats(0.0, 1.0, allow_nan=False)
rgb = st.tuples(unit, unit, unit)
materials = st.builds(
    Material,
    ambient=rgb,
    diffuse=rgb,
    specular=rgb,
    emission=rgb,
    shininess=st.floats(*SHININESS_RANGE),
    opacity=unit,
    model=st.sampled_from([None, "blinn", "phong"]),
    description=st.text(max_size=40),
)


@st.composite
def lights(draw):
    kind = draw(st.sampled_from(["directional", "point", "spot"]))
    light = {
        "type": kind,
        "ambient": draw(maybe_zero_rgb),
        "diffuse": draw(maybe_zero_rgb),
        "specular": draw(maybe_zero_rgb),
    }
    if kind == "directional":
        light["to_light"] = draw(vec)
    else:
        light["position"] = [c * 2 for c in draw(vec)]
        light["attenuation"] = draw(
            st.sampled_from(
                [[1, 0, 0], [2, 0, 0], [0.5, 0, 0], [1, 0.3, 0], [1, 0.1, 0.05], [0.2, 0, 0.3]]
            )
        )
    if kind == "spot":
        light["aim"] = draw(vec)
        light["cutoff"] = draw(st.sampled_from([180.0, 90.0, 60.0, 25.0]))
        light["exponent"] = draw(st.sampled_from([0.0, 1.0, 7.5, 128.0]))
    return light


@st.composite
def scenes(draw, max_lights=4):
    material = {
        "ambient": draw(maybe_zero_rgb),
        "diffuse": draw(maybe_zero_rgb),
        "specular": draw(maybe_zero_rgb),
        "emission": draw(maybe_zero_rgb),
        "shininess": draw(st.sampled_from([0.0, 1.0, 12.8, 76.8, 500.0])),
    }
    viewer = draw(
        st.one_of(
            st.builds(lambda v: {"eye": [c * 3 for c in v]}, vec),
            st.builds(lambda v: {"to_viewer": v}, vec),
        )
    )
    return {
        "material": material,
        "model": draw(st.sampled_from(["blinn", "phong"])),
        "ambient": draw(maybe_zero_rgb),
        "viewer": viewer,
        "two_sided": draw(st.booleans()),
        "lights": draw(st.lists(lights(), min_size=0, max_size=max_lights)),
    }


def vertices(seed: int, n: int = 64):
    """Positions in a unit-ish ball and random (non-unit) normals."""
    rng = np.random.default_rng(seed)
    return rng.normal(size=(n, 3)), rng.normal(size=(n, 3)) * rng.uniform(0.2, 3, (n, 1))


# -- random scenes in OpenGL's ranges, and the oracle's form of them ---------------------------


def random_gl_scene(rng: np.random.Generator) -> dict:
    """A random blinn scene inside OpenGL's ranges, in the engine's schema."""

    def rgb():
        return rng.uniform(0, 1, 3).round(6).tolist()

    lights = []
    for _ in range(rng.integers(1, 5)):
        kind = rng.choice(["directional", "point", "spot"])
        light = {"type": str(kind), "ambient": rgb(), "diffuse": rgb(), "specular": rgb()}
        if kind == "directional":
            light["to_light"] = rng.normal(size=3).tolist()
        else:
            light["position"] = (rng.normal(size=3) * 3).tolist()
            light["attenuation"] = [
                float(rng.uniform(0.5, 2)),
                float(rng.uniform(0, 0.5)),
                float(rng.uniform(0, 0.2)),
            ]
        if kind == "spot":
            light["aim"] = rng.normal(size=3).tolist()
            light["cutoff"] = float(rng.choice([rng.uniform(5, 90), 180.0]))
            light["exponent"] = float(rng.uniform(0, 128))
        lights.append(light)
    viewer = (
        {"eye": (rng.normal(size=3) * 4).tolist()}
        if rng.random() < 0.5
        else {"to_viewer": rng.normal(size=3).tolist()}
    )
    return {
        "material": {
            "ambient": rgb(),
            "diffuse": rgb(),
            "specular": rgb(),
            "emission": rgb(),
            "shininess": float(rng.choice([0.0, rng.uniform(0, 128)])),
        },
        "model": "blinn",
        "ambient": rgb(),
        "viewer": viewer,
        "lights": lights,
    }


def to_gl(scene: dict) -> dict:
    """The same scene in the oracle's OpenGL terms (w = 0 for directional lights)."""
    gl_lights = []
    for lt in scene["lights"]:
        if lt["type"] == "directional":
            pos = [*lt["to_light"], 0.0]
        else:
            pos = [*lt["position"], 1.0]
        gl_lights.append(
            {
                "position": pos,
                "ambient": lt["ambient"],
                "diffuse": lt["diffuse"],
                "specular": lt["specular"],
                "attenuation": lt.get("attenuation", [1, 0, 0]),
                "spot_direction": lt.get("aim", [0, 0, -1]) if lt["type"] == "spot" else None,
                "spot_cutoff": lt.get("cutoff", 180.0) if lt["type"] == "spot" else 180.0,
                "spot_exponent": lt.get("exponent", 0.0) if lt["type"] == "spot" else 0.0,
            }
        )
    v = scene["viewer"]
    return {
        "material": scene["material"],
        "ambient": scene["ambient"],
        "local_viewer": "eye" in v,
        "eye": v.get("eye"),
        "view_dir": v.get("to_viewer"),
        "lights": gl_lights,
    }


def check_oracle(scene: dict, oracle, rng: np.random.Generator, n: int) -> None:
    """The engine's float64 colours of ``scene`` at n random vertices equal ``oracle(vertex,
    normal, to_gl(scene))`` within ORACLE_ABS_TOL, and float32 is within 1/255 of float64."""
    P = rng.normal(size=(n, 3)) * 1.5
    N = rng.normal(size=(n, 3))
    got = explorer.shade(scene, P, N)
    gl = to_gl(scene)
    want = np.array([oracle(p.tolist(), v.tolist(), gl) for p, v in zip(P, N, strict=True)])
    assert np.abs(got - want).max() <= tol.ORACLE_ABS_TOL
    fast = explorer.shade(scene, P, N, precision="float32")
    assert np.abs(fast - got).max() <= tol.FLOAT32_MAX_ABS_ERROR
