"""The float64 light loops' specular lobe against the lighting equation evaluated exactly.

On the float64 path the light loops write the square of the lobe's base, raised to n/2
(``kernels.lobe_power``), and the inline point-light loop finds Blinn's base² as (N·u)²/|u|²
with u = l + |l|·V, without 1/|L + V|. Here the specular and diffuse sums of a float64
``Shader`` are compared with the equation at 40 digits (mpmath): random vertices, a light near a
vertex, a light opposite the viewer (L = -V: N·H = 0 by policy), grazing halfways (N·H near 0).
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

import explorer
from explorer.core.lights import PointLight
from explorer.core.material import Material
from explorer.core.scene import Scene, Viewer

EYE = (0.3, -0.2, 5.0)
LIGHTS = (
    PointLight(position=(2.0, 3.0, 1.0), attenuation=(1.0, 0.1, 0.01)),
    PointLight(position=(-3.0, 1.0, 2.5)),  # not attenuated
    PointLight(position=(0.5, -2.0, -3.0), attenuation=(0.2, 0.0, 0.3)),
    PointLight(position=(1.001, 0.0, 0.0), attenuation=(1.0, 1.0, 0.0)),  # near a vertex
)


def vertices(n: int = 160):
    rng = np.random.default_rng(11)
    N = rng.normal(size=(n, 3))
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    P = N * rng.uniform(0.5, 1.5, size=(n, 1))
    P[0], N[0] = (1.0, 0.0, 0.0), (1.0, 0.0, 0.0)  # 1e-3 from the fourth light
    # L = -V exactly: the eye, the vertex and the first light on one line, the light behind
    P[1] = np.array(EYE) + (np.array(LIGHTS[0].position) - EYE) * 0.5
    N[1] = np.array(LIGHTS[0].position) - P[1]
    N[1] /= np.linalg.norm(N[1])
    # a normal nearly perpendicular to H (N·H ~ 1e-7 for the first light): a grazing lobe
    L = np.array(LIGHTS[0].position) - P[2]
    V = np.array(EYE) - P[2]
    H = L / np.linalg.norm(L) + V / np.linalg.norm(V)
    t = np.cross(H, [0.0, 0.0, 1.0])
    N[2] = t / np.linalg.norm(t) + 1e-7 * H / np.linalg.norm(H)
    N[2] /= np.linalg.norm(N[2])
    return P, N


def exact_sums(P, N, shininess):
    """(specular, diffuse) sums of the grey lights above, (n,) each, and the scale of the
    specular one (Σ of the lights' attenuations: the sum's largest possible value), at 40
    digits."""
    spec, dif, scale = [], [], []
    with mpmath.workdps(40):
        eye = [mpmath.mpf(v) for v in EYE]
        nexp = mpmath.mpf(shininess)
        for p, nv in zip(P, N, strict=True):
            p = [mpmath.mpf(float(v)) for v in p]
            nn = [mpmath.mpf(float(v)) for v in nv]
            nn = [v / mpmath.norm(nn) for v in nn]
            V = [e - q for e, q in zip(eye, p, strict=True)]
            V = [v / mpmath.norm(V) for v in V]
            s = d = sc = mpmath.mpf(0)
            for light in LIGHTS:
                lv = [mpmath.mpf(q) - c for q, c in zip(light.position, p, strict=True)]
                dist = mpmath.norm(lv)
                L = [v / dist for v in lv]
                kc, kl, kq = (mpmath.mpf(v) for v in light.attenuation)
                att = 1 / (kc + kl * dist + kq * dist * dist)
                sc += att
                ndl = mpmath.fdot(nn, L)
                d += att * max(ndl, 0)
                H = [a + b for a, b in zip(L, V, strict=True)]
                if ndl > 0 and mpmath.norm(H) > 0:
                    ndh = mpmath.fdot(nn, H) / mpmath.norm(H)
                    s += att * (max(ndh, 0) ** nexp if shininess else 1)
            spec.append(float(s))
            dif.append(float(d))
            scale.append(float(sc))
    return np.array(spec), np.array(dif), np.array(scale)


def scene_with(shininess: float) -> Scene:
    return Scene(
        material=Material(specular=(1.0, 1.0, 1.0), shininess=shininess),
        viewer=Viewer(eye=EYE),
        lights=LIGHTS,
    )


def check_sums(shader, P, N, shininess):
    """The shader's float64 sums against the exact ones. A lobe base^n whose base is off by k
    ulp is off by about n·k ulp: the bound is (n + 4)·2 ulp of the sum's scale (about three
    times the largest error met here, 0.64), the diffuse sum's 4 ulp (1.9 met)."""
    terms = shader.terms
    spec, dif, scale = exact_sums(P, N, shininess)
    got_s, got_d = terms["specular"], terms["diffuse"]
    assert np.array_equal(got_s[:, 0], got_s[:, 2]) and np.array_equal(got_d[:, 0], got_d[:, 1])
    err = np.abs(got_s[:, 0] - spec)
    assert (err <= (shininess + 4.0) * 2.0 * 2.0**-53 * scale).all(), (err / scale).max()
    assert (np.abs(got_d[:, 0] - dif) <= 4.0 * 2.0**-53 * scale).all()
    assert got_s[1, 0] == pytest.approx(spec[1], abs=1e-15)  # L = -V: no lobe from that light


@pytest.mark.parametrize("shininess", [1.0, 25.6, 128.0, 1000.0])
def test_float64_lobe_is_within_a_few_ulp_per_unit_of_n(shininess):
    P, N = vertices()
    shader = explorer.Shader(scene_with(shininess), P, N, precision="float64")
    check_sums(shader, P, N, shininess)


def test_float64_shininess_drag_raises_the_stored_squares():
    # a shininess change stores each light's base row (base² in float64) and weight; the next
    # ones re-run the lobe alone from them, with the exponent halved (kernels.lobe_power)
    P, N = vertices()
    shader = explorer.Shader(scene_with(5.0), P, N, precision="float64")
    _ = shader.colors
    for shininess in (40.0, 200.0, 3.0):
        shader.set_material(shader.scene.material.replace(shininess=shininess))
        _ = shader.colors
        check_sums(shader, P, N, shininess)
    assert shader.stats["lobe"] >= 2
