"""The plan: what it decides, and that following it changes no colour."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.scenes import scenes, vertices
from hypothesis import given
from hypothesis import strategies as st

import explorer
from explorer.cli import main
from explorer.core import tolerances as tol
from explorer.core.scene import load_scene
from explorer.shading import kernels as K
from explorer.shading.equation import equation_shade
from explorer.shading.plan import make_plan


@given(scenes(), st.integers(0, 2**32 - 1))
def test_planned_result_equals_full_generality_result(scene, seed):
    P, N = vertices(seed)
    loaded = load_scene(scene)
    full = equation_shade(loaded, P, N, clamp=False)
    planned = explorer.shade(loaded, P, N, clamp=False)
    assert np.abs(planned - full).max(initial=0) <= tol.PLAN_ABS_TOL
    fast = explorer.shade(loaded, P, N, precision="float32")
    assert np.abs(fast - np.clip(full, 0, 1)).max(initial=0) <= tol.FLOAT32_MAX_ABS_ERROR


def plan_of(**scene):
    return make_plan(load_scene(scene))


def light_flags(scene) -> list[int]:
    sh = explorer.Shader(scene, np.zeros((1, 3)), np.ones((1, 3)))
    return list(sh._params_for(np.float32)[1])


def test_matte_material_plans_no_specular():
    plan = plan_of(material={"specular": [0, 0, 0]}, lights=[{"type": "point"}])
    assert not plan.specular and plan.view == "none" and plan.halfway == "none"
    sh = explorer.Shader({"material": {"specular": [0, 0, 0]}}, np.zeros((5, 3)), np.ones((5, 3)))
    _ = sh.colors
    assert sh.stats["specular"] == 0 and sh.stats["diffuse"] == 1


def test_lights_without_specular_colour_plan_no_specular():
    plan = plan_of(
        material={"specular": [1, 1, 1]}, lights=[{"type": "directional", "specular": [0, 0, 0]}]
    )
    assert not plan.specular


def test_directional_lights_need_no_distance():
    scene = {"lights": [{"type": "directional", "to_light": [1, 1, 1]}]}
    lp = plan_of(**scene).lights[0]
    assert not lp.positional and lp.attenuation == "none"
    assert not light_flags(scene)[0] & (K.POSITIONAL | K.ATTEN | K.SPOT)


@pytest.mark.parametrize(
    "att, want, factor",
    [([1, 0, 0], "none", 1.0), ([4, 0, 0], "constant", 0.25), ([1, 0.1, 0], "per-vertex", 1.0)],
)
def test_attenuation_is_planned_only_where_it_varies(att, want, factor):
    scene = {"lights": [{"type": "point", "position": [0, 0, 2], "attenuation": att}]}
    lp = plan_of(**scene).lights[0]
    assert (lp.attenuation, lp.factor) == (want, factor)
    assert bool(light_flags(scene)[0] & K.ATTEN) == (want == "per-vertex")


@pytest.mark.parametrize(
    "cutoff, exponent, want", [(180, 5, "none"), (30, 0, "cone"), (30, 5, "cone+exponent")]
)
def test_spot_factor_only_for_a_cone(cutoff, exponent, want):
    scene = {"lights": [{"type": "spot", "cutoff": cutoff, "exponent": exponent}]}
    assert plan_of(**scene).lights[0].spot == want
    f = light_flags(scene)[0]
    assert bool(f & K.SPOT) == (want != "none") and bool(f & K.SPOT_EXP) == (
        want == "cone+exponent"
    )


def test_constant_halfway_for_directional_light_and_infinite_viewer():
    base = {
        "material": {"specular": [1, 1, 1], "shininess": 10},
        "lights": [{"type": "directional", "to_light": [0, 1, 1]}],
    }
    assert plan_of(**base, viewer={"to_viewer": [0, 0, 1]}).halfway == "constant"
    assert light_flags({**base, "viewer": {"to_viewer": [0, 0, 1]}})[0] & K.CONST_H
    assert plan_of(**base, viewer={"eye": [0, 0, 5]}).halfway == "per-vertex"
    assert plan_of(**base, model="phong").halfway == "reflection"
    assert not light_flags({**base, "model": "phong"})[0] & K.CONST_H


def test_shininess_zero_needs_no_lobe():
    plan = plan_of(material={"specular": [1, 1, 1], "shininess": 0}, viewer={"eye": [0, 0, 3]})
    assert plan.flat_specular and plan.view == "none" and plan.halfway == "none"


def test_constant_light_ambient_folds_into_scene_ambient():
    plan = plan_of(
        material={"ambient": [1, 1, 1]},
        lights=[
            {"type": "directional", "ambient": [0.3, 0.3, 0.3]},
            {"type": "point", "ambient": [0.1, 0.1, 0.1], "attenuation": [1, 1, 0]},
        ],
    )
    assert plan.ambient_per_vertex  # the attenuated one
    plan = plan_of(
        material={"ambient": [1, 1, 1]},
        lights=[{"type": "directional", "ambient": [0.3, 0.3, 0.3]}],
    )
    assert not plan.ambient_per_vertex


def test_plan_command_prints_every_decision(tmp_path, capsys):
    f = tmp_path / "scene.yaml"
    f.write_text(
        "material: {specular: [1, 1, 1], shininess: 20}\nviewer: {to_viewer: [0, 0, 1]}\n"
        "lights:\n  - {type: directional, to_light: [1, 1, 1]}\n"
        "  - {type: point, position: [2, 3, 1], attenuation: [1, 0, 0]}\n"
        "  - {type: spot, position: [0, 4, 0], aim: [0, -1, 0], cutoff: 30}\n"
    )
    assert main(["plan", str(f)]) == 0
    out = capsys.readouterr().out
    assert "light 0 (directional)  distance     out" in out
    assert "constant H" in out
    assert "attenuation [1, 0, 0] is 1 everywhere" in out
    assert "cone test at 30°, exponent 0 (no pow)" in out
    assert "emission     out" in out


def test_plan_command_reports_bad_files_without_traceback(tmp_path, capsys):
    f = tmp_path / "bad.yaml"
    f.write_text("lights:\n  - {type: point, attenuation: [0, 0, 0]}\n  - {typ: spot}\n")
    assert main(["plan", str(f)]) == 2
    err = capsys.readouterr().err
    assert "bad.yaml:2: lights[0].attenuation" in err
    assert "did you mean 'type'" in err
    assert "Traceback" not in err
