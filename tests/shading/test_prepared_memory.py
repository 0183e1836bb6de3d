"""A kept shader's prepared rows G live in memory it keeps from one geometry to the next
(:class:`explorer.shading.prepared.RowMemory`): no fresh pages for each new geometry, the
colours bit for bit those of a new shader, no array handed out earlier written over, and a
geometry that fails half-way leaves the shader as it was. And light culling's sample of chunk
bounds: at most CULL_SAMPLES chunks, the same columns as the full bounds.
"""

from __future__ import annotations

import functools
import tracemalloc

import numba
import numpy as np
import pytest

import explorer
from explorer.shading import kernels as K
from explorer.shading import layout, prepared

SCENE = {
    "material": {"diffuse": [0.6, 0.5, 0.4], "specular": [0.7, 0.7, 0.7], "shininess": 30},
    "lights": [
        {"type": "point", "position": [2.0, 1.0, 3.0], "attenuation": [1.0, 0.1, 0.01]},
        {"type": "directional", "to_light": [-1.0, 0.5, 0.2]},
    ],
}


def _vertices(n: int, seed: int, dtype=np.float64):
    rng = np.random.default_rng(seed)
    N = rng.normal(size=(n, 3))
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    return (N * rng.uniform(0.5, 2.0, size=(n, 1))).astype(dtype), N.astype(dtype)


def _fresh(P, N, precision):
    return explorer.Shader(SCENE, P, N, precision=precision).colors


def test_a_new_geometry_of_the_same_size_is_prepared_without_new_memory():
    # before, each geometry's G was np.empty: 48 MB at a million float64 vertices, above glibc's
    # 32 MB threshold, so new pages from the kernel every time (page faults, 40-47 ms on two
    # threads). Now the second geometry on is prepared into the buffer the one before the last
    # used: no allocation of G's size while set_geometry runs
    n = 60_000
    geometries = [_vertices(n, seed) for seed in range(3)]
    sh = explorer.Shader(SCENE, *geometries[0], precision="float64")
    sh.set_geometry(*geometries[1])  # (its G: a second buffer, the first one's memory kept)
    size = sh._G.nbytes
    tracemalloc.start()
    try:
        sh.set_geometry(*geometries[2])
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < size / 2  # (the frame's sample and the plan: small)
    np.testing.assert_array_equal(sh.colors, _fresh(*geometries[2], "float64"))


