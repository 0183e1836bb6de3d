"""Light culling: runs of vertices that provably get nothing from a light skip it.

The bounds must hold every vertex of their chunk, a culled pass must give the colours of a pass
that computes every vertex-light (exactly, in float64), and culling must actually happen where a
scene allows it and never where it does not (two-sided, a light ambient that varies per vertex).
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import explorer
from explorer.core import tolerances as tol
from explorer.geometry import meshes as M
from explorer.shading import kernels as K
from explorer.shading import layout

MATERIAL = {
    "ambient": [0.2, 0.1, 0.1],
    "diffuse": [0.6, 0.5, 0.4],
    "specular": [0.7, 0.7, 0.7],
    "shininess": 40,
}


@functools.cache
def _mesh(name):
    """A built-in mesh in its own vertex order (built once per test session)."""
    return {
        "sphere": lambda: M.sphere(256),  # (rings of 256: 32 vertices span 45°)
        "teapot": lambda: M.teapot(12),
        "torus": lambda: M.torus(256),  # (a tube of 128: 32 vertices span a quarter of it)
        "plane": lambda: M.plane(40),
    }[name]()


def pair(scene, mesh, precision):
    """The same scene shaded with culling and without."""
    P, N = mesh.positions, mesh.normals
    on = explorer.Shader(scene, P, N, precision=precision)
    off = explorer.Shader(scene, P, N, precision=precision, cull=False)
    return on, off


def same(on, off):
    """Culled colours equal the unculled ones: exactly in float64 (a skipped light adds exact
    zeros); in float32 a lane may keep its float32 value where the unculled pass redid it in
    float64 (a light it faces away from put it in an ambiguity band that does not matter)."""
    a, b = np.asarray(on.colors), np.asarray(off.colors)
    if on.precision == "float64":
        np.testing.assert_array_equal(a, b)
    else:
        n = max(1.0, on.scene.material.shininess)
        assert np.abs(a - b).max() <= tol.FLOAT32_ROUTE_ABS_TOL * n


@pytest.mark.parametrize("name", ["sphere", "teapot", "torus", "plane"])
def test_bounds_hold_every_vertex_of_their_chunk(name):
    mesh = _mesh(name)
    sh = explorer.Shader({"material": MATERIAL}, mesh.positions, mesh.normals)
    _ = sh.colors  # the compiled tier prepares its geometry at its first pass
    G = sh._G.astype(np.float64)
    b = np.empty((layout.N_BOUNDS, -(-sh.n // K.CHUNK)))
    K.bounds(sh._G, sh._k, b, 1)
    chunk = np.arange(sh.n) // K.CHUNK
    d = np.linalg.norm(G[:3].T - b[[layout.B_CX, layout.B_CY, layout.B_CZ]][:, chunk].T, axis=1)
    assert np.all(d <= b[layout.B_R, chunk])
    cone = b[layout.B_COS, chunk] > 0
    cosine = np.einsum("ij,ij->j", G[3:], b[[layout.B_AX, layout.B_AY, layout.B_AZ]][:, chunk])
    assert np.all(cosine[cone] >= b[layout.B_COS, chunk][cone])
    assert np.all(b[layout.B_COS] ** 2 + b[layout.B_SIN] ** 2 >= 1 - 1e-12)  # sine never too small
    assert cone.mean() > 0.5  # a smooth mesh in its own order: most cones are narrow
    assert np.array_equal(sh._bounds, b)  # the shader's, found while preparing the geometry


def test_bounds_can_be_sampled_every_kth_chunk():
    # chunk_bounds first finds every CULL_SAMPLE-th chunk's bounds: those columns as the full
    # pass finds them, the others left untouched
    mesh = _mesh("sphere")
    sh = explorer.Shader({"material": MATERIAL}, mesh.positions, mesh.normals)
    _ = sh.colors
    full = np.empty((layout.N_BOUNDS, -(-sh.n // K.CHUNK)))
    K.bounds(sh._G, sh._k, full, 1)
    sampled = np.full_like(full, np.nan)
    K.bounds(sh._G, sh._k, sampled, 5)
    assert np.array_equal(sampled[:, ::5], full[:, ::5])
    keep = np.ones(full.shape[1], bool)
    keep[::5] = False
    assert np.isnan(sampled[:, keep]).all()


@pytest.mark.parametrize("source", ["prepared rows", "float32 vertices", "float64 vertices"])
def test_the_sample_is_every_kth_whole_chunk_of_the_full_bounds(source):
    # prepared.sample_bounds finds chunks 0, CULL_SAMPLE, 2·CULL_SAMPLE ... on a compact copy:
    # the same columns as the full pass, for every kind of a pass's geometry
    from explorer.shading import prepared

    mesh = _mesh("sphere")
    assert mesh.n_vertices % K.CHUNK  # a last, shorter chunk: left out of the sample
    sh = explorer.Shader({"material": MATERIAL}, mesh.positions, mesh.normals)
    _ = sh.colors
    dtype = np.float64 if source == "float64 vertices" else np.float32
    P, N = mesh.positions.astype(dtype), mesh.normals.astype(dtype)
    src = (
        prepared.rows(sh._G)
        if source == "prepared rows"
        else prepared.vertices(P, N, sh._centre, sh._scale, sh._k.dtype)
    )
    full = np.empty((layout.N_BOUNDS, -(-sh.n // K.CHUNK)))
    K.bounds(src, sh._k, full, 1)
    whole = sh.n // K.CHUNK
    want = full[:, : whole : prepared.CULL_SAMPLE]
    np.testing.assert_array_equal(prepared.sample_bounds(src, sh._k), want)


def test_a_sample_that_falls_short_finds_the_sampled_chunks_alone(monkeypatch):
    # shuffled vertices: the sample of the chunks' bounds says culling cannot pay, and finding
    # it ran the bounds over the sampled chunks alone, into an array of their size: not in
    # place into a bounds array for every chunk (written sparsely, each of its pages touched,
    # each sampled chunk a cache miss: twice the time on a million vertices)
    from explorer.shading import prepared

    n = 20_000
    rng = np.random.default_rng(0)
    N = rng.normal(size=(n, 3)).astype(np.float32)
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    k = K.constants(np.float32)
    src = prepared.vertices(N, N, np.zeros(3), 1.0, np.float32)
    calls = []
    bounds = K.bounds

    def spy(src, k, out, step):
        calls.append((len(src.P32), out.shape[1], step))
        return bounds(src, k, out, step)

    monkeypatch.setattr(K, "bounds", spy)
    assert prepared.chunk_bounds(src, k).shape == (layout.N_BOUNDS, 0)
    sampled = -(-(n // K.CHUNK) // prepared.CULL_SAMPLE)
    assert calls == [(sampled * K.CHUNK, sampled, 1)]


def test_shuffled_vertices_are_not_tested_at_all():
    # no chunk of shuffled sphere vertices has a cone narrower than 90°: the shader keeps no
    # bounds, so a pass does not even run the test
    mesh = _mesh("sphere")
    order = np.random.default_rng(0).permutation(mesh.n_vertices)
    P, N = mesh.positions[order], mesh.normals[order]
    sh = explorer.Shader({"material": MATERIAL}, P, N, precision="float32")
    _ = sh.colors
    assert sh._bounds.shape == (layout.N_BOUNDS, 0)
    assert sh.stats["culled"] == 0


LIGHTS = [
    {"type": "directional", "to_light": [1, 0.3, 0.2]},
    {"type": "point", "position": [2, 3, 1], "attenuation": [1, 0.1, 0.01]},
    {"type": "point", "position": [0, 0, 1.05]},  # close: a small lit cap
    {"type": "spot", "position": [0, 4, 0], "aim": [0, -1, 0], "cutoff": 6, "exponent": 5},
]


@pytest.mark.parametrize("precision", ["float32", "float64"])
@pytest.mark.parametrize("name", ["sphere", "teapot", "torus"])
@pytest.mark.parametrize("light", range(len(LIGHTS)))
def test_culled_colours_equal_every_vertex_light_computed(precision, name, light):
    scene = {"material": MATERIAL, "viewer": {"eye": [0, 1, 5]}, "lights": [LIGHTS[light]]}
    on, off = pair(scene, _mesh(name), precision)
    same(on, off)
    assert off.stats["culled"] == 0
    # how many runs of 32 lie wholly on the far side depends on the vertex order: the sphere's
    # rings keep neighbours together (a third or more culled), the teapot's patch rows and the
    # torus's tube rings less so (measured: 10-25%)
    assert (0.3 if name == "sphere" else 0.05) * on.n < on.stats["culled"] < on.n


@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_every_update_after_a_culled_pass_is_right(precision):
    # the lobe store (shininess drag), a viewer move, a recolour and a light move after
    # culled passes give what a fresh unculled pass gives
    scene = {"material": MATERIAL, "viewer": {"eye": [0, 1, 5]}, "lights": LIGHTS}
    on, off = pair(scene, _mesh("teapot"), precision)
    for change in (
        lambda s: s.set_material(s.scene.material.replace(shininess=80)),
        lambda s: s.set_material(s.scene.material.replace(shininess=12)),  # from stored lobes
        lambda s: s.set_viewer(explorer.core.scene.Viewer(eye=(3.0, 1.0, 2.0))),
        lambda s: s.set_material(s.scene.material.replace(diffuse=(0.1, 0.8, 0.3))),
        lambda s: s.set_lights(s.scene.lights[::-1]),
    ):
        change(on)
        change(off)
        same(on, off)
    assert on.stats["lobe"] >= 1 and on.stats["culled"] > 0


def test_two_sided_scenes_are_never_culled():
    # which way a normal points depends on V there: no vertex is known to face away
    scene = {"material": MATERIAL, "two_sided": True, "lights": [LIGHTS[0]]}
    on, off = pair(scene, _mesh("sphere"), "float64")
    same(on, off)
    assert on.stats["culled"] == 0
    assert "culling" in [r[0] for r in on.plan.reasons if r[1] == "out"]


def test_a_light_ambient_that_varies_keeps_the_light_unless_outside_its_cone():
    # an attenuated light ambient does not depend on N·L: facing away is no reason to skip;
    # outside a spot's cone the spot factor zeroes the ambient too
    amb = {"ambient": [0.3, 0.3, 0.3]}
    point = {**LIGHTS[1], **amb}
    spot = {**LIGHTS[3], **amb}
    mesh = _mesh("sphere")
    for light, culls in ((point, False), (spot, True)):
        scene = {"material": MATERIAL, "lights": [light]}
        for precision in ("float32", "float64"):
            on, off = pair(scene, mesh, precision)
            same(on, off)
            assert (on.stats["culled"] > 0) == culls, light["type"]


def test_a_light_at_a_vertex_or_inside_the_mesh_is_not_culled_wrongly():
    mesh = _mesh("sphere")
    lights = [
        {"type": "point", "position": mesh.positions[700].tolist()},  # exactly at a vertex
        {"type": "point", "position": [0.0, 0.0, 0.0]},  # at the centre: behind every vertex
        {"type": "point", "position": (mesh.positions[300] * (1 + 1e-7)).tolist()},
    ]
    for light in lights:
        scene = {"material": MATERIAL, "lights": [light]}
        for precision in ("float32", "float64"):
            on, off = pair(scene, mesh, precision)
            same(on, off)
    centre = explorer.Shader(
        {"material": MATERIAL, "lights": [lights[1]]}, mesh.positions, mesh.normals
    )
    _ = centre.colors
    # every outward normal faces away from it (but the last chunk: both poles, opposite normals)
    assert centre.stats["culled"] == centre.n - 2


@settings(max_examples=25)
@given(
    kind=st.sampled_from(["directional", "point", "spot"]),
    where=st.tuples(*[st.floats(-4, 4)] * 3),
    axis=st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda v: sum(c * c for c in v) > 1e-3),
    cutoff=st.floats(1, 90),
    mesh=st.sampled_from(["sphere", "teapot", "torus", "plane"]),
)
def test_property_culling_never_changes_a_colour(kind, where, axis, cutoff, mesh):
    if kind == "directional":
        if sum(c * c for c in where) < 1e-6:
            where = (0.0, 0.0, 1.0)
        light = {"type": "directional", "to_light": list(where)}
    else:
        light = {"type": kind, "position": list(where), "attenuation": [1, 0.2, 0.05]}
        if kind == "spot":
            light.update(aim=list(axis), cutoff=cutoff, exponent=2)
    scene = {"material": MATERIAL, "viewer": {"eye": [1, 2, 5]}, "lights": [light]}
    on, off = pair(scene, _mesh(mesh), "float64")
    same(on, off)


@pytest.mark.parametrize("ntasks", [1, 2, 3, 16, 63, 64])
def test_tasks_are_dealt_across_the_mesh_each_run_once(ntasks):
    runs = [K._spread(t, ntasks) for t in range(ntasks)]
    assert sorted(runs) == list(range(ntasks))
    if ntasks == 64:  # each thread's contiguous share of tasks covers the whole mesh
        first_half = runs[:32]
        assert min(first_half) == 0 and max(first_half) == 62
