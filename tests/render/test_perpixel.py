"""The per-pixel reference (explorer.render.perpixel): VTK's camera model, exact sphere hits, ray
casting with interpolated normals, agreement with a fine per-vertex render, render --per-pixel."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest
from helpers.brute_rays import brute_nearest
from helpers.interrupt import interrupt_ray_work

import explorer
from explorer.analysis.comparison import compare, coverage
from explorer.cli import main
from explorer.core.errors import Cancelled
from explorer.core.hdr import HDR
from explorer.core.lights import DirectionalLight
from explorer.core.presets import builtin_dir, load_material_file
from explorer.core.scene import Viewer
from explorer.geometry import meshes as M
from explorer.geometry.meshes import Mesh
from explorer.render import perpixel as PP
from explorer.render.camera import (
    Camera,
    apply_camera,
    camera_for,
    camera_from_vtk,
    pixel_ndc,
    pixel_rays,
    project,
    sphere_camera,
)
from explorer.render.faceids import MAX_FACES, FaceIdRenderer, decode, index_colors
from explorer.render.images import read_png
from explorer.render.offscreen import OffscreenRenderer
from explorer.render.perpixel import (
    hits,
    mesh_hits,
    point_colors,
    raster_hits,
    reference,
    sphere_hits,
)
from explorer.shading.display import vertex_colors

CHROME = load_material_file(builtin_dir() / "chrome.yaml")
LIGHT = DirectionalLight(to_light=(-0.4, 0.6, 1.0))


def _scene(viewer=None, material=CHROME, lights=(LIGHT,), **kw):
    return explorer.Scene(
        material=material, lights=lights, viewer=viewer or Viewer(to_viewer=(0, 0, 1)), **kw
    )


def _cameras():
    """Parallel and perspective cameras, square and not, with and without a window shift."""
    mesh = M.teapot(4)
    out = []
    for viewer in (Viewer(to_viewer=(1, 2, 3)), Viewer(eye=(0.5, 1.5, 4.0))):
        for aspect, bottom in ((1.0, 0.0), (1.6, 0.2), (0.7, 0.0)):
            out.append((camera_for(_scene(viewer), mesh, aspect, bottom=bottom), aspect))
    return out


def _vtk_camera(cam: Camera):
    from vtkmodules.vtkRenderingCore import vtkCamera

    c = vtkCamera()
    apply_camera(c, cam)
    return c


# -- camera model --------------------------------------------------------------------------


@pytest.mark.parametrize("index", range(6))
def test_pixel_rays_follow_vtk_projection(index):
    """Points along each pixel's ray project, by VTK's own matrices, to that pixel's centre."""
    cam, aspect = _cameras()[index]
    h = 30
    w = int(round(h * aspect))
    size = (w, h)
    origins, dirs = pixel_rays(cam, size)
    vc = _vtk_camera(cam)
    m = vc.GetCompositeProjectionTransformMatrix(w / h, -1, 1)
    M4 = np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])
    near, far = cam.clipping_range
    nx, ny = pixel_ndc(size)
    for t in (near + 0.1 * (far - near), near + 0.7 * (far - near)):
        # a point at depth t along the view direction on each ray
        depth = dirs @ np.asarray(cam.direction)
        along = (t - (origins - np.asarray(cam.position)) @ np.asarray(cam.direction)) / depth
        pts = origins + along[..., None] * dirs
        hom = np.concatenate([pts, np.ones((h, w, 1))], axis=2) @ M4.T
        ndc = hom[..., :2] / hom[..., 3:4]
        assert np.allclose(ndc[..., 0], nx[None, :], atol=1e-9)
        assert np.allclose(ndc[..., 1], ny[:, None], atol=1e-9)
    assert np.allclose(np.linalg.norm(dirs, axis=2), 1.0)


@pytest.mark.parametrize("index", range(6))
def test_project_inverts_pixel_rays(index):
    cam, aspect = _cameras()[index]
    size = (int(round(20 * aspect)), 20)
    origins, dirs = pixel_rays(cam, size)
    pts = (origins + 3.0 * dirs).reshape(-1, 3)
    col, row, z = project(cam, pts, size)
    rows, cols = np.indices((size[1], size[0]))
    assert np.allclose(col, cols.ravel(), atol=1e-9)
    assert np.allclose(row, rows.ravel(), atol=1e-9)
    if not cam.parallel:
        assert np.all(z > 0)


