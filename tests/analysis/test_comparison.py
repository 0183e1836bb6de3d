"""Comparing a per-vertex picture with the per-pixel reference (explorer.analysis.comparison)
and the heat map."""

from __future__ import annotations

import math

import numpy as np
import pytest

from explorer.analysis import comparison as C
from explorer.analysis.benchmark import bench_scene
from explorer.core.errors import Cancelled, ExplorerError
from explorer.core.presets import builtin_dir, load_material_file
from explorer.core.scene import Viewer
from explorer.geometry import meshes as M
from explorer.render import perpixel as PP
from explorer.render.camera import camera_for
from explorer.render.perpixel import Hits, Reference


def _reference(mask, colors, specular):
    hits = Hits(mask, np.zeros((mask.sum(), 3)), np.zeros((mask.sum(), 3)), "sphere")
    return Reference(hits, np.asarray(colors, float), np.asarray(specular, float))


def test_compare_by_definition():
    rng = np.random.default_rng(1)
    h, w = 12, 10
    mask = np.zeros((h, w), bool)
    mask[2:10, 3:8] = True
    k = int(mask.sum())
    colors = rng.random((k, 3))
    spec = rng.random(k)
    ref = _reference(mask, colors, spec)
    ref_img = ref.image()
    vertex = ref_img.astype(int) + rng.integers(-6, 7, size=ref_img.shape)
    vertex = np.clip(vertex, 0, 255).astype(np.uint8)
    cover = mask.copy()
    cover[2, 3:8] = False  # a row the per-vertex picture does not cover
    cover[0, 0] = True  # background pixel "covered": still not compared (reference misses it)
    c = C.compare(vertex, ref, cover)
    both = mask & cover
    d = np.abs(vertex.astype(int) - ref_img.astype(int))
    assert np.array_equal(c.mask, both)
    assert math.isclose(c.rmse, float(np.sqrt(np.mean(d[both].astype(float) ** 2))))
    assert c.max == d[both].max()
    assert np.array_equal(c.levels[both], d.max(axis=2)[both])
    assert np.all(c.levels[~both] == 0)
    rows, cols = np.nonzero(mask)
    p = int(np.argmax(spec))
    peak = (rows[p], cols[p])
    assert c.peak == (d.max(axis=2)[peak] if both[peak] else None)


def test_compare_peak_outside_coverage_and_no_highlight():
    mask = np.ones((4, 4), bool)
    ref = _reference(mask, np.full((16, 3), 0.5), np.arange(16.0))
    img = ref.image()
    cover = mask.copy()
    cover[3, 3] = False  # the peak (largest specular is the last pixel)
    assert C.compare(img, ref, cover).peak is None
    assert C.compare(img, ref, mask).peak == 0
    flat = _reference(mask, np.full((16, 3), 0.5), np.zeros(16))
    assert C.compare(img, flat, mask).peak is None


def test_heat_map():
    levels = np.array([[0, 1, 2, 4], [8, 16, 100, 3]])
    mask = np.ones_like(levels, bool)
    mask[1, 3] = False
    img = C.heat_map(levels, mask, vmax=16, background=(10, 20, 30))
    assert img.shape == (2, 4, 3) and img.dtype == np.uint8
    assert img[0, 0].tolist() == [0, 0, 0]
    assert img[0, 1].tolist() == [0, 0, 255]  # one level: blue
    assert img[1, 1].tolist() == [255, 255, 255] == img[1, 2].tolist()  # vmax and beyond
    assert img[1, 3].tolist() == [10, 20, 30]
    # logarithmic ramp: each doubling of the error (up to vmax = 16) is the next colour
    assert img[0, 2].tolist() == [0, 200, 0]  # 2 levels: green
    assert img[0, 3].tolist() == [255, 255, 0]  # 4: yellow
    assert img[1, 0].tolist() == [255, 0, 0]  # 8: red
    between = C.heat_map(np.array([[3]]), vmax=16)[0, 0]  # between green and yellow
    assert 0 < between[0] < 255 and 200 < between[1] < 255 and between[2] == 0
    with pytest.raises(ExplorerError):
        C.heat_map(levels, vmax=1.0)


def test_heat_map_of_whole_levels_is_the_ramp_of_those_levels():
    rng = np.random.default_rng(3)
    levels = rng.integers(0, 256, (40, 30))
    levels[0, :4] = [0, 1, 16, 255]
    mask = rng.random((40, 30)) < 0.8
    for vmax in (16.0, 3.5, 300.0):
        want = C.heat_map(levels.astype(float), mask, vmax=vmax, background=(9, 8, 7))
        got = C.heat_map(levels, mask, vmax=vmax, background=(9, 8, 7))
        assert np.array_equal(got, want) and got.dtype == np.uint8
    assert np.array_equal(C.heat_map(levels.astype(np.uint8)), C.heat_map(levels.astype(float)))


