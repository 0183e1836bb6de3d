"""The specular lobe plot of the explorer's inset, as BRDF Explorer draws it: a polar plot in
the plane of incidence of one light, with the surface's normal up.

Directions in the plane are angles from the normal, positive toward the mirror side: the light
comes from ``-theta_i``, its mirror direction is ``+theta_i``, and a viewer at ``theta_v``
(-90° to 90°) sees the specular term of the model in use::

    phong    (R·V)^n                  = cos(theta_v - theta_i)^n
    blinn    (N·H)^n                  = cos((theta_v - theta_i) / 2)^n
    threejs  (N·L)·(n/2 + 1)/4·(N·H)^n·(s(1 - g) + g),  g = Schlick's weight of V·L

each times the specular coefficient ``ks`` (three.js's: inside its Fresnel term), and 0 when
the light is below the surface (``N·L <= 0``), as the engine shades it
(:mod:`explorer.shading.equation`, per unit light colour), with the material's effects on it:
Schlick's F of ``fresnel`` and the ``energy_conserving`` factor (:mod:`explorer.shading.effects`;
three.js has both built in). The diffuse term ``kd·(N·L)`` does not depend on
the view: a circle. Both are drawn at one scale, the larger of the two at radius 1, so their
sizes compare.

The lobe is sampled where it is: uniformly across the half circle, and densely across the lobe
itself down to :data:`PEAK_LEVEL` of its peak, so a lobe of n = 1000 (a few degrees wide) is a
smooth curve. Plain numpy: no VTK.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from explorer.core.errors import ExplorerError
from explorer.shading.effects.fresnel import schlick
from explorer.shading.equation import threejs_fresnel

#: samples spread uniformly over the half circle of view directions
SAMPLES = 121
#: samples across the lobe itself, between the angles where it falls to PEAK_LEVEL of its peak
PEAK_SAMPLES = 121
#: the lobe is sampled densely down to this fraction of its peak value
PEAK_LEVEL = 1e-3
#: samples of the diffuse circle
CIRCLE_SAMPLES = 91
#: the caption of each model's lobe
MODEL_LABELS = {
    "phong": "Phong (R·V)^n",
    "blinn": "Blinn (N·H)^n",
    "threejs": "three.js (n/2+1)/4 (N·H)^n",
}


@dataclass(frozen=True)
class LobePlot:
    """One plot, in plot units: the origin is the surface point, y the normal, radius 1 the
    larger of the specular peak and the diffuse term.

    incidence : theta_i in radians (above pi/2 the light is below the surface)
    incident, mirror : (2,) unit directions toward the light and of its mirror direction
    lobe : (k, 2) the specular lobe's points; diffuse : (m, 2) the diffuse circle's (both
        empty when the light is below the surface)
    scale : the value drawn at radius 1
    """

    incidence: float
    incident: np.ndarray
    mirror: np.ndarray
    lobe: np.ndarray
    diffuse: np.ndarray
    scale: float

    @property
    def lit(self) -> bool:
        return math.cos(self.incidence) > 0.0


def lobe_width(model: str, n: float) -> float:
    """Angle (radians) from the peak at which the lobe falls to :data:`PEAK_LEVEL` of it
    (pi for n = 0, a lobe with no fall)."""
    if n <= 0.0:
        return math.pi
    half = math.acos(min(PEAK_LEVEL ** (1.0 / n), 1.0))
    return half if model == "phong" else 2.0 * half  # N·H turns half as fast as R·V


def view_angles(model: str, n: float, theta_i: float) -> np.ndarray:
    """(k,) sorted view angles in [-pi/2, pi/2]: :data:`SAMPLES` uniform ones and
    :data:`PEAK_SAMPLES` across the lobe around the mirror direction ``theta_i``."""
    half = 0.5 * math.pi
    even = np.linspace(-half, half, SAMPLES)
    w = lobe_width(model, n)
    lo, hi = max(theta_i - w, -half), min(theta_i + w, half)
    peak = np.linspace(lo, hi, PEAK_SAMPLES) if hi > lo else np.empty(0)
    return np.unique(np.concatenate([even, peak]))


def specular_lobe(model: str, n: float, theta_i: float, theta_v, ks: float = 1.0, *,
                  fresnel: float | None = None, energy: float = 1.0) -> np.ndarray:  # fmt: skip
    """The specular term (per unit light) seen from ``theta_v`` (k,) radians with the light at
    incidence ``theta_i``: (k,) float64 (see the module's table). numpy's 0^0 = 1 makes an
    n = 0 lobe 1 everywhere, as in the engine. ``fresnel``: Schlick's F0 weighting the term
    (None: off), ``energy``: its constant factor (phong and blinn only)."""
    if model not in MODEL_LABELS:
        raise ExplorerError(f"model must be one of {tuple(MODEL_LABELS)}, got {model!r}")
    tv = np.asarray(theta_v, np.float64)
    ndl = math.cos(theta_i)
    if ndl <= 0.0:
        return np.zeros_like(tv)
    if model == "phong":
        base = np.cos(tv - theta_i)
    else:
        base = np.cos(0.5 * (tv - theta_i))
    lobe = np.maximum(base, 0.0) ** float(n)
    if model != "threejs":
        weight = 1.0 if fresnel is None else schlick(fresnel, np.cos(tv + theta_i))
        return ks * energy * weight * lobe
    g = threejs_fresnel(np.cos(tv + theta_i))  # V·L: V at theta_v, L at -theta_i
    return ndl * (0.5 * n + 1.0) / 4.0 * lobe * (ks * (1.0 - g) + g)


def lobe_plot(model: str, n: float, theta_i: float, kd: float, ks: float, *,
              fresnel: float | None = None, energy: float = 1.0) -> LobePlot:  # fmt: skip
    """The plot for a light at incidence ``theta_i`` (radians) on a material of diffuse and
    specular coefficients ``kd``, ``ks`` and shininess ``n`` under ``model`` (``fresnel``,
    ``energy``: see :func:`specular_lobe`)."""
    incident = np.array([-math.sin(theta_i), math.cos(theta_i)])
    mirror = np.array([math.sin(theta_i), math.cos(theta_i)])
    ndl = math.cos(theta_i)
    if ndl <= 0.0:
        empty = np.empty((0, 2))
        return LobePlot(theta_i, incident, mirror, empty, empty, 1.0)
    tv = view_angles(model, n, theta_i)
    spec = specular_lobe(model, n, theta_i, tv, ks, fresnel=fresnel, energy=energy)
    diffuse = max(float(kd), 0.0) * ndl
    scale = max(float(spec.max()), diffuse)
    scale = scale if scale > 0.0 and math.isfinite(scale) else 1.0
    r = spec / scale
    lobe = np.column_stack([r * np.sin(tv), r * np.cos(tv)])
    t = np.linspace(-0.5 * math.pi, 0.5 * math.pi, CIRCLE_SAMPLES)
    rd = diffuse / scale
    circle = np.column_stack([rd * np.sin(t), rd * np.cos(t)]) if rd > 0 else np.empty((0, 2))
    return LobePlot(theta_i, incident, mirror, lobe, circle, scale)


def to_box(points, box) -> np.ndarray:
    """Plot points (k, 2) in pixels of ``box`` = (x, y, width, height) (y up): the origin at
    the middle of its bottom edge, radius 1 the largest half circle that fits; every point is
    held inside the box. Returns (k, 2) float64."""
    x, y, w, h = (float(v) for v in box)
    radius = min(0.5 * w, h)
    p = np.asarray(points, np.float64).reshape(-1, 2)
    out = np.column_stack([x + 0.5 * w + radius * p[:, 0], y + radius * p[:, 1]])
    out[:, 0] = np.clip(out[:, 0], x, x + w)
    out[:, 1] = np.clip(out[:, 1], y, y + h)
    return out


def incidence(to_viewer, to_light) -> float:
    """theta_i (radians) at the surface point that faces the viewer: the angle between the
    direction toward the viewer (its normal) and the direction toward the light, each (3,)."""
    n = np.asarray(to_viewer, np.float64)
    e = np.asarray(to_light, np.float64)
    ln, le = math.hypot(*n), math.hypot(*e)  # scale-safe lengths (no square overflows)
    c = float((n / ln) @ (e / le)) if ln > 0.0 and le > 0.0 else 0.0
    return math.acos(min(max(c, -1.0), 1.0))


def contrast_ratio(a, b) -> float:
    """WCAG 2 contrast ratio of two sRGB colours (each (3,) in [0, 1]): 1 to 21."""

    def luminance(c):
        c = np.asarray(c, np.float64)
        lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
        return float(lin @ np.array([0.2126, 0.7152, 0.0722]))

    la, lb = sorted((luminance(a), luminance(b)), reverse=True)
    return (la + 0.05) / (lb + 0.05)
