"""The controls table (explorer.core.controls) is the file validators' ranges: a value at a
control's end is taken from a file, one beyond it is refused; the shininess slider's log scale
maps both ways."""

from __future__ import annotations

import pytest

from explorer.core import controls as C
from explorer.core.lights import parse_light
from explorer.core.material import parse_material
from explorer.core.validate import Checker

MATERIAL_KEYS = ("ka", "kd", "ks", "shininess", "opacity")
BASE = {"ambient": [0.2, 0.2, 0.2], "diffuse": [0.5, 0.5, 0.5], "specular": [0.5, 0.5, 0.5],
        "shininess": 32}  # fmt: skip


def _material_problems(key: str, value: float) -> list:
    checker = Checker("m.yaml")
    mapping = dict(BASE)
    if key in ("ka", "kd", "ks"):  # the scalar form of a term: colour times the scalar
        mapping = {**BASE, "color": [1, 1, 1], key: value}
        for rgb in ("ambient", "diffuse", "specular"):
            mapping.pop(rgb)
    else:
        mapping[key] = value
    parse_material(mapping, checker)
    return checker.problems


@pytest.mark.parametrize("key", MATERIAL_KEYS)
def test_material_controls_span_exactly_what_a_file_takes(key):
    c = C.CONTROLS[key]
    lo, hi = c.field_range
    assert not _material_problems(key, lo) and not _material_problems(key, hi)
    assert _material_problems(key, hi * 1.01 + 0.01), f"{key} above {hi} must be refused"
    assert _material_problems(key, lo - 0.01), f"{key} below {lo} must be refused"


@pytest.mark.parametrize("key", ["cutoff", "exponent"])
def test_spot_controls_span_what_a_file_takes(key):
    c = C.CONTROLS[key]

    def problems(v):
        checker = Checker("s.yaml")
        spot = {"type": "spot", "position": [0, 0, 3], "aim": [0, 0, -1], key: v}
        parse_light(spot, checker, ("lights", 0))
        return checker.problems

    assert not problems(c.lo) and not problems(c.hi)
    assert problems(c.hi + 1.0) and problems(c.lo - 1.0)


def test_every_control_has_a_range_and_the_shininess_is_log():
    for key, c in C.CONTROLS.items():
        assert c.key == key and c.lo < c.hi
        flo, fhi = c.field_range
        assert flo <= c.lo and c.hi <= fhi
    assert C.CONTROLS["shininess"].scale == "log"
    assert {c.scale for k, c in C.CONTROLS.items() if k != "shininess"} == {"linear"}


def test_log_scale_maps_both_ways():
    s = C.CONTROLS["shininess"]
    assert C.to_step(s, 0.0) == 0 and C.from_step(s, 0) == 0.0
    assert C.from_step(s, 1) == 1.0 and C.from_step(s, C.STEPS) == 10.0**C.LOG_DECADES
    for n in (1.0, 8.0, 32.0, 128.0, 1000.0):
        assert C.from_step(s, C.to_step(s, n)) == pytest.approx(n, rel=0.01)
    kd = C.CONTROLS["kd"]
    assert C.to_step(kd, 0.5) == C.STEPS // 2 and C.from_step(kd, C.STEPS) == kd.hi
    assert C.to_step(kd, 2.0) == C.STEPS  # clamped to the slider's end
