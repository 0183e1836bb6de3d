"""Texture maps per pixel (explorer.render.pixelmaps, issue 40 item 4): each map at each pixel of
the live per-pixel view and ``render --per-pixel`` against closed forms: a constant map of value
c gives c times its untextured term, a pixel's (u, v) is the plane's own at its hit, a bump map
of a linear ramp tilts the normal by the angle computed by hand; in float32 and float64. A
colour change of a textured material composes with no light pass."""

from __future__ import annotations

import numpy as np
import pytest

import explorer
from explorer.cli import main
from explorer.core.errors import ExplorerError
from explorer.core.lights import DirectionalLight
from explorer.core.material import Material
from explorer.core.scene import Viewer
from explorer.core.texture import TextureMap
from explorer.geometry import meshes as M
from explorer.render.camera import camera_for
from explorer.render.images import read_png
from explorer.render.live import LivePixels
from explorer.render.perpixel import reference_of
from explorer.render.pixelmaps import bumped_normals, pixel_uv
from explorer.shading.display import to_bytes

SIZE = (96, 72)
TO_LIGHT = np.array([-0.4, 0.6, 1.0])
LIGHTS = (DirectionalLight(to_light=tuple(TO_LIGHT)),)
BLACK = (0.0, 0.0, 0.0)


def _png(path, rgb) -> str:
    from PIL import Image

    Image.fromarray(np.asarray(rgb, np.uint8)).save(path)
    return str(path)


def _scene(material, viewer=None):
    return explorer.Scene(
        material=material, lights=LIGHTS, viewer=viewer or Viewer(to_viewer=(1, 2, 3))
    )


def _levels(a, b) -> np.ndarray:
    return np.abs(a.astype(np.int64) - b.astype(np.int64)).max(axis=-1)


@pytest.fixture(scope="module")
def teapot():
    return M.teapot(6, uv=True)


#: a material with one term only (the map's own), and the constant the map holds
TERMS = {
    "diffuse_map": Material(ambient=BLACK, diffuse=(0.9, 0.7, 0.5)),
    "ambient_map": Material(ambient=(0.8, 0.9, 1.0), diffuse=BLACK),
    "emission_map": Material(emission=(0.6, 0.8, 0.4), ambient=BLACK, diffuse=BLACK),
    "specular_map": Material(
        specular=(1.0, 0.9, 0.8), ambient=BLACK, diffuse=BLACK, shininess=30.0
    ),
}


@pytest.mark.parametrize("precision", ["float64", "float32"])
@pytest.mark.parametrize("key", [*TERMS, "shininess_map"])
def test_a_constant_map_gives_its_value_times_the_untextured_term(tmp_path, teapot, key, precision):
    """A map whose every texel is c (= 128/255, or an RGB triple) gives each pixel c times the
    untextured term there (the engine's colours on the same hits); a constant shininess map
    gives the picture of shininess n·c. Within one level in float32, the same bytes on 99 % of
    the pixels in float64 (the rest one level: a product rounded apart)."""
    c = np.array([128, 64, 255]) if key in TERMS and key != "specular_map" else np.array([128] * 3)
    image = _png(tmp_path / "c.png", np.broadcast_to(c, (4, 4, 3)))
    if key == "shininess_map":
        material = Material(specular=(1.0, 1.0, 1.0), diffuse=(0.2, 0.2, 0.2), shininess=60.0)
    else:
        material = TERMS[key]
    scene = _scene(material.replace(**{key: TextureMap(image)}))
    cam = camera_for(scene, teapot, SIZE[0] / SIZE[1])
    with LivePixels(teapot, precision=precision) as live:
        f = live.frame(scene, cam, SIZE)
        hits = live._gbuffer.hits
    if key == "shininess_map":
        plain = scene.replace(material=material.replace(shininess=60.0 * 128 / 255))
        want = to_bytes(reference_of(plain, teapot, hits).colors)
    else:
        untextured = reference_of(scene.replace(material=material), teapot, hits).colors
        want = to_bytes(untextured * (c / 255.0))
    got = f.rgb[f.mask]
    assert f.mask.sum() > 1000
    assert _levels(got, want).max() <= 1
    if precision == "float64":
        assert (_levels(got, want) == 0).mean() > 0.99
    # the map is drawn: the untextured picture differs
    with LivePixels(teapot, precision=precision) as live:
        bare = live.frame(scene.replace(material=material), cam, SIZE)
    assert _levels(bare.rgb, f.rgb).max() > 10


