"""Library errors: bad values are ValueErrors, wrong types TypeErrors, each naming its argument
(issue 19, item 9)."""

from __future__ import annotations

import pytest

from explorer.core.errors import ExplorerError, ExplorerTypeError, ValidationError
from explorer.core.scene import Scene, load_scene


def test_error_classes_are_value_and_type_errors():
    assert issubclass(ExplorerError, ValueError)
    assert issubclass(ExplorerTypeError, ExplorerError) and issubclass(ExplorerTypeError, TypeError)
    assert issubclass(ValidationError, ValueError)


@pytest.mark.parametrize(
    "kw, match",
    [
        ({"material": "gold"}, "material: .*preset name is looked up by find_preset"),
        ({"lights": [1, 2]}, r"lights\[0\]: must be a mapping"),
        ({"lights": 5}, "lights: must be a list of lights"),
        ({"viewer": "x"}, "viewer: must be"),
    ],
)
def test_scene_constructor_refuses_what_would_fail_later(kw, match):
    with pytest.raises(ValueError, match=match):
        Scene(**kw)


def test_a_scene_of_the_wrong_type_is_a_type_error():
    with pytest.raises(TypeError, match="scene must be a scene-file path"):
        load_scene(5)


@pytest.mark.parametrize("dirs", ["/tmp", b"/tmp", 5, [3]])
def test_materials_dirs_must_be_a_list_of_paths(tmp_path, dirs):
    with pytest.raises(ExplorerTypeError, match="materials_dirs must"):
        load_scene({"material": "gold"}, materials_dirs=dirs)


def test_materials_dirs_as_a_list(tmp_path):
    (tmp_path / "mine.yaml").write_text("diffuse: [0.5, 0.25, 0.125]\n")
    scene = load_scene({"material": "mine"}, materials_dirs=[tmp_path])
    assert scene.material.diffuse == (0.5, 0.25, 0.125)
