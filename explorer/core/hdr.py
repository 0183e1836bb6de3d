"""HDR display settings of a scene: exposure in stops and a tone map (the ``hdr`` key).

What the settings do to colours is :mod:`explorer.shading.display`. The lecture notes' rule for
HDR, keep ``kd + ks`` at most 1 per channel so a surface never reflects more than it receives,
is :func:`energy_warnings`: one warning per channel where the material's diffuse + specular
exceeds 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

TONE_MAPS = ("clamp", "reinhard", "aces")
#: accepted exposure, in stops
EXPOSURE_RANGE = (-16.0, 16.0)
HDR_KEYS = ("exposure", "tone_map")


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
