"""HDR display settings of a scene: exposure in stops and a tone map (the ``hdr`` key).

What the settings do to colours is :mod:`explorer.shading.effects.hdr`. The lecture notes' rule for
HDR, keep ``kd + ks`` at most 1 per channel so a surface never reflects more than it receives,
is :func:`energy_warnings`: one warning per channel where the material's diffuse + specular
exceeds 1.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from explorer.core.validate import Check, Checked, Checker, check_fields

TONE_MAPS = ("clamp", "reinhard", "aces")
#: accepted exposure, in stops
EXPOSURE_RANGE = (-16.0, 16.0)


def _exposure(checker: Checker, value, path):
    return checker.number(value, path, *EXPOSURE_RANGE)


def _tone_map(checker: Checker, value, path):
    return checker.choice(value, path, TONE_MAPS)


@dataclass(frozen=True)
class HDR(Checked):
    """How an unclamped colour is shown: exposure in stops and a tone map."""

    exposure: float = 0.0
    tone_map: str = "reinhard"

    #: key -> its check, run by :func:`parse_hdr` and by the constructor
    KEYS: ClassVar[dict[str, Check]] = {"exposure": _exposure, "tone_map": _tone_map}

    def to_mapping(self) -> dict:
        return {"exposure": self.exposure, "tone_map": self.tone_map}


HDR_KEYS = tuple(HDR.KEYS)


def parse_hdr(value, checker: Checker, path=("hdr",)) -> HDR | None:
    """An :class:`HDR` from a scene's ``hdr`` mapping (``true`` means the defaults; ``false``
    means no HDR, as when the key is left out: None without a problem)."""
    if isinstance(value, HDR):
        return value
    if value is True:
        return HDR()
    if value is False:
        return None
    m = checker.mapping(value, path, "{exposure: stops, tone_map: clamp|reinhard|aces}")
    if m is None:
        return None
    checker.keys(m, path, HDR_KEYS)
    kw = check_fields(HDR.KEYS, m, checker, path)
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
