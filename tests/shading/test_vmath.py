"""The vectorising powers (explorer.shading.vmath) against exact powers."""

from __future__ import annotations

import math

import mpmath
import numba as nb
import numpy as np
import pytest
from helpers.lanes import round_trip
from hypothesis import example, given, settings
from hypothesis import strategies as st

from explorer.shading import vmath

TINY = 2.0**-1022  # the smallest normal float64


@nb.njit(fastmath=vmath._FASTMATH, error_model="numpy")
def _pow64(x, y):
    # in a loop, as the kernels use it (inlined, vectorised)
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        out[i] = vmath.pow64(x[i], y[i])
    return out


def pow64(x: float, y: float) -> float:
    return float(_pow64(np.array([x]), np.array([y]))[0])


def exact(x: float, y: float) -> tuple[mpmath.mpf, float]:
    """x**y to 120 bits, and t = y·log2 x (-inf for x = 0)."""
    with mpmath.workprec(120):
        X, Y = mpmath.mpf(x), mpmath.mpf(y)
        if x == 0.0:
            return (mpmath.mpf(1) if y == 0.0 else mpmath.mpf(0)), -math.inf
        return X**Y, float(Y * mpmath.log(X, 2))


def check_bound(x: float, y: float) -> None:
    got = pow64(x, y)
    want, t = exact(x, y)
    assert math.isfinite(got) and got >= 0.0
    if x == 0.0:  # as GL: 0^0 = 1, else 0
        assert got == float(want), (y, got)
        return
    if t < -1022.0 or want < TINY:  # below the normal range: flushed (or as tiny)
        assert got <= TINY * (1.0 + 1e-12), (x, y, got)
        return
    bound = (abs(t) + 4.0) * 2.0**-51  # the stated bound (vmath's docstring)
    err = abs(mpmath.mpf(got) - want) / want
    assert err <= bound, (x, y, float(err), bound)


@settings(max_examples=400, deadline=None)
@given(
    x=st.floats(0.0, 1.0, allow_subnormal=True),
    y=st.one_of(st.floats(0.0, 200.0), st.floats(0.0, 1e6), st.floats(0.0, 1e-3)),
)
@example(x=1.0, y=1e300)
@example(x=5e-324, y=1e-6)  # the smallest subnormal to a tiny power: 0.9993
@example(x=2.2250738585072014e-308, y=1.0)  # the smallest normal
@example(x=0.5, y=1022.0)  # the last normal power of a half
@example(x=1.0 - 2.0**-53, y=1e15)
def test_pow64_is_within_its_stated_bound(x, y):
    check_bound(x, y)


@settings(max_examples=200, deadline=None)
@given(x=st.floats(0.999, 1.0), y=st.floats(0.0, 1e4))
def test_pow64_near_one(x, y):
    # the lobe's peak: N·H close to 1, where a relative error of log2 x matters most
    check_bound(x, y)


def test_pow64_edge_values():
    assert pow64(0.0, 0.0) == 1.0  # as GL: 0^0 = 1
    assert pow64(0.0, 3.0) == 0.0 and pow64(0.0, 1e-300) == 0.0
    assert pow64(1.0, 0.0) == 1.0 and pow64(1.0, 1e300) == 1.0 and pow64(1.0, 25.6) == 1.0
    assert pow64(0.7, 0.0) == 1.0
    assert pow64(0.5, 1e300) == 0.0 and pow64(1e-300, 1e300) == 0.0  # huge exponents
    assert pow64(5e-324, 1.0) == 0.0  # a subnormal result flushes to 0
    # a little above 1 with a huge exponent: saturates, finite
    big = pow64(1.0 + 2.0**-52, 1e300)
    assert math.isfinite(big) and big > 1e307


@given(
    x=st.floats(0.0, 2.0, allow_subnormal=True),
    y=st.floats(0.0, 1e308),
)
@settings(max_examples=200, deadline=None)
def test_pow64_is_always_finite(x, y):
    got = pow64(x, y)
    assert math.isfinite(got) and got >= 0.0


@pytest.mark.parametrize("y", [1e-6, 0.5, 1.0, 12.8, 76.8, 128.0, 1000.0, 1e4])
def test_pow32_matches_float64_pow(y):
    x = np.concatenate([np.linspace(0, 1, 100001), [1e-30, 1e-38, 0.5, 1.0]]).astype(np.float32)
    got = np.array(
        [vmath.pow32(v, np.float32(y)) for v in x[::97]]
        + [vmath.pow32(v, np.float32(y)) for v in x[-4:]]
    )
    xs = np.concatenate([x[::97], x[-4:]]).astype(np.float64)
    want = xs**y
    assert np.all(np.isfinite(got))
    assert np.abs(got - want).max() <= 1e-6
    # relative accuracy where the lobe is visible (tiny results: the absolute bound above)
    normal = (xs >= 2.0**-126) & (want > 1e-4)
    rel = np.abs(got - want)[normal] / want[normal]
    assert rel.max() <= 1e-5


def test_pow32_edge_values():
    assert vmath.pow32(np.float32(0.0), np.float32(3.0)) == 0.0
    assert vmath.pow32(np.float32(1.0), np.float32(1e4)) == 1.0
    assert vmath.pow32(np.float32(1e-30), np.float32(1e-6)) == pytest.approx(1e-30**1e-6, rel=1e-6)


@settings(max_examples=100, deadline=None)
@given(
    groups=st.integers(1, 6),
    seed=st.integers(0, 2**32 - 1),
    kinds=st.sampled_from(["mixed", "none", "all", "signs"]),
)
def test_compress8_and_expand8_pack_and_put_back_the_positive_lanes(groups, seed, kinds):
    rng = np.random.default_rng(seed)
    n = 8 * groups
    src = rng.normal(size=n)
    w = {
        "mixed": rng.normal(size=n),
        "none": np.zeros(n),
        "all": rng.random(n) + 1e-300,
        # zero of either sign, NaN, subnormal and infinite weights: kept only where w > 0
        "signs": rng.choice([0.0, -0.0, np.nan, 5e-324, -5e-324, np.inf, -np.inf, 1.0], n),
    }[kinds]
    packed, back, nc, k = round_trip(src, w)  # (tests/helpers/lanes.py)
    keep = w > 0
    assert nc == k == np.count_nonzero(keep)
    assert np.array_equal(packed[:nc], src[keep])  # in order, at the front
    assert np.array_equal(back, np.where(keep, src, 0.0))  # the same lanes back, 0 elsewhere
