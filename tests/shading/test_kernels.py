"""The compiled kernels' own arithmetic."""

from __future__ import annotations

import numpy as np
import pytest

from explorer.shading import codegen, prepared
from explorer.shading import kernels as K
from explorer.shading.equation import equation_shade


def test_stream_is_the_bandwidth_yardstick():
    P = np.arange(30, dtype=np.float32).reshape(10, 3)
    out = np.empty_like(P)
    K.stream(P, P, out)
    assert np.array_equal(out, 2 * P)


def test_every_block_of_every_task_is_shaded():
    # more blocks than parallel tasks, and a last block that is not full: each vertex is shaded
    # once, whichever task it falls to (compared with the independent numpy reference)
    import explorer

    n = K.TASKS * K.BLOCK + K.BLOCK // 2 + 3
    rng = np.random.default_rng(5)
    P, N = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    scene = {
        "material": {"diffuse": [0.6, 0.5, 0.4], "specular": [0.5, 0.5, 0.5], "shininess": 20},
        "viewer": {"eye": [0, 0, 6]},
        "lights": [{"type": "point", "position": [2, 3, 1], "attenuation": [1, 0.1, 0.01]}],
    }
    ref = equation_shade(explorer.load_scene(scene), P, N)
    for precision in ("float32", "float64"):
        got = explorer.shade(scene, P, N, precision=precision)
        assert np.abs(got - ref).max() <= 1 / 255


def test_llvm_remarks_are_dropped_and_other_stderr_kept(capfd):
    # forcing a vector width makes LLVM print "remark: ... loop not vectorized" to fd 2 on a
    # first compile; those lines are dropped, anything else written there is passed on
    import os

    with codegen.quiet_llvm_remarks():
        os.write(2, b"remark: <unknown>:0:0: loop not vectorized: call instruction\n")
        os.write(2, b"a real warning\n")
    assert capfd.readouterr().err == "a real warning\n"


def test_wide_vectors_can_be_switched_off():
    # PHONG_EXPLORER_WIDE_VECTORS=0 keeps LLVM's own vector width: the entry points are the numba
    # dispatchers themselves, with no first-call wrapper
    import os
    import subprocess
    import sys

    code = (
        "from explorer.shading import codegen, kernels as K; import numba; "
        "assert not codegen.WIDE_VECTORS; "
        "assert isinstance(K.shade, numba.core.registry.CPUDispatcher); print('ok')"
    )
    env = dict(os.environ, PHONG_EXPLORER_WIDE_VECTORS="0")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.stdout.strip() == "ok", out.stderr


def test_each_new_kind_of_data_is_compiled_with_wide_vectors(monkeypatch):
    # codegen.wide compiles a call inside wide_vectors() the first time it meets a kind of data (the
    # first argument's dtype, dimensions, writability; a record's members) with a float dtype:
    # G (6, n) and a kernels.Source are separate signatures, and a Source of the prepared rows
    # or of float32 or float64 vertices is one (per precision)
    import contextlib

    widths = []

    @contextlib.contextmanager
    def wide(n=0):
        widths.append(n)
        yield

    class Kernel:  # stands for a numba dispatcher
        def py_func(self, *args):
            return None

        def __call__(self, *args):
            return None

    monkeypatch.setattr(codegen, "WIDE_VECTORS", True)
    monkeypatch.setattr(codegen, "wide_vectors", wide)
    f32, f64 = K.constants(np.float32), K.constants(np.float64)
    G32, P32, P64 = np.zeros((6, 4), np.float32), np.zeros((4, 3), np.float32), np.zeros((4, 3))
    R32 = prepared.rows(G32)
    V32, V64 = (prepared.vertices(P, P, np.zeros(3), 1.0, np.float32) for P in (P32, P64))
    V32d = prepared.vertices(P32, P32, np.zeros(3), 1.0, np.float64)
    # the lanes are the target's vector width (codegen.VECTOR_BITS): AVX-512's 512 bits, AVX2's 256
    for bits, lanes in ((512, [16, 16, 8]), (256, [8, 8, 4])):
        monkeypatch.setattr(codegen, "VECTOR_BITS", bits)
        widths.clear()
        call = codegen.wide(Kernel(), 1)
        for data, k in [(G32, f32), (G32, f32), (R32, f32), (V32, f32), (V64, f32), (V32d, f64)]:
            call(data, k)
        assert widths == lanes  # G32, then the Sources in float32, then in float64: once each
        call(np.zeros(3, np.int64), np.zeros(3, np.int64))  # no float data: no wide vectors
        assert widths == lanes
    # a kernel whose arithmetic is float64 whatever its data (item=8): float64's lanes
    call = codegen.wide(Kernel(), 1, item=8)
    call(G32, f32)
    assert widths == [8, 8, 4, 4]