def test_camera_from_vtk_round_trip():
    for cam, _ in _cameras():
        back = camera_from_vtk(_vtk_camera(cam))
        assert back.parallel == cam.parallel
        for a, b in zip(
            (back.position, back.focal_point, back.view_up, back.window_center),
            (cam.position, cam.focal_point, cam.view_up, cam.window_center),
            strict=True,
        ):
            assert np.allclose(a, b)
        assert math.isclose(back.parallel_scale, cam.parallel_scale)
        assert math.isclose(back.view_angle, cam.view_angle)


# -- hits ----------------------------------------------------------------------------------


def test_sphere_hits_are_the_exact_disc():
    scene = _scene()
    size = (64, 48)
    cam = sphere_camera(scene, size[0] / size[1])
    h = sphere_hits(cam, size)
    assert np.allclose(np.linalg.norm(h.positions, axis=1), 1.0)
    assert np.allclose(h.normals, h.positions)
    assert np.all(h.positions[:, 2] >= 0)  # the near side, seen from +z
    # independently: a pixel centre sees the sphere iff its view-plane point is within 1
    s = cam.parallel_scale
    x = ((np.arange(size[0]) + 0.5) * 2 / size[0] - 1) * s * size[0] / size[1]
    y = (1 - (np.arange(size[1]) + 0.5) * 2 / size[1]) * s
    centre = np.asarray(cam.focal_point)
    inside = (x[None, :] + centre[0]) ** 2 + (y[:, None] + centre[1]) ** 2 <= 1.0
    assert np.array_equal(h.mask, inside)


def test_local_viewer_sees_less_than_a_hemisphere():
    scene = _scene(Viewer(eye=(0.0, 0.0, 3.0)))
    cam = sphere_camera(scene)
    h = sphere_hits(cam, (40, 40))
    eye = np.array([0.0, 0.0, 3.0])
    # every hit faces the eye: N·(eye - P) >= 0, and the nearest root was taken
    assert np.all(np.einsum("ij,ij->i", h.normals, eye - h.positions) >= -1e-9)
    assert h.positions[:, 2].min() >= 1.0 / 3.0 - 1e-9  # tangent points sit at z = r²/d


def test_ray_cast_normals_are_barycentric():
    """One triangle with three different vertex normals, seen head on."""
    P = np.array([[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]])
    N = np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 1.0], [-1.0, -1.0, 1.0]])
    mesh = Mesh(P, N, np.array([[0, 1, 2]]), "triangle")
    cam = Camera((0, 0, 5), (0, 0, 0), (0, 1, 0), True, 1.2, 30.0, (1, 9))
    h = mesh_hits(cam, (24, 24), mesh)
    assert h.mask.sum() > 50
    assert np.allclose(h.positions[:, 2], 0.0)
    # barycentric coordinates of each hit, solved independently
    A = np.vstack([P[:, :2].T, np.ones(3)])
    lam = np.linalg.solve(A, np.vstack([h.positions[:, :2].T, np.ones(len(h.positions))]))
    assert np.all(lam > -1e-9)
    expect = lam.T @ N
    expect /= np.linalg.norm(expect, axis=1, keepdims=True)
    assert np.allclose(h.normals, expect, atol=1e-12)


def test_ray_cast_takes_the_nearest_surface_either_side():
    """Two parallel squares: the camera sees the nearer one from either side."""
    near = M.plane(2)
    far_pos = np.array(near.positions) + [0.0, 0.0, -1.0]
    pos = np.vstack([near.positions, far_pos])
    nrm = np.vstack([near.normals, near.normals])
    faces = np.vstack([near.faces, near.faces + near.n_vertices])
    mesh = Mesh(pos, nrm, faces, "two planes")
    for z_eye, z_seen in ((5.0, 0.0), (-5.0, -1.0)):
        cam = Camera((0, 0, z_eye), (0, 0, 0), (0, 1, 0), False, 1.0, 20.0, (1, 9))
        h = mesh_hits(cam, (32, 32), mesh)
        assert h.mask.any()
        assert np.allclose(h.positions[:, 2], z_seen)


