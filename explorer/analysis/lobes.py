"""A plot of several lobes, as Disney's BRDF Explorer draws them: each with its colour, legend
entry and visibility; polar (the plane of incidence, the normal up) or Cartesian (against the
view angle θ_v); linear or log; times N·L or not; and three quantities:

``intensity``
    what the engine adds to the colour per unit light (a white light of colour 1, no ambient):
    ``kd·(N·L) + specular`` (:mod:`explorer.analysis.lobe`'s table of the specular term, with
    the material's ``fresnel`` and ``energy_conserving``), 0 with the light below the surface;
``brdf``
    ``intensity / (π·N·L)`` in 1/sr. The π is the project's unit of light: an OpenGL light of
    colour 1 is an irradiance of π (what three.js's legacy lights assumed, see
    :mod:`explorer.shading.equation`), so that a Lambert term's BRDF is ``kd/π``;
``albedo``
    the directional albedo ``ρ(θ_i) = ∫ brdf(θ_i, ω)·cos θ_o dω`` over the hemisphere, the
    fraction of the light arriving at incidence θ_i that leaves (quadrature,
    :func:`albedo`): a Lambert term's is ``kd``; above 1 the surface reflects more than it
    receives. Plotted against θ_i.

What it shows. GL's specular term has no N·L (``f_i·(N·H)^n``, not ``(N·L)·...``), so its
BRDF grows as ``1/cos θ_i``: unnormalised, a broad lobe (small n) reflects more than it
receives at grazing light, and a narrow one (large n) reflects almost nothing anywhere (its
peak is 1 whatever its width). ``energy_conserving``'s constant ((n + 2)/(2π) for Phong) makes
the albedo the same for every n: ks/π at normal incidence (1/π of three.js's), within 1 up to
the angles the test measures (tests/analysis/test_lobes.py), and still above 1 at grazing light
for any finite n: the missing N·L is not a constant to fold in. three.js's lobe has its N·L and
keeps ρ <= 1 at every θ_i.

Directions are 3-vectors with the normal +z and the plane of incidence x-z: the light comes from
``-θ_i`` (toward ``(-sin θ_i, 0, cos θ_i)``), the viewer at ``θ_v`` sees from
``(sin θ_v, 0, cos θ_v)``. Plain numpy: no VTK.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from explorer.analysis.lobe import MODEL_LABELS, lobe_width
from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError
from explorer.shading.effects.energy import specular_scale
from explorer.shading.effects.fresnel import schlick
from explorer.shading.equation import threejs_fresnel

#: what a plot shows (see the module docstring)
QUANTITIES = ("intensity", "brdf", "albedo")
#: how it shows it
VIEWS = ("polar", "cartesian")
#: the lobes' colours in turn (Okabe and Ito's palette, told apart with any colour vision)
COLOURS = (
    (0.90, 0.62, 0.00),
    (0.34, 0.71, 0.91),
    (0.00, 0.62, 0.45),
    (0.94, 0.89, 0.26),
    (0.80, 0.47, 0.65),
    (0.84, 0.37, 0.00),
    (0.00, 0.45, 0.70),
)
#: a log plot shows this many decades below its largest value
LOG_DECADES = 4.0
#: view angles of a curve across the half circle (plus the lobe's own, :func:`view_samples`)
SAMPLES = 181
#: incidences of an albedo curve, 0 to :data:`ALBEDO_MAX_DEG`
ALBEDO_SAMPLES = 31
#: the last incidence of an albedo curve (degrees): at 90° GL's specular BRDF is infinite
ALBEDO_MAX_DEG = 88.0
#: quadrature nodes of :func:`albedo`: Gauss-Legendre in the polar angle (each of two spans
#: around the mirror direction), uniform in the azimuth
ALBEDO_NODES = (96, 96)


@dataclass(frozen=True)
class Lobe:
    """One lobe: a material's scalars under a model, lit at incidence ``theta_i`` (radians).

    label : its legend entry; colour : RGB in [0, 1]; visible : drawn or not (kept in the legend)
    model : one of :data:`explorer.analysis.lobe.MODEL_LABELS`; n : shininess; kd, ks : the
    diffuse and specular coefficients; fresnel : Schlick's F0 or None; energy : the constant
    of ``energy_conserving`` (1: off); threejs has both built in (give None and 1)
    """

    label: str
    model: str
    n: float
    kd: float
    ks: float
    theta_i: float = 0.0
    fresnel: float | None = None
    energy: float = 1.0
    colour: tuple = COLOURS[0]
    visible: bool = True

    def __post_init__(self):
        if self.model not in MODEL_LABELS:
            raise ExplorerError(f"model must be one of {tuple(MODEL_LABELS)}, got {self.model!r}")


def scene_lobe(scene, theta_i: float, label: str, colour=COLOURS[0], model=None) -> Lobe:
    """The lobe of a scene's material (its largest diffuse and specular channel) under its
    model (or ``model``), with the effects the engine applies to it."""
    model = model or scene.model
    s = scene.replace(model=model)
    _, kd, ks = s.material.scalars()
    three = model == "threejs"
    return Lobe(
        label,
        model,
        s.material.shininess,
        kd,
        ks,
        theta_i,
        None if three else s.material.fresnel,
        specular_scale(s),
        colour,
    )


def model_lobes(scene, theta_i: float) -> list[Lobe]:
    """The three models' lobes for the scene's material, each in its colour."""
    return [
        scene_lobe(scene, theta_i, MODEL_LABELS[m], COLOURS[i], model=m)
        for i, m in enumerate(MODEL_LABELS)
    ]


def to_light(theta_i: float) -> tuple[float, float, float]:
    """The unit direction toward the light at incidence ``theta_i`` (radians) from the normal
    +z, in the plane of incidence x-z, the light coming from the left."""
    return (-math.sin(theta_i), 0.0, math.cos(theta_i))


def directions(theta) -> np.ndarray:
    """(k, 3) unit directions in the plane of incidence at angles ``theta`` from the normal."""
    t = np.atleast_1d(np.asarray(theta, np.float64))
    return np.column_stack([np.sin(t), np.zeros_like(t), np.cos(t)])


def intensity(lobe: Lobe, V) -> np.ndarray:
    """What the engine adds per unit light seen from unit directions ``V`` (k, 3) (normal +z),
    the light at the lobe's incidence: (k,) float64 (0 below either horizon of the light)."""
    V = np.atleast_2d(np.asarray(V, np.float64))
    ti = lobe.theta_i
    L = np.array(to_light(ti))
    ndl = L[2]
    if ndl <= 0.0:
        return np.zeros(len(V))
    if lobe.model == "phong":
        R = 2.0 * ndl * np.array([0.0, 0.0, 1.0]) - L
        base = V @ R
    else:
        H = V + L
        h = np.sqrt(np.einsum("ij,ij->i", H, H))
        ok = h * h > tol.HALFWAY_EPS2
        base = np.where(ok, H[:, 2] / np.where(ok, h, 1.0), 0.0)
    base = np.where(base >= tol.LOBE_BASE_MIN, base, 0.0)
    lobe_v = base ** float(lobe.n)
    vdl = V @ L
    if lobe.model == "threejs":
        g = threejs_fresnel(vdl)
        spec = ndl * (0.5 * lobe.n + 1.0) / 4.0 * lobe_v * (lobe.ks * (1.0 - g) + g)
    else:
        weight = 1.0 if lobe.fresnel is None else schlick(lobe.fresnel, vdl)
        spec = lobe.ks * lobe.energy * weight * lobe_v
    return max(lobe.kd, 0.0) * ndl + spec


