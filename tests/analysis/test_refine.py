"""Adaptive refinement (explorer.analysis.refine)."""

from __future__ import annotations

import math

import numpy as np

import explorer
from explorer.analysis.benchmark import bench_material, bench_scene
from explorer.analysis.comparison import compare, coverage
from explorer.analysis.refine import refine_highlights
from explorer.geometry import meshes as M
from explorer.render.camera import sphere_camera
from explorer.render.offscreen import OffscreenRenderer
from explorer.render.perpixel import is_unit_sphere, point_colors, reference


def _edge_counts(faces):
    e = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return counts


def test_refine_highlights_on_a_sphere():
    chrome = bench_material("chrome", 1000.0)
    scene = bench_scene(chrome)
    base = M.icosphere(2)
    fine = refine_highlights(scene, base, 2.0)
    assert base.n_vertices < fine.n_vertices < M.icosphere(5).n_vertices
    assert np.array_equal(fine.positions[: base.n_vertices], base.positions)
    assert is_unit_sphere(fine)  # new vertices on the sphere: still the exact reference
    assert np.all(_edge_counts(fine.faces) == 2)  # closed, no cracks or T-junctions
    cross = np.cross(
        fine.positions[fine.faces[:, 1]] - fine.positions[fine.faces[:, 0]],
        fine.positions[fine.faces[:, 2]] - fine.positions[fine.faces[:, 0]],
    )
    assert np.all(np.einsum("ij,ij->i", cross, fine.positions[fine.faces].mean(1)) > 0)
    # every edge now passes the test that split the others: the Gouraud colour at the chord's
    # midpoint against the exact colour of the sphere point the same pixel shows (seen along
    # +z), or of the edge's own midpoint on the back
    e = np.unique(np.sort(np.concatenate([fine.faces[:, [0, 1]], fine.faces[:, [1, 2]],
                                          fine.faces[:, [2, 0]]]), axis=1), axis=0)  # fmt: skip
    c = point_colors(scene, fine.positions, fine.normals)
    chord = 0.5 * (fine.positions[e[:, 0]] + fine.positions[e[:, 1]])
    q = chord / np.linalg.norm(chord, axis=1, keepdims=True)
    front = q[:, 2] > 0
    q[front, 2] = np.sqrt(1.0 - (chord[front, :2] ** 2).sum(axis=1))
    q[front, :2] = chord[front, :2]
    exact = point_colors(scene, q, q)
    gouraud = 0.5 * (c[e[:, 0]] + c[e[:, 1]])
    assert (np.abs(exact - gouraud).max(axis=1) * 255).max() <= 2.0
    # edges shorter than min_edge are never split
    length = np.linalg.norm(base.positions[base.faces[:, 0]] - base.positions[base.faces[:, 1]],
                            axis=1)  # fmt: skip
    assert refine_highlights(scene, base, 2.0, min_edge=2 * length.max()).n_vertices == (
        base.n_vertices
    )
    # the new vertices sit where the light is: near the highlight's direction H
    h = np.add(scene.lights[0].to_light, (0, 0, 1))
    h /= np.linalg.norm(h)
    new = fine.positions[base.n_vertices :]
    assert np.median(new @ h) > 0.9
    # and the picture is closer to the per-pixel one than the base mesh's

    size = (120, 120)
    cam = sphere_camera(scene)
    ref = reference(scene, base, size, camera=cam)
    with OffscreenRenderer(size) as r, OffscreenRenderer(size, (0, 0, 0)) as rc:
        errs = [
            compare(r.render(scene, m, camera=cam), ref, coverage(rc, scene, m, cam))
            for m in (base, fine)
        ]
    assert errs[1].rmse < 0.5 * errs[0].rmse and errs[1].max < errs[0].max


def test_refine_a_flat_mesh_keeps_it_flat_and_respects_the_budget():
    plane = M.plane(4)
    scene = explorer.Scene(
        material=bench_material("chrome"),
        lights=(explorer.PointLight(position=(0.2, 0.1, 0.5)),),
        viewer=explorer.Viewer(eye=(0.0, 0.0, 3.0)),
    )
    fine = refine_highlights(scene, plane, 1.0)
    assert fine.n_vertices > plane.n_vertices
    assert np.allclose(fine.positions[:, 2], 0.0) and np.allclose(fine.normals, [0, 0, 1])
    P, F = fine.positions, fine.faces
    area = np.linalg.norm(np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]]), axis=1) / 2
    assert math.isclose(area.sum(), 4.0) and area.min() > 0
    counts = _edge_counts(fine.faces)
    assert set(counts.tolist()) <= {1, 2}  # boundary edges once, inner edges twice
    small = refine_highlights(scene, plane, 0.01, max_vertices=60)
    assert plane.n_vertices <= small.n_vertices <= 60