@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_rows_prepared_in_kept_memory_give_the_colours_of_a_new_shader_bit_for_bit(precision):
    # the kept buffers hold the rows of earlier geometries (and room to spare): every column of
    # the new G is written, and nothing past it is read; the same size, then a smaller mesh
    # that fits in kept memory, then the first again
    n = 20_000
    sizes = [(n, 0), (n, 1), (n - 777, 2), (n, 0), (n * 3 // 5, 3)]
    first = _vertices(n, 0)
    sh = explorer.Shader(SCENE, *first, precision=precision)
    for m, seed in sizes[1:]:
        P, N = _vertices(m, seed)
        sh.set_geometry(P, N)
        np.testing.assert_array_equal(sh.colors, _fresh(P, N, precision))
    held = sorted(b.size for b in sh._rows.buffers)
    assert held == [n * 6, n * 6 + n * 6 // 8]  # (both reused: the first's, then with room)


def test_an_array_handed_out_earlier_is_never_written_by_a_later_geometry():
    # colours already returned are read-only and keep their values; an earlier G (or a view of
    # it) that someone still holds is not prepared into: the memory kept is reused only once
    # nothing else views it
    n = 10_000
    sh = explorer.Shader(SCENE, *_vertices(n, 0))
    colours, rows = sh.colors, sh._G
    row = sh._G[3]  # (a view of a view: it holds the buffer, not G)
    was = colours.copy(), rows.copy(), row.copy()
    for seed in (1, 2, 3, 4):
        sh.set_geometry(*_vertices(n, seed))
        _ = sh.colors
        if seed == 2:
            rows = None  # (the row view alone still holds that buffer)
    assert not colours.flags.writeable
    np.testing.assert_array_equal(colours, was[0])
    np.testing.assert_array_equal(row, was[1][3])
    assert not np.shares_memory(row, sh._G)


def test_a_geometry_that_fails_half_way_leaves_the_shader_as_it_was():
    # a NaN normal is found by the preparation itself, after some blocks were written into the
    # spare buffer: the shader keeps its geometry, its rows and its colours, and the next
    # geometry is prepared into that buffer as into any other
    n = 10_000
    P, N = _vertices(n, 0)
    sh = explorer.Shader(SCENE, P, N)
    before, G, kept = sh.colors.copy(), sh._G.copy(), sh._P
    P2, N2 = _vertices(n, 1)
    N2[n - 3] = np.nan
    with pytest.raises(ValueError, match="normals"):
        sh.set_geometry(P2, N2)
    assert sh.n == n and sh._P is kept
    np.testing.assert_array_equal(sh._G, G)
    np.testing.assert_array_equal(sh.colors, before)
    P3, N3 = _vertices(n, 2)
    sh.set_geometry(P3, N3)
    np.testing.assert_array_equal(sh.colors, _fresh(P3, N3, "float32"))


def test_kept_memory_lets_a_much_larger_buffer_go_and_keeps_two():
    memory = prepared.RowMemory()
    a = memory.rows(1000, np.float64)
    assert a.shape == (6, 1000) and a.flags.c_contiguous and a.flags.writeable
    assert a.base.size == 6000  # (the first: the size asked for)
    b = memory.rows(1000, np.float64)  # (a still held: another buffer, an eighth larger)
    assert not np.shares_memory(a, b) and b.base.size == 6750
    del a
    c = memory.rows(900, np.float64)  # fits in a's buffer (free now)
    assert c.base is memory.buffers[-1] and not np.shares_memory(b, c)  # (the latest: last)
    del b, c
    small = memory.rows(100, np.float64)  # 600 values: the 6,000 and 6,750 are too large
    assert [x.size for x in memory.buffers] == [675] and small.base is memory.buffers[0]
    assert memory.rows(0, np.float64).shape == (6, 0)
    assert memory.rows(100, np.float32).dtype == np.float32


@pytest.mark.parametrize("source", ["prepared rows", "float32 vertices"])
def test_a_large_mesh_samples_at_most_cull_samples_chunks_evenly(source, monkeypatch, request):
    # every 16th chunk of a million vertices was 1,953 chunks, their bounds 0.6 ms of CPU, more
    # than the frame's pass over the positions: now at most CULL_SAMPLES chunks, evenly spread,
    # the same columns as the full bounds of every chunk, on one numba thread (a parallel
    # region for 0.1 ms of work waits for the second thread to wake)
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("one numba thread: nothing to tell apart")
    request.addfinalizer(functools.partial(numba.set_num_threads, numba.get_num_threads()))
    numba.set_num_threads(2)
    n = 20 * K.CHUNK * prepared.CULL_SAMPLES + 5  # (20·512 chunks, more than 16·512)
    P, N = _vertices(n, 0, np.float32)
    k = K.constants(np.float32)
    centre, scale = prepared.frame_of_positions(P)
    if source == "prepared rows":
        G = np.empty((6, n), np.float32)
        K.prepare(P, N, centre, 1.0 / scale, k, G)
        src = prepared.rows(G)
    else:
        src = prepared.vertices(P, N, centre, scale, np.float32)
    full = np.empty((layout.N_BOUNDS, -(-n // K.CHUNK)))
    K.bounds(src, k, full, 1)
    whole = n // K.CHUNK
    step = prepared.sample_step(whole)
    assert step > prepared.CULL_SAMPLE
    calls = []
    bounds = K.bounds

    def spy(src, k, out, step):
        calls.append((out.shape[1], numba.get_num_threads()))
        return bounds(src, k, out, step)

    monkeypatch.setattr(K, "bounds", spy)
    threads = numba.get_num_threads()
    sample = prepared.sample_bounds(src, k)
    assert calls == [(sample.shape[1], 1)] and sample.shape[1] <= prepared.CULL_SAMPLES
    assert numba.get_num_threads() == threads  # (one thread for the sample alone)
    np.testing.assert_array_equal(sample, full[:, :whole:step])
