"""Materials: the coefficients a surface has, and nothing else.

A :class:`Material` holds linear RGB reflection coefficients in [0, 1] and the shininess
exponent; the engine combines it with lights (see :mod:`explorer.shading.shader`). Defaults are
OpenGL's (``glMaterial``): ambient 0.2, diffuse 0.8, specular 0, emission 0, shininess 0.

Two ways to write a material (in a preset file or a scene's ``material:`` mapping), both from
the lecture notes; a material may use either form per term, but not both for the same term:

* the nine-coefficient RGB form: ``ambient``, ``diffuse``, ``specular`` (and ``emission``),
  each ``[r, g, b]`` in [0, 1];
* the scalar form: ``ka``, ``kd``, ``ks`` in [0, 1] with a base ``color`` (default white) and an
  optional ``specular_color`` (default white), meaning::

      ambient  = ka * color          (ka defaults to 0.2 when color is given)
      diffuse  = kd * color          (kd defaults to 0.8 when color is given)
      specular = ks * specular_color

  so ``{color: [1, 0, 0]}`` alone is OpenGL's default material in red.

``shininess`` (exponent in [0, 1000]), ``opacity`` (in [0, 1], 1 = opaque), an optional default
``model`` (``blinn`` / ``phong``) and a one-line ``description`` complete it; so do the texture
maps (``diffuse_map``, ``ambient_map``, ``emission_map``, ``specular_map``, ``shininess_map``,
``bump_map``: :mod:`explorer.core.texture`), each optional. Only the resolved
RGB coefficients are kept: a material read in the scalar form is saved in the RGB form, with
identical colours.

Each key is checked by one function (:attr:`Material.KEYS`, see :mod:`explorer.core.validate`),
run by :func:`parse_material` on a file and by the constructor, with the same messages. The
ranges above are a file's; the engine (the constructor) takes any coefficient and shininess
>= 0, and :data:`FILE_CHECKS` are the same checks with the file's bounds.

Scalars of an RGB material (:meth:`Material.scalars`, :meth:`Material.with_scalars`, used by
the ka / kd / ks sliders): the scalar of a term is its largest channel, ``k = max(r, g, b)``,
and its hue is the term divided by ``k`` (largest channel exactly 1). Setting a scalar keeps
the hue: ``term' = hue * k'``, so ``with_scalars(kd=k).scalars()[1] == k`` exactly and setting
the old value back restores the term to within rounding (a couple of ulps, unless a channel
times the scalar underflows to a subnormal number). A black term has no
hue of its own: ambient and diffuse then borrow the hue of the other one of the two (white if
both are black), specular uses white.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import partial
from typing import ClassVar

from explorer.core.texture import MAP_KEYS, TextureMap, parse_texture_map
from explorer.core.validate import Check, Checked, Checker, check_fields, check_values

RGB = tuple[float, float, float]

#: Keys of the nine-coefficient (RGB) form, in the order they are written.
RGB_KEYS = ("ambient", "diffuse", "specular", "emission")
#: Keys of the scalar form (ka * color, kd * color, ks * specular_color).
SCALAR_KEYS = ("ka", "kd", "ks", "color", "specular_color")
#: Every key a material mapping may have.
MATERIAL_KEYS = (
    RGB_KEYS
    + SCALAR_KEYS
    + (
        "shininess",
        "opacity",
        "model",
        "description",
        "fresnel",
        "energy_conserving",
    )
    + MAP_KEYS
)
#: Allowed shininess in files and sliders (the engine itself accepts any finite value >= 0).
SHININESS_RANGE = (0.0, 1000.0)
#: Allowed range of every reflection coefficient (RGB channels, ka, kd, ks) in files.
COEFFICIENT_RANGE = (0.0, 1.0)
OPACITY_RANGE = (0.0, 1.0)
#: Allowed Schlick reflectance at normal incidence ``F0`` (``fresnel``).
FRESNEL_RANGE = (0.0, 1.0)
#: The specular models: OpenGL's Blinn-Phong ``(N·H)^n`` and Phong ``(R·V)^n``, and three.js's
#: normalised Blinn-Phong (MeshPhongMaterial; see :mod:`explorer.shading.equation`).
MODELS = ("blinn", "phong", "threejs")

#: term -> its scalar key, and the scalar defaults applied to ``color`` (OpenGL's 0.2 / 0.8).
TERM_SCALARS = {"ambient": "ka", "diffuse": "kd", "specular": "ks"}
SCALAR_DEFAULTS = {"ka": 0.2, "kd": 0.8, "ks": 0.0}
_WHITE = (1.0, 1.0, 1.0)


# -- the checks of each key ------------------------------------------------------------------
# A coefficient or shininess check takes its upper bound ``hi``: the engine takes any value
# >= 0 (the constructor's default), a file holds COEFFICIENT_RANGE / SHININESS_RANGE.
def _coefficients(checker: Checker, value, path, hi: float = math.inf):
    """An RGB triple of reflection coefficients (ambient, color, ...), each in [0, hi]."""
    return checker.rgb(value, path, 0.0, hi)


def _scalar(checker: Checker, value, path, hi: float = math.inf):
    """One number in [0, hi]: a reflection coefficient (ka, kd, ks) or the shininess."""
    return checker.number(value, path, 0.0, hi)


def _opacity(checker: Checker, value, path):
    return checker.number(value, path, *OPACITY_RANGE)


def _model(checker: Checker, value, path):
    return checker.choice(value, path, MODELS)


def _text(checker: Checker, value, path):
    return checker.string(value, path)


def _fresnel(checker: Checker, value, path):
    return checker.number(value, path, *FRESNEL_RANGE)


def _flag(checker: Checker, value, path):
    return checker.boolean(value, path)


@dataclass(frozen=True)
class Material(Checked):
    """Surface coefficients.

    ambient, diffuse, specular, emission : RGB triples in [0, 1] (``a_m, d_m, s_m, e_m``)
    shininess : specular exponent ``n`` >= 0 (``0**0 == 1``: shininess 0 is a flat specular)
    opacity : alpha in [0, 1]; 1 is opaque
    model : default specular model for this material (``"blinn"`` / ``"phong"``) or None
    name, description : for people; never affect colours (and never affect ``==``)
    fresnel : Schlick's F0 in [0, 1], or None (off): the specular term of each light is
        weighted by ``F = F0 + (1 - F0)·(1 - V·H)^5`` (see :mod:`explorer.shading.effects`)
    energy_conserving : normalise the specular lobe, ``(n + 2)/(2π)`` (Phong) or
        ``(n + 8)/(8π)`` (Blinn), so a higher shininess narrows the highlight without dimming it
    diffuse_map, ambient_map, emission_map, specular_map, shininess_map, bump_map : a
        :class:`~explorer.core.texture.TextureMap` each, or None (no texture)
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
    fresnel: float | None = None
    energy_conserving: bool = False
    diffuse_map: TextureMap | None = None
    ambient_map: TextureMap | None = None
    emission_map: TextureMap | None = None
    specular_map: TextureMap | None = None
    shininess_map: TextureMap | None = None
    bump_map: TextureMap | None = None

    #: key -> its check (the engine's range: coefficients and shininess >= 0), in the order a
    #: file's problems are listed
    KEYS: ClassVar[dict[str, Check]] = {
        **dict.fromkeys(RGB_KEYS, _coefficients),
        "shininess": _scalar,
        "opacity": _opacity,
        "model": _model,
        "description": _text,
        "fresnel": _fresnel,
        "energy_conserving": _flag,
        **dict.fromkeys(MAP_KEYS, parse_texture_map),
    }

    def to_mapping(self) -> dict:
        """The nine-coefficient form as plain Python values (YAML-ready).

        ``parse_material(m.to_mapping(), ...) == m`` with identical floats (YAML writes floats
        with ``repr``, which reads back exactly).
        """
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
        if self.fresnel is not None:
            out["fresnel"] = float(self.fresnel)
        if self.energy_conserving:
            out["energy_conserving"] = True
        for key in MAP_KEYS:
            if getattr(self, key) is not None:
                out[key] = getattr(self, key).to_mapping()
        return out

    def maps(self) -> dict[str, TextureMap]:
        """The texture maps the material has, key -> map, in :data:`MAP_KEYS` order."""
        return {key: getattr(self, key) for key in MAP_KEYS if getattr(self, key) is not None}

    # -- scalar view (ka / kd / ks sliders) ---------------------------------------------------
    def scalars(self) -> tuple[float, float, float]:
        """``(ka, kd, ks)``: the largest channel of ambient, diffuse and specular."""
        return (max(self.ambient), max(self.diffuse), max(self.specular))

    def hue(self, term: str) -> RGB:
        """The colour of ``term`` ("ambient" / "diffuse" / "specular") scaled so its largest
        channel is 1; for a black term, the fallback described in the module docstring."""
        if term not in TERM_SCALARS:
            raise ValueError(f"term must be one of {tuple(TERM_SCALARS)}, got {term!r}")
        own = _hue(getattr(self, term))
        if own is not None:
            return own
        if term == "specular":
            return _WHITE
        other = "diffuse" if term == "ambient" else "ambient"
        return _hue(getattr(self, other)) or _WHITE

    def with_scalars(
        self, ka: float | None = None, kd: float | None = None, ks: float | None = None
    ) -> Material:
        """A copy whose ambient / diffuse / specular have the given scalars, hues kept.

        Each given value must be in [0, 1]; ``None`` leaves that term unchanged.
        """
        given = {key: k for key, k in (("ka", ka), ("kd", kd), ("ks", ks)) if k is not None}
        values = check_values({key: FILE_CHECKS[key] for key in given}, given)
        changes = {}
        for term, key in TERM_SCALARS.items():
            if key not in values or values[key] == max(getattr(self, term)):
                continue  # not given or unchanged: keep the exact values
            changes[term] = tuple(c * values[key] for c in self.hue(term))
        return self.replace(**changes) if changes else self


