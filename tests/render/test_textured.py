"""Textures drawn per vertex as OpenGL 2.1 draws them (GL_MODULATE, single colour or separate
specular), and every bad map refused in one line (issue 40, items 2 and 3). The fixed-function
Mesa oracle is tests/render/test_gl_oracle.py."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from helpers.imagecompare import GOLDEN_DIR, read_picture

import explorer
from explorer.cli import main
from explorer.core import tolerances as tol
from explorer.geometry import meshes as M
from explorer.render.textured import textured_colors
from explorer.render.textures import TextureError, read_texture, sample_nearest


def _png(path, rgb):
    from PIL import Image

    Image.fromarray(np.asarray(rgb, np.uint8)).save(path)
    return str(path)


def _white(tmp_path):
    return _png(tmp_path / "white.png", np.full((4, 4, 3), 255))


#: golden scenes (tests/render/test_render.py's FEATURES) redrawn on their mesh with (u, v)
GOLDEN_SCENES = {
    "directional": (
        {
            "material": {
                "ambient": [0.1, 0.1, 0.12],
                "diffuse": [0.2, 0.35, 0.7],
                "specular": [0.9, 0.9, 0.9],
                "shininess": 40,
            },
            "lights": [{"type": "directional", "to_light": [1, 1, 1]}],
        },
        "sphere",
        None,
    ),
}


def test_a_white_texture_reproduces_the_golden_bit_for_bit(renderer, tmp_path):
    """Single colour (OpenGL's default) under a white texture is today's picture: the texel
    1.0 times the interpolated colour is that colour, exactly."""
    mapping, name, res = GOLDEN_SCENES["directional"]
    scene = explorer.load_scene(mapping)
    white = scene.replace(material=scene.material.replace(diffuse_map=_white(tmp_path)))
    image = renderer.render(white, M.get_mesh(name, res, uv=True))
    np.testing.assert_array_equal(image, read_picture(GOLDEN_DIR / "feature_directional.png"))


@pytest.mark.parametrize("mesh", ["teapot", "torus", "plane"])
def test_a_white_texture_changes_no_pixel_on_any_mesh(renderer, tmp_path, mesh):
    scene = explorer.load_scene(
        {
            "material": "glossy_plastic",
            "lights": [{"type": "point", "position": [1, 1, 2]}],
            "two_sided": True,
        }
    )
    plain = renderer.render(scene, M.get_mesh(mesh, 16))
    white = scene.replace(material=scene.material.replace(diffuse_map=_white(tmp_path)))
    np.testing.assert_array_equal(renderer.render(white, M.get_mesh(mesh, 16, uv=True)), plain)


def _black_scene(tmp_path, control):
    black = _png(tmp_path / "black.png", np.zeros((2, 2, 3)))
    return explorer.load_scene(
        {
            "material": {
                "diffuse": [0.8, 0.2, 0.2],
                "specular": [1, 1, 1],
                "shininess": 30,
                "emission": [0.1, 0.1, 0.1],
                "diffuse_map": black,
            },
            "lights": [{"type": "directional", "to_light": [0.3, 0.4, 1]}],
            "color_control": control,
        }
    )


def test_single_colour_lets_a_black_texture_hide_the_highlight(renderer, tmp_path):
    scene = _black_scene(tmp_path, "single")
    image = renderer.render(scene, M.sphere(32, uv=True))
    covered = np.any(image != image[0, 0], axis=2)  # not the grey background
    assert covered.sum() > 10_000
    assert (image[covered] == 0).all()  # emission, light and highlight all times 0


def test_separate_specular_adds_the_highlight_after_a_black_texture(renderer, tmp_path):
    scene = _black_scene(tmp_path, "separate")
    mesh = M.sphere(32, uv=True)
    image = renderer.render(scene, mesh)
    only_specular = scene.material.replace(
        ambient=(0, 0, 0), diffuse=(0, 0, 0), emission=(0, 0, 0), diffuse_map=None
    )
    expected = renderer.render(scene.replace(material=only_specular), mesh)
    np.testing.assert_array_equal(image, expected)
    assert image.max() > 200  # the white highlight stays bright on the black texture


def test_separate_colours_sum_to_the_single_colour():
    scene = explorer.load_scene(
        {
            "material": "gold",
            "lights": [
                {
                    "type": "spot",
                    "position": [0, 1, 2],
                    "aim": [0, -0.5, -1],
                    "cutoff": 40,
                    "exponent": 4,
                }
            ],
        }
    )
    mesh = M.teapot(6, uv=True)
    single, zero = textured_colors(scene, mesh)
    assert not zero.any()
    p, q = textured_colors(scene.replace(color_control="separate"), mesh)
    np.testing.assert_allclose(np.minimum(p + q, 1.0), single, atol=1e-12)
    assert q.max() > 0.5 and (p < single).any()


def test_the_image_lies_as_opengl_reads_it(renderer, tmp_path):
    """(u, v) = (0, 0) is the image's lower-left corner: a plane (u = (x + 1)/2, v = (y + 1)/2)
    facing the viewer shows the image upright."""
    image = np.zeros((2, 2, 3), np.uint8)
    image[0, 0] = [255, 0, 0]  # top left
    image[0, 1] = [0, 255, 0]  # top right
    image[1, 0] = [0, 0, 255]  # bottom left
    image[1, 1] = [255, 255, 255]
    scene = explorer.load_scene(
        {
            "material": {
                "emission": [1, 1, 1],
                "diffuse": [0, 0, 0],
                "ambient": [0, 0, 0],
                "diffuse_map": _png(tmp_path / "quad.png", image),
            }
        }
    )
    picture = renderer.render(scene, M.plane(2, uv=True))
    h, w = picture.shape[:2]
    assert picture[h // 4, w // 4].tolist() == [255, 0, 0]
    assert picture[h // 4, 3 * w // 4].tolist() == [0, 255, 0]
    assert picture[3 * h // 4, w // 4].tolist() == [0, 0, 255]
    assert picture[3 * h // 4, 3 * w // 4].tolist() == [255, 255, 255]


def test_sample_nearest_repeats_and_clamps():
    image = np.arange(4, dtype=np.uint8).reshape(1, 4, 1)
    st = [[0.1, 0.5], [0.3, 0.5], [1.1, 0.5], [-0.1, 0.5]]
    assert sample_nearest(image, st)[:, 0].tolist() == [0, 1, 0, 3]
    assert sample_nearest(image, st, clamp=True)[:, 0].tolist() == [0, 1, 3, 0]


# -- bad maps: one line each, status 2, nothing written --------------------------------------
def _bad(tmp_path, kind):
    path = tmp_path / f"{kind}.png"
    good = _png(tmp_path / "good.png", np.random.default_rng(1).integers(0, 255, (64, 64, 3)))
    data = Path(good).read_bytes()
    if kind == "missing":
        pass
    elif kind == "empty":
        path.write_bytes(b"")
    elif kind == "truncated":
        path.write_bytes(data[: len(data) // 2])
    elif kind == "not an image":
        path.write_text("hello\n")
    elif kind == "huge":
        from PIL import Image

        Image.new("L", (tol.MAX_TEXTURE_PIXELS // 1000 + 1, 1000)).save(path)
    elif kind == "declared 50000x50000":  # a header only: Pillow's own guard refuses it
        import struct
        import zlib

        def chunk(t, d):
            return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d))

        head = struct.pack(">IIBBBBB", 50000, 50000, 8, 2, 0, 0, 0)
        path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", head) + chunk(b"IEND", b""))
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "directory":
        path.mkdir()
    return str(path)


BAD = {
    "missing": "does not exist",
    "empty": "the file is empty",
    "truncated": "a damaged or truncated image",
    "not an image": "not a PNG or JPEG image",
    "huge": r"16778x1000 is 16778000 pixels, more than the limit of 16777216 \(4096x4096\)",
    "declared 50000x50000": r"2500000000 pixels, more than the limit of 16777216 \(4096x4096\)",
    "fifo": r"it is a FIFO \(named pipe\), not a file",
    "directory": "it is a directory",
}


@pytest.mark.usefixtures("no_hang")  # a FIFO must never block the read
@pytest.mark.parametrize("kind", sorted(BAD))
def test_read_texture_refuses_a_bad_image_in_one_line(tmp_path, kind):
    path = _bad(tmp_path, kind)
    with pytest.raises(TextureError, match=f"^bump_map '{path}': {BAD[kind]}") as info:
        read_texture(path, "bump_map")
    assert "\n" not in str(info.value)


@pytest.mark.usefixtures("no_hang")
@pytest.mark.parametrize("kind", sorted(BAD))
def test_render_refuses_a_bad_map_with_status_2_and_writes_nothing(tmp_path, capsys, kind):
    path = _bad(tmp_path, kind)
    out = tmp_path / "out.png"
    argv = ["render", "--mesh", "plane", "--diffuse-map", path, "--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith(f"error: diffuse_map '{path}': ") and "Traceback" not in err[-1]
    assert not out.exists()


def test_render_refuses_a_scene_map_outside_its_folder(tmp_path, capsys):
    sub = tmp_path / "scene"
    sub.mkdir()
    _white(tmp_path)
    (sub / "s.yaml").write_text("material: {diffuse_map: ../white.png}\nmesh: plane\n")
    out = tmp_path / "out.png"
    assert main(["render", str(sub / "s.yaml"), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "material.diffuse_map" in err and "outside the scene file's folder" in err
    assert not out.exists()


def test_render_refuses_a_mesh_without_uv(tmp_path, capsys):
    obj = tmp_path / "tri.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    out = tmp_path / "out.png"
    argv = ["render", "--mesh", str(obj), "--diffuse-map", _white(tmp_path), "--out", str(out)]
    assert main(argv) == 2
    assert "mesh 'tri.obj' has no texture coordinates" in capsys.readouterr().err
    assert not out.exists()


def test_render_diffuse_map_on_the_teapot(tmp_path, capsys):
    out = tmp_path / "t.png"
    checker = np.kron((np.indices((4, 4)).sum(0) % 2) * 255, np.ones((1, 1)))
    img = _png(tmp_path / "c.png", np.repeat(checker[..., None], 3, axis=2))
    argv = [
        "render",
        "--mesh",
        "teapot",
        "--preset",
        "gold",
        "--diffuse-map",
        img,
        "--color-control",
        "separate",
        "--size",
        "64x64",
        "--out",
        str(out),
    ]
    assert main(argv) == 0
    assert out.exists()


EXAMPLES = Path(__file__).resolve().parents[2] / "docs" / "examples"


def test_the_textured_example_is_drawn_in_its_own_map(tmp_path, capsys):
    """docs/examples/textured_teapot.obj: its vt, its .mtl's map_Kd, tiles.png beside it."""
    out = tmp_path / "t.png"
    obj = str(EXAMPLES / "textured_teapot.obj")
    assert main(["render", "--mesh", obj, "--size", "96x72", "--out", str(out)]) == 0
    assert "warning" not in capsys.readouterr().err
    from explorer.geometry.filematerials import group_materials

    mesh = M.load_mesh(obj)
    (material,), _ = group_materials(mesh, explorer.Scene().material)
    assert material.diffuse_map.file == str(EXAMPLES / "tiles.png")
    plain = explorer.load_scene({}).replace(material=material.replace(diffuse_map=None))
    tiled = explorer.load_scene({}).replace(material=material)
    from explorer.render.offscreen import render_image

    a, b = render_image(plain, mesh, (96, 72)), render_image(tiled, mesh, (96, 72))
    assert np.abs(a.astype(int) - b.astype(int)).max() > 100  # the tiles show


def test_a_mesh_files_map_without_vt_is_a_warning_and_an_untextured_picture(tmp_path, capsys):
    (tmp_path / "m.mtl").write_text("newmtl red\nKd 1 0 0\nmap_Kd tex.png\n")
    (tmp_path / "m.obj").write_text(
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n"
    )
    out = tmp_path / "out.png"
    assert main(["render", "--mesh", str(tmp_path / "m.obj"), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "m.obj: diffuse_map" in err and "not drawn: it has no texture coordinates" in err
    assert out.exists()


def test_an_obj_export_keeps_the_texture_coordinates(tmp_path, capsys):
    out = tmp_path / "t.obj"
    argv = [
        "render",
        "--mesh",
        "plane",
        "--resolution",
        "2",
        "--diffuse-map",
        _white(tmp_path),
        "--out",
        str(out),
    ]
    assert main(argv) == 0
    back = M.load_mesh(out)
    plane = M.plane(2, uv=True)
    np.testing.assert_allclose(back.uv[back.faces], plane.uv[plane.faces])
    assert "map_Kd" in (tmp_path / "t.mtl").read_text()


def test_the_sheet_refuses_a_diffuse_map_it_would_not_draw(tmp_path, capsys):
    out = tmp_path / "s.png"
    argv = ["sheet", "--diffuse-map", _white(tmp_path), "--out", str(out)]
    assert main(argv) == 2
    assert "--diffuse-map: the sheet draws each preset untextured" in capsys.readouterr().err
    assert not out.exists()


def test_the_explorer_starts_on_a_built_in_mesh_with_uv_for_a_diffuse_map(tmp_path):
    from explorer.cli import build_parser
    from explorer.cli.explorerstart import start

    args = build_parser().parse_args(["gui", "--mesh", "torus", "--diffuse-map", _white(tmp_path)])
    scene, mesh, _ = start(args)
    assert scene.material.diffuse_map is not None and mesh.uv is not None
    _, plain, _ = start(build_parser().parse_args(["gui", "--mesh", "torus"]))
    # without a map too: the material tab's map rows can give the start's mesh one later
    assert plain.uv is not None and plain.n_faces == mesh.n_faces