def test_a_pixels_uv_is_the_planes_own_at_its_hit():
    """The plane's (u, v) is ((x + 1) / 2, (y + 1) / 2): at every covered pixel the (u, v)
    interpolated from the G-buffer's barycentrics is that of the hit point."""
    plane = M.plane(8, uv=True)
    scene = _scene(Material(), Viewer(to_viewer=(0.3, -0.4, 1.0)))
    with LivePixels(plane) as live:
        live.frame(scene, camera_for(scene, plane, 1.0), (64, 64))
        h = live._gbuffer.hits
    uv = pixel_uv(plane, h.triangles, h.barycentrics)
    assert len(uv) > 1000
    np.testing.assert_allclose(uv, (h.positions[:, :2] + 1.0) / 2.0, rtol=0, atol=1e-12)


def test_a_nonuniform_diffuse_map_shows_each_pixels_texel(tmp_path):
    """Left half of the image white, right half black: on the plane (u = (x + 1) / 2) the pixels
    with x < 0 keep their untextured colour, those with x > 0 are black (pixels within half a
    texel of the line excepted: none there, the texels are 0.5 wide)."""
    rgb = np.zeros((2, 2, 3))
    rgb[:, 0] = 255
    plane = M.plane(8, uv=True)
    material = Material(ambient=BLACK, diffuse=(0.8, 0.6, 0.4))
    scene = _scene(
        material.replace(diffuse_map=TextureMap(_png(tmp_path / "h.png", rgb))),
        Viewer(to_viewer=(0.0, 0.0, 1.0)),
    )
    with LivePixels(plane) as live:
        f = live.frame(scene, camera_for(scene, plane, 1.0), (64, 64))
        h = live._gbuffer.hits
    plain = to_bytes(reference_of(scene.replace(material=material), plane, h).colors)
    got, x = f.rgb[f.mask], h.positions[:, 0]
    left, right = x < -1e-9, x > 1e-9
    assert left.sum() > 500 and right.sum() > 500
    assert np.array_equal(got[left], plain[left])
    assert not got[right].any()


@pytest.mark.parametrize("precision", ["float64", "float32"])
def test_a_linear_ramp_bump_map_tilts_the_normal_by_the_hand_computed_angle(tmp_path, precision):
    """A plane P = (2u - 1, 2v - 1, 0) (so P_u = (L, 0, 0), L = 2) wearing a bump map whose
    height rises linearly along u (texel i of 16 holds 16·i, clamped: every central or
    one-sided difference is the slope) is the surface z = k·x / L with k = F_u: its normal is
    (-k/L, 0, 1) normalised, tilted by atan(k/L) about y. F_u = bm · (16/255) · w · su. Every
    covered pixel of a diffuse-only material shows d·max(0, n'·L̂) computed by hand."""
    w, bm, su = 16, 1.0, 1.0
    ramp = np.repeat(np.repeat((16 * np.arange(w))[None, :, None], 4, axis=0), 3, axis=2)
    tmap = TextureMap(_png(tmp_path / "ramp.png", ramp), clamp=True, bump_multiplier=bm)
    k = bm * (16 / 255) * w * su
    n = np.array([-k / 2.0, 0.0, 1.0]) / np.hypot(k / 2.0, 1.0)
    assert np.degrees(np.arccos(n[2])) == pytest.approx(np.degrees(np.arctan(k / 2.0)))
    plane = M.plane(8, uv=True)
    d = np.array([0.9, 0.8, 0.7])
    material = Material(ambient=BLACK, diffuse=tuple(d), bump_map=tmap)
    scene = _scene(material, Viewer(to_viewer=(0.2, 0.1, 1.0)))
    with LivePixels(plane, precision=precision) as live:
        f = live.frame(scene, camera_for(scene, plane, 1.0), (64, 64))
        h = live._gbuffer.hits
    tilted = bumped_normals(plane, h.triangles, h.barycentrics, h.normals, _image(tmap), tmap)
    np.testing.assert_allclose(tilted, np.broadcast_to(n, tilted.shape), atol=1e-12)
    lit = d * max(0.0, float(n @ (TO_LIGHT / np.linalg.norm(TO_LIGHT))))
    got = f.rgb[f.mask]
    assert len(got) > 1000
    assert _levels(got, to_bytes(lit[None, :])).max() <= (0 if precision == "float64" else 1)
    flat = d * float(TO_LIGHT[2] / np.linalg.norm(TO_LIGHT))
    assert _levels(to_bytes(lit[None, :]), to_bytes(flat[None, :])).max() > 10  # (it tilts)


