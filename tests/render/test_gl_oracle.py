"""The oracle no peer has: a real OpenGL 2.1 fixed-function render through Mesa
(tests/helpers/gl_fixed.py: ``glLightfv``, ``glMaterialfv``, ``glTexEnvi(GL_MODULATE)``,
``GL_LIGHT_MODEL_COLOR_CONTROL``), of the same mesh, lights, camera matrices and texture
(nearest), beside the explorer's textured picture (the engine's per-vertex sums, VTK's one pass):
within one level per channel on every covered pixel, in both colour-control modes, on point,
spot and directional lights, two-sided lighting, an emission map, repeat and clamp.

Skipped, with the reason, only where no OpenGL context can be made."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import gl_fixed
from helpers.scenes import to_gl

import explorer
from explorer.geometry import meshes as M
from explorer.render.offscreen import OffscreenRenderer

SIZE = (160, 160)
LIGHT = {"ambient": [0.1, 0.1, 0.1], "diffuse": [0.9, 0.85, 0.8], "specular": [1, 1, 1]}
SHINY = {
    "ambient": [0.2, 0.2, 0.2],
    "diffuse": [0.8, 0.7, 0.6],
    "specular": [0.9, 0.9, 0.9],
    "emission": [0.05, 0.0, 0.0],
    "shininess": 30,
}

#: name -> (mesh, resolution, scene in the engine's schema (every light colour given, as
#: helpers.scenes.to_gl needs), the map's options)
SCENES = {
    "point_teapot": (
        "teapot",
        12,
        {
            "material": SHINY,
            "viewer": {"to_viewer": [0, 0, 1]},
            "lights": [
                {
                    "type": "point",
                    "position": [1.5, 1.5, 2.5],
                    "attenuation": [1, 0.05, 0.01],
                    **LIGHT,
                }
            ],
        },
        {},
    ),
    "spot_plane_local_viewer": (
        "plane",
        48,
        {
            "material": {**SHINY, "shininess": 12},
            "viewer": {"eye": [0.3, 0.2, 3.5]},
            "lights": [
                {
                    "type": "spot",
                    "position": [0.2, 0.1, 1.5],
                    "aim": [-0.1, -0.05, -1],
                    "cutoff": 35,
                    "exponent": 6,
                    "attenuation": [1, 0.1, 0.0],
                    **LIGHT,
                }
            ],
        },
        {"scale": [2, 2, 1]},
    ),
    "directional_sphere": (
        "sphere",
        48,
        {
            "material": {**SHINY, "shininess": 60},
            "viewer": {"to_viewer": [0.2, 0.3, 1]},
            "lights": [{"type": "directional", "to_light": [1, 1, 1], **LIGHT}],
        },
        {},
    ),
    "two_sided_plane_from_behind": (
        "plane",
        32,
        {
            "material": SHINY,
            "viewer": {"to_viewer": [0.1, 0.2, -1]},
            "two_sided": True,
            "lights": [{"type": "directional", "to_light": [0.3, 0.2, -1], **LIGHT}],
        },
        {},
    ),
    "emission_map_torus": (
        "torus",
        48,
        {
            "material": {
                "ambient": [0.1, 0.1, 0.1],
                "diffuse": [0.2, 0.2, 0.2],
                "specular": [0.6, 0.6, 0.6],
                "emission": [0.7, 0.6, 0.5],
                "shininess": 20,
            },
            "viewer": {"to_viewer": [0, -0.4, 1]},
            "lights": [
                {"type": "directional", "to_light": [-1, 1, 1], **LIGHT},
                {"type": "point", "position": [1, -1, 1.5], "attenuation": [1, 0, 0.2], **LIGHT},
            ],
        },
        {"scale": [3, 1, 1]},
    ),
    "clamped_offset_cube_two_lights": (
        "cube",
        None,
        {
            "material": {**SHINY, "shininess": 8},
            "viewer": {"eye": [2.5, 2.0, 3.0]},
            "lights": [
                {"type": "point", "position": [2, 3, 2], "attenuation": [1, 0.1, 0], **LIGHT},
                {
                    "type": "spot",
                    "position": [0, 0, 4],
                    "aim": [0, 0, -1],
                    "cutoff": 20,
                    "exponent": 2,
                    "attenuation": [1, 0, 0],
                    **LIGHT,
                },
            ],
        },
        {"scale": [1.5, 1.5, 1], "offset": [-0.25, -0.25, 0], "clamp": True},
    ),
}


@pytest.fixture(scope="module")
def gl():
    module, why = gl_fixed.context()
    if module is None:
        pytest.skip(why)
    return module


@pytest.fixture(scope="module")
def texture(tmp_path_factory):
    """A 16 x 16 image of random colours (every texel its own: a wrong texel shows)."""
    from PIL import Image

    image = np.random.default_rng(3).integers(0, 256, (16, 16, 3)).astype(np.uint8)
    path = tmp_path_factory.mktemp("tex") / "random.png"
    Image.fromarray(image).save(path)
    return str(path), image


def _matrix(m) -> np.ndarray:
    return np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])


def _both(renderer, name, control, texture):
    mesh_name, res, mapping, options = SCENES[name]
    path, image = texture
    mesh = M.get_mesh(mesh_name, res, uv=True)
    material = {**mapping["material"], "diffuse_map": {"file": path, **options}}
    scene = explorer.load_scene({**mapping, "material": material, "color_control": control})
    ours = renderer.render(scene, mesh)
    camera = renderer.plotter.camera
    view = _matrix(camera.GetModelViewTransformMatrix())
    projection = _matrix(camera.GetProjectionTransformMatrix(SIZE[0] / SIZE[1], -1, 1))
    gl_scene = to_gl({"ambient": [0.2, 0.2, 0.2], **mapping})
    tmap = scene.material.diffuse_map
    mesa = gl_fixed.render(
        mesh.positions,
        mesh.normals,
        mesh.faces,
        gl_scene,
        view=view,
        projection=projection,
        size=SIZE,
        two_sided=scene.two_sided,
        separate=control == "separate",
        image=image,
        st=tmap.lookup(mesh.uv),
        clamp=tmap.clamp,
    )
    return ours, mesa


@pytest.fixture(scope="module")
def renderer():
    with OffscreenRenderer(SIZE) as r:
        yield r


@pytest.mark.parametrize("control", ["single", "separate"])
@pytest.mark.parametrize("name", sorted(SCENES))
def test_textured_pixels_equal_mesa_fixed_function(gl, renderer, texture, name, control):
    ours, mesa = _both(renderer, name, control, texture)
    covered = mesa[..., 3] == 255
    assert covered.sum() > 2000  # the mesh fills a good part of the picture
    # the same pixels are covered: where Mesa drew nothing the explorer shows its background
    background = ours[0, 0]
    assert (ours[~covered] == background).all()
    diff = np.abs(ours.astype(int) - mesa[..., :3].astype(int)).max(axis=2)
    assert diff[covered].max() <= 1, (
        f"{name} {control}: {int((diff[covered] > 1).sum())} of {int(covered.sum())} covered "
        f"pixels differ by more than one level (at most {int(diff[covered].max())})"
    )


def test_the_two_modes_differ_where_the_highlight_meets_the_texture(gl, renderer, texture):
    """So each mode's match above tests something: single colour darkens the highlight."""
    single, _ = _both(renderer, "directional_sphere", "single", texture)
    separate, _ = _both(renderer, "directional_sphere", "separate", texture)
    assert (separate.astype(int) - single.astype(int)).max() > 100
