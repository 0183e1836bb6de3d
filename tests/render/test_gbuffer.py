"""The compiled G-buffer (explorer.geometry.raster, explorer.render.perpixel.compiled_hits; issue
39's camera drag): the pixels, triangles, points and normals of VTK's picture of triangle
indices (explorer.render.faceids + raster_hits) without VTK, pixel centres on shared edges and
shared corners owned by exactly one triangle, VTK's picture where the mesh reaches outside the
clipping range, and the live view's default path."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import explorer
from explorer.core.lights import PointLight
from explorer.core.presets import find_preset
from explorer.core.scene import Viewer
from explorer.geometry import meshes as M
from explorer.geometry.raster import gbuffer
from explorer.render.camera import camera_for
from explorer.render.faceids import FaceIdRenderer
from explorer.render.live import LivePixels
from explorer.render.perpixel import compiled_hits, raster_hits

SIZE = (160, 120)


def _scene(viewer):
    return explorer.Scene(
        material=find_preset("chrome"),
        lights=(PointLight(position=(1.5, 2.0, 2.0)),),
        viewer=viewer,
    )


def _cameras(mesh):
    """Perspective, parallel, and a perspective one with its picture shifted (window centre)."""
    near = camera_for(_scene(Viewer(eye=(2.0, 1.5, 3.0))), mesh, SIZE[0] / SIZE[1])
    far = camera_for(_scene(Viewer(to_viewer=(1, 2, 3))), mesh, SIZE[0] / SIZE[1])
    return near, far, dataclasses.replace(near, window_center=(0.13, -0.07))


@pytest.mark.parametrize("name", ["teapot", "torus"])
def test_the_compiled_gbuffer_is_vtks_picture(name):
    """Every camera kind: the pixels VTK's picture covers (up to 3 silhouette pixels), the
    same triangle at nearly every pixel, there the same float64 point and normal to 1e-12 (the
    arithmetic of raster_hits), and elsewhere a neighbour at a shared edge (close points)."""
    mesh = M.teapot(6) if name == "teapot" else M.torus(24)
    with FaceIdRenderer(SIZE) as r:
        for cam in _cameras(mesh):
            vtk = raster_hits(cam, SIZE, mesh, r.render(mesh, cam))
            ours = compiled_hits(cam, SIZE, mesh)
            assert ours is not None and ours.method == "raster" and ours.mask.sum() > 3000
            assert np.array_equal(ours.pixels, np.flatnonzero(ours.mask))
            assert (ours.mask ^ vtk.mask).sum() <= 3
            both = ours.mask & vtk.mask
            ko, kv = np.flatnonzero(both[ours.mask]), np.flatnonzero(both[vtk.mask])
            same = ours.triangles[ko] == vtk.triangles[kv]
            assert same.mean() > 0.97
            for a, b in ((ours.positions, vtk.positions), (ours.normals, vtk.normals)):
                d = np.abs(a[ko] - b[kv]).max(axis=1)
                assert d[same].max() < 1e-12 and d.max() < 0.05
            d_uv = np.abs(ours.barycentrics[ko][same] - vtk.barycentrics[kv][same])
            assert d_uv.max() < 1e-12


def _flat(positions, faces, size):
    """The G-buffer of a flat mesh in the plane z = 0 seen from above by a parallel camera
    whose view spans [-1, 1]² (pixel centres of an odd size fall on x = 0 and y = 0)."""
    P = np.asarray(positions, np.float64)
    N = np.tile([0.0, 0.0, 1.0], (len(P), 1))
    cam = [0, 0, 10, 1, 0, 0, 0, 1, 0, 0, 0, -1, 1.0, 1.0, 0.0, 0.0, 1.0, 20.0]
    return gbuffer(P, N, np.asarray(faces), cam, False, size)


def test_a_pixel_centre_on_a_shared_edge_or_corner_belongs_to_one_triangle():
    """Two triangles whose shared diagonal runs through 9 pixel centres, and a fan of 8 around
    a vertex on a pixel centre (either winding): drawn one triangle at a time, every pixel of
    the square is covered by exactly one (no gap, no double hit: the top-left rule)."""
    size = (9, 9)
    square = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
    ring = [(-1, -1), (0, -1), (1, -1), (1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0)]
    fan = [(0, 0, 0)] + [(x, y, 0) for x, y in ring]
    cases = {
        "diagonal": (square, [(0, 1, 2), (0, 2, 3)]),
        "diagonal, one wound the other way": (square, [(0, 1, 2), (0, 3, 2)]),
        "fan": (fan, [(0, 1 + i, 1 + (i + 1) % 8) for i in range(8)]),
    }
    for name, (P, faces) in cases.items():
        count = np.zeros(size[::-1], np.int64)
        for f in faces:
            mask = _flat(P, [f], size)[0]
            count += mask
        assert (count == 1).all(), name
        whole = _flat(P, faces, size)
        assert whole[0].all() and len(whole[1]) == 81, name


def test_a_mesh_cut_by_the_clipping_range_takes_vtks_picture():
    """A near plane that cuts the mesh: compiled_hits declines (VTK clips, it would not), and
    a LivePixels asked for the compiled G-buffer makes VTK's (the same as gbuffer_method vtk)."""
    mesh = M.teapot(6)
    cam = _cameras(mesh)[0]
    lo, hi = cam.clipping_range
    cut = dataclasses.replace(cam, clipping_range=(lo + 0.3 * (hi - lo), hi))
    assert compiled_hits(cut, SIZE, mesh) is None
    with (
        LivePixels(mesh, gbuffer_method="compiled") as a,
        LivePixels(mesh, gbuffer_method="vtk") as b,
    ):
        ga, gb = a.gbuffer(cut, SIZE)[0], b.gbuffer(cut, SIZE)[0]
        assert a._faceids is not None  # (VTK's picture was drawn)
    assert np.array_equal(ga.hits.mask, gb.hits.mask)
    assert np.array_equal(ga.hits.positions, gb.hits.positions)
    with pytest.raises(explorer.ExplorerError, match="gbuffer_method must be one of"):
        LivePixels(mesh, gbuffer_method="gl")