def test_ray_cast_of_a_fine_sphere_matches_the_exact_sphere():
    scene = _scene(Viewer(eye=(1.0, 2.0, 4.0)))
    size = (80, 60)
    cam = sphere_camera(scene, size[0] / size[1])
    exact = sphere_hits(cam, size)
    cast = mesh_hits(cam, size, M.icosphere(5))
    both = exact.mask & cast.mask
    assert (exact.mask ^ cast.mask).sum() <= 0.03 * exact.mask.sum()  # rim pixels only
    ke = np.flatnonzero(both[exact.mask])
    kc = np.flatnonzero(both[cast.mask])
    assert np.abs(exact.positions[ke] - cast.positions[kc]).max() < 0.01
    cos = np.einsum("ij,ij->i", exact.normals[ke], cast.normals[kc])
    assert np.percentile(cos, 99) > np.cos(np.radians(1.0)) and cos.min() > 0.9


def test_ray_cast_coverage_matches_vtk():
    """The ray caster sees exactly the pixels VTK's rasteriser fills (teapot, perspective)."""
    mesh = M.teapot(6)
    scene = _scene(Viewer(eye=(2.0, 1.5, 3.0)))
    size = (120, 90)
    cam = camera_for(scene, mesh, size[0] / size[1])
    h = mesh_hits(cam, size, mesh)
    with OffscreenRenderer(size, (0, 0, 0)) as r:
        img = r.render(scene, mesh, np.ones((mesh.n_vertices, 3)), camera=cam)
    vtk_mask = img.max(axis=2) > 127
    assert vtk_mask.sum() > 1500
    assert (vtk_mask ^ h.mask).sum() <= 3  # pixel centres exactly on an edge may go either way


def test_hits_method_choice():
    scene = _scene()
    assert hits(scene, M.sphere(16), (20, 20)).method == "sphere"
    assert hits(scene, M.icosphere(2), (20, 20)).method == "sphere"
    assert hits(scene, M.sphere(16), (20, 20), method="raycast").method == "raycast"
    assert hits(scene, M.torus(12), (20, 20)).method == "raycast"
    squashed = Mesh(M.sphere(8).positions * [1, 0.5, 1], M.sphere(8).normals, M.sphere(8).faces,
                    "sphere")  # fmt: skip
    assert hits(scene, squashed, (20, 20)).method == "raycast"
    with pytest.raises(explorer.ExplorerError, match="not a built-in unit sphere"):
        hits(scene, M.torus(12), (20, 20), method="sphere")
    with pytest.raises(explorer.ExplorerError, match="method"):
        hits(scene, M.torus(12), (20, 20), method="exact")


# -- colours ---------------------------------------------------------------------------------


def test_point_colors_at_the_vertices_are_the_vertex_colors():
    """The per-pixel colour pipeline is the renderer's: HDR display and shadows included."""

    s, p = M.sphere(12), M.plane(8)
    mesh = Mesh(
        np.vstack([s.positions * 0.4 + [0, 0, 0.6], p.positions]),
        np.vstack([s.normals, p.normals]),
        np.vstack([s.faces, p.faces + s.n_vertices]),
        "sphere over plane",
    )
    shadow = DirectionalLight(to_light=(0.3, 0.2, 1.0), shadows=True)
    for scene in (
        _scene(),
        _scene(hdr=HDR(exposure=1.0)),
        _scene(lights=(shadow,), material=CHROME.replace(ambient=(0, 0, 0))),
    ):
        want = vertex_colors(scene, mesh)
        got = point_colors(scene, mesh.positions, mesh.normals, mesh=mesh)
        assert np.allclose(got, want, atol=1e-12)
    assert (want[s.n_vertices :] == 0).any()  # the shadow case really has shadowed vertices


