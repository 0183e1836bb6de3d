"""Files other tools read: the unlit GLB (read back with pygltflib and trimesh), OBJ + MTL,
OBJ meshes with their own materials (render and sheet), and turntables."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pygltflib
import pytest
import trimesh
from helpers.frames import read_frames

import explorer
from explorer.cli import main
from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError
from explorer.core.mtl import read_mtl
from explorer.geometry import meshes as M
from explorer.render.exports import UNLIT, glb_bytes, linear_colors
from explorer.render.images import read_png
from explorer.render.turntable import check_frames, check_turntable, orbit_scene
from explorer.shading.display import group_vertex_colors, vertex_colors

# two unit squares side by side, each its own usemtl group; the shared edge (x = 1) is split
TWO_GROUPS_OBJ = """mtllib two.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 2 0 0
v 2 1 0
usemtl left_red
f 1 2 3
f 1 3 4
usemtl right_blue
f 2 5 6
f 2 6 3
"""
TWO_GROUPS_MTL = """newmtl left_red\r
Ka 0.2 0 0\r
Kd 1 0 0\r
\r
newmtl right_blue\r
Ka 0 0 0.2\r
Kd\t0 0 1\r
"""


@pytest.fixture
def two_groups(tmp_path) -> Path:
    (tmp_path / "two.mtl").write_bytes(TWO_GROUPS_MTL.encode())
    path = tmp_path / "two.obj"
    path.write_text(TWO_GROUPS_OBJ)
    return path


# -- GLB -------------------------------------------------------------------------------------


def test_glb_is_unlit_and_holds_linear_colours(tmp_path):
    mesh = M.icosphere(2)
    scene = explorer.load_scene({"material": "ruby"})
    colors = vertex_colors(scene, mesh)
    path = tmp_path / "m.glb"
    path.write_bytes(glb_bytes(mesh, colors, 0.5))
    gltf = pygltflib.GLTF2().load(str(path))
    assert UNLIT in gltf.extensionsUsed
    (material,) = gltf.materials
    assert material.extensions == {UNLIT: {}} and material.alphaMode == "BLEND"
    assert material.pbrMetallicRoughness.baseColorFactor == [1.0, 1.0, 1.0, 1.0]
    (prim,) = gltf.meshes[0].primitives
    accessor = gltf.accessors[prim.attributes.COLOR_0]
    assert accessor.type == "VEC4" and accessor.componentType == pygltflib.FLOAT
    view = gltf.bufferViews[accessor.bufferView]
    blob = gltf.binary_blob()
    rgba = np.frombuffer(blob, np.float32, accessor.count * 4, view.byteOffset).reshape(-1, 4)
    # linear: the sRGB decoding of the display colours (a mid grey 0.5 is 0.214 linear)
    assert np.allclose(rgba[:, :3], linear_colors(colors), atol=1e-6)
    assert np.all(rgba[:, :3] <= colors + 1e-7) and (rgba[:, 3] == 0.5).all()
    assert np.isclose(linear_colors([[0.5, 0.5, 0.5]])[0, 0], 0.21404114)
    # a viewer encodes linear back to sRGB: the engine's 8-bit pixels come back
    back = np.where(
        rgba[:, :3] <= 0.0031308, 12.92 * rgba[:, :3], 1.055 * rgba[:, :3] ** (1 / 2.4) - 0.055
    )
    assert np.array_equal(np.round(back * 255), np.round(colors * 255))
    # trimesh reads the same geometry
    tm = trimesh.load(path, process=False).to_geometry()
    assert len(tm.vertices) == mesh.n_vertices
    assert np.allclose(tm.vertices, mesh.positions, atol=1e-6)
    assert np.array_equal(tm.faces, mesh.faces)


def test_cli_glb_matches_the_engine(tmp_path):
    out = tmp_path / "c.glb"
    argv = ["render", "--preset", "copper", "--mesh", "icosphere", "--resolution", "2"]
    assert main([*argv, "--out", str(out)]) == 0
    gltf = pygltflib.GLTF2().load(str(out))
    assert gltf.materials[0].alphaMode == "OPAQUE" and gltf.materials[0].doubleSided is False
    two = tmp_path / "two.glb"
    assert main([*argv, "--two-sided", "--out", str(two)]) == 0
    assert pygltflib.GLTF2().load(str(two)).materials[0].doubleSided is True
    accessor = gltf.accessors[gltf.meshes[0].primitives[0].attributes.COLOR_0]
    view = gltf.bufferViews[accessor.bufferView]
    rgba = np.frombuffer(gltf.binary_blob(), np.float32, accessor.count * 4, view.byteOffset)
    want = linear_colors(vertex_colors(explorer.load_scene({"material": "copper"}), M.icosphere(2)))
    assert np.allclose(rgba.reshape(-1, 4)[:, :3], want, atol=1e-6)


# -- OBJ with its own materials --------------------------------------------------------------


def test_obj_groups_split_the_shared_edge(two_groups):
    mesh = M.load_mesh(two_groups)
    groups = mesh.groups
    assert set(groups.names) == {"left_red", "right_blue"}
    assert groups.libraries == (str(two_groups.parent / "two.mtl"),)
    assert mesh.n_vertices == 8  # 6 in the file, the two on the shared edge split
    for g in range(2):
        faces = mesh.faces[groups.of_vertex[mesh.faces[:, 0]] == g]
        assert (groups.of_vertex[faces] == g).all()  # no triangle reaches the other group


def test_each_group_is_shaded_in_its_own_material(two_groups):
    mesh = M.load_mesh(two_groups)
    scene = explorer.Scene()
    by_name = {m.name: m.material for m in read_mtl(two_groups.parent / "two.mtl")}
    materials = tuple(by_name[n] for n in mesh.groups.names)
    colors = group_vertex_colors(scene, mesh, materials)
    for g, material in enumerate(materials):
        rows = mesh.groups.vertices(g)
        alone = vertex_colors(scene.replace(material=material), mesh)
        assert np.array_equal(colors[rows], alone[rows])
    assert mesh.groups.names == ("left_red", "right_blue")  # the file's order
    red = colors[mesh.groups.vertices(mesh.groups.names.index("left_red"))]
    blue = colors[mesh.groups.vertices(mesh.groups.names.index("right_blue"))]
    assert (red[:, 0] > 0.5).all() and (red[:, 2] == 0).all()
    assert (blue[:, 2] > 0.5).all() and (blue[:, 0] == 0).all()


def test_render_draws_both_colours_and_preset_overrides(two_groups, tmp_path):
    out = tmp_path / "two.png"
    assert main(["render", "--mesh", str(two_groups), "--out", str(out), "--size", "200x120"]) == 0
    img = read_png(out).astype(int)
    row = img[60]
    left, right = row[40], row[160]
    assert left[0] > 200 and left[2] < 10, left
    assert right[2] > 200 and right[0] < 10, right
    gold = tmp_path / "gold.png"
    argv = ["render", "--mesh", str(two_groups), "--preset", "gold", "--size", "200x120"]
    assert main([*argv, "--out", str(gold)]) == 0
    g = read_png(gold).astype(int)[60]
    assert np.abs(g[40] - g[160]).max() <= 2  # one material everywhere


def test_sheet_starts_with_the_files_own_materials(two_groups, tmp_path):
    argv = ["sheet", "--mesh", str(two_groups), "--tile", "100x80", "--columns", "60"]
    out = tmp_path / "sheet.png"
    assert main([*argv, "--out", str(out), "--preset", "gold"]) == 0  # presets named: only them
    assert read_png(out).shape[1] == 100 + 2 * 2
    out2 = tmp_path / "sheet2.png"
    assert main([*argv, "--out", str(out2)]) == 0
    first = read_png(out2)[2 : 2 + 80, 2 : 2 + 100].astype(int)
    assert (first[..., 0] > 200).any() and (first[..., 2] > 200).any()


def test_a_bad_mtllib_is_one_line_naming_file_and_line(two_groups, tmp_path, capsys):
    (two_groups.parent / "two.mtl").write_text("newmtl left_red\nKd 1 zero 0\n")
    assert main(["render", "--mesh", str(two_groups), "--out", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "two.mtl:2: Kd: 'zero' is not a number" in err
    assert "--preset" in err and "Traceback" not in err


def test_missing_material_and_missing_library_are_warned(two_groups, tmp_path, capsys):
    (two_groups.parent / "two.mtl").write_text("newmtl left_red\nKd 1 0 0\n")
    assert main(["render", "--mesh", str(two_groups), "--out", str(tmp_path / "a.png")]) == 0
    assert "usemtl 'right_blue': not in its mtllib" in capsys.readouterr().err
    (two_groups.parent / "two.mtl").unlink()
    assert main(["render", "--mesh", str(two_groups), "--out", str(tmp_path / "b.png")]) == 0
    assert "two.mtl: no such file; its materials are not read" in capsys.readouterr().err


def test_other_formats_say_their_colours_are_not_read(tmp_path):
    tm = trimesh.creation.icosphere(1)
    tm.visual.vertex_colors = np.tile([255, 0, 0, 255], (len(tm.vertices), 1))
    path = tmp_path / "red.ply"
    tm.export(path)
    with pytest.warns(explorer.core.errors.Notice, match="colours or materials are not read"):
        mesh = M.load_mesh(path)
    assert mesh.groups is None


# -- OBJ + MTL out ---------------------------------------------------------------------------


def test_obj_export_writes_its_mtl_and_reads_back(two_groups, tmp_path):
    out = tmp_path / "out.obj"
    assert main(["render", "--mesh", str(two_groups), "--out", str(out)]) == 0
    mtl = {m.name: m.material for m in read_mtl(tmp_path / "out.mtl")}
    src = {m.name: m.material for m in read_mtl(two_groups.parent / "two.mtl")}
    assert mtl == src
    back = M.load_mesh(out)
    assert set(back.groups.names) == {"left_red", "right_blue"} and back.n_vertices == 8
    # never over a file: the .mtl beside it counts too
    (tmp_path / "again.mtl").write_text("keep me")
    assert main(["render", "--preset", "gold", "--out", str(tmp_path / "again.obj")]) == 2
    assert (tmp_path / "again.mtl").read_text() == "keep me"
    assert not (tmp_path / "again.obj").exists()
    assert (
        main(["render", "--preset", "gold", "--out", str(tmp_path / "again.obj"), "--force"]) == 0
    )
    (gold,) = read_mtl(tmp_path / "again.mtl")
    assert gold.name == "gold" and gold.material == explorer.core.presets.find_preset("gold")


# -- turntables ------------------------------------------------------------------------------


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_turntable_writes_n_frames_and_never_overwrites(tmp_path, suffix):
    out = tmp_path / f"spin{suffix}"
    argv = ["render", "--preset", "gold", "--mesh", "teapot", "--resolution", "4"]
    argv += ["--size", "64x48", "--turntable", "6", "--out", str(out)]
    assert main(argv) == 0
    frames = read_frames(out)
    assert frames.shape[:3] == (6, 48, 64)
    # the teapot turns: frames differ, and a half turn is not the first frame
    assert np.abs(frames[0].astype(int) - frames[3].astype(int)).max() > 50
    before = out.read_bytes()
    assert main(argv) == 2
    assert out.read_bytes() == before


def test_turntable_options_are_checked(tmp_path, capsys):
    assert main(["render", "--turntable", "1", "--out", str(tmp_path / "a.gif")]) == 2
    assert "from 2 to 360" in capsys.readouterr().err
    assert main(["render", "--turntable", "4", "--out", str(tmp_path / "a.png")]) == 2
    assert "must end in .gif or .mp4" in capsys.readouterr().err
    assert check_frames(36) == 36


def _no_frame(monkeypatch):
    """Make any off-screen frame render fail the test."""
    from explorer.render import offscreen

    def render(*args, **kw):
        raise AssertionError("a frame was rendered")

    monkeypatch.setattr(offscreen.OffscreenRenderer, "render", render)


def test_turntable_needs_are_checked_before_any_frame_renders(tmp_path, capsys, monkeypatch):
    # issue 31 item 5: an odd-sized MP4 rendered every frame before it was refused, and a
    # turntable of 360 frames of 8192² asked 67.5 GiB (a traceback)
    _no_frame(monkeypatch)
    out = tmp_path / "t.mp4"
    assert main(["render", "--turntable", "4", "--size", "121x120", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--size 121x120" in err and "even width and height" in err and "122x120" in err
    assert "Traceback" not in err and not out.exists()
    argv = ["render", "--turntable", "360", "--size", "8192x8192", "--out"]
    for suffix, cap in (
        (".mp4", tol.MAX_TURNTABLE_PIXELS),
        (".gif", tol.MAX_TURNTABLE_HELD_PIXELS),
    ):
        assert main([*argv, str(tmp_path / f"t{suffix}")]) == 2
        err = capsys.readouterr().err
        assert "--turntable 360 --size 8192x8192" in err and f"at most {cap:,}" in err, err
        assert "Traceback" not in err
    # within the budget a GIF of these frames is refused, an MP4 accepted
    assert check_turntable(360, (2048, 2048), ".mp4") == 360
    with pytest.raises(ExplorerError, match="an .mp4 may have more"):
        check_turntable(360, (2048, 2048), ".gif")
    with pytest.raises(ExplorerError, match="held until the end"):
        check_turntable(360, (2048, 2048), ".mp4", held=True)  # the window keeps its frames


def _turntable_peak(tmp_path, monkeypatch, frames: int, size=(256, 256)) -> int:
    """tracemalloc's peak over ``render --turntable frames`` into an MP4, the off-screen render
    replaced by a fresh synthetic picture per frame (the encoder and the loop are real)."""
    import tracemalloc

    from explorer.render import offscreen

    w, h = size

    def render(self, scene, mesh, colors, camera=None):
        frame = np.empty((h, w, 3), np.uint8)
        frame[:] = np.asarray(colors[0] * 255, np.uint8)
        return frame

    monkeypatch.setattr(offscreen.OffscreenRenderer, "render", render)
    out = tmp_path / f"t{frames}.mp4"
    argv = ["render", "--mesh", "sphere", "--resolution", "6", "--size", f"{w}x{h}"]
    tracemalloc.start()
    try:
        assert main([*argv, "--turntable", str(frames), "--out", str(out)]) == 0
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_a_turntable_streams_its_frames(tmp_path, monkeypatch):
    # issue 31 item 5: every frame was held until the end (360 x 2048²: 12.3 GiB); an MP4's
    # frames now go to the encoder as they render, so memory does not grow with their number
    small = _turntable_peak(tmp_path, monkeypatch, 6)
    large = _turntable_peak(tmp_path, monkeypatch, 30)
    frame = 256 * 256 * 3
    assert large < small + 4 * frame, (small, large)  # held frames: 24 more frames, 4.7 MB
    assert read_frames(tmp_path / "t30.mp4").shape[:3] == (30, 256, 256)


def test_orbit_turns_viewer_and_lights_together():
    import math

    scene = explorer.load_scene(
        {"lights": [{"type": "point", "position": [0, 0, 3]}, {"to_light": [1, 0, 0]}]}
    )
    mesh = M.sphere(8)
    s = orbit_scene(scene, mesh, math.pi / 2)
    assert np.allclose(s.viewer.to_viewer, (1, 0, 0), atol=1e-12)
    assert np.allclose(s.lights[0].position, (3, 0, 0), atol=1e-12)
    assert np.allclose(s.lights[1].to_light, (0, 0, -1), atol=1e-12)
    # the same turn for everything: the sphere's colours are the same as at the start
    a = vertex_colors(scene, mesh)
    b = vertex_colors(s, mesh)
    assert np.abs(np.sort(a, axis=0) - np.sort(b, axis=0)).max() < 1e-9


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".glb"])
def test_an_export_larger_than_the_read_cap_is_written_with_a_warning(
    tmp_path, monkeypatch, capsys, suffix
):
    """A 5M-vertex export (1.1 GB .obj, 320 MB .glb) is more than ``--mesh`` reads back: the
    write says so, naming the cap (lowered here so that the file stays small)."""
    from explorer.core import tolerances

    monkeypatch.setattr(tolerances, "MAX_MESH_FILE_BYTES", 2048)
    out = tmp_path / f"big{suffix}"
    assert main(["render", "--mesh", "sphere", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert f"{out} is {out.stat().st_size} bytes, more than the 2048 bytes" in err
    assert "MAX_MESH_FILE_BYTES" in err
