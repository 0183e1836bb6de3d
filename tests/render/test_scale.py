"""Meshes at extreme scales (issue 31 item 6): a correct picture or a clear refusal, never an
empty one. The camera, the renderers, the exports and the welding of a file's vertices follow
the engine's frame-relative policy (docs/limits.md)."""

from __future__ import annotations

import json
import struct
import warnings

import numpy as np
import pytest

import explorer
from explorer.core.errors import ExplorerError
from explorer.geometry.meshes import Mesh, load_mesh, sphere
from explorer.render.camera import camera_for
from explorer.render.exports import mesh_file_bytes
from explorer.render.offscreen import BACKGROUND, render_image

SIZE = (48, 48)
SCALES = (1e-20, 1e-13, 1e38, 1e39, 1e154, 1e300)


def _scaled(r: float) -> Mesh:
    m = sphere(12)
    return Mesh(m.positions * r, m.normals, m.faces, name=f"sphere x {r:g}")


def _mesh_pixels(picture) -> int:
    bg = np.round(np.asarray(BACKGROUND) * 255).astype(int)
    return int((np.abs(picture.astype(int) - bg).sum(axis=2) > 3).sum())


@pytest.mark.parametrize("viewer", [{}, {"eye": [0.3, 0.4, 3.0]}])
def test_a_mesh_renders_alike_at_every_scale(viewer):
    # a sphere of radius 1e154 and more rendered an empty picture with rc 0 (1e155: numpy
    # RuntimeWarnings from the camera); the eye moves with the mesh so the view is the same
    unit = _scaled(1.0)
    reference = None
    for r in (1.0, *SCALES):
        mesh = _scaled(r)
        v = {"eye": [c * r for c in viewer["eye"]]} if viewer else {}
        scene = explorer.load_scene({"viewer": v} if v else {})
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            colors = explorer.shade(scene, unit.positions, unit.normals)  # (the same colours)
            picture = render_image(scene, mesh, SIZE, colors=colors)
        if reference is None:
            reference = picture
            assert _mesh_pixels(picture) > 0.3 * SIZE[0] * SIZE[1]
        else:  # the same picture, to a pixel's rounding at the silhouette
            different = (np.abs(picture.astype(int) - reference.astype(int)).max(axis=2) > 8).sum()
            assert different <= 0.02 * SIZE[0] * SIZE[1], (r, different)


def test_a_turntable_frames_a_mesh_at_every_scale():
    from explorer.render.turntable import iter_frames

    unit = _scaled(1.0)
    scene = explorer.load_scene({})
    colors = explorer.shade(scene, unit.positions, unit.normals)
    counts = {}
    for r in (1.0, 1e-20, 1e155):
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            frames = list(iter_frames(scene, _scaled(r), 2, lambda s: colors, SIZE))
        counts[r] = [_mesh_pixels(f) for f in frames]
    assert counts[1.0][0] > 0.3 * SIZE[0] * SIZE[1]
    for r in (1e-20, 1e155):
        pairs = zip(counts[r], counts[1.0], strict=True)
        assert all(abs(a - b) <= 0.02 * SIZE[0] * SIZE[1] for a, b in pairs), counts


def test_the_per_pixel_reference_sees_a_mesh_at_every_scale():
    # the per-pixel reference cast its rays in world units: empty pictures at 1e-20 and 1e155
    from explorer.render.perpixel import mesh_hits

    scene = explorer.load_scene({})
    masks = {}
    for r in (1.0, 1e-20, 1e155, 1e300):
        mesh = _scaled(r)
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            hits = mesh_hits(camera_for(scene, mesh), SIZE, mesh)
        masks[r] = hits.mask
        assert np.isfinite(hits.positions).all() and np.isfinite(hits.normals).all()
    assert masks[1.0].sum() > 0.3 * SIZE[0] * SIZE[1]
    for r in (1e-20, 1e155, 1e300):
        assert (masks[r] != masks[1.0]).sum() <= 0.02 * SIZE[0] * SIZE[1], r


def test_a_mesh_too_large_for_its_camera_is_refused():
    mesh = _scaled(1.5e308)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(ExplorerError, match="too large to frame"):
            camera_for(explorer.load_scene({}), mesh)


@pytest.mark.parametrize("r", [1e-20, 1e-13, 1e-200])
def test_a_tiny_mesh_file_welds_as_a_unit_one(tmp_path, r):
    # radius <= 1e-13 was refused as "only degenerate triangles": the weld's tolerance was
    # absolute (12 decimals)
    m = sphere(10)
    path = tmp_path / "s.obj"
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in (m.positions * r).tolist()]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in m.faces.tolist()]
    path.write_text("\n".join(lines) + "\n")
    tiny = load_mesh(path)
    unit_path = tmp_path / "u.obj"
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in m.positions.tolist()]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in m.faces.tolist()]
    unit_path.write_text("\n".join(lines) + "\n")
    unit = load_mesh(unit_path)
    assert tiny.n_vertices == unit.n_vertices and tiny.n_faces == unit.n_faces
    np.testing.assert_allclose(tiny.normals, unit.normals, atol=1e-9)


def _glb_json(data: bytes) -> dict:
    length = struct.unpack_from("<I", data, 12)[0]
    return json.loads(data[20 : 20 + length])


@pytest.mark.parametrize("r", [1e-20, 1e-13, 1e38])
def test_exports_within_float32_are_finite(r):
    mesh = _scaled(r)
    colors = np.full((mesh.n_vertices, 3), 0.5)
    doc = _glb_json(mesh_file_bytes(mesh, colors, ".glb"))
    bounds = [v for a in doc["accessors"] for k in ("min", "max") for v in a.get(k, [])]
    assert bounds and all(np.isfinite(bounds))
    import io

    import trimesh

    ply = trimesh.load(
        io.BytesIO(mesh_file_bytes(mesh, colors, ".ply")), file_type="ply", process=False
    )
    assert np.isfinite(ply.vertices).all() and len(ply.faces) == mesh.n_faces


@pytest.mark.parametrize("r, why", [(1e39, "at most 3.4e\\+38"), (1e154, "at most"),
                                    (1e-40, "too small")])  # fmt: skip
def test_exports_beyond_float32_are_refused(r, why):
    # radius 1e39 wrote a .glb with -Infinity in its JSON and a .ply with inf vertices
    mesh = _scaled(r)
    colors = np.full((mesh.n_vertices, 3), 0.5)
    for suffix in (".glb", ".ply"):
        with pytest.raises(ExplorerError, match=why):
            mesh_file_bytes(mesh, colors, suffix)