def test_the_live_view_draws_from_the_compiled_gbuffer():
    """The default live path (the compiled kernels serve) opens no VTK window for its G-buffer,
    and its picture is the VTK path's within 1 level wherever both cover (float64)."""
    mesh = M.teapot(6)
    scene = _scene(Viewer(eye=(2.0, 1.5, 3.0)))
    cam = _cameras(mesh)[0]
    with LivePixels(mesh) as live, LivePixels(mesh, gbuffer_method="vtk") as vtk:
        a, b = live.frame(scene, cam, SIZE), vtk.frame(scene, cam, SIZE)
        assert live._faceids is None and vtk._faceids is not None
    both = a.mask & b.mask
    assert (a.mask ^ b.mask).sum() <= 3
    levels = np.abs(a.rgb.astype(int) - b.rgb.astype(int)).max(axis=2)
    assert np.mean(levels[both] <= 1) > 0.995


def test_a_camera_change_in_the_live_view_finds_no_chunk_bounds(monkeypatch):
    """The live view's shader does not cull lights (``cull=False``), so a new G-buffer costs
    no chunk bounds of the pixels (two passes over them, more than culling saves: counted),
    and its colours are those of a culling shader."""
    from explorer.shading import prepared
    from explorer.shading.shader import Shader

    calls = []
    real = prepared.chunk_bounds
    monkeypatch.setattr(prepared, "chunk_bounds", lambda *a: calls.append(1) or real(*a))
    mesh = M.teapot(6)
    scene = _scene(Viewer(eye=(2.0, 1.5, 3.0)))
    cams = _cameras(mesh)
    with LivePixels(mesh, precision="float32") as live:
        for cam in cams:
            frame = live.frame(scene, cam, SIZE)
            assert frame.gbuffer_made
        h = live.gbuffer(cams[-1], SIZE)[0].hits
        colors = live._shader.colors
    assert calls == []
    culling = Shader(scene, h.positions, h.normals, precision="float32")
    assert calls and np.array_equal(culling.colors, colors)