def test_marked_reads_only_the_blocks_that_count_marks():
    # a block that counts no marks does not write them: what its part of the array holds is
    # stale and must not be read
    n = 2 * K.BLOCK + 7
    redo = np.ones(n, np.bool_)  # stale everywhere
    redo[K.BLOCK :] = False  # blocks 1 and 2 write their marks: three in all
    redo[[K.BLOCK + 3, K.BLOCK + 400, 2 * K.BLOCK + 6]] = True
    marks = np.array([0, 2, 1], np.int32)
    idx = K.marked(redo, marks)
    assert idx.tolist() == [K.BLOCK + 3, K.BLOCK + 400, 2 * K.BLOCK + 6]
    assert K.marked(redo, np.zeros(3, np.int32)).size == 0


@pytest.mark.parametrize("precision", [np.float32, np.float64])
def test_compose_reads_every_layout_of_the_sums(precision):
    # A absent or (n, 3); D and S each absent, (n, 3) or grey (n, 1): every combination gives
    # e + a_m·(aconst + A) + d_m·D + s_m·S, clamped, with a grey sum counted in every channel
    import itertools

    rng = np.random.default_rng(7)
    n = K.COMPOSE_BLOCK + 5  # two parallel chunks, the second short
    mat = rng.uniform(0, 0.5, 12).astype(precision)
    aconst = rng.uniform(0, 0.3, 3).astype(precision)
    k = K.constants(precision)
    layouts = {"absent": (0, 3), "rgb": (n, 3), "grey": (n, 1)}
    for a, d, s in itertools.product(("absent", "rgb"), layouts, layouts):
        A, D, S = (rng.uniform(0, 1, layouts[x]).astype(precision) for x in (a, d, s))
        out = np.empty((n, 3), precision)
        K.compose(mat, aconst, A, D, S, True, k, out)
        want = mat[0:3] + mat[3:6] * aconst
        for X, m in ((A, mat[3:6]), (D, mat[6:9]), (S, mat[9:12])):
            if X.shape[0]:
                want = want + m * X  # (n, 1) broadcasts over the channels
        want = np.clip(np.broadcast_to(want, (n, 3)), 0, 1)
        tol_ = 1e-6 if precision == np.float32 else 1e-12
        assert np.abs(out - want).max() <= tol_, (a, d, s)


def test_shade_refuses_grey_sums_for_a_pass_that_is_not_grey(monkeypatch):
    # the caller asks grey_pass before allocating grey (n, 1) sums; a pass whose options make
    # it RGB would write three values per vertex into them: the kernel refuses, not overflows
    import explorer

    P = np.random.default_rng(2).normal(size=(700, 3))
    scene = {
        "material": {"diffuse": [0.6, 0.5, 0.4], "specular": [0.5, 0.5, 0.5], "shininess": 20},
        "viewer": {"eye": [0, 0, 6]},
        "lights": [{"type": "point", "position": [2, 3, 1], "attenuation": [1, 0.1, 0.01]}],
    }
    sh = explorer.Shader(scene, P, P, precision="float32")
    seen = []
    shade = K.shade
    monkeypatch.setattr(K, "shade", lambda *a: (seen.append(a), shade(*a))[1])
    _ = sh.colors
    args = list(seen[0])
    sums = args[5]
    assert sums.D.shape == sums.S.shape == (700, 1)  # a grey pass (white light)
    args[1] = args[1]._replace(flags=args[1].flags & ~K.GREY)  # RGB lights: not a grey pass
    with pytest.raises(ValueError, match="grey pass"):
        shade(*args)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_extent_is_the_positions_smallest_and_largest_coordinates(dtype):
    # more points than parallel tasks, spread so every task holds a different extreme
    rng = np.random.default_rng(3)
    n = K.TASKS * K.BLOCK + 7
    P = (rng.normal(size=(n, 3)) * [1.0, 1e3, 1e-3] + [5.0, -2.0, 0.0]).astype(dtype)
    got = K.extent(P)
    assert np.array_equal(got, np.stack([P.min(axis=0), P.max(axis=0)]).astype(np.float64))
    assert np.array_equal(K.extent(P[:1]), np.stack([P[0], P[0]]).astype(np.float64))


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("where", [0, 1, K.BLOCK + 2, "last"])
def test_extent_is_nan_when_a_coordinate_is_not_finite(dtype, bad, where):
    # the extent's pass is the positions' finiteness test (shader.prepared_geometry)
    n = K.TASKS * K.BLOCK + 7
    P = np.random.default_rng(4).normal(size=(n, 3)).astype(dtype)
    i = n - 1 if where == "last" else where
    P[i, i % 3] = bad
    assert np.isnan(K.extent(P)).all()
    P[i, i % 3] = dtype(3e38)  # large but finite: an extent
    assert np.isfinite(K.extent(P)).all()


