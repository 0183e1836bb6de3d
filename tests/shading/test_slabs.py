"""One-shot passes in slabs: a one-shot shader (``keep=False``, what :func:`explorer.shade`
uses) prepares and shades its vertices :data:`explorer.shading.prepared.SLAB` at a time, and gives
the colours of one pass over every vertex, bit for bit, with the same compiled kernels."""

from __future__ import annotations

import numpy as np
import pytest

import explorer
from explorer.core.errors import ExplorerError
from explorer.geometry import meshes as M
from explorer.shading import kernels as K
from explorer.shading import prepared
from explorer.shading.equation import equation_shade

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaPerformanceWarning")

SCENE = {
    "material": {
        "ambient": [0.2, 0.1, 0.1],
        "diffuse": [0.6, 0.5, 0.4],
        "specular": [0.7, 0.6, 0.5],
        "shininess": 40,
    },
    "viewer": {"eye": [0.3, 1.0, 5.0]},
    "lights": [
        {"type": "point", "position": [2, 3, 1], "attenuation": [1, 0.1, 0.01]},
        {"type": "directional", "to_light": [-1, 0.3, 0.2], "specular": [1, 0.5, 0.2]},
        {"type": "spot", "position": [0, 4, 0], "aim": [0, -1, 0], "cutoff": 30, "exponent": 5},
    ],
}
#: a slab of 2 blocks: meshes of a few blocks run several slabs and a shorter last one
SMALL = 2 * K.BLOCK


def one_shot(scene, P, N, precision, slab, monkeypatch, **kw):
    """A one-shot shader's colours and stats with slabs of ``slab`` vertices."""
    monkeypatch.setattr(prepared, "SLAB", slab)
    s = explorer.Shader(scene, P, N, precision=precision, keep=False, tier="compiled", **kw)
    return np.asarray(s.colors).copy(), s


def signatures():
    return {
        name: len(getattr(getattr(K, name), "dispatcher", getattr(K, name)).signatures)
        for name in ("prepare", "bounds", "shade", "fixup")
    }


@pytest.mark.parametrize("precision", ["float32", "float64"])
@pytest.mark.parametrize("cull", [True, False])
@pytest.mark.parametrize("order", ["mesh", "shuffled"])
def test_slabs_give_the_colours_of_one_pass(precision, cull, order, monkeypatch):
    mesh = M.sphere(128)  # rings of 128 vertices: runs of 32 face away from a light together
    assert mesh.n_vertices % K.CHUNK and mesh.n_vertices > 3 * SMALL  # a tail, not whole chunks
    P, N = mesh.positions, mesh.normals
    if order == "shuffled":
        idx = np.random.default_rng(1).permutation(len(P))
        P, N = P[idx], N[idx]
    whole, w = one_shot(SCENE, P, N, precision, len(P), monkeypatch, cull=cull)
    before = signatures()
    got, s = one_shot(SCENE, P, N, precision, SMALL, monkeypatch, cull=cull)
    assert signatures() == before  # the same compiled kernels, no new specialisation
    np.testing.assert_array_equal(got, whole)
    assert s.stats["culled"] == w.stats["culled"]
    if cull and order == "mesh":
        assert s.stats["culled"] > 0  # every slab culls, as the whole mesh does
    assert s._G is None and s.stats["geometry"] == 1  # the frame alone: no full-size G


def test_float32_lanes_redone_on_a_slab_boundary(monkeypatch):
    # normals at right angles to a directional light: N·L is nearly 0 on every lane, so the
    # float32 pass marks them and redoes them in float64, those at the boundaries too
    n = 3 * SMALL + 45
    rng = np.random.default_rng(2)
    P = rng.normal(size=(n, 3))
    N = np.tile([0.0, 1.0, 0.0], (n, 1)) + rng.normal(size=(n, 3)) * [1e-9, 0, 1]
    scene = {**SCENE, "lights": [{"type": "directional", "to_light": [1, 0, 0]}]}
    whole, w = one_shot(scene, P, N, "float32", n, monkeypatch)
    got, s = one_shot(scene, P, N, "float32", SMALL, monkeypatch)
    assert s._redo[SMALL - 1] and s._redo[SMALL] and s._redo[n - 1]
    assert s.stats["fixup_vertices"] == w.stats["fixup_vertices"] > n // 2
    np.testing.assert_array_equal(got, whole)


@pytest.mark.parametrize("precision", ["float32", "float64"])
@pytest.mark.parametrize("n", [0, 1, 37, K.BLOCK + 3])
def test_a_mesh_smaller_than_a_slab(precision, n, monkeypatch):
    rng = np.random.default_rng(n)
    P, N = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    got = explorer.shade(SCENE, P, N, precision=precision, tier="compiled")
    want = equation_shade(explorer.load_scene(SCENE), P, N)
    assert got.shape == (n, 3)
    assert n == 0 or np.abs(got - want).max() <= (1e-12 if precision == "float64" else 1 / 255)


@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_normals_out_of_range_in_a_later_slab_are_scaled(precision, monkeypatch):
    n = 3 * SMALL + 7
    rng = np.random.default_rng(3)
    P, N = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    N[2 * SMALL + 5] *= 1e-20  # (still a normal: not below NORMAL_EPS once scaled)
    N[n - 1] *= 1e20
    whole, _ = one_shot(SCENE, P, N, precision, n, monkeypatch)
    got, _ = one_shot(SCENE, P, N, precision, SMALL, monkeypatch)
    np.testing.assert_array_equal(got, whole)


def test_shadowed_slabs(monkeypatch):
    mesh = M.teapot(8)
    scene = {
        **SCENE,
        "lights": [
            {"type": "point", "position": [1.5, 2.0, 1.0], "shadows": True},
            {"type": "directional", "to_light": [-0.5, 1.0, 0.2], "shadows": True},
        ],
    }
    P, N, F = mesh.positions, mesh.normals, mesh.faces
    assert len(P) > 2 * SMALL
    for precision in ("float32", "float64"):
        whole, _ = one_shot(scene, P, N, precision, len(P), monkeypatch, faces=F)
        got, s = one_shot(scene, P, N, precision, SMALL, monkeypatch, faces=F)
        assert s.stats["shadow_rays"] > 0
        np.testing.assert_array_equal(got, whole)


@pytest.mark.parametrize("which", ["positions", "normals"])
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_nan_or_inf_in_a_later_slab_raises_before_colours_are_returned(which, bad, monkeypatch):
    monkeypatch.setattr(prepared, "SLAB", SMALL)
    n = 3 * SMALL + 7
    rng = np.random.default_rng(4)
    P, N = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    (P if which == "positions" else N)[2 * SMALL + 3, 2] = bad
    for precision in ("float32", "float64"):
        with pytest.raises(ExplorerError, match=rf"{which}\[{2 * SMALL + 3}\] is not finite"):
            explorer.shade(SCENE, P, N, precision=precision, tier="compiled")


def test_a_one_shot_shader_shades_again_after_a_change(monkeypatch):
    # keep=False keeps no sums and no prepared geometry: a second pass prepares its slabs again
    mesh = M.sphere(48)
    P, N = mesh.positions, mesh.normals
    got, s = one_shot(SCENE, P, N, "float64", SMALL, monkeypatch)
    other = {**SCENE, "viewer": {"eye": [2.0, 0.0, 3.0]}}
    s.set_scene(other)
    again = np.asarray(s.colors)
    want = equation_shade(explorer.load_scene(other), P, N)
    assert np.abs(again - want).max() <= 1e-12
    assert s.stats["pass"] == 2 and s.stats["geometry"] == 1
