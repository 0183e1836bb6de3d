"""Scene and HDR settings: one check per key, run by the scene-file parser and the constructor
(explorer.core.scene, explorer.core.hdr)."""

from __future__ import annotations

import pathlib

import pytest

from explorer.core.errors import ValidationError
from explorer.core.hdr import HDR
from explorer.core.lights import PointLight
from explorer.core.material import Material
from explorer.core.scene import DEFAULT_LIGHTS, Scene, Viewer, load_scene

# (key, bad value, the message of the file and of the constructor)
SCENE_BAD = [
    ("model", "phon", "must be one of blinn, phong, threejs, got 'phon' (did you mean 'phong'?)"),
    ("ambient", [0.2, -0.1, 0.2], "must be >= 0, got -0.1"),
    ("ambient", [0.2, 0.2], "must be a list of 3 numbers each >= 0, got a list of 2 [0.2, 0.2]"),
    ("two_sided", "yes", "must be true or false, got text 'yes'"),
    ("lights", {"type": "point"}, "must be a list of lights (- {type: ..., ...})"),
    ("lights", [{"type": "spot", "cutoff": 120}], "must be in [0, 90] or exactly 180, got 120"),
    ("mesh", 3, "must be text, got int 3"),
    ("hdr", {"exposure": 40}, "must be in [-16, 16], got 40"),
    ("hdr", {"tone_map": "filmic"}, "must be one of clamp, reinhard, aces, got 'filmic'"),
    ("viewer", {"eye": [0, "a", 0]}, "must be a number, got text 'a'"),
    ("material", {"opacity": 2}, "must be in [0, 1], got 2"),
    ("shading", "per-face", "must be one of per-vertex, per-pixel, got 'per-face'"),
]


@pytest.mark.parametrize("key, value, message", SCENE_BAD)
def test_file_and_constructor_report_a_bad_scene_key_alike(key, value, message):
    with pytest.raises(ValidationError) as from_mapping:
        load_scene({key: value})
    (p,) = from_mapping.value.problems
    assert p.key.startswith(key) and p.message == message
    with pytest.raises(ValidationError) as from_code:
        Scene(**{key: value})
    (q,) = from_code.value.problems
    assert (q.key, q.message) == (p.key, p.message)
    assert isinstance(from_code.value, ValueError)


@pytest.mark.parametrize(
    "key, value, message",
    [
        ("exposure", 17, "must be in [-16, 16], got 17"),
        ("exposure", float("nan"), "must be a finite number in [-16, 16], got nan"),
        ("exposure", "1", "must be a number in [-16, 16], got text '1'"),
        ("tone_map", "Reinhard", "must be one of clamp, reinhard, aces, got 'Reinhard'"),
    ],
)
def test_hdr_file_and_constructor_report_alike(key, value, message):
    with pytest.raises(ValidationError) as from_mapping:
        load_scene({"hdr": {key: value}})
    (p,) = from_mapping.value.problems
    assert p.key == f"hdr.{key}" and p.message.startswith(message)
    with pytest.raises(ValidationError) as from_code:
        HDR(**{key: value})
    (q,) = from_code.value.problems
    assert (q.key, q.message) == (key, p.message)


def test_a_file_reports_every_scene_problem_with_file_and_line(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text("model: flat\nambient: [0, 0, -1]\ntwo_sided: 1\nhdr: {exposure: 20}\n")
    with pytest.raises(ValidationError) as err:
        load_scene(str(f))
    assert str(err.value).splitlines() == [
        f"{f}:1: model: must be one of blinn, phong, threejs, got 'flat'",
        f"{f}:2: ambient[2]: must be >= 0, got -1",
        f"{f}:3: two_sided: must be true or false, got int 1",
        f"{f}:4: hdr.exposure: must be in [-16, 16], got 20",
    ]


def test_constructor_reports_every_problem_at_once():
    with pytest.raises(ValidationError) as err:
        Scene(model="x", ambient=(0, 0), two_sided=None, lights=[None], hdr=HDR(), mesh=b"m")
    assert [p.key for p in err.value.problems] == [
        "model",
        "ambient",
        "two_sided",
        "lights[0]",
        "mesh",
    ]


def test_constructor_converts_like_the_file():
    scene = Scene(
        ambient=[0, 0.5, 1],
        lights=[PointLight()],
        mesh=pathlib.Path("a/b.ply"),
        viewer={"eye": [0, 0, 4]},
        hdr=True,
    )
    assert scene.ambient == (0.0, 0.5, 1.0) and isinstance(scene.ambient[0], float)
    assert scene.lights == (PointLight(),) and scene.mesh == "a/b.ply"
    assert scene.viewer == Viewer(eye=(0, 0, 4)) and scene.hdr == HDR()
    assert Scene(mesh=None, hdr=None).lights == DEFAULT_LIGHTS  # None: not given
    assert Scene(material={"color": [1, 0, 0]}).material == Material(
        ambient=(0.2, 0, 0), diffuse=(0.8, 0, 0)
    )


def test_file_only_forms_stay_in_the_parser():
    scene = load_scene({"material": "chrome"})  # a preset name, and the model it names
    assert scene.material.name == "chrome" and scene.model == (scene.material.model or "blinn")
    with pytest.raises(ValidationError, match="material: must be a Material or a mapping"):
        Scene(material="chrome")


def test_hdr_false_means_no_hdr_like_leaving_it_out(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text("hdr: false\n")
    assert load_scene(f) == Scene() and load_scene(f).hdr is None
    assert load_scene({"hdr": False}).hdr is None and Scene(hdr=False).hdr is None
    assert load_scene({"hdr": True}).hdr == HDR()
    with pytest.raises(ValidationError, match="hdr: must be"):
        load_scene({"hdr": "no"})
