"""Lights: what arrives at a surface point and from where, and nothing else.

Three kinds, as in OpenGL's fixed-function pipeline. Every light has ``ambient``, ``diffuse``
and ``specular`` RGB colours (defaults 0, 1, 1: OpenGL's ``GL_LIGHT0``); the ``color`` +
``intensity`` shorthand in files sets diffuse = specular = intensity·color.

- :class:`DirectionalLight`: ``direction`` points *toward* the light; never attenuated.
- :class:`PointLight`: ``position``; ``attenuation = (kc, kl, kq)`` gives
  ``1 / (kc + kl·d + kq·d²)`` at distance ``d``.
- :class:`SpotLight`: a point light with an ``axis`` it points along (``direction``), a
  ``cutoff`` half-angle in degrees (0–90, or 180 for no cone) and an ``exponent`` (0–128).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import ClassVar

from explorer.core.validate import Checker

Vec3 = tuple[float, float, float]
RGB = tuple[float, float, float]

LIGHT_TYPES = ("directional", "point", "spot")
NO_ATTENUATION: Vec3 = (1.0, 0.0, 0.0)
#: Upper bound accepted for a light colour channel (HDR lights above 1 are allowed).
MAX_LIGHT_VALUE = 1e6
SPOT_EXPONENT_RANGE = (0.0, 128.0)


def _vec(value, name: str, *, nonzero: bool = False) -> Vec3:
    v = tuple(float(c) for c in value)
    if len(v) != 3 or not all(math.isfinite(c) for c in v):
        raise ValueError(f"{name} must be 3 finite numbers, got {value!r}")
    if nonzero and not any(v):
        raise ValueError(f"{name} must be a non-zero direction")
    return v  # type: ignore[return-value]


def _colour(value, name: str) -> RGB:
    v = _vec(value, name)
    if not all(0.0 <= c <= MAX_LIGHT_VALUE for c in v):
        raise ValueError(f"{name} channels must be in [0, {MAX_LIGHT_VALUE:g}], got {v}")
    return v


def _unit(v: Vec3) -> Vec3:
    n = math.sqrt(sum(c * c for c in v))
    return (v[0] / n, v[1] / n, v[2] / n)


@dataclass(frozen=True)
class _Light:
    ambient: RGB = (0.0, 0.0, 0.0)
    diffuse: RGB = (1.0, 1.0, 1.0)
    specular: RGB = (1.0, 1.0, 1.0)
    #: cast hard shadows on the mesh (see :mod:`explorer.shading.shadows`); keyword only
    shadows: bool = field(default=False, kw_only=True)

    type: ClassVar[str] = ""

    def _check_colours(self):
        for key in ("ambient", "diffuse", "specular"):
            object.__setattr__(self, key, _colour(getattr(self, key), f"light {key}"))
        object.__setattr__(self, "shadows", bool(self.shadows))

    def replace(self, **changes):
        """A copy with some fields changed."""
        return replace(self, **changes)


@dataclass(frozen=True)
class DirectionalLight(_Light):
    """A light at infinity. direction : (3,) toward the light (stored unit length)."""

    direction: Vec3 = (0.0, 0.0, 1.0)
    type: ClassVar[str] = "directional"

    def __post_init__(self):
        self._check_colours()
        object.__setattr__(
            self, "direction", _unit(_vec(self.direction, "light direction", nonzero=True))
        )


@dataclass(frozen=True)
class PointLight(_Light):
    """A positional light. attenuation : (kc, kl, kq) >= 0, not all zero."""

    position: Vec3 = (0.0, 0.0, 1.0)
    attenuation: Vec3 = NO_ATTENUATION
    type: ClassVar[str] = "point"

    def __post_init__(self):
        self._check_colours()
        object.__setattr__(self, "position", _vec(self.position, "light position"))
        att = _vec(self.attenuation, "light attenuation")
        if min(att) < 0.0 or not any(att):
            raise ValueError(
                f"light attenuation [kc, kl, kq] must be >= 0 and not all zero, got {list(att)}"
            )
        object.__setattr__(self, "attenuation", att)


@dataclass(frozen=True)
class SpotLight(PointLight):
    """A point light restricted to a cone.

    direction : (3,) the axis the spot points along (stored unit length)
    cutoff : cone half-angle in degrees, in [0, 90], or 180 for no cone (OpenGL's rule)
    exponent : spot exponent in [0, 128]; the factor is (cos angle to the axis)**exponent
    """

    direction: Vec3 = (0.0, 0.0, -1.0)
    cutoff: float = 180.0
    exponent: float = 0.0
    type: ClassVar[str] = "spot"

    def __post_init__(self):
        super().__post_init__()
        object.__setattr__(
            self, "direction", _unit(_vec(self.direction, "spot direction", nonzero=True))
        )
        c = float(self.cutoff)
        if not (0.0 <= c <= 90.0 or c == 180.0):
            raise ValueError(f"spot cutoff must be in [0, 90] or exactly 180, got {c:g}")
        e = float(self.exponent)
        if not (SPOT_EXPONENT_RANGE[0] <= e <= SPOT_EXPONENT_RANGE[1]):
            raise ValueError(f"spot exponent must be in [0, 128], got {e:g}")
        object.__setattr__(self, "cutoff", c)
        object.__setattr__(self, "exponent", e)


Light = DirectionalLight | PointLight | SpotLight

_COMMON = ("type", "ambient", "diffuse", "specular", "color", "intensity", "shadows")
LIGHT_KEYS = {
    "directional": _COMMON + ("direction",),
    "point": _COMMON + ("position", "attenuation"),
    "spot": _COMMON + ("position", "attenuation", "direction", "cutoff", "exponent"),
}
ALL_LIGHT_KEYS = tuple(dict.fromkeys(k for keys in LIGHT_KEYS.values() for k in keys))


def parse_light(value, checker: Checker, path: tuple) -> Light | None:
    """Build a light from a scene-file mapping, reporting every problem to ``checker``."""
    if isinstance(value, _Light):
        return value
    m = checker.mapping(value, path)
    if m is None:
        return None
    kind = m.get("type", "directional" if "position" not in m else "point")
    kind = checker.choice(kind, path + ("type",), LIGHT_TYPES)
    if kind is None:
        checker.keys(m, path, ALL_LIGHT_KEYS)
        return None
    checker.keys(m, path, LIGHT_KEYS[kind])
    before = len(checker.problems)
    kw: dict = {}
    for key in ("ambient", "diffuse", "specular"):
        if key in m:
            kw[key] = checker.rgb(m[key], path + (key,), 0.0, MAX_LIGHT_VALUE)
    if "color" in m or "intensity" in m:
        for key in ("diffuse", "specular"):
            if key in m:
                checker.problem(
                    path + (key,),
                    "cannot be combined with color/intensity (they set diffuse and specular)",
                )
        color = (1.0, 1.0, 1.0)
        if "color" in m:
            color = checker.rgb(m["color"], path + ("color",), 0.0, MAX_LIGHT_VALUE)
        k = 1.0
        if "intensity" in m:
            k = checker.number(m["intensity"], path + ("intensity",), 0.0, MAX_LIGHT_VALUE)
        if color is not None and k is not None:
            kw["diffuse"] = kw["specular"] = tuple(k * c for c in color)
    if "shadows" in m:
        kw["shadows"] = checker.boolean(m["shadows"], path + ("shadows",))
    if kind == "directional":
        if "direction" in m:
            kw["direction"] = checker.direction(m["direction"], path + ("direction",))
    else:
        if "position" in m:
            kw["position"] = checker.triple(m["position"], path + ("position",))
        if "attenuation" in m:
            att = checker.triple(m["attenuation"], path + ("attenuation",), 0.0)
            if att is not None and not any(att):
                checker.problem(
                    path + ("attenuation",),
                    "must not be all zero (1 / (kc + kl·d + kq·d²) would divide by zero); "
                    "use [1, 0, 0] for no attenuation",
                )
            kw["attenuation"] = att
    if kind == "spot":
        if "direction" in m:
            kw["direction"] = checker.direction(m["direction"], path + ("direction",))
        if "cutoff" in m:
            c = checker.number(m["cutoff"], path + ("cutoff",), 0.0, 180.0)
            if c is not None and 90.0 < c < 180.0:
                checker.problem(path + ("cutoff",), f"must be in [0, 90] or exactly 180, got {c:g}")
            kw["cutoff"] = c
        if "exponent" in m:
            kw["exponent"] = checker.number(m["exponent"], path + ("exponent",), 0.0, 128.0)
    if len(checker.problems) > before or any(v is None for v in kw.values()):
        return None
    cls = {"directional": DirectionalLight, "point": PointLight, "spot": SpotLight}[kind]
    try:
        return cls(**kw)
    except ValueError as exc:  # pragma: no cover - the checks above mirror __post_init__
        checker.problem(path, str(exc))
        return None


def light_to_mapping(light: Light) -> dict:
    """The scene-file form of a light (plain Python values)."""
    out: dict = {"type": light.type}
    if isinstance(light, DirectionalLight):
        out["direction"] = list(light.direction)
    else:
        out["position"] = list(light.position)
        if light.attenuation != NO_ATTENUATION:
            out["attenuation"] = list(light.attenuation)
    if isinstance(light, SpotLight):
        out["direction"] = list(light.direction)
        out["cutoff"] = light.cutoff
        out["exponent"] = light.exponent
    for key in ("ambient", "diffuse", "specular"):
        out[key] = list(getattr(light, key))
    if light.shadows:
        out["shadows"] = True
    return out
