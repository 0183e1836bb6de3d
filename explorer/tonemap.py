"""HDR display: exposure, a tone map and the exact sRGB encoding (pure numpy, no VTK).

The engine's unclamped colours (``shade(..., clamp=False)``) are linear radiance-like values
``>= 0`` that may exceed 1 (several lights, an energy-conserving lobe, bright lights). A scene
with ``hdr: {exposure: E, tone_map: T}`` is displayed as::

    x = c · 2**E                      exposure in stops (E = 0: unchanged, +1: twice as bright)
    y = tone_map(x)                   into [0, 1]
    out = srgb_encode(y)              the exact sRGB OETF (IEC 61966-2-1)

Tone maps (:data:`TONE_MAPS`):

- ``clamp``: ``min(x, 1)`` (what OpenGL does; HDR then only adds exposure and sRGB);
- ``reinhard``: ``x / (1 + x)`` per channel (Reinhard et al. 2002, simple form): never clips,
  compresses highlights smoothly, darkens mid-tones (0.5 -> 0.33);
- ``aces``: Narkowicz's fit of the ACES filmic curve (2015),
  ``x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)`` clamped to [0, 1], with the input scaled by
  0.6 as in the original fit: contrasty mid-tones, highlights roll off to white.

The sRGB OETF: ``12.92·y`` for ``y <= 0.0031308``, else ``1.055·y^(1/2.4) - 0.055``.

The lecture notes' rule for HDR: keep ``kd + ks`` constant (at most 1 per channel) so a surface
never reflects more than it receives. :func:`energy_warnings` offers it as a check: one warning
per channel where the material's diffuse + specular exceeds 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

TONE_MAPS = ("clamp", "reinhard", "aces")
#: accepted exposure, in stops
EXPOSURE_RANGE = (-16.0, 16.0)
HDR_KEYS = ("exposure", "tone_map")
#: ACES (Narkowicz) input scale: the fit maps scene value 1/0.6 to about 0.8
ACES_INPUT_SCALE = 0.6


@dataclass(frozen=True)
class HDR:
    """How an unclamped colour is shown: exposure in stops and a tone map."""

    exposure: float = 0.0
    tone_map: str = "reinhard"

    def __post_init__(self):
        e = float(self.exposure)
        if not (math.isfinite(e) and EXPOSURE_RANGE[0] <= e <= EXPOSURE_RANGE[1]):
            raise ValueError(f"hdr exposure must be in {list(EXPOSURE_RANGE)} stops, got {e}")
        if self.tone_map not in TONE_MAPS:
            raise ValueError(f"hdr tone_map must be one of {TONE_MAPS}, got {self.tone_map!r}")
        object.__setattr__(self, "exposure", e)

    def to_mapping(self) -> dict:
        return {"exposure": self.exposure, "tone_map": self.tone_map}


def parse_hdr(value, checker, path=("hdr",)) -> HDR | None:
    """An :class:`HDR` from a scene's ``hdr`` mapping (``true`` means the defaults)."""
    if isinstance(value, HDR):
        return value
    if value is True:
        return HDR()
    m = checker.mapping(value, path, "{exposure: stops, tone_map: clamp|reinhard|aces}")
    if m is None:
        return None
    checker.keys(m, path, HDR_KEYS)
    kw = {}
    if "exposure" in m:
        kw["exposure"] = checker.number(m["exposure"], path + ("exposure",), *EXPOSURE_RANGE)
    if "tone_map" in m:
        kw["tone_map"] = checker.choice(m["tone_map"], path + ("tone_map",), TONE_MAPS)
    if any(v is None for v in kw.values()):
        return None
    return HDR(**kw)


def expose(colors, exposure: float) -> np.ndarray:
    """colors · 2**exposure; colors : (..., 3) float >= 0."""
    return np.asarray(colors, np.float64) * (2.0 ** float(exposure))


def tone_map(x, name: str) -> np.ndarray:
    """One of :data:`TONE_MAPS` applied per channel: (..., 3) float >= 0 -> [0, 1]."""
    x = np.maximum(np.asarray(x, np.float64), 0.0)
    if name == "clamp":
        return np.minimum(x, 1.0)
    if name == "reinhard":
        return x / (1.0 + x)
    if name == "aces":
        a = x * ACES_INPUT_SCALE
        return np.clip(a * (2.51 * a + 0.03) / (a * (2.43 * a + 0.59) + 0.14), 0.0, 1.0)
    raise ValueError(f"tone map must be one of {TONE_MAPS}, got {name!r}")


def srgb_encode(y) -> np.ndarray:
    """The exact sRGB OETF: linear [0, 1] -> encoded [0, 1] (monotone, continuous)."""
    y = np.clip(np.asarray(y, np.float64), 0.0, 1.0)
    return np.where(y <= 0.0031308, 12.92 * y, 1.055 * np.power(y, 1.0 / 2.4) - 0.055)


def srgb_decode(v) -> np.ndarray:
    """The inverse of :func:`srgb_encode`."""
    v = np.clip(np.asarray(v, np.float64), 0.0, 1.0)
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def display(colors, hdr: HDR) -> np.ndarray:
    """Unclamped linear colours (n, 3) -> display values in [0, 1] (sRGB-encoded)."""
    return srgb_encode(tone_map(expose(colors, hdr.exposure), hdr.tone_map))


def energy_warnings(material) -> list[str]:
    """The notes' HDR rule kd + ks <= 1, per channel: one message per channel that breaks it."""
    out = []
    for name, d, s in zip("RGB", material.diffuse, material.specular, strict=True):
        if d + s > 1.0 + 1e-12:
            out.append(
                f"material diffuse + specular is {d + s:.4g} > 1 in the {name} channel: the "
                "surface reflects more light than it receives (keep kd + ks <= 1 for HDR)"
            )
    return out
