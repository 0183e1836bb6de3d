"""HDR display (``hdr: {exposure: E, tone_map: T}`` on the scene).

The engine's colours are then unclamped linear radiance-like values ``>= 0`` that may exceed 1
(several lights, an energy-conserving lobe, bright lights), shown as::

    x = c · 2**E                      exposure in stops (E = 0: unchanged, +1: twice as bright)
    y = tone_map(x)                   into [0, 1]
    out = srgb_encode(y)              the exact sRGB OETF (IEC 61966-2-1)

Tone maps (:data:`~explorer.core.hdr.TONE_MAPS`):

- ``clamp``: ``min(x, 1)`` (what OpenGL does; HDR then only adds exposure and sRGB);
- ``reinhard``: ``x / (1 + x)`` per channel (Reinhard et al. 2002, simple form): never clips,
  compresses highlights smoothly, darkens mid-tones (0.5 -> 0.33);
- ``aces``: Narkowicz's fit of the ACES filmic curve (2015),
  ``x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)`` clamped to [0, 1], with the input scaled by
  0.6 as in the original fit: contrasty mid-tones, highlights roll off to white.

The sRGB OETF: ``12.92·y`` for ``y <= 0.0031308``, else ``1.055·y^(1/2.4) - 0.055``.

The lecture notes' rule for HDR (keep ``kd + ks`` at most 1 per channel) is checked by
:func:`explorer.core.hdr.energy_warnings`; the plan lists its warnings.
"""

from __future__ import annotations

import numpy as np

from explorer.core.hdr import HDR, TONE_MAPS, energy_warnings
from explorer.shading.effects.base import Effect

#: ACES (Narkowicz) input scale: the fit maps scene value 1/0.6 to about 0.8
ACES_INPUT_SCALE = 0.6
#: tone maps take min(x, this): reinhard's x/(1 + x) rounds to exactly 1 from x = 2**53, the
#: ACES fit clips to 1 from 0.6·x = 7.25; so capping changes no value and keeps inf and huge
#: inputs (an HDR scene with exposure 16 and a blinding light) from giving inf/inf = NaN
TONE_MAP_CAP = 1e20


def expose(colors, exposure: float) -> np.ndarray:
    """colors · 2**exposure; colors : (..., 3) float >= 0."""
    return np.asarray(colors, np.float64) * (2.0 ** float(exposure))


def tone_map(x, name: str) -> np.ndarray:
    """One of :data:`~explorer.core.hdr.TONE_MAPS` applied per channel: (..., 3) float >= 0 ->
    [0, 1]."""
    # huge and inf map to 1 (x/(1 + x) -> 1): the input is capped where each map is already
    # exactly 1 (inf/inf would be NaN, and a² overflows beyond 1e154); NaN is kept (no guess)
    x = np.maximum(np.asarray(x, np.float64), 0.0)
    if name == "clamp":
        return np.minimum(x, 1.0)
    if name == "reinhard":
        x = np.minimum(x, TONE_MAP_CAP)
        return x / (1.0 + x)
    if name == "aces":
        a = np.minimum(x, TONE_MAP_CAP) * ACES_INPUT_SCALE
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


def display(colors, hdr: HDR | None) -> np.ndarray:
    """The engine's colours (n, 3) -> display values in [0, 1] under an ``hdr`` setting.

    hdr : the scene's ``hdr`` (None: the engine clamped the colours, as OpenGL does, and they
        are shown as they are, the same array; else the unclamped sums go through exposure,
        tone map and sRGB encoding)
    """
    if hdr is None:
        return colors
    return srgb_encode(tone_map(expose(colors, hdr.exposure), hdr.tone_map))


class HDRDisplay(Effect):
    """Value: the scene is shown through exposure, tone map and sRGB (the engine does not
    clamp)."""

    name = "hdr"

    def setting(self, scene):
        return scene.hdr

    def active(self, scene) -> bool:
        return scene.hdr is not None

    def plan(self, scene, terms):
        hdr = scene.hdr
        if hdr is None:
            return False, [(self.name, "out", "no hdr: colours clamped to [0, 1] (OpenGL)")]
        why = f"unclamped, exposure {hdr.exposure:g} stops, {hdr.tone_map} tone map, sRGB"
        rows = [(self.name, "in", why)]
        rows += [("kd + ks", "out", "warning: " + w) for w in energy_warnings(scene.material)]
        return True, rows

    def clamps(self, scene) -> bool:
        return scene.hdr is None

    def display(self, colors, scene):
        return display(colors, scene.hdr)
