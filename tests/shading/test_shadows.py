"""Shadow rays through the BVH: the brute force's shadowed vertices, and no convexity shortcut."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from helpers.interrupt import interrupt_ray_work

import explorer
from explorer.core.errors import Cancelled
from explorer.core.scene import load_scene
from explorer.geometry.frame import frame_of
from explorer.geometry.meshes import get_mesh
from explorer.geometry.rays import any_hit as brute_any_hit
from explorer.shading.equation import equation_shade
from explorer.shading.shadows import GEOMETRY_KEY, frame_bvh, visibility, visibility_rows

LIGHTS = [
    {"type": "point", "position": [1.5, 2.0, 1.0], "shadows": True},
    {"type": "directional", "to_light": [-1, 0.4, 0.2], "shadows": True},
    {"type": "spot", "position": [0.2, 2.5, 0.3], "aim": [0, -1, 0], "cutoff": 60, "shadows": True},
]


def _brute_rows(mesh, lights):
    """Visibility by testing every ray against every triangle, from the vertices the engine
    casts from (N·L > -SHADOW_NDL_MARGIN)."""
    centre, scale = frame_of(mesh.positions)
    Q = (mesh.positions - centre) / scale
    rows = np.ones((len(lights), len(Q)))
    for i, light in enumerate(lights):
        lit = np.einsum("ij,ij->i", light.toward(mesh.positions), mesh.normals) > -1e-6
        D, tmax = light.shadow_ray(Q[lit], centre, scale)
        rows[i, np.flatnonzero(lit)[brute_any_hit(Q[lit], D, tmax, Q[mesh.faces])]] = 0.0
    return rows


@pytest.mark.parametrize("name, resolution", [("teapot", 8), ("torus", 32)])
def test_shadowed_vertices_are_the_brute_force_ones(name, resolution):
    mesh = get_mesh(name, resolution)
    lights = load_scene({"lights": LIGHTS}).lights
    cache: dict = {}
    rows, index, rays = visibility_rows(
        mesh.positions, mesh.normals, mesh.faces, lights, [True] * 3,
        two_sided=False, force_all=False, cache=cache,
    )  # fmt: skip
    assert list(index) == [0, 1, 2] and rows.dtype == np.uint8
    expected = _brute_rows(mesh, lights)
    assert np.array_equal(rows, expected)
    assert ((expected == 0).sum(axis=1) > 0).all()  # every light shadows something
    assert (GEOMETRY_KEY, "explorer.geometry.bvh") in cache and rays > 0  # the compiled tier


def _many_lights(count: int, shadowed: tuple[int, ...]) -> list[dict]:
    """``count`` point lights around the mesh; those at ``shadowed`` cast shadows."""
    angles = np.linspace(0.0, 2.0 * np.pi, count, endpoint=False)
    return [{"type": "point", "position": [2.0 * np.cos(a), 1.5, 2.0 * np.sin(a)],
             "diffuse": [0.6 / count ** 0.5] * 3, "specular": [0.3] * 3,
             "shadows": i in shadowed} for i, a in enumerate(angles)]  # fmt: skip


def test_visibility_is_kept_as_bytes_for_the_shadowing_lights_only():
    # issue 31 item 4: visibility was (lights, vertices) float64 whatever cast shadows: one
    # shadowed light among 1,000 on a 523k-vertex sphere took 4.7 GiB, 5,000 raised
    mesh = get_mesh("torus", 24)
    n = len(mesh.positions)
    scene = {"lights": _many_lights(12, (3, 7)), "material": "gold"}
    for tier in ("compiled", "numpy"):
        s = explorer.Shader(scene, mesh.positions, mesh.normals, faces=mesh.faces, tier=tier)
        rows, index = s._visibility()
        assert rows.shape == (2, n) and rows.dtype == np.uint8
        assert list(index) == [-1, -1, -1, 0, -1, -1, -1, 1, -1, -1, -1, -1]
        assert set(np.unique(rows)) == {0, 1}  # both lights shadow some vertices

    def peak(count: int) -> int:
        import tracemalloc

        lights = load_scene({"lights": _many_lights(count, (1,))}).lights
        shadowed = [light.shadows for light in lights]
        cache: dict = {}
        visibility_rows(mesh.positions, mesh.normals, mesh.faces, lights, shadowed,
                        two_sided=False, force_all=False, cache=cache)  # fmt: skip
        cache = {k: v for k, v in cache.items() if k[0] == GEOMETRY_KEY}  # the tree kept
        tracemalloc.start()
        try:
            rows, _, _ = visibility_rows(mesh.positions, mesh.normals, mesh.faces, lights,
                                         shadowed, two_sided=False, force_all=False,
                                         cache=cache)  # fmt: skip
            assert rows.shape == (1, n)
            return tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()

    # 1,000 lights cost what 10 do beyond a few bytes a light (the old rows: 8 bytes a
    # vertex-light, 990 x 8 x n = 4.6 MB more here)
    assert peak(1000) - peak(10) < 64 * 1000


@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_colours_with_some_lights_shadowed_are_the_equations(precision):
    # the rows of the shadowing lights only, mapped to their lights: the equation's colours
    mesh = get_mesh("torus", 24)
    scene = {"lights": _many_lights(9, (0, 4, 5)), "material": "gold",
             "viewer": {"eye": [0.0, 2.0, 3.0]}}  # fmt: skip
    exact = equation_shade(load_scene(scene), mesh.positions, mesh.normals, faces=mesh.faces)
    atol = 1e-5 if precision == "float64" else 1 / 255
    for tier in ("compiled", "numpy"):
        c = explorer.shade(scene, mesh.positions, mesh.normals, faces=mesh.faces,
                           precision=precision, tier=tier)  # fmt: skip
        np.testing.assert_allclose(c, exact, rtol=0, atol=atol)
    plain = equation_shade(load_scene({**scene, "lights": _many_lights(9, ())}),
                           mesh.positions, mesh.normals)  # fmt: skip
    assert (exact < plain - 0.01).any()  # the shadows darken some vertices


def test_a_shader_with_shadows_shades_as_the_brute_force_says():
    mesh = get_mesh("teapot", 8)
    scene = {"lights": LIGHTS[:2], "material": "gold"}
    shaded = explorer.shade(scene, mesh.positions, mesh.normals, faces=mesh.faces)
    plain = explorer.shade(
        {**scene, "lights": [{**lt, "shadows": False} for lt in LIGHTS[:2]]},
        mesh.positions, mesh.normals,
    )  # fmt: skip
    rows = _brute_rows(mesh, load_scene(scene).lights)
    dark = (rows == 0).any(axis=0)
    assert (shaded[dark].sum(axis=1) < plain[dark].sum(axis=1)).mean() > 0.9
    # lit vertices keep their colours (to rounding: a shadowed light takes the kernel's row
    # path, an unshadowed one may take an inline loop)
    np.testing.assert_allclose(shaded[~dark], plain[~dark], rtol=0, atol=1e-12)


def test_the_fine_torus_is_shadowed():
    """At resolution 1024 a tolerance-based convexity test called the torus convex and no ray
    was cast; its far side is shadowed by the near side of the ring."""
    mesh = get_mesh("torus", 1024)
    scene = load_scene(
        {"lights": [{"type": "directional", "to_light": [1, 0.2, 0], "shadows": True}]}
    )
    plan = explorer.Shader(scene, mesh.positions[:3], mesh.normals[:3], faces=[[0, 1, 2]]).plan
    assert plan.shadows  # the plan does not skip a mesh for looking convex
    light = scene.lights[0]
    lit = np.flatnonzero(mesh.normals @ np.asarray(light.to_light) > 0)
    rng = np.random.default_rng(0)
    sample = rng.choice(lit, 2000, replace=False)
    only = np.zeros(mesh.n_vertices, bool)
    only[sample] = True
    geometry = frame_bvh(mesh.positions, mesh.faces)
    vis = visibility(mesh.positions, mesh.faces, light, only=only, geometry=geometry)
    shadowed = sample[vis[sample] == 0]
    # the light lies in the ring's plane: the far half of the ring (behind the centre as seen
    # from the light), where it faces the light across the hole, lies behind the near half
    assert len(shadowed) > 200
    assert (mesh.positions[shadowed] @ np.asarray(light.to_light) < 0).all()
    # a few of them against the brute force (every triangle: 1M of them)
    centre, scale, Q, _, _ = geometry
    few = sample[:150]
    D, tmax = light.shadow_ray(Q[few], centre, scale)
    assert np.array_equal(vis[few] == 0, brute_any_hit(Q[few], D, tmax, Q[mesh.faces]))


def test_a_shader_pass_can_be_cancelled_and_the_next_one_is_whole():
    mesh = get_mesh("teapot", 16)
    scene = load_scene({"material": "gold", "lights": LIGHTS[:2]})
    asked = []
    sh = explorer.Shader(scene, mesh.positions, mesh.normals, faces=mesh.faces,
                         cancelled=lambda: asked.append(1) or len(asked) > 3)  # fmt: skip
    with pytest.raises(Cancelled):  # asked while the BVH is built and between chunks of rays
        _ = sh.colors
    sh.cancelled = None
    fresh = explorer.Shader(scene, mesh.positions, mesh.normals, faces=mesh.faces)
    assert np.array_equal(sh.colors, fresh.colors)
    assert (fresh.colors < explorer.Shader(scene, mesh.positions, mesh.normals).colors).any()


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_ctrl_c_stops_a_render_with_shadows_in_its_rays(tmp_path):
    """SIGINT in the middle of the shadow rays (two lights, several chunks each of 0.1 s or
    more): the command stops after the chunks already running, with one line and exit status
    130, and leaves no file. Counted in chunks, not timed."""
    scene = tmp_path / "scene.yaml"
    scene.write_text("material: gold\nlights:\n" + "".join(
        f"  - {{type: point, position: {p}, shadows: true}}\n"
        for p in ([2, 3, 1.5], [-2.5, 1, 1.5])))  # fmt: skip
    argv = ["render", str(scene), "--mesh", "teapot", "--resolution", "40",
            "--out", str(tmp_path / "out.png")]  # fmt: skip
    lines, chunks, status = interrupt_ray_work("_any_hit_chunk", argv)
    assert chunks <= 4
    assert lines == ["error: interrupted (Ctrl-C); no unfinished file was left"]
    assert status == 130
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.yaml"]
