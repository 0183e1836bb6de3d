"""Invariants that hold for every scene (hypothesis)."""

from __future__ import annotations

import copy

import numpy as np
from helpers.scenes import scenes, vertices
from hypothesis import given
from hypothesis import strategies as st

import explorer
from explorer.core import tolerances as tol


def rotation(seed: int) -> np.ndarray:
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def moved(scene: dict, R: np.ndarray, t: np.ndarray) -> dict:
    """The whole scene rotated by R and translated by t."""
    s = copy.deepcopy(scene)

    def point(p):
        return (R @ np.asarray(p) + t).tolist()

    def direction(d):
        return (R @ np.asarray(d)).tolist()

    for light in s["lights"]:
        if "position" in light:
            light["position"] = point(light["position"])
        for key in ("to_light", "aim"):
            if key in light:
                light[key] = direction(light[key])
    v = s["viewer"]
    s["viewer"] = (
        {"eye": point(v["eye"])} if "eye" in v else {"to_viewer": direction(v["to_viewer"])}
    )
    return s


@given(scenes(), st.integers(0, 2**32 - 1), st.integers(0, 2**32 - 1))
def test_rotating_and_translating_the_scene_changes_no_colour(scene, seed, rseed):
    P, N = vertices(seed)
    R = rotation(rseed)
    t = np.random.default_rng(rseed).normal(size=3) * 10
    before = explorer.shade(scene, P, N)
    after = explorer.shade(moved(scene, R, t), P @ R.T + t, N @ R.T)
    # decisions exactly on a threshold may flip under rounding; those are measure-zero
    assert np.abs(after - before).max(initial=0) <= tol.INVARIANCE_ABS_TOL


def scaled(scene, *, kd=1.0, ks=1.0, light=None, k=1.0):
    s = copy.deepcopy(scene)
    m = s["material"]
    m["diffuse"] = [min(c * kd, 1.0) for c in m["diffuse"]]
    m["specular"] = [min(c * ks, 1.0) for c in m["specular"]]
    if light is not None and s["lights"]:
        lt = s["lights"][light % len(s["lights"])]
        for key in ("ambient", "diffuse", "specular"):
            lt[key] = [c * k for c in lt[key]]
    return s


@given(
    scenes(),
    st.integers(0, 2**32 - 1),
    st.floats(1, 4),
    st.floats(1, 4),
    st.integers(0, 3),
    st.floats(1, 4),
    st.sampled_from(["float64", "float32"]),
)
def test_colours_never_decrease_when_kd_ks_or_a_light_grow(scene, seed, kd, ks, li, k, prec):
    P, N = vertices(seed)
    base = explorer.shade(scene, P, N, precision=prec)
    eps = 0.0 if prec == "float64" else 1e-6
    for grown in (scaled(scene, kd=kd), scaled(scene, ks=ks), scaled(scene, light=li, k=k)):
        assert np.all(explorer.shade(grown, P, N, precision=prec) >= base - eps)


@given(
    scenes(),
    st.integers(0, 2**32 - 1),
    st.sampled_from([1e-8, 1.0, 1e8]),
    st.sampled_from(["float64", "float32"]),
)
def test_every_output_is_finite_and_in_range(scene, seed, size, prec):
    P, N = vertices(seed, 128)
    c = explorer.shade(scene, P * size, N, precision=prec)
    assert c.shape == (128, 3)
    assert np.all(np.isfinite(c)) and np.all((c >= 0) & (c <= 1))
