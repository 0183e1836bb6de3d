"""Per-pixel shading, live (explorer.render.live, issue 39): a LivePixels frame is the picture of
``render --per-pixel`` after any history of changes, agrees with the independent ray caster up
to bounded silhouette pixels, shows the highlight a 24-vertex cube hides, caches what it should
(counted) and computes every term, model, effect and light type as the engine does."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import explorer
from explorer.cli import main
from explorer.core.errors import Cancelled
from explorer.core.hdr import HDR
from explorer.core.lights import DirectionalLight, PointLight, SpotLight
from explorer.core.presets import find_preset
from explorer.core.scene import Viewer
from explorer.geometry import meshes as M
from explorer.render.camera import camera_for, project
from explorer.render.images import read_png
from explorer.render.live import LivePixels
from explorer.render.offscreen import BACKGROUND, OffscreenRenderer
from explorer.render.perpixel import reference, reference_of
from explorer.shading.display import display_colors, to_bytes, vertex_colors

EXAMPLES = Path(__file__).resolve().parents[2] / "docs" / "examples"
SIZE = (120, 90)
CHROME = find_preset("chrome")
LIGHTS = (DirectionalLight(to_light=(-0.4, 0.6, 1.0)),)


def _scene(viewer=None, material=CHROME, lights=LIGHTS, **kw):
    return explorer.Scene(
        material=material, lights=lights, viewer=viewer or Viewer(to_viewer=(1, 2, 3)), **kw
    )


def _levels(a, b) -> np.ndarray:
    """(h, w) the largest channel difference of two pictures, in 8-bit levels."""
    return np.abs(a.astype(np.int64) - b.astype(np.int64)).max(axis=2)


@pytest.fixture(scope="module")
def teapot():
    return M.teapot(6)


# -- the same picture as render --per-pixel ----------------------------------------------------


def test_a_live_frame_after_changes_is_the_render_per_pixel_picture(tmp_path, teapot):
    """The CLI's default per-pixel picture equals a live frame of the same state, reached after
    other materials, cameras and sizes (the caches leave nothing stale)."""
    scene = _scene(Viewer(eye=(2.0, 1.5, 3.0)), lights=(PointLight(position=(1.5, 2.0, 2.0)),))
    cam = camera_for(scene, teapot, SIZE[0] / SIZE[1])
    with LivePixels(teapot) as live:
        live.frame(scene.replace(material=find_preset("jade")), cam, SIZE)
        other = camera_for(_scene(), teapot, 1.0)
        live.frame(scene, other, (64, 64))
        live.frame(scene.replace(model="phong"), cam, SIZE)
        got = live.frame(scene, cam, SIZE)
    out = tmp_path / "pp.png"
    argv = "render --per-pixel --preset chrome --mesh teapot --resolution 6 --viewer-eye 2 1.5 3"
    argv = [*argv.split(), "--light-position", "1.5", "2", "2", "--size", "120x90"]
    argv += ["--out", str(out)]
    assert main(argv) == 0
    assert np.array_equal(read_png(out), got.rgb)
    assert got.mask.sum() > 1500


@pytest.mark.parametrize("viewer", [Viewer(eye=(2.0, 1.5, 3.0)), Viewer(to_viewer=(1, 2, 3))])
def test_live_agrees_with_the_ray_cast_picture_but_for_bounded_silhouette_pixels(teapot, viewer):
    """The ray caster (``render --per-pixel --per-pixel-method raycast``) finds its triangles
    by its own search: on every pixel both cover the two pictures agree within one level but
    for a few pixel centres on a shared edge, and they cover the same pixels but for a few on
    the silhouette (each counted, bounded)."""
    scene = _scene(viewer)
    cam = camera_for(scene, teapot, SIZE[0] / SIZE[1])
    with LivePixels(teapot) as live:
        got = live.frame(scene, cam, SIZE)
    ref = reference(scene, teapot, SIZE, camera=cam, method="raycast")
    both = got.mask & ref.mask
    silhouette = int((got.mask ^ ref.mask).sum())
    off = int((_levels(got.rgb, ref.image())[both] > 1).sum())
    assert both.sum() > 1500
    assert silhouette <= 3
    assert off <= 2


# -- what per-pixel shows that per-vertex cannot ---------------------------------------------


def test_a_cube_shows_the_highlight_per_pixel_that_its_vertices_miss():
    """A point light just above the middle of the 24-vertex cube's front face: the vertices (the
    face's corners) get no highlight, so the per-vertex picture has none; per pixel the peak is
    the pixel whose ray meets the face's centre (below the light), with the engine's colour of
    that surface point."""
    mesh = M.cube()
    # (a peak below 255: its pixel is the only brightest one)
    material = CHROME.replace(shininess=60.0, diffuse=(0.2,) * 3, specular=(0.5,) * 3)
    scene = _scene(Viewer(to_viewer=(0, 0, 1)), material, (PointLight(position=(0, 0, 1.3)),))
    size = (101, 101)  # (odd: the centre pixel's ray runs through the face's centre)
    cam = camera_for(scene, mesh, 1.0)
    with LivePixels(mesh) as live:
        got = live.frame(scene, cam, size)
    with OffscreenRenderer(size) as r:
        gouraud = r.render(scene, mesh, vertex_colors(scene, mesh), camera=cam)
    col, row, _ = project(cam, np.array([[0.0, 0.0, 1.0]]), size)
    centre = (round(float(row[0] - 0.5)), round(float(col[0] - 0.5)))
    assert centre == (50, 50)
    bright = got.rgb.astype(np.int64).sum(axis=2)
    peak = np.unravel_index(np.argmax(np.where(got.mask, bright, -1)), bright.shape)
    assert tuple(int(i) for i in peak) == centre
    engine = to_bytes(display_colors(scene, [[0.0, 0.0, 1.0]], [[0.0, 0.0, 1.0]]))[0]
    assert np.array_equal(got.rgb[centre], engine)
    # the Gouraud picture's front face: no highlight anywhere, far below the peak
    face = (
        got.mask
        & (np.abs(np.arange(101) - 50) < 45)[:, None]
        & (np.abs(np.arange(101) - 50) < 45)[None, :]
    )
    assert int(gouraud.astype(np.int64).sum(axis=2)[face].max()) < int(bright[centre]) - 300
    assert 100 < int(engine.max()) < 255


# -- the caches, counted ---------------------------------------------------------------------


def test_changes_cost_what_they_should(teapot):
    """A material change composes with no light pass; a shininess change reruns the specular
    alone (then only its lobe); a camera or size change makes one G-buffer; every frame is the
    independent one-shot picture of its state (reference_of: the engine on the same hits)."""
    scene = _scene(lights=(PointLight(position=(1.5, 2.0, 2.0)), LIGHTS[0]))
    cam = camera_for(scene, teapot, SIZE[0] / SIZE[1])
    moved = camera_for(_scene(Viewer(to_viewer=(-1, 1, 2))), teapot, SIZE[0] / SIZE[1])
    with LivePixels(teapot) as live:

        def frame(sc, camera=cam, size=SIZE):
            f = live.frame(sc, camera, size)
            want = reference_of(sc, teapot, live._gbuffer.hits).image()
            assert _levels(f.rgb, want).max() <= 1
            return f

        first = frame(scene)
        assert first.gbuffer_made and live.gbuffers == 1 and live.light_passes == 1
        kd = scene.replace(material=CHROME.replace(diffuse=(0.6, 0.2, 0.1)))
        again = frame(kd)
        assert not again.gbuffer_made and live.gbuffers == 1
        assert live.light_passes == 1 and live.stats["compose"] == 1
        assert not np.array_equal(again.rgb, first.rgb)
        before = live.stats
        frame(kd.replace(material=kd.material.replace(shininess=20.0)))
        after = live.stats
        assert after["specular"] == before["specular"] + 1 and live.light_passes == 2
        assert (after["ambient"], after["diffuse"]) == (before["ambient"], before["diffuse"])
        frame(kd.replace(material=kd.material.replace(shininess=40.0)))
        assert live.stats["lobe"] == 1 and live.light_passes == 2
        made = frame(kd.replace(material=kd.material.replace(shininess=40.0)), moved)
        assert made.gbuffer_made and live.gbuffers == 2
        assert not frame(kd, moved).gbuffer_made and live.gbuffers == 2
        assert frame(kd, moved, (80, 60)).gbuffer_made and live.gbuffers == 3
        coarse = M.teapot(4)
        live.set_mesh(coarse)
        f = live.frame(kd, moved, (80, 60))
        assert f.gbuffer_made and live.gbuffers == 4
        assert _levels(f.rgb, reference_of(kd, coarse, live._gbuffer.hits).image()).max() <= 1


def test_a_frame_can_be_cancelled_and_the_next_one_is_whole(teapot):
    scene = _scene()
    cam = camera_for(scene, teapot, SIZE[0] / SIZE[1])
    asked = []
    with LivePixels(teapot) as live:
        with pytest.raises(Cancelled):
            live.frame(scene, cam, SIZE, cancelled=lambda: asked.append(1) or len(asked) > 1)
        assert len(asked) == 2  # before the G-buffer, then before the shading
        got = live.frame(scene, cam, SIZE)
    assert np.array_equal(got.rgb, reference_of(scene, teapot, live._gbuffer.hits).image())


# -- every term, model, effect and light type ----------------------------------------------


def _cases():
    spot = SpotLight(position=(0.5, 2.0, 2.0), aim=(-0.2, -1.0, -1.0), cutoff=25.0, exponent=8.0)
    point = PointLight(position=(1.2, 1.5, 1.5), attenuation=(1.0, 0.2, 0.05))
    shadowing = PointLight(position=(-1.5, 2.5, 0.5), shadows=True)
    gold = find_preset("gold")
    return {
        "directional": {},
        "point, attenuated": {"lights": (point,)},
        "spot": {"lights": (spot,)},
        "three lights": {"lights": (point, spot, LIGHTS[0])},
        "phong": {"model": "phong"},
        "threejs": {"model": "threejs"},
        "two-sided, local viewer": {"two_sided": True, "viewer": Viewer(eye=(0.4, 0.3, 2.5))},
        "fresnel": {"material": gold.replace(fresnel=0.6)},
        "energy": {"material": gold.replace(energy_conserving=True)},
        "hdr": {"hdr": HDR(exposure=1.5, tone_map="aces"), "lights": (point,)},
        "shadows": {"lights": (shadowing, LIGHTS[0])},
    }


@pytest.mark.parametrize("case", list(_cases()))
def test_every_effect_and_light_type_is_the_engine_at_each_pixel(teapot, case):
    """Each pixel of a live frame is the engine's colour (the one-shot path,
    :func:`~explorer.render.perpixel.reference_of`) at that pixel's surface point, for each
    light type, model and effect; a shadowing light darkens some pixels (the rays are cast)."""
    kw = dict(_cases()[case])
    viewer, material = kw.pop("viewer", None), kw.pop("material", CHROME)
    scene = _scene(viewer, material, kw.pop("lights", LIGHTS), **kw)
    cam = camera_for(scene, teapot, SIZE[0] / SIZE[1])
    with LivePixels(teapot) as live:
        got = live.frame(scene, cam, SIZE)
        hits = live._gbuffer.hits
    want = reference_of(scene, teapot, hits).image()
    levels = _levels(got.rgb, want)
    assert levels.max() <= 1 and np.mean(levels[got.mask] == 0) > 0.99
    assert np.array_equal(got.mask, hits.mask)
    assert np.array_equal(got.rgb[~got.mask], want[~got.mask])
    if case == "shadows":
        unshadowed = tuple(lt.replace(shadows=False) for lt in scene.lights)
        lit = reference_of(scene.replace(lights=unshadowed), teapot, hits).image()
        assert (_levels(lit, got.rgb)[got.mask] > 8).sum() > 50


def test_per_group_materials_recompose_each_group(teapot):
    """A mesh file's own materials (an OBJ's groups): each pixel in its triangle's group's
    material, as the one-shot path colours it."""
    mesh = M.load_mesh(EXAMPLES / "teapot_parts.obj")
    names = mesh.groups.names
    materials = [find_preset(p) for p in ("gold", "jade", "ruby", "chrome", "pewter")][: len(names)]
    assert len(materials) == len(names) >= 2
    scene = _scene(lights=(PointLight(position=(1.5, 2.0, 2.0)),))
    cam = camera_for(scene, mesh, SIZE[0] / SIZE[1])
    with LivePixels(mesh) as live:
        got = live.frame(scene, cam, SIZE, materials=materials)
        hits = live._gbuffer.hits
        passes = live.light_passes
        live.frame(scene, cam, SIZE, materials=materials[::-1])
        assert live.light_passes == passes  # other materials: no light pass
    want = reference_of(scene, mesh, hits, materials=materials).image()
    assert _levels(got.rgb, want).max() <= 1
    with pytest.raises(explorer.ExplorerError, match="one material per group"):
        LivePixels(mesh).frame(scene, cam, SIZE, materials=materials[:1])


def test_float32_is_within_one_level_of_float64(teapot):
    scene = _scene(lights=_cases()["three lights"]["lights"])
    cam = camera_for(scene, teapot, SIZE[0] / SIZE[1])
    with LivePixels(teapot, precision="float32") as fast, LivePixels(teapot) as exact:
        a, b = fast.frame(scene, cam, SIZE), exact.frame(scene, cam, SIZE)
    assert np.array_equal(a.mask, b.mask)
    assert _levels(a.rgb, b.rgb).max() <= 1
    with pytest.raises(explorer.ExplorerError, match="precision"):
        LivePixels(teapot, precision="float16")


def test_the_background_is_where_nothing_is_covered(teapot):
    scene = _scene()
    cam = camera_for(scene, teapot, SIZE[0] / SIZE[1])
    with LivePixels(teapot) as live:
        grey = live.frame(scene, cam, SIZE)
        red = live.frame(scene, cam, SIZE, background=(1.0, 0.0, 0.0))
    assert np.array_equal(grey.rgb[~grey.mask][0], to_bytes(np.array([BACKGROUND]))[0])
    assert (red.rgb[~red.mask] == [255, 0, 0]).all()
    assert np.array_equal(grey.rgb[grey.mask], red.rgb[red.mask])


def test_the_gbuffer_holds_each_pixels_triangle_and_float64_barycentrics(teapot):
    """The corners' weights (1-u-v, u, v) of each covered pixel give back its position and its
    normal (before normalising) on its own triangle; one G-buffer per camera and size."""
    scene = _scene(Viewer(eye=(2.0, 1.5, 3.0)))
    cam = camera_for(scene, teapot, SIZE[0] / SIZE[1])
    with LivePixels(teapot) as live:
        g, made = live.gbuffer(cam, SIZE)
        assert made and live.gbuffer(cam, SIZE) == (g, False) and live.gbuffers == 1
    h = g.hits
    u, v = h.barycentrics.T
    assert h.barycentrics.dtype == np.float64 and len(u) == h.mask.sum() > 1500
    corners = teapot.faces[h.triangles]
    weights = np.stack([1.0 - u - v, u, v], axis=1)[:, :, None]
    P = (weights * teapot.positions[corners]).sum(axis=1)
    N = (weights * teapot.normals[corners]).sum(axis=1)
    assert np.abs(P - h.positions).max() < 1e-12
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    assert np.abs(N - h.normals).max() < 1e-12
    # inside the triangle but for pixel centres on an edge, which the rasteriser (float32) may
    # give to either neighbour
    inside = (u > -1e-6) & (v > -1e-6) & (u + v < 1 + 1e-6)
    assert inside.mean() > 0.99 and weights.min() > -0.01
    rows, cols = np.nonzero(h.mask)
    assert np.array_equal(g.pixels, rows * SIZE[0] + cols)


def test_shadows_are_cast_once_per_gbuffer(teapot):
    """A shadowing light: the pixels' shadow rays are cast with the light sums; a material
    change reuses both (no rays, no light pass), a camera change casts them again, and each
    frame is the one-shot engine's."""
    shadowing = PointLight(position=(-1.5, 2.5, 0.5), shadows=True)
    scene = _scene(lights=(shadowing,))
    cam = camera_for(scene, teapot, SIZE[0] / SIZE[1])
    moved = camera_for(_scene(Viewer(to_viewer=(-1, 1, 2))), teapot, SIZE[0] / SIZE[1])
    with LivePixels(teapot) as live:
        live.frame(scene, cam, SIZE)
        rays, passes = live.stats["shadow_rays"], live.light_passes
        assert rays > 0 and passes == 1
        kd = scene.replace(material=CHROME.replace(diffuse=(0.6, 0.2, 0.1)))
        got = live.frame(kd, cam, SIZE)
        assert (live.stats["shadow_rays"], live.light_passes) == (rays, passes)
        assert _levels(got.rgb, reference_of(kd, teapot, live._gbuffer.hits).image()).max() <= 1
        got = live.frame(kd, moved, SIZE)
        assert live.stats["shadow_rays"] > rays and live.light_passes == passes + 1
        assert _levels(got.rgb, reference_of(kd, teapot, live._gbuffer.hits).image()).max() <= 1