def brdf(lobe: Lobe, V) -> np.ndarray:
    """:func:`intensity` / (π·N·L) in 1/sr (0 with the light below the surface)."""
    ndl = math.cos(lobe.theta_i)
    if ndl <= 0.0:
        return np.zeros(len(np.atleast_2d(V)))
    return intensity(lobe, V) / (math.pi * ndl)


def albedo(lobe: Lobe, nodes: tuple = ALBEDO_NODES) -> float:
    """ρ(θ_i) of the lobe at its incidence: ``∫ brdf·cos θ_o dω`` over the hemisphere by
    quadrature, the diffuse part in rings around the normal, the specular part too when it is
    broad (:func:`~explorer.analysis.lobe.lobe_width` at least 90°), else in rings around the
    mirror direction, finely within the lobe's width of it (what falls below the horizon is 0:
    its kink there leaves a relative error near 1e-4, tests/analysis/test_lobes.py).
    nodes : (Gauss-Legendre nodes in the angle from the axis per span, azimuths)."""
    ti = lobe.theta_i
    if math.cos(ti) <= 0.0:
        return 0.0
    up = np.array([0.0, 0.0, 1.0])
    x_axis, y_axis = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    diffuse = _rings(
        replace(lobe, ks=0.0, model="phong", n=0.0, fresnel=None, energy=0.0),
        (up, x_axis, y_axis),
        [(0.0, 0.5 * math.pi)],
        nodes,
    )
    R = np.array([math.sin(ti), 0.0, math.cos(ti)])
    u = np.array([math.cos(ti), 0.0, -math.sin(ti)])
    w = lobe_width("phong" if lobe.model == "phong" else "blinn", lobe.n)
    spec = replace(lobe, kd=0.0)
    if w >= 0.5 * math.pi:  # a broad lobe: smooth over the hemisphere, exact for n = 0
        return diffuse + _rings(spec, (up, x_axis, y_axis), [(0.0, 0.5 * math.pi)], nodes)
    return diffuse + _rings(spec, (R, u, y_axis), [(0.0, w), (w, math.pi)], nodes)


