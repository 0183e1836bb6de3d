"""Lights: what arrives at a surface point and from where, and nothing else.

Three kinds, as in OpenGL's fixed-function pipeline. Every light has ``ambient``, ``diffuse``
and ``specular`` RGB colours (defaults 0, 1, 1: OpenGL's ``GL_LIGHT0``); the ``color`` +
``intensity`` shorthand in files sets diffuse = specular = intensity·color.

- :class:`DirectionalLight`: ``to_light``, the unit vector from the surface toward the light;
  never attenuated.
- :class:`PointLight`: ``position``; ``attenuation = (kc, kl, kq)`` gives
  ``1 / (kc + kl·d + kq·d²)`` at distance ``d``.
- :class:`SpotLight`: a positional light with an ``aim`` (the axis it shines along, from the
  light outward), a ``cutoff`` half-angle in degrees (0–90, or 180 for no cone) and an
  ``exponent`` (0–128).

A light type is one class that owns its behaviour; the code that combines lights (the plan, the
shader, the reference equation, shadows, the window) asks the light and never its type:

- ``KEYS``: one check per key (:mod:`explorer.core.validate`), run by :func:`parse_light` on a
  scene file (every problem at once, with file and line) and by the constructor (one
  :class:`~explorer.core.errors.ValidationError`, same messages);
- :meth:`Light.work`: what the light needs per vertex (distance, attenuation, cone) and why;
- :meth:`Light.kernel_row`: its row of the compiled kernel's parameters. The light writes the
  slots of :mod:`explorer.core.lightrow` itself: the layout is plain constants that the kernels
  read too, so a new light type adds its slots and its class, and no table in the shader has to
  follow;
- :meth:`Light.incident`: the reference's "what arrives and from where" (L, distance, weight);
- :meth:`Light.shadow_ray`: the ray from a vertex toward the light;
- :meth:`Light.placement`, :meth:`Light.placed`, :meth:`Light.as_type`: its handle in the
  window;
- ``CONTROL_KEYS``, ``AT_INFINITY``: the explorer's controls it has (a spot's cone, a
  positional light's attenuation) and whether it is at infinity: the panel's rows
  (:mod:`explorer.app.panelmodel`) ask these, so no front end knows a light type;
- ``GLYPH``, :meth:`Light.cone`: what the window's handle of the selected light shows (an
  arrow, the light's cone, nothing), which :mod:`explorer.app.view` draws.

A new light type is a class here, in :data:`LIGHT_CLASSES` (whose names are
:data:`LIGHT_TYPES`); no file of :mod:`explorer.app` changes.

The old key ``direction`` (``to_light`` or ``aim``) still loads, with a
:class:`~explorer.core.errors.DeprecatedName` notice.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from explorer.core import lightrow as R
from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError
from explorer.core.validate import (
    Check,
    Checked,
    Checker,
    check_fields,
    format_number,
    old_keywords,
)

Vec3 = tuple[float, float, float]
RGB = tuple[float, float, float]

NO_ATTENUATION: Vec3 = (1.0, 0.0, 0.0)
#: Upper bound accepted for a light colour channel (HDR lights above 1 are allowed).
MAX_LIGHT_VALUE = 1e6
SPOT_EXPONENT_RANGE = (0.0, 128.0)
#: a spot's cone half-angle (degrees); 180 (no cone) is taken too, nothing between
SPOT_CUTOFF_RANGE = (0.0, 90.0)
NO_CONE = 180.0


# -- the checks of each key ------------------------------------------------------------------
def _colour(checker: Checker, value, path):
    return checker.rgb(value, path, 0.0, MAX_LIGHT_VALUE)


def _flag(checker: Checker, value, path):
    return checker.boolean(value, path)


def _point(checker: Checker, value, path):
    return checker.triple(value, path)


def _direction(checker: Checker, value, path):
    return checker.direction(value, path)


def _attenuation(checker: Checker, value, path):
    att = checker.triple(value, path, 0.0)
    if att is not None and not any(att):
        checker.problem(
            path,
            "must not be all zero (1 / (kc + kl·d + kq·d²) would divide by zero); "
            "use [1, 0, 0] for no attenuation",
        )
        return None
    return att


def _cutoff(checker: Checker, value, path):
    lo, hi = SPOT_CUTOFF_RANGE
    c = checker.number(value, path, lo, NO_CONE)
    if c is not None and hi < c < NO_CONE:
        checker.problem(
            path, f"must be in [{lo:g}, {hi:g}] or exactly {NO_CONE:g}, got {format_number(c)}"
        )
        return None
    return c


def _exponent(checker: Checker, value, path):
    return checker.number(value, path, *SPOT_EXPONENT_RANGE)


# -- small vector helpers --------------------------------------------------------------------
def unit_vector(v: Vec3) -> Vec3:
    """``v`` (3 finite floats, not all zero) at unit length, for any scale: divided by its
    largest absolute component first (so no square overflows to inf or underflows to 0, from
    1e308 down to subnormals like 1e-320), then by the length of that (between 1 and √3)."""
    m = max(abs(c) for c in v)
    if not m > 0.0:
        raise ValueError(f"a direction must be non-zero and finite, got {list(v)}")
    w = (v[0] / m, v[1] / m, v[2] / m)
    n = math.hypot(*w)
    return (w[0] / n, w[1] / n, w[2] / n)


def unit_rows(v: np.ndarray, eps: float, fallback) -> tuple[np.ndarray, np.ndarray]:
    """Rows of ``v`` (n, 3) made unit length; rows shorter than ``eps`` replaced by
    ``fallback`` ((3,) or (n, 3)). Returns the unit rows (n, 3) and the lengths (n,)."""
    length = np.sqrt(np.einsum("ij,ij->i", v, v))
    ok = length > eps
    unit = np.where(ok[:, None], v / np.where(ok, length, 1.0)[:, None], fallback)
    return unit, length


def span(point, centre, scale: float) -> tuple[Vec3, Vec3, float]:
    """``v = (point - centre) / scale`` (3,) (components inf where they overflow), its
    direction as a unit vector (3,) and its length (inf when that overflows), with no overflow
    or underflow on the way to the direction: halves first (``point - centre`` could overflow
    near 1e308; halving is exact, so ``v`` is bit for bit ``(point - centre) / scale``), then
    divided by the largest component. Python floats."""
    h = [0.5 * p - 0.5 * float(c) for p, c in zip(point, centre, strict=True)]
    v = tuple(c / scale * 2.0 for c in h)
    m = max(abs(c) for c in h)
    if m == 0.0:
        return v, (0.0, 0.0, 0.0), 0.0
    x, y, z = (c / m for c in h)  # the largest is ±1
    n = math.sqrt(x * x + y * y + z * z)  # in [1, √3]
    return v, (x / n, y / n, z / n), m / scale * 2.0 * n


def _times(k: float, d: float) -> float:
    """k·d, with 0·inf = 0 (a zero coefficient contributes nothing at any distance)."""
    return k * d if k != 0.0 else 0.0


def in_frame(point, centre=None, scale=1.0) -> np.ndarray:
    """A world point (3,) in the normalised frame ``(point - centre) / scale``, float64 (the
    point itself when ``centre`` is None)."""
    p = np.asarray(point, dtype=np.float64)
    return p if centre is None else (p - centre) / scale


def direction_of(azimuth: float, elevation: float) -> np.ndarray:
    """(3,) unit vector of a placement: y up, azimuth in degrees from +z (the front) toward
    +x, elevation in degrees above the xz plane."""
    a, e = math.radians(azimuth), math.radians(elevation)
    return np.array([math.cos(e) * math.sin(a), math.sin(e), math.cos(e) * math.cos(a)])


def angles_of(v) -> tuple[float, float, float]:
    """``(azimuth, elevation, length)`` of a vector (degrees, degrees, its length); the zero
    vector gives (0, 0, 0)."""
    v = np.asarray(v, dtype=np.float64)
    length = math.hypot(*v)  # scale-safe: no square overflows (1e300) or underflows (1e-200)
    if length == 0.0:
        return 0.0, 0.0, 0.0
    x, y, z = v / length
    azimuth = math.degrees(math.atan2(x, z)) if abs(y) < 1.0 else 0.0
    elevation = math.degrees(math.asin(min(max(y, -1.0), 1.0)))
    return azimuth, elevation, length


@dataclass(frozen=True)
class LightWork:
    """What a light needs computed per vertex, decided from the light alone.

    positional : L = normalize(position - P) per vertex (else constant)
    attenuation : "none" | "constant" (``factor`` folded into the colours) | "per-vertex"
    spot : "none" | "cone" | "cone+exponent"
    factor : the constant attenuation 1/kc folded into the colours (1 otherwise)
    reasons : (item, "in"|"out", why) rows for people: distance, attenuation, spot
    """

    positional: bool
    attenuation: str = "none"
    spot: str = "none"
    factor: float = 1.0
    reasons: tuple = ()


@dataclass(frozen=True)
class Light(Checked):
    """What every light has: colours and whether it casts shadows (see the module docstring)."""

    ambient: RGB = (0.0, 0.0, 0.0)
    diffuse: RGB = (1.0, 1.0, 1.0)
    specular: RGB = (1.0, 1.0, 1.0)
    #: cast hard shadows on the mesh (see :mod:`explorer.shading.shadows`); keyword only
    shadows: bool = field(default=False, kw_only=True)

    type: ClassVar[str] = ""
    #: key -> its check (the scene-file keys that are fields, in the order they are checked)
    KEYS: ClassVar[dict[str, Check]] = {
        "ambient": _colour,
        "diffuse": _colour,
        "specular": _colour,
        "shadows": _flag,
    }
    #: old key -> (new key, what the new name means); both still load
    RENAMED: ClassVar[dict[str, tuple[str, str]]] = {}
    #: the keys a scene file may give this type, in the order messages list them
    FILE_KEYS: ClassVar[tuple[str, ...]] = ()
    #: fields a light made by :meth:`like` gets (a new spot's cone, say)
    LIKE_DEFAULTS: ClassVar[dict] = {}
    #: the explorer's controls this type has (its panel rows, :mod:`explorer.app.panelmodel`,
    #: in the order they are drawn): a front end asks the light, never its type
    CONTROL_KEYS: ClassVar[tuple[str, ...]] = (
        "type",
        "color",
        "intensity",
        "azimuth",
        "elevation",
        "distance",
        "shadows",
    )
    #: the light is at infinity (only its direction counts; its handle's distance is a choice)
    AT_INFINITY: ClassVar[bool] = False
    #: what the explorer draws at the selected light's handle (:mod:`explorer.app.view`):
    #: ``"arrow"`` (toward the mesh: where the light comes from), ``"cone"`` (its cone,
    #: :meth:`cone`) or ``""`` (the handle alone): the view asks the light, never its type
    GLYPH: ClassVar[str] = ""

    def cone(self) -> tuple[Vec3, float] | None:
        """The light's cone as its glyph draws it: ``(aim, half-angle in degrees)``, or None."""
        return None

    def _settle(self) -> None:
        """Store direction fields unit length (after the checks)."""

    def to_mapping(self) -> dict:
        """The scene-file form of the light (plain Python values, new key names)."""
        out: dict = {"type": self.type, **self._own_mapping()}
        for key in ("ambient", "diffuse", "specular"):
            out[key] = list(getattr(self, key))
        if self.shadows:
            out["shadows"] = True
        return out

    def as_type(self, kind: str) -> Light:
        """This light as another type (``directional``, ``point`` or ``spot``; see
        :meth:`like`), or itself when it is that type already."""
        if kind not in LIGHT_CLASSES:
            raise ExplorerError(f"light type must be directional, point or spot, got {kind!r}")
        return self if self.type == kind else LIGHT_CLASSES[kind].like(self)

    @classmethod
    def like(cls, light: Light) -> Light:
        """A light of this type with the colours and the shadows of ``light`` (and its
        attenuation between positional types; a new spot gets the cone of ``LIKE_DEFAULTS``),
        at this type's default place: move it with :meth:`placed`."""
        return cls(
            ambient=light.ambient, diffuse=light.diffuse, specular=light.specular,
            shadows=light.shadows, **cls._kept_from(light), **cls.LIKE_DEFAULTS,
        )  # fmt: skip

    @classmethod
    def _kept_from(cls, light: Light) -> dict:
        return {}

    # -- per type ------------------------------------------------------------------------------
    def _own_mapping(self) -> dict:
        raise NotImplementedError

    def work(self) -> LightWork:
        """Which per-vertex work the light needs, with the reasons (see :class:`LightWork`)."""
        raise NotImplementedError

    def _pack(self, row: list, plan, centre, scale, halfway_view) -> int:
        """Write the light's own slots of ``row``; returns its flag bits."""
        raise NotImplementedError

    def toward(self, points, centre=None, scale=1.0) -> np.ndarray:
        """(n, 3) float64 vectors from ``points`` (n, 3), in the frame ``centre``/``scale``
        (world when None), toward the light: not unit length."""
        raise NotImplementedError

    def shadow_ray(self, points, centre=None, scale=1.0) -> tuple[np.ndarray, np.ndarray]:
        """Rays from ``points`` (n, 3) toward the light: unit directions (n, 3) and the
        distance (n,) to the light (inf for a light at infinity), in the same frame."""
        raise NotImplementedError

    def incident(self, P, N, centre, scale) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """What arrives at each vertex and from where (the reference equation's terms).

        P : (n, 3) float64 positions in the normalised frame ``(world - centre) / scale``
        N : (n, 3) float64 unit normals (zero where absent): L where the light sits on the vertex
        Returns L : (n, 3) unit vectors toward the light, distance : (n,) world distances (inf
        at infinity), weight : (n,) attenuation × spot factor."""
        raise NotImplementedError

    def placement(self, centre) -> tuple[float, float, float | None]:
        """``(azimuth, elevation, distance)`` of the light around ``centre`` (degrees, degrees,
        world units); a light at infinity has no distance (None)."""
        raise NotImplementedError

    def placed(self, azimuth: float, elevation: float, distance: float, centre) -> Light:
        """The light moved to a placement around ``centre`` (see :func:`direction_of`);
        colours, attenuation and cone are kept."""
        raise NotImplementedError

    @property
    def anchor(self) -> tuple[str, Vec3]:
        """Where the light is: ``("from", to_light)`` or ``("at", position)``; the window
        shows it, and shadow rays depend on nothing else (a hashable key)."""
        raise NotImplementedError

    # -- shared --------------------------------------------------------------------------------
    def kernel_row(
        self,
        plan,
        centre,
        scale: float,
        *,
        halfway_view=None,
        specular_scale: float = 1.0,
    ) -> tuple[list[float], int]:
        """The light's row of :data:`~explorer.core.lightrow.N_PARAMS` floats and its flag
        bits for the compiled kernel, in the normalised frame ``centre`` (3,), ``scale``.

        plan : this light's row of the plan (:class:`explorer.shading.plan.LightPlan`: which
            terms, attenuation, spot, factor)
        halfway_view : the constant unit V when a constant Blinn halfway vector may be used
            (infinite viewer), else None
        specular_scale : a constant the effects fold into the specular colour (energy
            conservation); the effects' own slots and flags are theirs to add
            (:meth:`explorer.shading.effects.base.Effect.pack`)
        Built in Python floats (a light drag rebuilds rows every frame: small numpy operations
        per light cost more than the row)."""
        row = [0.0] * R.N_PARAMS
        f = self._pack(row, plan, centre, scale, halfway_view)
        fa, fs = plan.factor, plan.factor * specular_scale
        dif = [fa * v for v in self.diffuse]
        spec = [fs * v for v in self.specular]
        row[R.P_AMB : R.P_AMB + 3] = [fa * v for v in self.ambient]
        row[R.P_DIF : R.P_DIF + 3] = dif
        row[R.P_SPEC : R.P_SPEC + 3] = spec
        if plan.ambient and plan.varying_weight:
            f |= R.AMBIENT
        if plan.diffuse:
            f |= R.DIFFUSE
        if plan.specular:
            f |= R.SPECULAR
        if min(dif) == max(dif) and min(spec) == max(spec):
            f |= R.GREY  # one sum per vertex instead of three (the kernel may use it)
        return row, f