def _image(tmap):
    from explorer.render.textures import read_texture

    return read_texture(tmap, "bump_map")


def test_a_bump_map_raises_the_surface_along_its_normal_whichever_way_uv_turn(tmp_path):
    """The same ramp on a plane whose (u, v) run the other way round (u mirrored: P_u × P_v
    points against the normal): the height now rises towards -x, so the normal tilts towards
    +x by the same angle: the height still raises the surface along its own normal."""
    ramp = np.repeat(np.repeat((16 * np.arange(16))[None, :, None], 2, axis=0), 3, axis=2)
    tmap = TextureMap(_png(tmp_path / "ramp.png", ramp), clamp=True, bump_multiplier=0.3)
    plane = M.plane(8, uv=True)
    flipped = np.column_stack([1.0 - plane.uv[:, 0], plane.uv[:, 1]])
    mirrored = M.Mesh(plane.positions, plane.normals, plane.faces, "plane", uv=flipped)
    bary = np.array([[0.25, 0.25]])
    up = np.array([[0.0, 0.0, 1.0]])
    a = bumped_normals(plane, np.array([5]), bary, up, _image(tmap), tmap)[0]
    b = bumped_normals(mirrored, np.array([5]), bary, up, _image(tmap), tmap)[0]
    assert a[0] < -0.05 and b[0] == pytest.approx(-a[0]) and b[2] == pytest.approx(a[2])


def test_a_colour_change_of_a_textured_material_runs_no_light_pass(tmp_path, teapot):
    """With a diffuse and a specular map, a colour change or another image composes the kept
    sums (no light pass); a bump map is new normals: one light pass."""
    rng = np.random.default_rng(4)
    one = _png(tmp_path / "a.png", rng.integers(0, 256, (8, 8, 3)))
    two = _png(tmp_path / "b.png", rng.integers(0, 256, (8, 8, 3)))
    m = Material(
        diffuse=(0.7, 0.5, 0.3),
        specular=(0.5,) * 3,
        shininess=20.0,
        diffuse_map=TextureMap(one),
        specular_map=TextureMap(two),
    )
    scene = _scene(m)
    cam = camera_for(scene, teapot, SIZE[0] / SIZE[1])
    with LivePixels(teapot) as live:
        first = live.frame(scene, cam, SIZE)
        assert live.light_passes == 1
        second = live.frame(scene.replace(material=m.replace(diffuse=(0.2, 0.9, 0.4))), cam, SIZE)
        third = live.frame(
            scene.replace(material=m.replace(diffuse_map=TextureMap(two))), cam, SIZE
        )
        assert live.light_passes == 1
        assert _levels(first.rgb, second.rgb).max() > 10
        assert _levels(first.rgb, third.rgb).max() > 10
        live.frame(scene.replace(material=m.replace(bump_map=TextureMap(one))), cam, SIZE)
        assert live.light_passes == 2


