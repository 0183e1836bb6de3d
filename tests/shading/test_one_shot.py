"""One-shot passes: a one-shot shader (``keep=False``, what :func:`explorer.shade` uses) hands
the kernel the caller's vertices (:class:`explorer.shading.kernels.Vertices`), which the pass
prepares block by block as it reaches them, and gives the colours of a kept shader's pass over
its prepared geometry G, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

import explorer
from explorer.core.errors import ExplorerError
from explorer.geometry import meshes as M
from explorer.shading import kernels as K
from explorer.shading import layout, prepared
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
#: meshes of a few blocks: several parallel tasks, a shorter last block
SMALL = 2 * K.BLOCK


def one_shot(scene, P, N, precision, keep=False, **kw):
    """A shader's colours and the shader: one-shot (``keep`` False) or kept (True)."""
    s = explorer.Shader(scene, P, N, precision=precision, keep=keep, tier="compiled", **kw)
    return np.asarray(s.colors).copy(), s


def kept(scene, P, N, precision, **kw):
    """A kept shader's colours and the shader: the pass over the prepared geometry G."""
    return one_shot(scene, P, N, precision, keep=True, **kw)


@pytest.mark.parametrize("precision", ["float32", "float64"])
@pytest.mark.parametrize("cull", [True, False])
@pytest.mark.parametrize("order", ["mesh", "shuffled"])
def test_one_shot_gives_the_colours_of_a_pass_over_prepared_geometry(precision, cull, order):
    mesh = M.sphere(128)  # rings of 128 vertices: runs of 32 face away from a light together
    assert mesh.n_vertices % K.CHUNK and mesh.n_vertices > 3 * SMALL  # a tail, not whole chunks
    P, N = mesh.positions, mesh.normals
    if order == "shuffled":
        idx = np.random.default_rng(1).permutation(len(P))
        P, N = P[idx], N[idx]
    whole, w = kept(SCENE, P, N, precision, cull=cull)
    got, s = one_shot(SCENE, P, N, precision, cull=cull)
    np.testing.assert_array_equal(got, whole)
    assert s.stats["culled"] == w.stats["culled"]  # the same chunk bounds, the same skips
    if cull and order == "mesh":
        assert s.stats["culled"] > 0
    assert s._G is None and s.stats["geometry"] == 1  # the frame alone: no prepared copy


@pytest.mark.parametrize("precision", ["float32", "float64"])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("step", [1, 3])
def test_chunk_bounds_of_vertices_are_those_of_the_prepared_geometry(precision, dtype, step):
    mesh = M.sphere(64)
    assert mesh.n_vertices % K.CHUNK  # a last, shorter chunk
    P, N = mesh.positions.astype(dtype), mesh.normals.astype(dtype)
    N[5] = 0.0  # an absent normal: its chunk is never culled
    s = explorer.Shader(SCENE, P, N, precision=precision, tier="compiled")
    _ = s.colors
    src = prepared.vertices(P, N, s._centre, s._scale, s._k.dtype)
    want = np.full((layout.N_BOUNDS, -(-len(P) // K.CHUNK)), np.nan)
    got = want.copy()
    K.bounds(prepared.rows(s._G), s._k, want, step)
    K.bounds(src, s._k, got, step)
    np.testing.assert_array_equal(got, want)
    assert np.isnan(got[:, 1]).all() == (step > 1) and not np.isnan(got[:, ::step]).any()
    assert got[layout.B_COS, 0] == -1.0


def test_float32_lanes_redone_in_a_one_shot_pass():
    # normals at right angles to a directional light: N·L is nearly 0 on every lane, so the
    # float32 pass marks them and redoes them in float64, those at block boundaries too
    n = 3 * SMALL + 45
    rng = np.random.default_rng(2)
    P = rng.normal(size=(n, 3))
    N = np.tile([0.0, 1.0, 0.0], (n, 1)) + rng.normal(size=(n, 3)) * [1e-9, 0, 1]
    scene = {**SCENE, "lights": [{"type": "directional", "to_light": [1, 0, 0]}]}
    whole, w = kept(scene, P, N, "float32")
    got, s = one_shot(scene, P, N, "float32")
    assert s._redo[K.BLOCK - 1] and s._redo[K.BLOCK] and s._redo[n - 1]
    assert s.stats["fixup_vertices"] == w.stats["fixup_vertices"] > n // 2
    np.testing.assert_array_equal(got, whole)


@pytest.mark.parametrize("precision", ["float32", "float64"])
@pytest.mark.parametrize("n", [0, 1, 37, K.BLOCK + 3])
def test_small_meshes(precision, n):
    rng = np.random.default_rng(n)
    P, N = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    got = explorer.shade(SCENE, P, N, precision=precision, tier="compiled")
    want = equation_shade(explorer.load_scene(SCENE), P, N)
    assert got.shape == (n, 3)
    assert n == 0 or np.abs(got - want).max() <= (1e-12 if precision == "float64" else 1 / 255)


@pytest.mark.parametrize("precision", ["float32", "float64"])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_normals_out_of_range_in_a_later_block_are_scaled(precision, dtype):
    n = 3 * SMALL + 7
    rng = np.random.default_rng(3)
    P, N = rng.normal(size=(n, 3)).astype(dtype), rng.normal(size=(n, 3)).astype(dtype)
    N[2 * SMALL + 5] *= dtype(1e-20)  # (still a normal: not below NORMAL_EPS once scaled)
    N[n - 1] *= dtype(1e20)
    given = N.copy()
    whole, _ = kept(SCENE, P, N, precision)
    got, s = one_shot(SCENE, P, N, precision)
    np.testing.assert_array_equal(got, whole)
    np.testing.assert_array_equal(N, given)  # scaled in a copy: the caller's stay as they were
    assert s._scaled and s._N is not N
    want = equation_shade(explorer.load_scene(SCENE), P, N)
    assert np.abs(got - want).max() <= (1e-12 if precision == "float64" else 1 / 255)


def test_shadows_in_a_one_shot_pass():
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
        whole, _ = kept(scene, P, N, precision, faces=F)
        got, s = one_shot(scene, P, N, precision, faces=F)
        assert s.stats["shadow_rays"] > 0
        np.testing.assert_array_equal(got, whole)


@pytest.mark.parametrize("which", ["positions", "normals"])
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_nan_or_inf_in_a_later_block_raises_before_colours_are_returned(which, bad):
    n = 3 * SMALL + 7
    rng = np.random.default_rng(4)
    P, N = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    (P if which == "positions" else N)[2 * SMALL + 3, 2] = bad
    for precision in ("float32", "float64"):
        with pytest.raises(ExplorerError, match=rf"{which}\[{2 * SMALL + 3}\] is not finite"):
            explorer.shade(SCENE, P, N, precision=precision, tier="compiled")


def test_a_one_shot_shader_shades_again_after_a_change():
    # keep=False keeps no sums and no prepared geometry: a second pass prepares its blocks again
    mesh = M.sphere(48)
    P, N = mesh.positions, mesh.normals
    got, s = one_shot(SCENE, P, N, "float64")
    other = {**SCENE, "viewer": {"eye": [2.0, 0.0, 3.0]}}
    s.set_scene(other)
    again = np.asarray(s.colors)
    want = equation_shade(explorer.load_scene(other), P, N)
    assert np.abs(again - want).max() <= 1e-12
    assert s.stats["pass"] == 2 and s.stats["geometry"] == 1
