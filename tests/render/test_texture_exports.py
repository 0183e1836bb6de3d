"""Textures in other tools' files: GLB with baseColorTexture (unlit: single colour mode), three.js
JSON with ``map``, X3D with ``ImageTexture`` (issue 40, item 5)."""

from __future__ import annotations

import io
import json

import numpy as np
import pygltflib
from PIL import Image

import explorer
from explorer.cli import main
from explorer.core.formats import convert
from explorer.core.material import Material
from explorer.core.texture import TextureMap
from explorer.geometry import meshes as M
from explorer.render.exports import glb_bytes, linear_colors
from explorer.render.textured import textured


def _image(tmp_path):
    image = np.random.default_rng(5).integers(0, 256, (4, 8, 3)).astype(np.uint8)
    path = tmp_path / "t.png"
    Image.fromarray(image).save(path)
    return str(path), image


def _array(gltf, blob, accessor, dtype, width):
    view = gltf.bufferViews[gltf.accessors[accessor].bufferView]
    data = blob[view.byteOffset : view.byteOffset + view.byteLength]
    return np.frombuffer(data, dtype).reshape(-1, width)


def test_glb_holds_the_texture_the_uv_and_the_single_colour(tmp_path):
    path, image = _image(tmp_path)
    tmap = TextureMap(path, clamp=True, scale=(2.0, 1.0, 1.0))
    scene = explorer.load_scene(
        {"material": {"specular": [1, 1, 1], "shininess": 20, "diffuse_map": tmap.to_mapping()}}
    )
    mesh = M.sphere(12, uv=True)
    t = textured(scene, mesh)
    gltf = pygltflib.GLTF2.load_from_bytes(glb_bytes(mesh, None, texture=t))
    blob = gltf.binary_blob()
    material = gltf.materials[0]
    assert "KHR_materials_unlit" in material.extensions
    assert material.pbrMetallicRoughness.baseColorTexture.index == 0
    sampler = gltf.samplers[0]
    assert (sampler.magFilter, sampler.minFilter) == (9728, 9728)  # nearest
    assert (sampler.wrapS, sampler.wrapT) == (33071, 33071)  # clamp to edge
    view = gltf.bufferViews[gltf.images[0].bufferView]
    png = blob[view.byteOffset : view.byteOffset + view.byteLength]
    np.testing.assert_array_equal(np.asarray(Image.open(io.BytesIO(png)))[..., :3], image)
    st = _array(gltf, blob, gltf.meshes[0].primitives[0].attributes.TEXCOORD_0, np.float32, 2)
    expected = tmap.lookup(mesh.uv)
    np.testing.assert_allclose(st[:, 0], expected[:, 0], atol=1e-7)
    np.testing.assert_allclose(st[:, 1], 1.0 - expected[:, 1], atol=1e-7)  # glTF's v: top = 0
    colour = _array(gltf, blob, gltf.meshes[0].primitives[0].attributes.COLOR_0, np.float32, 4)
    np.testing.assert_allclose(colour[:, :3], linear_colors(t.primary / 255.0), atol=1e-6)


def test_render_glb_of_a_separate_scene_holds_single_colour_and_says_so(tmp_path, capsys):
    path, _ = _image(tmp_path)
    out = tmp_path / "t.glb"
    argv = [
        "render",
        "--mesh",
        "sphere",
        "--resolution",
        "12",
        "--preset",
        "gold",
        "--diffuse-map",
        path,
        "--color-control",
        "separate",
        "--out",
        str(out),
    ]
    assert main(argv) == 0
    assert "glTF has no separate specular colour" in capsys.readouterr().err
    gltf = pygltflib.GLTF2.load_from_bytes(out.read_bytes())
    blob = gltf.binary_blob()
    colour = _array(gltf, blob, gltf.meshes[0].primitives[0].attributes.COLOR_0, np.float32, 4)
    scene = explorer.load_scene({"material": "gold"})
    scene = scene.replace(material=scene.material.replace(diffuse_map=path))
    single = textured(scene, M.sphere(12, uv=True))  # the highlight inside COLOR_0
    np.testing.assert_allclose(colour[:, :3], linear_colors(single.primary / 255.0), atol=1e-6)


def test_threejs_json_names_the_map_and_says_it_is_srgb():
    m = Material(diffuse_map=TextureMap("wood.png", scale=(2.0, 3.0, 1.0), clamp=True))
    converted = convert(m, "wood", "threejs")
    data = json.loads(converted.text)
    (texture,) = data["textures"]
    assert data["map"] == texture["uuid"] and texture["repeat"] == [2.0, 3.0]
    assert texture["wrap"] == [1001, 1001] and texture["magFilter"] == 1003
    assert data["images"][0]["url"] == "wood.png" and texture["colorSpace"] == "srgb"
    assert any("decodes the image as sRGB" in note for note in converted.notes)
    assert "map" not in json.loads(convert(Material(), "plain", "threejs").text)


def test_x3d_writes_an_image_texture():
    m = Material(diffuse_map=TextureMap("my wood.png", offset=(0.5, 0.0, 0.0)))
    converted = convert(m, "wood", "x3d")
    assert """<ImageTexture url='"my wood.png"' repeatS='true' repeatT='true'/>""" in converted.text
    assert "<TextureTransform scale='1.0 1.0' translation='0.5 0.0'/>" in converted.text
    assert any("ImageTexture" in note for note in converted.notes)
    assert "ImageTexture" not in convert(Material(), "plain", "x3d").text