@pytest.mark.parametrize("n", [1, 7, 9, K.BLOCK - 5, K.BLOCK + 33, 3 * K.BLOCK + 13])
def test_float64_lobe_packing_keeps_every_lane(n):
    # the float64 lobe computes its power only for lanes with a lobe weight, packed (see
    # kernels._split_lobe): lights on one side light a few lanes of each run (packed), lights
    # all around most of them (not packed); runs of any length, tails of any size
    import explorer

    rng = np.random.default_rng(n)
    P, N = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    for positions in ([[4.0, 0.0, 0.0]], [[0, 0, 9], [9, 1, 0], [-9, 0, 1], [0, -9, 0]]):
        scene = {
            "material": {"diffuse": [0.6, 0.5, 0.4], "specular": [0.5, 0.4, 0.3], "shininess": 30},
            "viewer": {"eye": [0, 0, 6]},
            "lights": [
                {"type": "point", "position": p, "specular": [1, 0.5, 0.2]} for p in positions
            ]
            + [{"type": "point", "position": [p[0], p[1], -p[2]]} for p in positions],
        }
        want = equation_shade(explorer.load_scene(scene), P, N)
        for cull in (True, False):
            s = explorer.Shader(scene, P, N, precision="float64", cull=cull, tier="compiled")
            assert np.abs(s.colors - want).max() <= 1e-12


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("length", [0.0, 1.0, 1e-7, 1e-20, 1e-310, 1e7, 1e20])
def test_prepare_counts_the_blocks_scale_normals_would_change(dtype, length):
    # prepare tests each normal as scale_normals does: a block counts when some normal is neither
    # zero nor in NORMAL_RANGE (the caller then scales them and prepares again)
    from explorer.geometry.frame import scale_normals

    if length and not np.isfinite(dtype(length)) or (length and dtype(length) == 0):
        pytest.skip("not a finite non-zero value in this dtype")
    n = 3 * K.BLOCK + 5
    N = np.tile(np.array([0.6, 0.0, 0.8], dtype), (n, 1))
    N[K.BLOCK + 3] = N[K.BLOCK + 3] * dtype(length)  # one normal in the second block
    P = np.zeros((n, 3), dtype)
    G = np.empty((6, n), dtype)
    outside = K.prepare(P, N, np.zeros(3), 1.0, K.constants(dtype), G)
    assert outside == (0 if scale_normals(N) is N else 1)
    assert outside == (0 if length in (0.0, 1.0) else 1)


def test_one_shot_calls_share_only_memory_nobody_else_sees():
    # a later call on other vertices of the same count shades those, and colours returned
    # earlier stay as they were
    import explorer

    rng = np.random.default_rng(9)
    n = 2 * K.BLOCK + 3
    scene = {
        "material": {"diffuse": [0.6, 0.5, 0.4], "specular": [0.5, 0.5, 0.5], "shininess": 20},
        "lights": [{"type": "point", "position": [2, 3, 1]}],
    }
    meshes = [(rng.normal(size=(n, 3)), rng.normal(size=(n, 3))) for _ in range(3)]
    for precision in ("float32", "float64"):
        first = explorer.shade(scene, *meshes[0], precision=precision)
        kept = first.copy()
        for P, N in meshes[1:]:
            got = explorer.shade(scene, P, N, precision=precision)
            want = equation_shade(explorer.load_scene(scene), P, N)
            assert np.abs(got - want).max() <= (1e-9 if precision == "float64" else 1 / 255)
        assert np.array_equal(first, kept)
