"""The term strip off screen (explorer.render.strip) and ``render --strip`` / ``sheet --strip``."""

from __future__ import annotations

import numpy as np
import pytest

from explorer.cli import main
from explorer.core.lights import DirectionalLight, PointLight
from explorer.core.material import Material
from explorer.core.presets import find_preset
from explorer.core.scene import Scene
from explorer.geometry.meshes import get_mesh
from explorer.render.images import read_png
from explorer.render.offscreen import render_image
from explorer.render.strip import COLUMNS, OVERFLOW_COLOR, render_strip
from explorer.shading.strip import light_scene

TILE = (96, 80)


def _tile(picture, row, column):
    x, y, w, h = picture.boxes[(row, column)]
    return picture.image[y : y + h, x : x + w]


@pytest.mark.parametrize(
    ("preset", "mesh", "hdr"),
    [("gold", "teapot", None), ("jade", "sphere", {"exposure": 0.5, "tone_map": "aces"})],
)
def test_the_sum_tile_is_the_render_bit_for_bit(preset, mesh, hdr):
    scene = Scene(material=find_preset(preset), hdr=hdr)
    m = get_mesh(mesh)
    picture = render_strip(scene, m, tile=TILE)
    np.testing.assert_array_equal(_tile(picture, 0, "sum"), render_image(scene, m, TILE))
    assert picture.image.shape == (picture.image.shape[0], len(COLUMNS) * (TILE[0] + 2) + 2, 3)


def test_a_light_row_is_the_render_of_that_light_alone_and_the_mask_is_where_it_clamps():
    lights = (
        DirectionalLight(to_light=(1.0, 1.0, 1.0)),
        PointLight(position=(-2.0, 1.0, 2.0), diffuse=(0.6, 0.6, 0.6)),
    )
    scene = Scene(material=find_preset("gold"), lights=lights)
    mesh = get_mesh("sphere")
    picture = render_strip(scene, mesh, tile=TILE, lights=True)
    assert picture.rows == ("all lights", "light 1: directional", "light 2: point")
    for row in (1, 2):
        alone = render_image(light_scene(scene, row - 1), mesh, TILE)
        np.testing.assert_array_equal(_tile(picture, row, "sum"), alone)
    # the overflow tile: the sum tile, magenta (and blends of it) only where the mask is set
    strip = picture.strips[0]
    assert strip.overflow.any()
    changed = np.any(_tile(picture, 0, "overflow") != _tile(picture, 0, "sum"), axis=2)
    magenta = np.all(_tile(picture, 0, "overflow") == np.multiply(OVERFLOW_COLOR, 255), axis=2)
    assert magenta.any() and changed[magenta].all()
    dim = Material(ambient=(0.1,) * 3, diffuse=(0.5,) * 3, specular=(0.3,) * 3, shininess=20.0)
    no_clamp = render_strip(Scene(material=dim), mesh, tile=TILE)
    assert not no_clamp.strips[0].overflow.any()
    np.testing.assert_array_equal(_tile(no_clamp, 0, "overflow"), _tile(no_clamp, 0, "sum"))
    assert no_clamp.caption.startswith("overflow: none")


def test_render_strip_writes_the_labelled_picture_and_says_the_caption(tmp_path, capsys):
    out = tmp_path / "strip.png"
    argv = ["render", "--preset", "gold", "--mesh", "teapot", "--strip", "--tile", "96x80"]
    assert main([*argv, "--strip-lights", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "term strip, 2 rows (teapot, gold, blinn, weighted)" in text
    assert "overflow: 1.3% of the surface" in text
    image = read_png(out)
    assert image.shape[1] == len(COLUMNS) * 98 + 2
    picture = render_strip(
        Scene(material=find_preset("gold")), get_mesh("teapot"), tile=TILE, lights=True
    )
    np.testing.assert_array_equal(image, picture.image)


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--strip", "--out", "s.ply"], "error: --strip draws a picture: give --out FILE.png"),
        (["--tile", "9x9", "--out", "s.png"], "error: --tile and --strip-lights draw the strip"),
        (["--strip", "--per-pixel", "--out", "s.png"], "error: --strip draws the terms per vertex"),
    ],
)
def test_render_strip_mistakes_are_one_line(tmp_path, monkeypatch, capsys, extra, message):
    monkeypatch.chdir(tmp_path)
    assert main(["render", *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(message) and "\n" not in err
    assert not list(tmp_path.iterdir())


def test_sheet_strip_is_a_row_per_preset(tmp_path, capsys):
    out = tmp_path / "sheet.png"
    argv = ["sheet", "--strip", "--preset", "gold", "--preset", "jade", "--tile", "96x80"]
    assert main([*argv, "--strip-mode", "raw", "--out", str(out)]) == 0
    assert "term strips of 2 presets on teapot" in capsys.readouterr().out
    assert read_png(out).shape[0] > 2 * 80


def test_render_strip_draws_each_group_of_a_mesh_file_in_its_own_material(tmp_path, capsys):
    """``render --strip`` of an OBJ of three materials (docs/examples/teapot_parts.obj): its
    sum tile is ``render`` of the file in its materials bit for bit, and each group's tiles are
    the engine's terms of that group's material (the diffuse tile is the render of the diffuse
    colours of a Shader in each group's material, group by group)."""
    from pathlib import Path

    from explorer.cli import build_parser
    from explorer.cli.options import build_scene, mesh_materials
    from explorer.render.strip import mesh_strip

    obj = Path(__file__).resolve().parents[2] / "docs" / "examples" / "teapot_parts.obj"
    strip_png, whole_png = tmp_path / "strip.png", tmp_path / "whole.png"
    argv = ["--mesh", str(obj)]
    tile = ["--tile", "96x80", "--out", str(strip_png)]
    assert main(["render", *argv, "--strip", *tile]) == 0
    assert "term strip, 1 row (teapot_parts.obj, 3 materials of the file" in capsys.readouterr().out
    assert main(["render", *argv, "--size", "96x80", "--out", str(whole_png)]) == 0
    args = build_parser().parse_args(["render", *argv, "--out", "x.png"])
    args.mesh_default = "sphere"
    scene, mesh = build_scene(args)
    scene, materials = mesh_materials(args, scene, mesh)
    assert len(set(materials)) == 3
    picture = render_strip(scene, mesh, tile=TILE, materials=materials)
    np.testing.assert_array_equal(read_png(strip_png), picture.image)
    np.testing.assert_array_equal(_tile(picture, 0, "sum"), read_png(whole_png))
    diffuse = np.zeros((mesh.n_vertices, 3))
    for g, material in enumerate(materials):
        rows = mesh.groups.vertices(g)
        alone = mesh_strip(scene.replace(material=material), mesh)
        for term in ("emission", "ambient", "diffuse", "specular", "sum"):
            np.testing.assert_array_equal(
                picture.strips[0].terms[term][rows], alone.terms[term][rows]
            )
        diffuse[rows] = alone.tiles["diffuse"][rows]
    want = render_image(scene, mesh, TILE, colors=diffuse)
    np.testing.assert_array_equal(_tile(picture, 0, "diffuse"), want)
