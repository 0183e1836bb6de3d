"""Materials: the coefficients a surface has, and nothing else.

A :class:`Material` holds linear RGB reflection coefficients in [0, 1] and the shininess
exponent; the engine combines it with lights (see :mod:`explorer.engine`). Defaults are
OpenGL's (``glMaterial``): ambient 0.2, diffuse 0.8, specular 0, emission 0, shininess 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace

from .validate import Checker

RGB = tuple[float, float, float]

#: Keys of the nine-coefficient (RGB) form, in the order they are written.
RGB_KEYS = ("ambient", "diffuse", "specular", "emission")
#: Every key the engine's material understands.
MATERIAL_KEYS = RGB_KEYS + ("shininess", "opacity", "model", "description")
#: Allowed shininess in files and sliders (the engine itself accepts any finite value >= 0).
SHININESS_RANGE = (0.0, 1000.0)
MODELS = ("blinn", "phong")


@dataclass(frozen=True)
class Material:
    """Surface coefficients.

    ambient, diffuse, specular, emission : RGB triples in [0, 1] (``a_m, d_m, s_m, e_m``)
    shininess : specular exponent ``n`` >= 0 (``0**0 == 1``: shininess 0 is a flat specular)
    opacity : alpha in [0, 1]; 1 is opaque
    model : default specular model for this material (``"blinn"`` / ``"phong"``) or None
    name, description : for people; never affect colours
    """

    ambient: RGB = (0.2, 0.2, 0.2)
    diffuse: RGB = (0.8, 0.8, 0.8)
    specular: RGB = (0.0, 0.0, 0.0)
    emission: RGB = (0.0, 0.0, 0.0)
    shininess: float = 0.0
    opacity: float = 1.0
    model: str | None = None
    name: str | None = field(default=None, compare=False)
    description: str = field(default="", compare=False)

    def __post_init__(self):
        for key in RGB_KEYS:
            value = tuple(float(c) for c in getattr(self, key))
            if len(value) != 3 or not all(math.isfinite(c) and c >= 0.0 for c in value):
                raise ValueError(f"material {key} must be 3 finite numbers >= 0, got {value}")
            object.__setattr__(self, key, value)
        s = float(self.shininess)
        if not (math.isfinite(s) and s >= 0.0):
            raise ValueError(f"material shininess must be finite and >= 0, got {s}")
        object.__setattr__(self, "shininess", s)
        o = float(self.opacity)
        if not (0.0 <= o <= 1.0):
            raise ValueError(f"material opacity must be in [0, 1], got {o}")
        object.__setattr__(self, "opacity", o)
        if self.model is not None and self.model not in MODELS:
            raise ValueError(f"material model must be one of {MODELS}, got {self.model!r}")

    def replace(self, **changes) -> Material:
        """A copy with some fields changed (``m.replace(shininess=64)``)."""
        return replace(self, **changes)

    def to_mapping(self) -> dict:
        """The nine-coefficient form as plain Python values (YAML-ready)."""
        out: dict = {}
        if self.description:
            out["description"] = self.description
        for key in RGB_KEYS:
            out[key] = [float(c) for c in getattr(self, key)]
        out["shininess"] = float(self.shininess)
        if self.opacity != 1.0:
            out["opacity"] = float(self.opacity)
        if self.model is not None:
            out["model"] = self.model
        return out


def parse_material(value, checker: Checker, path: tuple = ()) -> Material | None:
    """Build a :class:`Material` from a mapping of :data:`MATERIAL_KEYS`, reporting every
    problem to ``checker``; returns None when anything is wrong."""
    m = checker.mapping(value, path)
    if m is None:
        return None
    checker.keys(m, path, MATERIAL_KEYS)
    before = len(checker.problems)
    kw: dict = {}
    for key in RGB_KEYS:
        if key in m:
            kw[key] = checker.rgb(m[key], path + (key,))
    if "shininess" in m:
        kw["shininess"] = checker.number(m["shininess"], path + ("shininess",), *SHININESS_RANGE)
    if "opacity" in m:
        kw["opacity"] = checker.number(m["opacity"], path + ("opacity",), 0.0, 1.0)
    if "model" in m:
        kw["model"] = checker.choice(m["model"], path + ("model",), MODELS)
    if "description" in m:
        kw["description"] = checker.string(m["description"], path + ("description",))
    if len(checker.problems) > before:
        return None
    return Material(**kw)


def material_fields() -> tuple[str, ...]:
    return tuple(f.name for f in fields(Material))