_COMMON = ("type", "ambient", "diffuse", "specular", "color", "intensity", "shadows")


@old_keywords
@dataclass(frozen=True)
class DirectionalLight(Light):
    """A light at infinity. to_light : (3,) unit vector from the surface toward the light."""

    to_light: Vec3 = (0.0, 0.0, 1.0)

    type: ClassVar[str] = "directional"
    KEYS: ClassVar[dict[str, Check]] = {**Light.KEYS, "to_light": _direction}
    RENAMED: ClassVar[dict] = {"direction": ("to_light", "the direction toward the light")}
    FILE_KEYS: ClassVar[tuple[str, ...]] = _COMMON + ("to_light",)
    AT_INFINITY: ClassVar[bool] = True
    GLYPH: ClassVar[str] = "arrow"

    def _settle(self) -> None:
        object.__setattr__(self, "to_light", unit_vector(self.to_light))

    def _own_mapping(self) -> dict:
        return {"to_light": list(self.to_light)}

    def work(self) -> LightWork:
        out = ("distance", "out", "directional: L is constant and never attenuated")
        return LightWork(positional=False, reasons=(out,))

    def _pack(self, row, plan, centre, scale, halfway_view) -> int:
        row[R.P_POS : R.P_POS + 3] = self.to_light
        if halfway_view is None:
            return 0
        dx, dy, dz = self.to_light
        vx, vy, vz = halfway_view
        hx, hy, hz = dx + vx, dy + vy, dz + vz
        hn = math.sqrt(hx * hx + hy * hy + hz * hz)
        if hn * hn > tol.HALFWAY_EPS2:  # else H undefined: N·H = 0
            row[R.P_H : R.P_H + 3] = (hx / hn, hy / hn, hz / hn)
        return R.CONST_H

    def toward(self, points, centre=None, scale=1.0) -> np.ndarray:
        return np.broadcast_to(np.asarray(self.to_light, np.float64), (len(points), 3))

    def shadow_ray(self, points, centre=None, scale=1.0):
        D = self.toward(points).copy()
        return D, np.full(len(points), np.inf)

    def incident(self, P, N, centre, scale):
        n = len(P)
        L = np.broadcast_to(np.asarray(self.to_light), (n, 3))
        return L, np.full(n, np.inf), np.ones(n)

    def placement(self, centre):
        az, el, _ = angles_of(self.to_light)
        return az, el, None

    def placed(self, azimuth, elevation, distance, centre):
        return self.replace(to_light=tuple(direction_of(azimuth, elevation)))

    @property
    def anchor(self):
        return "from", self.to_light