def test_per_pixel_shadows_follow_geometry():
    """Per-pixel points of the plane under a ball are dark exactly where the ball blocks the
    light (directional light from straight above, camera above)."""
    s, p = M.icosphere(3), M.plane(4)
    radius, height = 0.4, 0.6
    mesh = Mesh(
        np.vstack([s.positions * radius + [0, 0, height], p.positions]),
        np.vstack([s.normals, p.normals]),
        np.vstack([s.faces, p.faces + s.n_vertices]),
        "ball over plane",
    )
    material = explorer.Material(ambient=(0, 0, 0), diffuse=(1, 1, 1))
    scene = explorer.Scene(
        material=material,
        ambient=(0, 0, 0),
        lights=(DirectionalLight(to_light=(0, 0, 1), shadows=True),),
    )
    ref = reference(scene, mesh, (64, 64))
    on_plane = np.abs(ref.hits.positions[:, 2]) < 1e-9
    r = np.linalg.norm(ref.hits.positions[:, :2], axis=1)
    lit = ref.colors[:, 0]
    assert np.all(lit[on_plane & (r > radius + 0.02)] > 0.99)
    shadowed = on_plane & (r < radius - 0.04)  # the tessellated ball is a little smaller
    assert shadowed.sum() == 0  # the ball hides its own shadow from a camera above ...
    side = explorer.Scene(
        material=material,
        ambient=(0, 0, 0),
        viewer=Viewer(to_viewer=(1, 0, 1)),
        lights=scene.lights,
    )
    ref = reference(side, mesh, (96, 96))  # ... so look from the side
    pos = ref.hits.positions
    on_plane = np.abs(pos[:, 2]) < 1e-9
    r = np.linalg.norm(pos[:, :2], axis=1)
    lit = ref.colors[:, 0]
    assert (on_plane & (r < radius - 0.04)).sum() > 30
    assert np.all(lit[on_plane & (r < radius - 0.04)] == 0.0)
    assert np.all(lit[on_plane & (r > radius + 0.02)] > 0.99)


# -- agreement with the per-vertex render ------------------------------------------------------


@pytest.mark.parametrize(
    "viewer, bottom",
    [(Viewer(to_viewer=(0, 0, 1)), 0.0), (Viewer(eye=(0.6, 0.4, 4.0)), 0.15)],
    ids=["parallel", "perspective-shifted"],
)
def test_per_pixel_agrees_with_a_very_fine_per_vertex_render(viewer, bottom):
    """The issue's check of the camera model: same camera, a 1024-segment sphere drawn per
    vertex is within a level (RMSE) of the per-pixel picture; a coarse one is not."""

    scene = _scene(viewer)
    size = (160, 120)
    cam = camera_for(scene, M.sphere(64), size[0] / size[1], bottom=bottom)
    ref = reference(scene, M.sphere(8), size, camera=cam)
    assert ref.hits.method == "sphere"
    results = {}
    with OffscreenRenderer(size) as r, OffscreenRenderer(size, (0, 0, 0)) as rc:
        for res in (16, 1024):
            mesh = M.sphere(res)
            img = r.render(scene, mesh, camera=cam)
            cov = coverage(rc, scene, mesh, cam)
            assert (cov & ~ref.mask).sum() <= 2  # an inscribed polygon never covers more
            results[res] = compare(img, ref, cov)
    fine, coarse = results[1024], results[16]
    assert fine.mask.sum() > 0.95 * ref.mask.sum()
    assert fine.rmse < 1.0
    assert fine.max <= 4
    assert coarse.rmse > 3.0 and coarse.max > 20


# -- the command ---------------------------------------------------------------------------


