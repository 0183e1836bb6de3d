"""Ambient and emission maps per vertex (explorer.render.textured's layers, issue 40 item 2):
the primary colour's terms interpolated apart, each times its own map's texel, against closed
forms: white maps give the untextured picture within the terms' rounding, a constant map of
value c gives c times its term; the diffuse map alone stays GL 2.1's one texture (the Mesa
oracle: tests/render/test_gl_oracle.py)."""

from __future__ import annotations

import numpy as np
import pytest

import explorer
from explorer.cli import main
from explorer.core.lights import DirectionalLight, PointLight
from explorer.core.material import Material
from explorer.core.scene import Viewer
from explorer.core.texture import TextureMap
from explorer.geometry import meshes as M
from explorer.render.offscreen import BACKGROUND
from explorer.render.textured import only, textured
from explorer.shading.display import to_bytes, vertex_colors

BLACK = (0.0, 0.0, 0.0)
#: every vertex's primary and specular sums below 1 (0.96 at most), where the layers' separately
#: clamped terms and GL's one clamped colour agree
MATERIAL = Material(
    ambient=(0.3, 0.25, 0.2),
    diffuse=(0.3, 0.35, 0.25),
    specular=(0.35,) * 3,
    emission=(0.1, 0.05, 0.15),
    shininess=30.0,
)


def _png(path, rgb) -> str:
    from PIL import Image

    Image.fromarray(np.asarray(rgb, np.uint8)).save(path)
    return str(path)


def _scene(material, **kw):
    return explorer.Scene(
        material=material,
        lights=(PointLight(position=(2, 2, 3)), DirectionalLight(to_light=(-1, 0.5, 0.5))),
        viewer=Viewer(to_viewer=(0.3, 0.4, 1.0)),
        ambient=(0.4, 0.4, 0.4),
        **kw,
    )


def _levels(a, b) -> np.ndarray:
    return np.abs(a.astype(np.int64) - b.astype(np.int64)).max(axis=-1)


def _covered(image) -> np.ndarray:
    return np.any(image != to_bytes(np.asarray(BACKGROUND)[None, :])[0], axis=-1)


@pytest.fixture(scope="module")
def teapot():
    return M.teapot(8, uv=True)


@pytest.mark.parametrize("color_control", ["single", "separate"])
def test_white_ambient_and_emission_maps_give_the_untextured_picture(
    renderer, tmp_path, teapot, color_control
):
    """Each term rounded to 8 bits apart and summed: within two levels of the untextured picture
    (one term's rounding is half a level) where no vertex's sum exceeds 1 (the terms are clamped
    apart: docs/formats.md); the layers are drawn."""
    white = _png(tmp_path / "w.png", np.full((2, 2, 3), 255))
    m = MATERIAL.replace(ambient_map=TextureMap(white), emission_map=TextureMap(white))
    scene = _scene(m, color_control=color_control)
    t = textured(scene, teapot)
    assert [layer.key for layer in t.layers] == ["emission_map", "ambient_map"]
    terms = [
        vertex_colors(scene.replace(material=only(k)(MATERIAL)), teapot)
        for k in ("emission", "ambient", "diffuse", "specular")
    ]
    assert sum(terms).max() < 1.0
    got = renderer.render(scene, teapot)
    want = renderer.render(scene.replace(material=MATERIAL), teapot)
    assert _covered(want).sum() > 2000
    assert _levels(got, want).max() <= 2


@pytest.mark.parametrize("key", ["emission_map", "ambient_map"])
def test_a_constant_layer_map_gives_its_value_times_its_term(renderer, tmp_path, teapot, key):
    """A material with the map's term alone and a map of one colour c: every pixel is c times
    the untextured term (the picture of the material whose colour is c times its own), within
    one level; the other terms' layers are white."""
    c = np.array([200, 100, 30])
    image = _png(tmp_path / "c.png", np.broadcast_to(c, (4, 4, 3)))
    term = "emission" if key == "emission_map" else "ambient"
    alone = Material(
        **{k: BLACK for k in ("ambient", "diffuse", "specular", "emission") if k != term},
        **{term: (0.9, 0.8, 0.7)},
    )
    scaled = alone.replace(**{term: tuple(np.array((0.9, 0.8, 0.7)) * c / 255.0)})
    got = renderer.render(_scene(alone.replace(**{key: TextureMap(image)})), teapot)
    want = renderer.render(_scene(scaled), teapot)
    untextured = renderer.render(_scene(alone), teapot)
    covered = _covered(want)
    assert covered.sum() > 2000
    assert _levels(got[covered], want[covered]).max() <= 1
    assert _levels(got[covered], untextured[covered]).max() > 50


def test_a_layer_map_samples_its_own_texels(renderer, tmp_path):
    """An emission map black on its left half, white on its right, on the plane seen from the
    front (u = (x + 1) / 2): the picture's left half is dark, its right half the emission."""
    rgb = np.zeros((2, 2, 3))
    rgb[:, 1] = 255
    plane = M.plane(8, uv=True)
    e = (0.9, 0.6, 0.3)
    m = Material(
        emission=e,
        ambient=BLACK,
        diffuse=BLACK,
        emission_map=TextureMap(_png(tmp_path / "h.png", rgb)),
    )
    scene = explorer.Scene(
        material=m,
        lights=(DirectionalLight(to_light=(0, 0, 1)),),
        viewer=Viewer(to_viewer=(0, 0, 1)),
    )
    image = renderer.render(scene, plane)
    covered = _covered(image)
    rows, cols = np.nonzero(covered)
    mid = (cols.min() + cols.max()) / 2
    left = covered & (np.arange(image.shape[1])[None, :] < mid - 2)
    right = covered & (np.arange(image.shape[1])[None, :] > mid + 2)
    assert left.sum() > 500 and right.sum() > 500
    assert not image[left].any()
    assert _levels(image[right], to_bytes(np.array([e]))).max() <= 1


def test_render_draws_ambient_and_emission_maps_without_a_warning(tmp_path, capsys):
    """``render`` no longer says an ambient or emission map is not drawn per vertex; a GLB
    holds the diffuse map alone and says so for the others."""
    image = _png(tmp_path / "t.png", np.random.default_rng(2).integers(0, 256, (8, 8, 3)))
    scene = tmp_path / "s.yaml"
    assert image.endswith("t.png")
    scene.write_text(
        "material: {ambient_map: t.png, emission: [0.2, 0.2, 0.2], emission_map: t.png}\n"
    )
    out = tmp_path / "p.png"
    assert (
        main(["render", str(scene), "--mesh", "teapot", "--size", "96x72", "--out", str(out)]) == 0
    )
    assert "warning" not in capsys.readouterr().err
    assert main(["render", str(scene), "--mesh", "teapot", "--out", str(tmp_path / "m.glb")]) == 0
    err = capsys.readouterr().err
    assert "ambient_map" in err and "emission_map" in err and "GLB" in err