@dataclass(frozen=True)
class PositionalLight(Light):
    """A light at a point. attenuation : (kc, kl, kq) >= 0, not all zero."""

    position: Vec3 = (0.0, 0.0, 1.0)
    attenuation: Vec3 = NO_ATTENUATION

    KEYS: ClassVar[dict[str, Check]] = {
        **Light.KEYS,
        "position": _point,
        "attenuation": _attenuation,
    }
    CONTROL_KEYS: ClassVar[tuple[str, ...]] = Light.CONTROL_KEYS + ("attenuation",)

    def _own_mapping(self) -> dict:
        out: dict = {"position": list(self.position)}
        if self.attenuation != NO_ATTENUATION:
            out["attenuation"] = list(self.attenuation)
        return out

    @classmethod
    def _kept_from(cls, light: Light) -> dict:
        return {"attenuation": getattr(light, "attenuation", NO_ATTENUATION)}

    def work(self) -> LightWork:
        reasons = [("distance", "in", "positional: L = normalize(position - P) per vertex")]
        attenuation, factor = "none", 1.0
        kc, kl, kq = self.attenuation
        if self.attenuation == NO_ATTENUATION:
            reasons.append(("attenuation", "out", "attenuation [1, 0, 0] is 1 everywhere"))
        elif kl == 0.0 and kq == 0.0:
            attenuation, factor = "constant", 1.0 / max(kc, tol.ATTENUATION_FLOOR)
            reasons.append(
                ("attenuation", "out", f"constant 1/kc = {factor:g} folded into the colours")
            )
        else:
            attenuation = "per-vertex"
            reasons.append(("attenuation", "in", "1/(kc + kl·d + kq·d²) per vertex"))
        return LightWork(True, attenuation, "none", factor, tuple(reasons))

    def _pack(self, row, plan, centre, scale, halfway_view) -> int:
        f = R.POSITIONAL
        row[R.P_POS : R.P_POS + 3], row[R.P_ATT : R.P_ATT + 3] = self.framed(centre, scale)
        if plan.attenuation == "per-vertex":
            f |= R.ATTEN
        return f

    def framed(self, centre, scale: float) -> tuple[Vec3, Vec3]:
        """Where the engine puts the light in the normalised frame ``centre`` (3,) (None: the
        world), ``scale``, and its attenuation there: ``position`` (3,) and ``(kc, kl·s, kq·s²)``
        (so that ``1 / (kc + kl·d + kq·d²)`` takes frame distances ``d``), each coefficient at
        most ATTENUATION_CAP. The far-light policy (:data:`~explorer.core.tolerances.FAR_LIGHT`):
        a light farther than FAR_LIGHT from the frame's origin is put at FAR_LIGHT along its
        direction, with ``(A, 0, 0)``: A the attenuation's denominator at its true distance.
        Python floats (a light drag rebuilds the rows every frame)."""
        cap = tol.ATTENUATION_CAP
        kc, kl, kq = self.attenuation
        kl, kq = min(kl * scale, cap), min(kq * scale * scale, cap)
        v, u, distance = span(self.position, (0.0,) * 3 if centre is None else centre, scale)
        if distance <= tol.FAR_LIGHT:
            return v, (min(kc, cap), kl, kq)
        denominator = kc + _times(kl, distance) + _times(_times(kq, distance), distance)
        ux, uy, uz = u
        far = tol.FAR_LIGHT
        return (far * ux, far * uy, far * uz), (min(denominator, cap), 0.0, 0.0)

    def toward(self, points, centre=None, scale=1.0) -> np.ndarray:
        if centre is None:  # the world: the light where it is
            return in_frame(self.position) - points
        return np.asarray(self.framed(centre, scale)[0]) - points  # (the far-light policy)

    def shadow_ray(self, points, centre=None, scale=1.0):
        D = self.toward(points, centre, scale)
        tmax = np.linalg.norm(D, axis=1)
        return D / np.where(tmax > 0, tmax, 1.0)[:, None], tmax

    def _attenuated(self, P, N, centre, scale):
        position, (kc, kl, kq) = self.framed(centre, scale)
        L, d = unit_rows(np.asarray(position) - P, tol.POINT_EPS, N)
        at = np.where(d > tol.POINT_EPS, d, 0.0)  # at the light: distance 0 (POINT_EPS)
        att = 1.0 / np.maximum(kc + (kl + kq * at) * at, tol.ATTENUATION_FLOOR)
        return L, d * scale, att  # world distances (up to FAR_LIGHT·scale)

    def placement(self, centre):
        return angles_of(np.subtract(self.position, centre))

    def _position_at(self, azimuth, elevation, distance, centre) -> tuple[np.ndarray, tuple]:
        d = direction_of(azimuth, elevation)
        return d, tuple(np.asarray(centre, dtype=np.float64) + float(distance) * d)

    @property
    def anchor(self):
        return "at", self.position