def test_render_per_pixel_command(tmp_path, capsys):
    out = tmp_path / "pp.png"
    assert main(["render", "--preset", "chrome", "--per-pixel", "--per-pixel-method", "sphere",
                 "--size", "64x48", "--out", str(out)]) == 0  # fmt: skip
    assert "per-pixel picture (sphere, exact sphere, chrome, blinn)" in capsys.readouterr().out
    img = read_png(out)
    scene = _scene().replace(lights=explorer.Scene().lights)
    want = reference(scene, M.sphere(), (64, 48)).image()
    assert np.array_equal(img, want)
    # an existing file is kept without --force
    assert main(["render", "--per-pixel", "--out", str(out)]) == 2
    assert "already exists" in capsys.readouterr().err
    torus = "--mesh torus --resolution 12 --size 40x40".split()
    argv = ["render", "--per-pixel", "--per-pixel-method", "raycast", *torus, "--out", str(out)]
    assert main([*argv, "--force"]) == 0
    assert "ray cast" in capsys.readouterr().out
    # what the method chooses needs --per-pixel; the exact sphere needs a sphere
    assert main(["render", "--per-pixel-method", "sphere", "--out", str(out), "--force"]) == 2
    assert "give --per-pixel" in capsys.readouterr().err
    argv = ["render", "--per-pixel", "--per-pixel-method", "sphere", "--mesh", "torus"]
    assert main([*argv, "--out", str(out), "--force"]) == 2
    assert "not a built-in unit sphere" in capsys.readouterr().err


