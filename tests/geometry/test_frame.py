"""Checks of the arrays given to the engine (explorer.geometry.frame) and to Mesh: every bad
input is a ValueError naming the argument, raised before anything else reads it."""

from __future__ import annotations

import numpy as np
import pytest

from explorer.core.errors import ExplorerError
from explorer.geometry.frame import (
    check_faces,
    check_finite,
    check_vertices,
    frame_from_extent,
    frame_of,
    scale_normals,
)
from explorer.geometry.meshes import Mesh

TRI = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
UP = np.tile([0.0, 0.0, 1.0], (3, 1))


@pytest.mark.parametrize(
    "positions",
    [
        [[0, 0, 0], [1, 2]],  # ragged
        [[0, 0, "x"]],
        [[0, 0, 1j]],
        [[0, 0, 2**70]],  # a Python int beyond int64: an object array
        [[0, 0]],
        "abc",
    ],
)
def test_bad_positions_name_the_argument(positions):
    with pytest.raises(ValueError, match="positions") as info:
        check_vertices(positions, [[0, 0, 1]])
    assert isinstance(info.value, ExplorerError)


@pytest.mark.parametrize(
    "faces, match",
    [
        ([[0, 1]], r"faces must have shape \(m, 3\)"),
        ([[0, 1, 2], [0, 1]], "faces must be"),  # ragged
        ([[0, 1, 2**70]], "faces index vertices that do not exist"),
        ([[0, 1, 2**64 - 1]], "faces index vertices that do not exist"),
        (np.array([[0, 1, 2**63 - 1]], np.uint64), "faces index vertices that do not exist"),
        ([[0, 1, -1]], "faces index vertices that do not exist: -1"),
        ([[0, 1, 3]], r"3 is not in \[0, 3\)"),
        ([[0, 1, 1.5]], "faces must hold whole numbers"),
        ([[0, 1, np.nan]], "faces must hold whole numbers"),
        ([[True, False, True]], "faces must be"),
        ("abc", "faces must be"),
    ],
)
def test_bad_faces_name_the_argument(faces, match):
    with pytest.raises(ValueError, match=match):
        check_faces(faces, 3)


def test_good_faces():
    assert check_faces([], 3).shape == (0, 3)
    f = check_faces([[0, 1, 2.0]], 3)
    assert f.dtype == np.int64 and f.tolist() == [[0, 1, 2]]


@pytest.mark.parametrize(
    "args, match",
    [
        ((np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3), int)), "at least one vertex"),
        (([[0, 0, 0], [1, 2]], UP, [[0, 1, 2]]), "positions must be"),
        ((TRI, UP, [[0, 1]]), r"faces must have shape"),
        ((TRI, UP, [[0, 1, 2**70]]), "faces index vertices that do not exist"),
        ((TRI, UP[:2], [[0, 1, 2]]), "same length"),
        ((TRI * np.nan, UP, [[0, 1, 2]]), r"positions\[0\] is not finite"),
    ],
)
def test_mesh_checks_its_arrays(args, match):
    with pytest.raises(ExplorerError, match=match):
        Mesh(*args)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_scale_normals_is_exact_and_copies_only_when_needed(dtype):
    unit = np.array([[0.0, 0.6, 0.8], [0, 0, 0], [1e5, 0, 0]], dtype)
    assert scale_normals(unit) is unit  # in range: passed on as is
    tiny = np.finfo(dtype).tiny
    N = np.array([[0, 0.6 * tiny, 0.8 * tiny], [3e-7, 0, 4e-7], [0, 0, 0], [0, 0.6, 0.8]], dtype)
    out = scale_normals(N)
    assert out.dtype == dtype and out is not N
    big = np.abs(out).max(axis=1)
    assert np.all((big[[0, 1, 3]] >= 0.5) & (big[[0, 1, 3]] < 1)) and big[2] == 0
    for i in (0, 1):  # one power of two per row: the direction is exact
        nz = N[i] != 0
        ratio = out[i][nz].astype(np.float64) / N[i][nz]
        assert np.all(ratio == ratio[0]) and np.log2(ratio[0]) % 1 == 0
    assert np.array_equal(out[3], N[3])


def test_frame_from_extent_is_frame_of():
    rng = np.random.default_rng(1)
    for P in (rng.normal(size=(50, 3)) * 1e8 + 3e8, np.array([[1.0, 2.0, 3.0]]), np.zeros((4, 3))):
        centre, scale = frame_from_extent(P.min(axis=0), P.max(axis=0))
        want = frame_of(P)
        assert np.array_equal(centre, want[0]) and scale == want[1]


def test_check_vertices_can_leave_the_normals_as_given():
    N = np.array([[0.0, 0.0, 1e-20]])  # outside NORMAL_RANGE: scaled unless told not to
    assert check_vertices(np.zeros((1, 3)), N, scale=False)[1] is N
    scaled = check_vertices(np.zeros((1, 3)), N)[1]
    assert scaled is not N and 0.5 <= scaled[0, 2] < 1


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_check_vertices_can_leave_the_finiteness_test_to_its_caller(bad):
    # (the compiled engine's own passes find NaN and inf, then call check_finite for the error)
    P = np.zeros((4, 3))
    P[2, 0] = bad
    with pytest.raises(ExplorerError, match=r"positions\[2\] is not finite"):
        check_vertices(P, np.ones((4, 3)))
    got, _ = check_vertices(P, np.ones((4, 3)), finite=False)
    assert got is P
    with pytest.raises(
        ExplorerError, match=r"normals\[2\] is not finite: \[.*\] \(vertex 2 of 4\)"
    ):
        check_finite("normals", P)
    check_finite("normals", np.ones((4, 3), np.float32))  # finite: nothing to say
    with pytest.raises(ExplorerError, match="must have shape"):  # the other checks still run
        check_vertices(np.zeros((4, 2)), np.ones((4, 3)), finite=False)