@dataclass(frozen=True)
class PointLight(PositionalLight):
    """A light at ``position`` shining every way; attenuation : (kc, kl, kq)."""

    type: ClassVar[str] = "point"
    FILE_KEYS: ClassVar[tuple[str, ...]] = _COMMON + ("position", "attenuation")

    def incident(self, P, N, centre, scale):
        return self._attenuated(P, N, centre, scale)

    def placed(self, azimuth, elevation, distance, centre):
        _, position = self._position_at(azimuth, elevation, distance, centre)
        return self.replace(position=position)


@old_keywords
@dataclass(frozen=True)
class SpotLight(PositionalLight):
    """A positional light restricted to a cone.

    aim : (3,) unit vector of the axis the spot shines along, from the light outward
    cutoff : cone half-angle in degrees, in [0, 90], or 180 for no cone (OpenGL's rule)
    exponent : spot exponent in [0, 128]; the factor is (cos angle to the axis)**exponent
    """

    aim: Vec3 = (0.0, 0.0, -1.0)
    cutoff: float = 180.0
    exponent: float = 0.0

    type: ClassVar[str] = "spot"
    KEYS: ClassVar[dict[str, Check]] = {
        **PositionalLight.KEYS,
        "aim": _direction,
        "cutoff": _cutoff,
        "exponent": _exponent,
    }
    RENAMED: ClassVar[dict] = {"direction": ("aim", "the axis the spot shines along")}
    FILE_KEYS: ClassVar[tuple[str, ...]] = _COMMON + (
        "position",
        "attenuation",
        "aim",
        "cutoff",
        "exponent",
    )
    #: the cone of a spot made from another light (:meth:`like`)
    LIKE_DEFAULTS: ClassVar[dict] = {"cutoff": 25.0, "exponent": 10.0}
    CONTROL_KEYS: ClassVar[tuple[str, ...]] = PositionalLight.CONTROL_KEYS + ("cutoff", "exponent")
    GLYPH: ClassVar[str] = "cone"

    def _settle(self) -> None:
        object.__setattr__(self, "aim", unit_vector(self.aim))

    def cone(self) -> tuple[Vec3, float]:
        return self.aim, float(self.cutoff)

    def _own_mapping(self) -> dict:
        return {
            **super()._own_mapping(),
            "aim": list(self.aim),
            "cutoff": self.cutoff,
            "exponent": self.exponent,
        }

    def work(self) -> LightWork:
        w = super().work()
        if self.cutoff == 180.0:
            spot, row = "none", ("spot", "out", "cutoff 180: no cone")
        elif self.exponent == 0.0:
            spot = "cone"
            row = ("spot", "in", f"cone test at {self.cutoff:g}°, exponent 0 (no pow)")
        else:
            spot = "cone+exponent"
            row = ("spot", "in", f"cone test at {self.cutoff:g}° and x^{self.exponent:g}")
        return replace(w, spot=spot, reasons=w.reasons + (row,))

    def _pack(self, row, plan, centre, scale, halfway_view) -> int:
        f = super()._pack(row, plan, centre, scale, halfway_view)
        if plan.spot == "none":
            return f
        f |= R.SPOT
        row[R.P_AXIS : R.P_AXIS + 3] = self.aim
        row[R.P_COS] = math.cos(math.radians(self.cutoff))
        row[R.P_EXP] = self.exponent
        if plan.spot == "cone+exponent":
            f |= R.SPOT_EXP
        return f

    def incident(self, P, N, centre, scale):
        L, d, att = self._attenuated(P, N, centre, scale)
        if self.cutoff == 180.0:
            return L, d, att * np.ones(len(P))
        x = -np.einsum("ij,j->i", L, np.asarray(self.aim))
        inside = x >= math.cos(math.radians(self.cutoff))
        return L, d, att * np.where(inside, np.maximum(x, 0.0) ** self.exponent, 0.0)

    def placed(self, azimuth, elevation, distance, centre):
        """Placed like a point light, aiming at ``centre``."""
        d, position = self._position_at(azimuth, elevation, distance, centre)
        return self.replace(position=position, aim=tuple(-d))