def test_render_per_pixel_names_the_method_for_more_triangles_than_the_index_picture(
    tmp_path, capsys, monkeypatch
):
    import explorer.cli.render as R

    monkeypatch.setattr(R, "MAX_FACES", 100)  # (the 24-bit picture's limit, made small)
    out = tmp_path / "pp.png"
    assert main(["render", "--per-pixel", "--mesh", "torus", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "more than a picture of triangle indices" in err
    assert "--per-pixel-method raycast" in err and not out.exists()
    assert main(["render", "--per-pixel", "--out", str(tmp_path / "x.ply")]) == 2
    assert "--per-pixel draws a picture" in capsys.readouterr().err
    assert not (tmp_path / "x.ply").exists()


def test_ray_cast_equals_testing_every_triangle():
    """The per-pixel rays through the mesh's BVH hit what testing every triangle hits: the
    same pixels, at the same distances."""
    mesh = M.teapot(4)
    scene = _scene(Viewer(eye=(2.0, 1.5, 3.0)))
    size = (64, 48)
    cam = camera_for(scene, mesh, size[0] / size[1])
    h = mesh_hits(cam, size, mesh)
    origins, dirs = (a.reshape(-1, 3) for a in pixel_rays(cam, size))
    best = brute_nearest(origins, dirs, mesh.positions[mesh.faces], 1e-9)[0]
    seen = np.isfinite(best)
    assert np.array_equal(h.mask.ravel(), seen) and seen.sum() > 300
    assert np.array_equal(h.positions, origins[seen] + best[seen][:, None] * dirs[seen])


def test_specular_sums_are_made_when_first_asked_for(monkeypatch):
    mesh = M.teapot(4)
    scene = _scene()
    calls = []
    real = PP.specular_sums
    monkeypatch.setattr(PP, "specular_sums", lambda *a: calls.append(1) or real(*a))
    ref = reference(scene, mesh, (60, 40))
    assert not calls  # the colours alone
    want = real(scene, ref.hits.positions, ref.hits.normals)
    assert np.array_equal(ref.specular, want) and ref.specular.max() > 0 and calls == [1]
    assert ref.specular is ref.specular and calls == [1]  # kept
    assert ref.peak_index() is not None


def test_reference_can_be_cancelled():
    mesh = M.teapot(4)
    scene = _scene()
    asked = []
    with pytest.raises(Cancelled):  # asked before the rays, then before the colours
        reference(scene, mesh, (40, 30), cancelled=lambda: asked.append(1) or len(asked) > 1)
    assert len(asked) == 2
    with pytest.raises(Cancelled):  # and between chunks of rays
        reference(scene, mesh, (400, 300), cancelled=lambda: asked.append(1) or len(asked) > 4)
    assert len(asked) == 5
    ref = reference(scene, mesh, (40, 30), cancelled=lambda: False)
    assert np.array_equal(ref.image(), reference(scene, mesh, (40, 30)).image())


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_ctrl_c_stops_ray_work_at_the_end_of_the_current_chunk(tmp_path):
    """SIGINT in the middle of the per-pixel rays (many chunks of 0.1 s or more): the command
    stops after the chunks already running, with one line and exit status 130, and leaves no
    file (not even a temporary one). Counted in chunks, not timed."""
    argv = ["render", "--per-pixel", "--per-pixel-method", "raycast", "--mesh", "teapot",
            "--size", "640x480", "--out", str(tmp_path / "pp.png")]  # fmt: skip
    lines, chunks, status = interrupt_ray_work("_nearest_chunk", argv)
    # at most the other thread's chunk started before the signal, and one chunk per thread
    # that was already handed out
    assert chunks <= 4
    assert lines == ["error: interrupted (Ctrl-C); no unfinished file was left"]
    assert status == 130
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("index", range(len(_cameras())))
def test_pixel_rays_of_a_rectangle_are_those_of_the_whole_picture(index):
    cam, size = _cameras()[index][0], (37, 23)
    origins, dirs = pixel_rays(cam, size)
    o, d = pixel_rays(cam, size, (5, 20, 3, 11))
    assert np.array_equal(o, origins[3:12, 5:21]) and np.array_equal(d, dirs[3:12, 5:21])
    rows, cols = np.array([0, 3, 3, 22, 11]), np.array([0, 5, 36, 36, 20])  # (any pixels)
    o, d = pixel_rays(cam, size, pixels=(rows, cols))
    assert np.array_equal(o, origins[rows, cols]) and np.array_equal(d, dirs[rows, cols])


# -- the rasteriser's triangles ----------------------------------------------------------------


def test_triangle_index_colours_round_trip():
    codes = index_colors(MAX_FACES)[[0, 255, 256, 65535, 65536, MAX_FACES - 1]]
    assert np.array_equal(decode(codes[None]), [[0, 255, 256, 65535, 65536, MAX_FACES - 1]])
    assert decode(np.zeros((2, 3, 3), np.uint8)).tolist() == [[-1] * 3] * 2  # the background
    with pytest.raises(explorer.ExplorerError, match="at most 16,777,215"):
        index_colors(MAX_FACES + 1)


def test_raster_hits_are_the_ray_casts_hits():
    """The triangle the rasteriser shows at each pixel gives the ray cast's surface point and
    normal (teapot, perspective and parallel), and its pixels are the coverage render's."""
    mesh = M.teapot(6)
    size = (160, 120)
    for viewer in (Viewer(eye=(2.0, 1.5, 3.0)), Viewer(to_viewer=(1, 2, 3))):
        scene = _scene(viewer)
        cam = camera_for(scene, mesh, size[0] / size[1])
        with FaceIdRenderer(size) as r:
            seen = r.render(mesh, cam)
            again = r.render(mesh, cam)
        with OffscreenRenderer(size, (0, 0, 0)) as r:
            white = r.render(scene, mesh, np.ones((mesh.n_vertices, 3)), camera=cam)
        assert np.array_equal(seen, again) and seen.max() < mesh.n_faces
        assert np.array_equal(seen >= 0, white.max(axis=2) > 127)
        raster, cast = raster_hits(cam, size, mesh, seen), mesh_hits(cam, size, mesh)
        assert raster.method == "raster" and raster.mask.sum() > 3000
        assert (raster.mask ^ cast.mask).sum() <= 3  # pixel centres on a silhouette edge
        both = raster.mask & cast.mask
        kr, kc = np.flatnonzero(both[raster.mask]), np.flatnonzero(both[cast.mask])
        dp = np.abs(raster.positions[kr] - cast.positions[kc]).max(axis=1)
        dn = np.abs(raster.normals[kr] - cast.normals[kc]).max(axis=1)
        assert np.mean(dp < 1e-12) > 0.99 and dp.max() < 0.01  # neighbours at shared edges
        assert np.mean(dn < 1e-12) > 0.99 and dn.max() < 0.05


def test_raster_hits_check_the_picture_size():
    mesh = M.teapot(4)
    cam = camera_for(_scene(), mesh, 1.0)
    empty = raster_hits(cam, (8, 6), mesh, np.full((6, 8), -1))
    assert empty.mask.shape == (6, 8) and not empty.mask.any() and empty.positions.shape == (0, 3)
    with pytest.raises(explorer.ExplorerError, match=r"shape \(6, 8\)"):
        raster_hits(cam, (8, 6), mesh, np.full((8, 6), -1))