#: key -> its check in a file (every key of :data:`MATERIAL_KEYS`): the checks of
#: :attr:`Material.KEYS` with the file's ranges, and the scalar form's keys
FILE_CHECKS: dict[str, Check] = {
    **Material.KEYS,
    **{key: partial(_coefficients, hi=COEFFICIENT_RANGE[1]) for key in RGB_KEYS},
    "shininess": partial(_scalar, hi=SHININESS_RANGE[1]),
    **{key: partial(_scalar, hi=COEFFICIENT_RANGE[1]) for key in TERM_SCALARS.values()},
    "color": partial(_coefficients, hi=COEFFICIENT_RANGE[1]),
    "specular_color": partial(_coefficients, hi=COEFFICIENT_RANGE[1]),
}


def _hue(rgb: RGB) -> RGB | None:
    m = max(rgb)
    if m <= 0.0:
        return None
    # c / m is exactly 1.0 for the largest channel, so max(hue * k) == k exactly
    r, g, b = rgb
    return r / m, g / m, b / m


def parse_material(value, checker: Checker, path: tuple = ()) -> Material | None:
    """Build a :class:`Material` from a mapping of :data:`MATERIAL_KEYS` (either form, see the
    module docstring), reporting every problem to ``checker``; None when anything is wrong."""
    m = checker.mapping(value, path, "a material mapping")
    if m is None:
        return None
    before = len(checker.problems)
    checker.keys(m, path, MATERIAL_KEYS)

    def check(key):
        return FILE_CHECKS[key](checker, m[key], path + (key,))

    kw = check_fields({key: FILE_CHECKS[key] for key in RGB_KEYS}, m, checker, path)

    # the scalar form
    color = check("color") if "color" in m else None
    specular_color = check("specular_color") if "specular_color" in m else None
    ks_given = "ks" in m
    for term, key in TERM_SCALARS.items():
        if key in m and term in m:
            checker.problem(
                path + (key,),
                f"'{key}' and '{term}' both set the {term} term; use either the scalar form "
                f"({key} x {'specular_color' if key == 'ks' else 'color'}) or the RGB form "
                f"({term}: [r, g, b]), not both",
            )
    if "color" in m and "ambient" in m and "diffuse" in m:
        checker.problem(
            path + ("color",),
            "'color' is not used: ambient and diffuse are both given as [r, g, b] "
            "(color is the base of ka and kd)",
        )
    if "specular_color" in m and not ks_given:
        checker.problem(
            path + ("specular_color",),
            "'specular_color' needs 'ks' (specular = ks x specular_color)",
        )
    base = color if color is not None else _WHITE
    for term, key in (("ambient", "ka"), ("diffuse", "kd")):
        if term in m:
            continue
        if key in m or "color" in m:
            k = check(key) if key in m else SCALAR_DEFAULTS[key]
            if k is not None and ("color" not in m or color is not None):
                kw[term] = tuple(k * c for c in base)
    if ks_given and "specular" not in m:
        ks = check("ks")
        if ks is not None and ("specular_color" not in m or specular_color is not None):
            base = specular_color if specular_color is not None else _WHITE
            kw["specular"] = tuple(ks * c for c in base)

    rest = [key for key in Material.KEYS if key not in RGB_KEYS]
    kw.update(check_fields({key: FILE_CHECKS[key] for key in rest}, m, checker, path))
    if len(checker.problems) > before or any(v is None for v in kw.values()):
        return None
    return Material(**kw)
