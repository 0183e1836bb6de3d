"""Off-screen renders (explorer.render, explorer.cli.render) and golden pictures.

Goldens live in tests/golden/: feature pictures, the preset sheet and the presets' stored colours;
see tests/helpers/imagecompare.py for the tolerances and for ``--regenerate-goldens``.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import tempfile

import numpy as np
import pytest
import trimesh
from helpers import vtkpng
from helpers.imagecompare import (
    MAX_DIFFERENT_FRACTION,
    PIXEL_TOL,
    array_differences,
    check_golden,
    check_golden_arrays,
    compare,
    diff_image,
)

import explorer
from explorer.cli import main
from explorer.core import presets
from explorer.core.atomic import write_atomic
from explorer.core.errors import DeprecatedName, ExplorerError
from explorer.core.lights import DirectionalLight
from explorer.core.material import Material
from explorer.core.scene import Viewer
from explorer.core.tolerances import GOLDEN_COLOR_ABS_TOL
from explorer.geometry import meshes as M
from explorer.render.camera import FRAME_MARGIN, Camera, back_to_front, camera_for
from explorer.render.exports import mesh_file_bytes
from explorer.render.images import check_size, decode_png, encode_png, parse_size, read_png
from explorer.render.offscreen import (
    BACKGROUND,
    LABEL_HEIGHT,
    SHEET_LIGHT_DIRECTION,
    OffscreenRenderer,
    render_image,
    sheet,
)
from explorer.shading.display import to_bytes, vertex_colors

SIZE = (400, 400)  # the shared ``renderer`` fixture's size (tests/conftest.py)
BG = np.rint(np.asarray(BACKGROUND) * 255).astype(np.uint8)


def _mesh_mask(img) -> np.ndarray:
    return (img != BG).any(axis=2)


# -- camera --------------------------------------------------------------------------------


def _project(cam: Camera, points, aspect):
    """Normalised image coordinates ([-1, 1] inside the picture) of world points."""
    fwd = cam.direction
    up = np.asarray(cam.view_up)
    right = np.cross(fwd, up)
    rel = np.asarray(points) - np.asarray(cam.position)
    x, y, z = rel @ right, rel @ up, rel @ fwd
    if cam.parallel:
        half_h = cam.parallel_scale
        return x / (half_h * aspect), y / half_h - cam.window_center[1], z
    t = math.tan(math.radians(cam.view_angle) / 2)
    return x / (z * t * aspect), y / (z * t) - cam.window_center[1], z


@pytest.mark.parametrize("name", ["sphere", "teapot", "torus", "plane"])
@pytest.mark.parametrize("aspect", [1.0, 2.0, 0.5])
def test_infinite_viewer_camera_frames_mesh(name, aspect):
    mesh = M.get_mesh(name, 8 if name != "teapot" else 4)
    for d in [(0, 0, 1), (1, 2, 3), (0, 1, 0), (0, -1, 0), (0, 0, -1)]:
        scene = explorer.Scene(viewer=Viewer(to_viewer=d))
        cam = camera_for(scene, mesh, aspect)
        assert cam.parallel
        # looks along -to_viewer: the engine's constant V points back at the camera
        assert np.allclose(cam.direction, -np.asarray(d) / np.linalg.norm(d))
        assert abs(np.dot(cam.view_up, cam.direction)) < 1e-12
        x, y, z = _project(cam, mesh.positions, aspect)
        assert np.abs(x).max() <= 1.0 and np.abs(y).max() <= 1.0
        # fitted: the mesh spans most of one image direction
        assert max(np.ptp(x), np.ptp(y)) > 2.0 / FRAME_MARGIN - 1e-9
        near, far = cam.clipping_range
        assert near < z.min() and z.max() < far


@pytest.mark.parametrize("aspect", [1.0, 1.6, 0.6])
def test_local_viewer_camera_sits_at_the_eye(aspect):
    mesh = M.teapot(4)
    for eye in [(0, 0, 5), (3, 2, 1), (0, 10, 0), (0.1, -4, 0.2)]:
        scene = explorer.Scene(viewer=Viewer(eye=eye))
        cam = camera_for(scene, mesh, aspect)
        assert not cam.parallel
        assert np.allclose(cam.position, eye)
        assert np.allclose(cam.focal_point, mesh.centre)
        x, y, z = _project(cam, mesh.positions, aspect)
        assert (z > 0).all()
        assert np.abs(x).max() <= 1.0 and np.abs(y).max() <= 1.0
        near, far = cam.clipping_range
        assert near < z.min() and z.max() < far


def test_label_band_is_left_free():
    mesh = M.sphere(16)
    for viewer in (Viewer(to_viewer=(0, 0, 1)), Viewer(eye=(0, 0, 4))):
        cam = camera_for(explorer.Scene(viewer=viewer), mesh, 1.0, bottom=0.25)
        _, y, _ = _project(cam, mesh.positions, 1.0)
        assert y.min() >= -1.0 + 2 * 0.25 - 1e-9 and y.max() <= 1.0


# -- colours and pixels --------------------------------------------------------------------


def test_to_bytes_rounds_and_clamps():
    c = np.array([[0.0, 0.5, 1.0], [1.2, -0.1, 127.4 / 255]])
    assert to_bytes(c).tolist() == [[0, 128, 255], [255, 0, 127]]
    assert to_bytes(c, 0.5)[:, 3].tolist() == [128, 128]


def test_to_bytes_writes_in_place_and_rounds_float32_exactly():
    c = np.array([[0.0, 0.5, 1.0], [1.2, -0.1, 127.4 / 255]])
    out = np.full((2, 3), 7, np.uint8)
    assert to_bytes(c, out=out) is out and out.tolist() == to_bytes(c).tolist()
    # float32 colours round as their exact (float64) values: x·255 is just below 129.5, and
    # the float32 product would round it to 129.5 and then to 130
    x = np.float32(0.5078431367874146)
    assert float(x) * 255 < 129.5 and x * np.float32(255) == np.float32(129.5)
    assert to_bytes(np.full((1, 3), x, np.float32)).tolist() == [[129, 129, 129]]
    strided = np.zeros((2, 6), np.uint8)  # an array that is not contiguous is written too
    assert to_bytes(c, out=strided[:, ::2]).tolist() == to_bytes(c).tolist()
    assert strided[:, ::2].tolist() == to_bytes(c).tolist() and not strided[:, 1::2].any()
    with pytest.raises(ExplorerError, match="opacity"):
        to_bytes(c, 0.5, out=out)


def test_vtk_adds_nothing(renderer):
    """A plane facing a head-on directional light: every vertex has the same engine colour,
    and every pixel of the plane is exactly that colour (no VTK light, no VTK specular)."""
    mesh = M.plane(4)
    mat = Material(
        ambient=(0.3, 0.2, 0.1), diffuse=(0.5, 0.3, 0.7), specular=(0.2, 0.2, 0.2), shininess=8
    )
    scene = explorer.Scene(material=mat)
    colors = vertex_colors(scene, mesh)
    assert np.ptp(colors, axis=0).max() < 1e-12
    img = renderer.render(scene, mesh)
    mask = _mesh_mask(img)
    assert mask.mean() > 0.5
    expect = to_bytes(colors[:1])[0]
    assert (img[mask] == expect).all()
    assert (img[~mask] == BG).all()


def test_gouraud_interpolation(renderer):
    """Colours vary linearly between vertices (OpenGL's smooth shading): a plane whose
    colour ramps with x shows the same ramp across the picture."""
    mesh = M.plane(1)
    colors = np.zeros((4, 3))
    colors[:, 0] = (mesh.positions[:, 0] + 1) / 2  # red 0 at x = -1 .. 1 at x = 1
    img = renderer.render(explorer.Scene(), mesh, colors)
    row = img[200, :, 0].astype(float)
    inside = np.nonzero(_mesh_mask(img)[200])[0]
    xs = inside[5:-5]
    slope = np.polyfit(xs, row[xs], 1)
    assert np.abs(np.polyval(slope, xs) - row[xs]).max() <= 1.0
    assert row[inside[0]] < 10 and row[inside[-1]] > 245


@pytest.mark.parametrize("opacity", [1.0, 0.75, 0.3])
def test_opacity_blends_over_background(renderer, opacity):
    mesh = M.plane(2)
    c = np.full((mesh.n_vertices, 3), 0.8)
    img = renderer.render(explorer.Scene(material=Material(opacity=opacity)), mesh, c)
    expect = opacity * 204 + (1 - opacity) * BG.astype(float)
    assert np.abs(img[200, 200].astype(float) - expect).max() <= 1.0


@pytest.mark.parametrize(
    "viewer", [Viewer(to_viewer=(0, 0, 1)), Viewer(eye=(0, 0, 4)), Viewer(to_viewer=(1, 0, 0))]
)
def test_translucent_front_over_back(renderer, viewer):
    """The near half of a translucent sphere is white, the far half black: the nearer layer
    must end on top, whatever the triangle order in the file."""
    mesh = M.sphere(32)
    toward = np.asarray(viewer.eye if viewer.eye else viewer.to_viewer, float)
    colors = np.where((mesh.positions @ toward)[:, None] > 0, 1.0, 0.0) * np.ones(3)
    scene = explorer.Scene(material=Material(opacity=0.9), viewer=viewer)
    img = renderer.render(scene, mesh, colors)
    back_then_front = 0.9 * 255 + 0.1 * (0.9 * 0 + 0.1 * BG[0])
    assert abs(int(img[200, 200, 0]) - back_then_front) <= 1.5
    # the same file order rendered opaque shows the front only
    img = renderer.render(scene.replace(material=Material()), mesh, colors)
    assert img[200, 200].tolist() == [255, 255, 255]


def test_back_to_front_order():
    mesh = M.sphere(8)
    cam = camera_for(explorer.Scene(), mesh)
    order = back_to_front(mesh, cam)
    z = mesh.positions[mesh.faces[order]].mean(axis=1)[:, 2]
    assert (np.diff(z) >= -1e-12).all()  # camera on +z: far (low z) first


def test_render_twice_identical(renderer):
    scene = explorer.load_scene(
        {"material": "gold", "lights": [{"type": "point", "position": [1, 2, 3]}]}
    )
    mesh = M.teapot(6)
    a = renderer.render(scene, mesh)
    b = renderer.render(scene, mesh)
    c = render_image(scene, mesh, SIZE)  # a fresh window
    assert np.array_equal(a, b) and np.array_equal(a, c)


def test_reused_window_matches_fresh_one(renderer):
    """One window drawing one mesh under changing materials (new colours, opacity, sorted
    faces) gives what a fresh window gives each time."""
    mesh = M.teapot(6)
    for mapping in (
        {"material": "gold"},
        {"material": "emerald"},  # translucent: faces sorted
        {"material": "chalk", "viewer": {"eye": [2, 1, 3]}},
        {"material": "ruby", "model": "phong"},
    ):
        scene = explorer.load_scene(mapping)
        assert np.array_equal(renderer.render(scene, mesh), render_image(scene, mesh, SIZE))


def test_size_and_label():
    mesh = M.cube()
    black = np.zeros((mesh.n_vertices, 3))
    img = render_image(explorer.Scene(), mesh, (200, 150), colors=black, label="cube")
    assert img.shape == (150, 200, 3) and img.dtype == np.uint8
    # white text, centred, in a band at the bottom that the mesh leaves free
    text = img.max(axis=2) > 200
    rows, cols = np.nonzero(text)
    assert len(rows) > 20
    assert rows.min() > 150 - 1.5 * round(LABEL_HEIGHT * 150) - 2
    assert abs(0.5 * (cols.min() + cols.max()) - 100) < 4
    mesh_rows = np.nonzero((img == 0).all(axis=2).any(axis=1))[0]
    assert mesh_rows.max() < rows.min()
    plain = render_image(explorer.Scene(), mesh, (120, 48), colors=black)
    assert plain.shape == (48, 120, 3) and not (plain.max(axis=2) > 200).any()


def test_wrong_colour_count(renderer):
    with pytest.raises(ExplorerError, match="shape"):
        renderer.render(explorer.Scene(), M.cube(), np.zeros((3, 3)))


# -- sizes and files -----------------------------------------------------------------------


def test_parse_size():
    assert parse_size("400x300") == (400, 300)
    assert parse_size(" 64 X 32 ") == (64, 32)
    for bad in ["400", "x300", "400x", "4.5x300", "-4x300", "400x300x2", "abc"]:
        with pytest.raises(ExplorerError, match="WIDTHxHEIGHT"):
            parse_size(bad)
    for bad in ["8x400", "400x9000"]:
        with pytest.raises(ExplorerError, match=r"\[16, 8192\]"):
            parse_size(bad)
    with pytest.raises(ExplorerError):
        check_size((400.5, 300))


def _chunks(data: bytes) -> list[bytes]:
    names, at = [], 8
    while at < len(data):
        length = int.from_bytes(data[at : at + 4], "big")
        names.append(data[at + 4 : at + 8])
        at += 12 + length
    return names


def test_png_round_trip_and_vtk_agrees(tmp_path):
    rng = np.random.default_rng(1)
    for c, colour_type in ((3, 2), (4, 6)):  # PNG colour types: RGB, RGBA
        img = rng.integers(0, 256, (7, 11, c), dtype=np.uint8)
        data = encode_png(img)
        path = tmp_path / f"x{c}.png"
        path.write_bytes(data)
        assert np.array_equal(read_png(path), img)
        # 8-bit, the colour type, nothing but the picture; VTK reads it the same and the
        # codec reads VTK's file the same
        assert data[24:26] == bytes([8, colour_type])
        assert _chunks(data) == [b"IHDR", b"IDAT", b"IEND"]
        assert np.array_equal(vtkpng.read(path), img)
        assert np.array_equal(decode_png(vtkpng.encode(img)), img)


def test_a_fast_png_is_the_picture_exactly_with_one_row_filter(tmp_path):
    """``encode_png(fast=True)`` (the page's still pictures): the same pixels as the picture,
    RGB and RGBA, one row and many, odd widths, read back by the codec and by VTK; every row
    filtered by PNG's Up filter (each row's first byte of the inflated data is 2), the one
    filter this writer uses."""
    import zlib

    rng = np.random.default_rng(7)
    smooth = np.repeat(np.arange(0, 250, 10, dtype=np.uint8)[:, None], 33, 1)  # (a gradient)
    pictures = [
        rng.integers(0, 256, (7, 11, 3), dtype=np.uint8),
        rng.integers(0, 256, (1, 5, 4), dtype=np.uint8),
        rng.integers(0, 256, (9, 1, 3), dtype=np.uint8),
        np.dstack([smooth, smooth[::-1], 255 - smooth]),
        np.zeros((600, 800, 3), np.uint8),
    ]
    for i, img in enumerate(pictures):
        data = encode_png(img, fast=True)
        assert np.array_equal(decode_png(data), img), img.shape
        assert data[24:26] == bytes([8, 2 if img.shape[2] == 3 else 6])
        assert _chunks(data) == [b"IHDR", b"IDAT", b"IEND"]
        h, w, c = img.shape
        raw = zlib.decompress(data[41:-16])  # IDAT's content (after the 8 + 25 + 8 bytes)
        assert len(raw) == h * (w * c + 1)
        assert set(raw[:: w * c + 1]) == {2}
        path = tmp_path / f"fast{i}.png"
        path.write_bytes(data)
        assert np.array_equal(vtkpng.read(path), img)


def test_png_reading_refuses_what_it_cannot_read(tmp_path):
    with pytest.raises(ExplorerError, match="missing.png: cannot read PNG file: no such file"):
        read_png(tmp_path / "missing.png")
    os.mkfifo(tmp_path / "fifo.png")  # through the checked open: refused at once, never waited on
    with pytest.raises(ExplorerError, match="fifo.png: cannot read PNG file: it is a FIFO"):
        read_png(tmp_path / "fifo.png")
    data = encode_png(np.zeros((4, 5, 3), np.uint8))
    with pytest.raises(ExplorerError, match="half.png: not a readable PNG file"):
        decode_png(data[: len(data) // 2], "half.png")
    with pytest.raises(ExplorerError, match="x.gif: not a readable PNG file"):
        decode_png(b"GIF89a" + bytes(40), "x.gif")
    grey = np.arange(20, dtype=np.uint8).reshape(4, 5, 1)
    assert np.array_equal(decode_png(vtkpng.encode(grey)), np.repeat(grey, 3, axis=2))
    deep = vtkpng.encode(np.full((4, 5, 3), 40000, np.uint16))  # a 16-bit RGB file
    with pytest.raises(ExplorerError, match="deep.png: a 16-bit PNG"):
        decode_png(deep, "deep.png")


def test_write_atomic(tmp_path):
    target = tmp_path / "out.bin"
    write_atomic(target, b"one")
    with pytest.raises(ExplorerError, match="already exists"):
        write_atomic(target, b"two")
    assert target.read_bytes() == b"one"
    write_atomic(target, b"two", overwrite=True)
    assert target.read_bytes() == b"two"
    assert [p.name for p in tmp_path.iterdir()] == ["out.bin"]  # no temporary left over
    with pytest.raises(ExplorerError, match="does not exist"):
        write_atomic(tmp_path / "nodir" / "x.png", b"")
    with pytest.raises(ExplorerError, match="directory"):
        write_atomic(tmp_path, b"")


@pytest.mark.parametrize("suffix", [".ply"])  # .glb: tests/render/test_exports.py
def test_mesh_export_keeps_colours(tmp_path, suffix):
    mesh = M.icosphere(2)
    scene = explorer.load_scene({"material": "ruby"})
    colors = vertex_colors(scene, mesh)
    path = tmp_path / f"m{suffix}"
    path.write_bytes(mesh_file_bytes(mesh, colors, suffix, scene.material.opacity))
    back = trimesh.load(path, process=False)
    if isinstance(back, trimesh.Scene):
        back = back.to_geometry()
    assert len(back.vertices) == mesh.n_vertices
    assert np.allclose(back.vertices, mesh.positions, atol=1e-6)
    rgba = np.asarray(back.visual.vertex_colors)
    assert np.array_equal(rgba[:, :3], to_bytes(colors))
    assert (rgba[:, 3] == round(scene.material.opacity * 255)).all()


# -- image comparison ----------------------------------------------------------------------


def _highlight_scene(angle_deg: float):
    """A red sphere lit by two lights: one for diffuse only (fixed) and one for the specular
    only, turned by ``angle_deg`` about the y axis. Only the highlight moves."""
    a = math.radians(angle_deg)
    mat = Material(
        ambient=(0.1, 0.1, 0.1), diffuse=(0.6, 0.1, 0.1), specular=(1, 1, 1), shininess=60
    )
    return explorer.Scene(
        material=mat,
        lights=(
            DirectionalLight(to_light=(0.5, 0.5, 1), specular=(0, 0, 0)),
            DirectionalLight(
                to_light=(0.5 * math.cos(a) + math.sin(a), 0.5, math.cos(a) - 0.5 * math.sin(a)),
                diffuse=(0, 0, 0),
            ),
        ),
    )


def test_comparison_catches_uniform_shift(renderer):
    img = renderer.render(_highlight_scene(0), M.sphere())
    assert compare(img, img).ok
    for shift in (3, -3):
        other = np.clip(img.astype(int) + shift, 0, 255).astype(np.uint8)
        assert not compare(other, img).ok
    # ... but not one level of rounding noise, nor a few pixels of a silhouette
    rng = np.random.default_rng(0)
    noisy = np.clip(img.astype(int) + rng.integers(-1, 2, img.shape), 0, 255).astype(np.uint8)
    assert compare(noisy, img).ok
    edge = img.copy()
    idx = rng.choice(img.shape[0] * img.shape[1], int(0.5 * MAX_DIFFERENT_FRACTION * img.size / 3))
    edge.reshape(-1, 3)[idx] = 255 - edge.reshape(-1, 3)[idx]
    assert compare(edge, img).ok


def test_comparison_catches_moved_highlight(renderer):
    mesh = M.sphere()
    base = renderer.render(_highlight_scene(0), mesh)
    moved = renderer.render(_highlight_scene(2.0), mesh)
    # only the highlight moved: without the specular term the pictures are the same
    matte = Material(ambient=(0.1, 0.1, 0.1), diffuse=(0.6, 0.1, 0.1))
    assert np.array_equal(
        renderer.render(_highlight_scene(0).replace(material=matte), mesh),
        renderer.render(_highlight_scene(2.0).replace(material=matte), mesh),
    )
    changed = (np.abs(moved.astype(int) - base.astype(int)) > PIXEL_TOL).any(axis=2)
    assert 0 < changed.mean() < 0.2
    assert not compare(moved, base).ok
    d = diff_image(moved, base)
    assert (d[changed] == (255, 0, 255)).all()


# -- goldens -------------------------------------------------------------------------------


def _builtin_presets():

    old = os.environ.get(presets.ENV_VAR)
    os.environ[presets.ENV_VAR] = os.path.join(tempfile.gettempdir(), "no-such-dir-phong")
    try:
        infos = presets.list_presets()
    finally:
        if old is None:
            del os.environ[presets.ENV_VAR]
        else:
            os.environ[presets.ENV_VAR] = old
    return {i.name: i.material for i in infos if i.source == "builtin"}


PRESETS = _builtin_presets()

#: the fixed scene of the preset goldens: the teapot under the preset sheet's light; a preset
#: with a model of its own keeps it
PRESET_SCENE = {
    "model": "blinn",
    "viewer": {"to_viewer": [0, 0, 1]},
    "lights": [{"type": "directional", "to_light": list(SHEET_LIGHT_DIRECTION)}],
}

_SPHERE_MAT = {
    "ambient": [0.1, 0.1, 0.12],
    "diffuse": [0.2, 0.35, 0.7],
    "specular": [0.9, 0.9, 0.9],
    "shininess": 40,
}
_WHITE = {
    "ambient": [0.2, 0.2, 0.2],
    "diffuse": [0.8, 0.8, 0.8],
    "specular": [0.5, 0.5, 0.5],
    "shininess": 20,
}

#: feature goldens: name -> (scene mapping, mesh, resolution)
FEATURES = {
    "directional": (
        {"material": _SPHERE_MAT, "lights": [{"type": "directional", "to_light": [1, 1, 1]}]},
        "sphere",
        None,
    ),
    "point_attenuation": (
        {
            "material": _WHITE,
            "lights": [
                {"type": "point", "position": [-0.3, 0.3, 0.5], "attenuation": [0.2, 1.0, 4.0]}
            ],
        },
        "plane",
        64,
    ),
    "spot": (
        {
            "material": _WHITE,
            "lights": [
                {
                    "type": "spot",
                    "position": [0.2, 0.1, 2],
                    "aim": [-0.1, -0.05, -1],
                    "cutoff": 25,
                    "exponent": 30,
                    "intensity": 0.8,
                }
            ],
        },
        "plane",
        96,
    ),
    "model_blinn": (
        {
            "material": _SPHERE_MAT,
            "model": "blinn",
            "lights": [{"type": "directional", "to_light": [1.5, 0.4, 0.3]}],
        },
        "sphere",
        None,
    ),
    "model_phong": (
        {
            "material": _SPHERE_MAT,
            "model": "phong",
            "lights": [{"type": "directional", "to_light": [1.5, 0.4, 0.3]}],
        },
        "sphere",
        None,
    ),
    "model_threejs": (
        {
            "material": _SPHERE_MAT,
            "model": "threejs",
            "lights": [{"type": "directional", "to_light": [1.5, 0.4, 0.3]}],
        },
        "sphere",
        None,
    ),
    "two_sided": (
        {
            "material": _WHITE,
            "two_sided": True,
            "viewer": {"to_viewer": [0.3, 0.2, -1]},
            "lights": [{"type": "point", "position": [0.4, 0.3, -1.5], "intensity": 0.6}],
        },
        "plane",
        32,
    ),
    "translucent": (
        {
            "material": {
                "ambient": [0.17, 0.01, 0.01],
                "diffuse": [0.61, 0.04, 0.04],
                "specular": [0.73, 0.63, 0.63],
                "shininess": 76.8,
                "opacity": 0.4,
            },
            "viewer": {"eye": [3.2, 1.6, 1.8]},
            "lights": [{"type": "directional", "to_light": [0, 1, 1]}],
        },
        "teapot",
        None,
    ),
    "emissive": (
        {
            "material": {
                "ambient": [0.1, 0.1, 0.1],
                "diffuse": [0.3, 0.3, 0.3],
                "emission": [0.6, 0.25, 0.0],
                "specular": [0.3, 0.3, 0.3],
                "shininess": 10,
            },
            "lights": [{"type": "directional", "to_light": [-1, 1, 1], "intensity": 0.5}],
        },
        "icosphere",
        3,
    ),
}


def _feature_image(renderer, name):
    mapping, mesh_name, res = FEATURES[name]
    return renderer.render(explorer.load_scene(mapping), M.get_mesh(mesh_name, res))


def _preset_scene(material):
    return explorer.load_scene(PRESET_SCENE).replace(
        material=material, model=material.model or PRESET_SCENE["model"]
    )


def _preset_colors() -> dict[str, np.ndarray]:
    """The engine's colours of every built-in preset on the teapot: name -> (n, 3) float64."""
    mesh = M.teapot()
    return {name: vertex_colors(_preset_scene(m), mesh) for name, m in sorted(PRESETS.items())}


def test_golden_preset_colors():
    """Every preset's numbers, through the engine: the stored float64 colours of each preset
    on the teapot under the sheet's light."""
    check_golden_arrays("preset_colors", _preset_colors(), GOLDEN_COLOR_ABS_TOL)


def test_golden_preset_colors_catch_a_small_change():
    """The stored colours' tolerance passes rounding and catches a change of 0.001 in one
    coefficient of one preset."""
    mesh = M.teapot()
    gold = PRESETS["gold"]
    colors = vertex_colors(_preset_scene(gold), mesh)
    ulps = colors * (1 + 8 * np.finfo(float).eps)
    assert array_differences({"gold": ulps}, {"gold": colors}, GOLDEN_COLOR_ABS_TOL) == []
    dim = gold.replace(diffuse=tuple(np.subtract(gold.diffuse, 0.001)))
    changed = vertex_colors(_preset_scene(dim), mesh)
    problems = array_differences({"gold": changed}, {"gold": colors}, GOLDEN_COLOR_ABS_TOL)
    assert len(problems) == 1 and problems[0].startswith("gold: ")
    assert array_differences({"gold": colors}, {"jade": colors}, 1.0) == [
        "jade: in the golden, not computed",
        "gold: computed, not in the golden",
    ]


def test_golden_preset_sheet():
    """What people see: every built-in preset on the teapot, as
    ``phong-explorer sheet --tile 160x120 --columns 7`` draws it."""
    items = sorted(PRESETS.items())
    image = sheet(items, explorer.load_scene(PRESET_SCENE), M.teapot(), tile=(160, 120), columns=7)
    check_golden("preset_sheet", image)


@pytest.mark.parametrize("name", sorted(FEATURES))
def test_golden_feature(renderer, name):
    check_golden(f"feature_{name}", _feature_image(renderer, name))


def test_golden_features_show_their_feature(renderer):
    """The feature scenes really differ where they should (so each golden guards something)."""
    blinn = _feature_image(renderer, "model_blinn")
    phong = _feature_image(renderer, "model_phong")
    threejs = _feature_image(renderer, "model_threejs")
    assert not compare(blinn, phong).ok
    assert not compare(blinn, threejs).ok
    mapping, _, _ = FEATURES["two_sided"]
    one_sided = renderer.render(explorer.load_scene({**mapping, "two_sided": False}), M.plane(32))
    two_sided = _feature_image(renderer, "two_sided")
    assert two_sided.mean() > one_sided.mean() + 5  # the back is lit only when two-sided
    mapping, _, _ = FEATURES["emissive"]
    dark = explorer.load_scene({**mapping, "lights": []})
    img = renderer.render(dark, M.icosphere(3))
    em = np.rint(np.add(mapping["material"]["emission"], 0.02) * 255)  # + ambient 0.1·0.2
    assert np.abs(img[200, 200].astype(float) - em).max() <= 1  # emission needs no light


# -- command line --------------------------------------------------------------------------


def test_cli_render_png(tmp_path, capsys):
    out = tmp_path / "gold.png"
    rc = main(
        [
            "render",
            "--preset",
            "gold",
            "--mesh",
            "sphere",
            "--resolution",
            "24",
            "--out",
            str(out),
            "--size",
            "96x64",
            "--light-to-light",
            "1",
            "1",
            "1",
        ]
    )
    assert rc == 0 and "wrote" in capsys.readouterr().out
    img = read_png(out)
    assert img.shape == (64, 96, 3)
    scene = explorer.load_scene(
        {"material": "gold", "lights": [{"type": "directional", "to_light": [1, 1, 1]}]}
    )
    assert np.array_equal(img, render_image(scene, M.sphere(24), (96, 64)))
    # never overwritten silently
    assert main(["render", "--out", str(out), "--size", "96x64"]) == 2
    assert "already exists" in capsys.readouterr().err
    assert np.array_equal(read_png(out), img)
    assert main(["render", "--out", str(out), "--size", "96x64", "--force"]) == 0
    assert not np.array_equal(read_png(out), img)


def test_cli_scene_file_and_overrides(tmp_path, capsys):
    scene_file = tmp_path / "s.yaml"
    scene_file.write_text(
        "material: jade\nmesh: cube\nviewer: {eye: [2, 2, 3]}\n"
        "lights:\n  - {type: point, position: [2, 3, 1], attenuation: [1, 0.1, 0.01]}\n"
    )
    out = tmp_path / "a.png"
    assert main(["render", str(scene_file), "--out", str(out), "--size", "80x80"]) == 0
    scene = explorer.load_scene(scene_file)
    assert np.array_equal(read_png(out), render_image(scene, M.cube(), (80, 80)))
    # options override parts of the scene
    out2 = tmp_path / "b.png"
    assert (
        main(
            [
                "render",
                str(scene_file),
                "--out",
                str(out2),
                "--size",
                "80x80",
                "--preset",
                "ruby",
                "--model",
                "phong",
                "--light-type",
                "spot",
                "--light-position",
                "0",
                "0",
                "3",
                "--light-aim",
                "0",
                "0",
                "-1",
                "--light-cutoff",
                "30",
                "--viewer-to-viewer",
                "0",
                "0",
                "1",
            ]
        )
        == 0
    )
    want = scene.replace(
        material=explorer.load_scene({"material": "ruby"}).material,
        model="phong",
        viewer=Viewer(to_viewer=(0, 0, 1)),
        lights=(explorer.SpotLight(position=(0, 0, 3), aim=(0, 0, -1), cutoff=30),),
    )
    assert np.array_equal(read_png(out2), render_image(want, M.cube(), (80, 80)))
    capsys.readouterr()


@pytest.mark.parametrize(
    "old, new",
    [
        (["--light-direction", "1", "1", "1"], ["--light-to-light", "1", "1", "1"]),
        (
            ["--light-cutoff", "30", "--light-position", "0", "0", "3"]
            + ["--light-direction", "0", "0", "-1"],
            ["--light-cutoff", "30", "--light-position", "0", "0", "3"]
            + ["--light-aim", "0", "0", "-1"],
        ),
        (["--viewer-direction", "0", "1", "1"], ["--viewer-to-viewer", "0", "1", "1"]),
    ],
)
def test_cli_old_direction_flags_still_work_with_a_notice(tmp_path, old, new):
    """The old flag warns (a DeprecatedName notice, which the command prints as a ``notice:``
    line: tests/shading/test_tiers.py checks that printing in a process of its own)."""
    base = ["render", "--mesh", "sphere", "--resolution", "16", "--size", "64x64", "--out"]
    assert main([*base, str(tmp_path / "new.png"), *new]) == 0  # no warning (they are errors)
    flag = new[-4]
    with pytest.warns(DeprecatedName, match=rf"^{old[-4]} is now {flag} \(") as notes:
        assert main([*base, str(tmp_path / "old.png"), *old]) == 0
    assert len(notes) == 1 and "the old name still works" in str(notes[0].message)
    assert np.array_equal(read_png(tmp_path / "old.png"), read_png(tmp_path / "new.png"))


@pytest.mark.parametrize("suffix", [".ply"])  # .glb: tests/render/test_exports.py
def test_cli_render_mesh_file(tmp_path, suffix):
    out = tmp_path / f"m{suffix}"
    assert (
        main(
            [
                "render",
                "--preset",
                "copper",
                "--mesh",
                "icosphere",
                "--resolution",
                "2",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    back = trimesh.load(out, process=False)
    if isinstance(back, trimesh.Scene):
        back = back.to_geometry()
    scene = explorer.load_scene({"material": "copper"})
    want = to_bytes(vertex_colors(scene, M.icosphere(2)))
    assert np.array_equal(np.asarray(back.visual.vertex_colors)[:, :3], want)


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--out", "x.jpg"], "must end in .png or .ply or .glb or .obj"),
        (["--out", "OUT", "--size", "100"], "--size 100: size must look like"),
        (["--out", "OUT", "--size", "10x10"], "[16, 8192]"),
        (["--out", "nodir/x.png"], "does not exist"),
        (["--out", "OUT", "--preset", "gld"], "did you mean 'gold'"),
        (["--out", "OUT", "--mesh", "spere"], "did you mean 'sphere'"),
        (["--out", "OUT", "--mesh", "missing.obj"], "does not exist"),
        (["--out", "OUT", "--mesh", "cube", "--resolution", "4"], "--resolution applies"),
        (["--out", "OUT", "--resolution", "2"], "[3, 1024]"),
        (["--out", "OUT", "--light-cutoff", "120"], "--light-cutoff: must be in [0, 90]"),
        (
            ["--out", "OUT", "--light-type", "directional", "--light-position", "1", "1", "1"],
            "--light-position does not apply to a directional light",
        ),
        (["--out", "OUT", "--light-attenuation", "0", "0", "0"], "--light-attenuation"),
        (["--out", "OUT", "--viewer-to-viewer", "0", "0", "0"], "--viewer-to-viewer"),
        (["--out", "OUT", "--light-aim", "0", "0", "0"], "--light-aim: must be a non-zero"),
        (
            ["--out", "OUT", "--light-position", "1", "1", "1", "--light-to-light", "1", "0", "0"],
            "--light-to-light does not apply to a point light (only to: directional)",
        ),
        (
            ["--out", "OUT", "--light-type", "point", "--light-direction", "1", "0", "0"],
            "--light-direction does not apply to a point light (only to: directional, spot)",
        ),
        (["--out", "OUT", "--background", "2", "0", "0"], "--background"),
        (["--out", "OUT", "--materials", "no_such_dir"], "--materials"),
        (["missing_scene.yaml", "--out", "OUT"], "missing_scene.yaml"),
    ],
)
def test_cli_render_errors(tmp_path, capsys, argv, message):
    argv = [a.replace("OUT", str(tmp_path / "o.png")) for a in argv]
    argv = [str(tmp_path / a) if a.startswith("nodir/") else a for a in argv]
    assert main(["render", *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and message in err and "Traceback" not in err
    assert not (tmp_path / "o.png").exists()


def test_a_sheet_beyond_the_picture_cap_is_refused_before_allocating(tmp_path, monkeypatch, capsys):
    """``sheet --tile 8192x8192`` aborted inside VTK with std::bad_alloc: the whole sheet's
    size is checked first (the renderer is never reached), and so is a render's size."""
    from explorer.render import offscreen

    def never(*args, **kwargs):
        raise AssertionError("the renderer was reached")

    monkeypatch.setattr(offscreen, "OffscreenRenderer", never)
    out = tmp_path / "s.png"
    args = ["sheet", "--out", str(out), "--tile", "8192x8192", "--preset", "gold"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: sheet of 1 tiles of 8192x8192 in 1 columns: 8196x8196")
    assert "more than the limit of 67108864" in err and not out.exists()
    with pytest.raises(ExplorerError, match="more than the limit"):
        offscreen.sheet(
            [("a", Material())] * 2, explorer.Scene(), M.get_mesh("sphere"), tile=(4096, 8192)
        )


def test_cli_sheet(tmp_path, capsys):
    out = tmp_path / "sheet.png"
    rc = main(
        [
            "sheet",
            "--out",
            str(out),
            "--tile",
            "64x48",
            "--columns",
            "2",
            "--preset",
            "gold",
            "--preset",
            "jade",
            "--preset",
            "ruby",
            "--mesh",
            "sphere",
            "--resolution",
            "12",
        ]
    )
    assert rc == 0 and "3 presets" in capsys.readouterr().out
    img = read_png(out)
    gap = 2
    assert img.shape == (2 * 48 + 3 * gap, 2 * 64 + 3 * gap, 3)
    tile = img[gap : gap + 48, gap : gap + 64]
    scene = explorer.Scene(lights=(DirectionalLight(to_light=SHEET_LIGHT_DIRECTION),))
    gold = explorer.load_scene({"material": "gold"}).material
    with OffscreenRenderer((64, 48)) as r:
        size = r.label_font_size(["gold", "jade", "ruby"])
        want = r.render(scene.replace(material=gold), M.sphere(12), label="gold", label_size=size)
    assert np.array_equal(tile, want)
    # the empty fourth cell is background
    assert (img[gap + 48 + gap :, gap + 64 + gap :] == BG).all()
    assert main(["sheet", "--out", str(out), "--preset", "gold"]) == 2
    assert main(["sheet", "--out", str(tmp_path / "s.ply")]) == 2
    assert main(["sheet", "--out", str(tmp_path / "t.png"), "--columns", "0"]) == 2
    assert main(["sheet", "--out", str(tmp_path / "t.png"), "--preset", "nope"]) == 2
    err = capsys.readouterr().err
    assert "already exists" in err and "must end in .png" in err and "--columns" in err
    assert "nope" in err


def test_renders_without_display(tmp_path):
    """No DISPLAY and no X server: VTK renders through EGL, with no X warning."""
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("DISPLAY", "WAYLAND_DISPLAY", "VTK_DEFAULT_OPENGL_WINDOW")
    }
    out = tmp_path / "x.png"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "explorer.cli",
            "render",
            "--mesh",
            "cube",
            "--out",
            str(out),
            "--size",
            "64x64",
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert "X server" not in proc.stderr and "Traceback" not in proc.stderr
    assert read_png(out).shape == (64, 64, 3)


def test_window_setting_not_left_behind(monkeypatch):
    """The EGL choice is made for the renderer's own window only: the process environment
    is unchanged afterwards (a GUI opened later with a display must get an X window)."""
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.delenv("VTK_DEFAULT_OPENGL_WINDOW", raising=False)
    with OffscreenRenderer((32, 32)) as r:
        r.render(explorer.Scene(), M.cube())
        assert type(r.plotter.render_window).__name__ == "vtkEGLRenderWindow"
    assert "VTK_DEFAULT_OPENGL_WINDOW" not in os.environ


def test_cli_sheet_under_several_models(tmp_path, capsys):
    """``--model blinn,threejs``: each preset once under each model, side by side, each tile
    as a one-model sheet draws it; a bad model list is one usage error, no file."""
    out = tmp_path / "models.png"
    args = ["sheet", "--out", str(out), "--tile", "64x48", "--preset", "gold", "--preset",
            "jade", "--mesh", "sphere", "--resolution", "12"]  # fmt: skip
    assert main([*args, "--model", "blinn,threejs"]) == 0
    assert "2 presets under blinn, threejs" in capsys.readouterr().out
    img = read_png(out)
    gap = 2
    assert img.shape == (48 + 2 * gap, 4 * 64 + 5 * gap, 3)
    tiles = [
        img[gap : gap + 48, gap + i * (64 + gap) : gap + i * (64 + gap) + 64] for i in range(4)
    ]
    scene = explorer.Scene(lights=(DirectionalLight(to_light=SHEET_LIGHT_DIRECTION),))
    labels = ["gold · blinn", "gold · threejs", "jade · blinn", "jade · threejs"]
    with OffscreenRenderer((64, 48)) as r:
        size = r.label_font_size(labels)
        for tile, label in zip(tiles, labels, strict=True):
            name, model = label.split(" · ")
            s = scene.replace(
                material=explorer.load_scene({"material": name}).material, model=model
            )
            want = r.render(s, M.sphere(12), label=label, label_size=size)
            assert np.array_equal(tile, want), label
    assert not np.array_equal(tiles[0][:40], tiles[1][:40])  # the highlights differ
    bad = tmp_path / "bad.png"
    with pytest.raises(SystemExit) as e:
        main(["sheet", "--out", str(bad), "--model", "blinn,gouraud"])
    assert e.value.code == 2 and not bad.exists()
    assert "expected names from blinn, phong, threejs" in capsys.readouterr().err