def test_compare_view_for_the_gui():
    """The GUI's comparison of a live view: a coarse sphere glows, a fine one does not."""

    chrome = load_material_file(builtin_dir() / "chrome.yaml")
    scene = bench_scene(chrome).replace(viewer=Viewer(eye=(0.3, 0.4, 3.5)))
    size = (120, 100)
    cam = camera_for(scene, M.sphere(64), size[0] / size[1])
    coarse = C.compare_view(scene, M.sphere(12), size, camera=cam)
    fine = C.compare_view(scene, M.sphere(512), size, camera=cam)
    assert coarse.rmse > 4 * fine.rmse and coarse.max > 20
    assert fine.rmse < 1.0
    heat = C.heat_map(coarse.levels, coarse.mask)
    assert heat.shape == (100, 120, 3)
    assert (heat[coarse.mask].sum(axis=1) > 0).mean() > 0.3
    teapot = C.compare_view(scene, M.teapot(4), size)  # any mesh: ray cast reference
    assert teapot.mask.sum() > 1000 and teapot.rmse > 0
    with C.ViewComparer(size) as v:  # reused windows give the same answers
        again = [v.compare(scene, M.sphere(12), camera=cam), v.compare(scene, M.teapot(4))]
    assert np.array_equal(again[0].levels, coarse.levels)
    assert np.array_equal(again[1].levels, teapot.levels)


def test_compare_view_can_be_cancelled_and_leaves_nothing_behind():
    """A cancelled comparison raises Cancelled; the next one on the same windows equals a
    direct comparison (nothing of the cancelled one is left in them)."""
    chrome = load_material_file(builtin_dir() / "chrome.yaml")
    scene = bench_scene(chrome).replace(viewer=Viewer(eye=(0.3, 0.4, 3.5)))
    size = (320, 240)
    mesh = M.teapot(6)
    asked = []

    def cancelled():
        asked.append(1)
        return len(asked) > 3

    with pytest.raises(Cancelled):
        C.compare_view(scene, mesh, size, cancelled=cancelled)
    assert len(asked) == 4  # stopped in the middle of the rays
    with C.ViewComparer(size) as v:
        with pytest.raises(Cancelled):
            v.compare(scene, M.sphere(12), cancelled=lambda: True)
        after = v.compare(scene, mesh, cancelled=lambda: False)
    direct = C.compare_view(scene, mesh, size)
    assert np.array_equal(after.levels, direct.levels) and after.mask.sum() > 1000


def test_raster_reference_compares_as_the_ray_cast_one():
    """The difference view from the rasteriser's triangles equals the ray-cast one but for
    pixel centres on a silhouette or shared edge."""
    chrome = load_material_file(builtin_dir() / "chrome.yaml")
    scene = bench_scene(chrome).replace(viewer=Viewer(eye=(0.3, 0.4, 3.5)))
    mesh = M.teapot(6)
    with C.ViewComparer((200, 150)) as v:
        raster = v.compare(scene, mesh, method="raster")
        cast = v.compare(scene, mesh, method="raycast")
    assert raster.mask.sum() > 4000 and (raster.mask ^ cast.mask).sum() <= 3
    same = raster.levels == cast.levels
    assert same.mean() > 0.999 and np.abs(raster.levels - cast.levels).max() <= 2
    assert abs(raster.rmse - cast.rmse) < 0.01 and cast.rmse > 0.3


def test_cold_difference_view_casts_no_rays(monkeypatch):
    """While the compiled ray kernels are not loaded (a fresh install), "auto" takes the
    rasteriser's triangles for a mesh and never the numpy tier's rays; the built-in spheres
    keep their closed form."""
    teapot, sphere = M.teapot(4), M.sphere(16)
    assert not C.rasterised("auto", teapot)  # the suite runs on the compiled kernels
    monkeypatch.setattr(C, "loaded", lambda: False)
    assert C.rasterised("auto", teapot) and C.rasterised("raster", sphere)
    assert not C.rasterised("auto", sphere) and not C.rasterised("raycast", teapot)

    def no_rays(*args, **kwargs):
        raise AssertionError("rays cast")

    monkeypatch.setattr(PP, "mesh_hits", no_rays)
    scene = bench_scene(load_material_file(builtin_dir() / "gold.yaml"))
    c = C.compare_view(scene, teapot, (120, 90))
    assert c.mask.sum() > 1000 and c.max >= 1