def test_a_mesh_without_uv_cannot_wear_a_map_per_pixel(tmp_path):
    """One line naming the mesh."""
    scene = _scene(Material(diffuse_map=TextureMap(_png(tmp_path / "w.png", np.ones((2, 2, 3))))))
    mesh = M.sphere(12)
    with LivePixels(mesh) as live, pytest.raises(ExplorerError, match="no texture coordinates"):
        live.frame(scene, camera_for(scene, mesh, 1.0), (32, 32))


def test_render_per_pixel_draws_the_maps(tmp_path, capsys):
    """``render --per-pixel --diffuse-map IMG`` writes the live view's textured picture, with
    no warning; the ray-cast method says in one line that it draws no maps (status 2)."""
    rng = np.random.default_rng(7)
    image = _png(tmp_path / "t.png", rng.integers(0, 256, (8, 8, 3)))
    out = tmp_path / "p.png"
    args = ["render", "--mesh", "teapot", "--per-pixel", "--size", "96x72", "--diffuse-map", image]
    assert main([*args, "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "warning" not in err
    drawn = read_png(out)
    assert (
        main(
            [
                "render",
                "--mesh",
                "teapot",
                "--per-pixel",
                "--size",
                "96x72",
                "--out",
                str(tmp_path / "plain.png"),
            ]
        )
        == 0
    )
    assert _levels(drawn, read_png(tmp_path / "plain.png")).max() > 10
    capsys.readouterr()
    bad = [*args, "--per-pixel-method", "raycast", "--out", str(tmp_path / "r.png")]
    assert main(bad) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "raster" in err[0] and "raycast" in err[0]
    assert not (tmp_path / "r.png").exists()


def test_each_group_wears_its_own_materials_maps(tmp_path):
    """A mesh file's groups per pixel: the group whose material wears a constant diffuse map
    of c shows c times its diffuse term, the others their own untextured colours (each pixel
    in its triangle's group's material, the maps included)."""
    from pathlib import Path

    from explorer.geometry.meshes import load_mesh

    parts = load_mesh(Path(__file__).resolve().parents[2] / "docs/examples/teapot_parts.obj")
    uv = (parts.positions[:, :2] - parts.positions[:, :2].min(axis=0)) / 4.0
    mesh = M.Mesh(parts.positions, parts.normals, parts.faces, "parts", parts.groups, uv=uv)
    c = np.array([100, 200, 150])
    image = _png(tmp_path / "c.png", np.broadcast_to(c, (2, 2, 3)))
    first = Material(ambient=BLACK, diffuse=(0.9, 0.8, 0.7))
    others = (
        Material(diffuse=(0.2, 0.3, 0.9)),
        Material(diffuse=(0.8, 0.7, 0.1), specular=(1, 1, 1), shininess=50.0),
    )
    worn = (first.replace(diffuse_map=TextureMap(image)), *others)
    scaled = (first.replace(diffuse=tuple(np.array(first.diffuse) * c / 255.0)), *others)
    scene = _scene(Material())
    cam = camera_for(scene, mesh, SIZE[0] / SIZE[1])
    with LivePixels(mesh) as live:
        f = live.frame(scene, cam, SIZE, materials=worn)
        hits = live._gbuffer.hits
    want = to_bytes(reference_of(scene, mesh, hits, materials=scaled).colors)
    plain = to_bytes(reference_of(scene, mesh, hits, materials=(first, *others)).colors)
    got = f.rgb[f.mask]
    assert _levels(got, want).max() <= 1
    of_hit = mesh.groups.of_vertex[mesh.faces[hits.triangles, 0]]
    assert (of_hit == 0).sum() > 200 and (of_hit > 0).sum() > 200
    changed = _levels(got, plain) > 5
    assert changed[of_hit == 0].mean() > 0.5 and not changed[of_hit > 0].any()
