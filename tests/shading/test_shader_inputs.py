"""Bad inputs to shade() and Shader: a ValueError (or a TypeError for a wrong type) naming the
argument, raised before any state changes (issue 19, item 9)."""

from __future__ import annotations

import numpy as np
import pytest

import explorer
from explorer.core.errors import ExplorerError, ExplorerTypeError
from explorer.core.material import Material
from explorer.geometry.meshes import get_mesh

MESH = get_mesh("icosphere", 1)


@pytest.fixture(params=["float32", "float64"])
def shader(request):
    return explorer.Shader(
        {"material": "gold"}, MESH.positions, MESH.normals, precision=request.param
    )


def same_state(shader, scene, colours):
    assert shader.scene == scene
    assert np.array_equal(shader.colors, colours)
    fresh = explorer.shade(scene, MESH.positions, MESH.normals, precision=shader.precision)
    assert np.allclose(shader.colors, fresh, atol=1e-6)


@pytest.mark.parametrize(
    "setter, value, error, match",
    [
        ("set_material", "no_such_preset", ExplorerError, "no_such_preset"),
        ("set_material", 3, ExplorerTypeError, "material must be"),
        ("set_material", {"diffuse": [2, 0, 0]}, ExplorerError, r"material\.diffuse"),
        ("set_lights", 5, ExplorerTypeError, "lights must be a list of lights"),
        ("set_lights", {"type": "point"}, ExplorerTypeError, "lights must be a list of lights"),
        ("set_lights", [1, 2], ExplorerError, r"lights\[0\]"),
        ("set_viewer", "x", ExplorerTypeError, "viewer must be"),
        ("set_viewer", {"eye": [0, 0]}, ExplorerError, r"viewer\.eye"),
        ("set_model", 3, ExplorerTypeError, "model must be"),
        ("set_model", "gouraud", ExplorerError, "model: must be one of"),
        ("set_scene", 5, ExplorerTypeError, "scene must be"),
    ],
)
def test_a_bad_setter_argument_leaves_the_shader_as_it_was(shader, setter, value, error, match):
    scene, colours = shader.scene, shader.colors.copy()
    with pytest.raises(error, match=match) as info:
        getattr(shader, setter)(value)
    assert isinstance(info.value, TypeError if error is ExplorerTypeError else ValueError)
    same_state(shader, scene, colours)


def test_set_material_takes_a_preset_name(shader, tmp_path):
    shader.set_material("jade")
    assert shader.scene.material.name == "jade"
    (tmp_path / "mine.yaml").write_text("diffuse: [0.5, 0.25, 0.125]\n")
    s = explorer.Shader(None, MESH.positions, MESH.normals, materials_dirs=[tmp_path])
    s.set_material("mine")
    assert s.scene.material.diffuse == (0.5, 0.25, 0.125)
    s.set_scene({"material": "mine", "model": "phong"})  # the shader's directories again
    assert s.scene.material.diffuse == (0.5, 0.25, 0.125)
    s.set_material(Material())
    assert s.scene.material == Material()


@pytest.mark.parametrize(
    "kw, error, match",
    [
        ({"positions": [[0, 0, 0], [1, 2]]}, ExplorerError, "positions must be"),
        ({"faces": [[0, 1]]}, ExplorerError, r"faces must have shape \(m, 3\)"),
        ({"faces": [[0, 1, 2**70]]}, ExplorerError, "faces index vertices that do not exist"),
        ({"faces": [[0, 1, 2.5]]}, ExplorerError, "faces must hold whole numbers"),
        ({"precision": "float16"}, ExplorerError, "precision must be one of"),
        ({"precision": 32}, ExplorerTypeError, "precision must be one of"),
        ({"materials_dirs": "/tmp"}, ExplorerTypeError, "materials_dirs must be a list"),
    ],
)
def test_shade_refuses_bad_arguments_by_name(kw, error, match):
    args = {"positions": MESH.positions, "normals": MESH.normals, **kw}
    with pytest.raises(error, match=match):
        explorer.shade({"material": "gold"}, **args)
    with pytest.raises(error, match=match):
        explorer.Shader({"material": "gold"}, **args)


@pytest.mark.parametrize("tier", [None, "compiled", "numpy"])
@pytest.mark.parametrize("which", ["positions", "normals"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_nan_or_inf_vertices_are_refused_before_any_state_changes(tier, which, bad):
    # on the compiled tier the geometry is prepared at once and its passes find such values
    # (kernels.extent, kernels.prepare); on the numpy tier check_vertices does: the same error
    s = explorer.Shader({"material": "gold"}, MESH.positions, MESH.normals, tier=tier)
    assert s.stats["geometry"] == (0 if tier == "numpy" else 1)  # prepared by the constructor
    scene, colours = s.scene, s.colors.copy()
    P, N = MESH.positions.copy(), MESH.normals.copy()
    (P if which == "positions" else N)[5, 1] = bad
    with pytest.raises(ExplorerError, match=rf"{which}\[5\] is not finite"):
        s.set_geometry(P, N)
    same_state(s, scene, colours)
    with pytest.raises(ExplorerError, match=rf"{which}\[5\] is not finite"):
        explorer.Shader(scene, P, N, tier=tier)