def _rings(lobe: Lobe, frame, spans, nodes) -> float:
    """``∫ brdf·max(cos θ_o, 0) dω`` in rings around ``frame[0]`` (``frame``: three orthonormal
    vectors), Gauss-Legendre over each ``(lo, hi)`` of ``spans`` in the angle from it."""
    axis, u, v = frame
    na, nb = nodes
    x, wx = np.polynomial.legendre.leggauss(na)
    beta = (np.arange(nb) + 0.5) * (2.0 * math.pi / nb)
    ring = np.cos(beta)[:, None] * u + np.sin(beta)[:, None] * v  # (nb, 3)
    total = 0.0
    for lo, hi in spans:
        a = lo + (x + 1.0) * 0.5 * (hi - lo)
        wa = wx * 0.5 * (hi - lo) * np.sin(a)
        V = np.cos(a)[:, None, None] * axis + np.sin(a)[:, None, None] * ring  # (na, nb, 3)
        cos_o = np.maximum(V[..., 2], 0.0)
        f = brdf(lobe, V.reshape(-1, 3)).reshape(cos_o.shape)
        total += float(((f * cos_o).sum(axis=1) * wa).sum()) * (2.0 * math.pi / nb)
    return total


def albedo_curve(lobe: Lobe, incidences=None, nodes: tuple = ALBEDO_NODES) -> tuple:
    """``(θ_i (k,), ρ (k,))`` from 0 to :data:`ALBEDO_MAX_DEG` (or at ``incidences``)."""
    ti = (
        np.radians(np.linspace(0.0, ALBEDO_MAX_DEG, ALBEDO_SAMPLES))
        if incidences is None
        else (np.asarray(incidences, np.float64))
    )
    rho = np.array([albedo(replace(lobe, theta_i=float(t)), nodes) for t in ti])
    return ti, rho


def view_samples(lobes) -> np.ndarray:
    """(k,) sorted view angles in [-π/2, π/2]: :data:`SAMPLES` uniform ones and 121 across each
    lobe around its mirror direction, so a narrow lobe is a smooth curve."""
    half = 0.5 * math.pi
    parts = [np.linspace(-half, half, SAMPLES)]
    for lb in lobes:
        w = lobe_width("phong" if lb.model == "phong" else "blinn", lb.n)
        lo, hi = max(lb.theta_i - w, -half), min(lb.theta_i + w, half)
        if hi > lo:
            parts.append(np.linspace(lo, hi, 121))
    return np.unique(np.concatenate(parts))