#: light type name -> class
LIGHT_CLASSES: dict[str, type[Light]] = {
    cls.type: cls for cls in (DirectionalLight, PointLight, SpotLight)
}
#: the light types' names, in the order the explorer steps through them
LIGHT_TYPES = tuple(LIGHT_CLASSES)
#: every key any light type accepts in a file (old names included)
ALL_LIGHT_KEYS = tuple(
    dict.fromkeys(k for cls in LIGHT_CLASSES.values() for k in cls.FILE_KEYS + tuple(cls.RENAMED))
)


def parse_light(value, checker: Checker, path: tuple) -> Light | None:
    """Build a light from a scene-file mapping, reporting every problem to ``checker``."""
    if isinstance(value, Light):
        return value
    m = checker.mapping(value, path)
    if m is None:
        return None
    kind = m.get("type", "directional" if "position" not in m else "point")
    kind = checker.choice(kind, path + ("type",), LIGHT_TYPES)
    if kind is None:
        checker.keys(m, path, ALL_LIGHT_KEYS)
        return None
    cls = LIGHT_CLASSES[kind]
    m = checker.renamed(m, path, cls.RENAMED)
    checker.keys(m, path, cls.FILE_KEYS)
    before = len(checker.problems)
    kw = check_fields(cls.KEYS, m, checker, path)
    if "color" in m or "intensity" in m:
        shorthand = _color_intensity(m, checker, path)
        if shorthand is not None:
            kw["diffuse"] = kw["specular"] = shorthand
    if len(checker.problems) > before or any(v is None for v in kw.values()):
        return None
    try:
        return cls(**kw)
    except ValueError as exc:  # a colour·intensity product beyond MAX_LIGHT_VALUE
        for p in getattr(exc, "problems", ()):
            checker.problem(path + (p.key,) if p.key else path, p.message)
        return None


def _color_intensity(m: dict, checker: Checker, path: tuple):
    """diffuse = specular = intensity·color (both optional), or None after a problem."""
    for key in ("diffuse", "specular"):
        if key in m:
            checker.problem(
                path + (key,),
                "cannot be combined with color/intensity (they set diffuse and specular)",
            )
    color: RGB | None = (1.0, 1.0, 1.0)
    if "color" in m:
        color = checker.rgb(m["color"], path + ("color",), 0.0, MAX_LIGHT_VALUE)
    k: float | None = 1.0
    if "intensity" in m:
        k = checker.number(m["intensity"], path + ("intensity",), 0.0, MAX_LIGHT_VALUE)
    if color is None or k is None:
        return None
    return tuple(k * c for c in color)