@dataclass(frozen=True)
class Curve:
    """One lobe's curve: ``x`` (k,) its abscissa (θ_v, or θ_i for the albedo; radians),
    ``values`` (k,) the quantity, ``points`` (k, 2) in plot units (see :class:`Chart`)."""

    lobe: Lobe
    x: np.ndarray
    values: np.ndarray
    points: np.ndarray


@dataclass(frozen=True)
class Chart:
    """A plot in plot units: x in [-1, 1], y in [0, 1] (polar: the origin at (0, 0), the normal
    up, radius 1 the top of the scale; Cartesian: x the angle from -90° to 90° (the albedo's θ_i
    from 0 to 90°: x in [0, 1]), y up).

    curves : the visible lobes' :class:`Curve`; legend : ``(label, colour, visible)`` of every
    lobe; top : the value at radius / height 1 (log: 10**top decades, see ``floor``); floor :
    the value at 0 on a log scale (None: linear); title : what is plotted, in words
    """

    view: str
    quantity: str
    log: bool
    times_ndl: bool
    curves: tuple
    legend: tuple
    top: float
    floor: float | None
    title: str = field(default="")


def chart(
    lobes,
    *,
    view: str = "polar",
    quantity: str = "intensity",
    log: bool = False,
    times_ndl: bool = False,
    nodes: tuple = ALBEDO_NODES,
) -> Chart:
    """The plot of ``lobes`` (see the module docstring; ``times_ndl`` multiplies each value by
    its lobe's N·L). Every curve at one scale: the largest value at 1."""
    if view not in VIEWS:
        raise ExplorerError(f"view must be one of {VIEWS}, got {view!r}")
    if quantity not in QUANTITIES:
        raise ExplorerError(f"quantity must be one of {QUANTITIES}, got {quantity!r}")
    lobes = list(lobes)
    shown = [lb for lb in lobes if lb.visible]
    raw = []
    tv = view_samples(shown)
    for lb in shown:
        if quantity == "albedo":
            x, values = albedo_curve(lb, nodes=nodes)
            ndl = np.cos(x)
        else:
            x = tv
            f = brdf if quantity == "brdf" else intensity
            values = f(lb, directions(tv))
            ndl = np.full(len(x), math.cos(lb.theta_i))
        raw.append((lb, x, values * ndl if times_ndl else values))
    finite = [float(v[np.isfinite(v)].max()) for _, _, v in raw if np.isfinite(v).any()]
    top = max([t for t in finite if t > 0.0], default=1.0)
    floor = top * 10.0**-LOG_DECADES if log else None
    curves = []
    for lb, x, values in raw:
        if log:
            r = np.clip(np.log10(np.maximum(values, floor) / floor) / LOG_DECADES, 0.0, 1.0)
        else:
            r = np.clip(values / top, 0.0, 1.0)
        if view == "polar":  # (the albedo on the light's side: its θ_i is where light comes from)
            angle = -x if quantity == "albedo" else x
            pts = np.column_stack([r * np.sin(angle), r * np.cos(angle)])
        else:  # (the albedo's θ_i from 0 to 90°: x from 0 to 1)
            pts = np.column_stack([x / (0.5 * math.pi), r])
        curves.append(Curve(lb, x, values, pts))
    legend = tuple((lb.label, lb.colour, lb.visible) for lb in lobes)
    what = {
        "intensity": "intensity per unit light",
        "brdf": "BRDF (1/sr)",
        "albedo": "directional albedo ρ(θ_i)",
    }[quantity]
    title = what + (" × N·L" if times_ndl else "") + (", log" if log else "")
    return Chart(view, quantity, log, times_ndl, tuple(curves), legend, top, floor, title)
