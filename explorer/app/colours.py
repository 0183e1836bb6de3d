"""Colours as the controls of both front ends show them (no Qt, no trame): a colour value as
text, the 8-bit colour the view draws for it, and a material's swatch."""

from __future__ import annotations

import numpy as np

from explorer.core.errors import ExplorerError
from explorer.shading.display import to_bytes


def rgb_text(rgb) -> str:
    """A colour as the fields show it: ``"r, g, b"`` to three decimals."""
    return ", ".join(f"{c:.3f}" for c in rgb)


def rgb_bytes(rgb) -> tuple[int, int, int]:
    """The 8-bit colour the view draws for the value ``rgb`` (3,): each channel clamped to
    [0, 1] and times 255, rounded as :func:`~explorer.shading.display.to_bytes` rounds the
    engine's colours (no transfer function: the view shows the values as they are)."""
    c = np.clip(np.asarray(rgb, dtype=np.float64).reshape(1, 3), 0.0, 1.0)
    return tuple(int(v) for v in to_bytes(c)[0])


def rgb_hex(rgb) -> str:
    """The 8-bit colour of ``rgb`` (3,) (:func:`rgb_bytes`) as ``"#rrggbb"``, what a colour
    picker shows."""
    return "#{:02x}{:02x}{:02x}".format(*rgb_bytes(rgb))


def parse_hex(key: str, text: str) -> tuple[float, float, float]:
    """A picker's ``"#rrggbb"`` (``"#rgb"``, or with an alpha ``"#rrggbbaa"``, which is
    dropped) as an RGB value in [0, 1], each channel ``byte / 255``; anything else an error
    naming ``key``."""
    t = str(text).strip().lstrip("#")
    if len(t) in (3, 4):
        t = "".join(c * 2 for c in t)
    if len(t) not in (6, 8) or any(c not in "0123456789abcdefABCDEF" for c in t):
        raise ExplorerError(f"{key}: a picked colour is #rrggbb, got {text!r}")
    return tuple(int(t[i : i + 2], 16) / 255.0 for i in (0, 2, 4))


def relative_luminance(rgb) -> float:
    """WCAG 2's relative luminance of the 8-bit colour the view draws for ``rgb`` (3,)
    (:func:`rgb_bytes`), its channels decoded from sRGB: 0 (black) .. 1 (white)."""
    c = np.asarray(rgb_bytes(rgb), dtype=np.float64) / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return float(lin @ np.array([0.2126, 0.7152, 0.0722]))


def contrast_ratio(l1: float, l2: float) -> float:
    """WCAG 2's contrast ratio of two relative luminances: 1 (none) .. 21 (black on white)."""
    hi, lo = max(l1, l2), min(l1, l2)
    return (hi + 0.05) / (lo + 0.05)


def text_on(rgb) -> str:
    """``"#000000"`` or ``"#ffffff"``: the text colour with the higher contrast on a swatch of
    ``rgb`` (3,) (WCAG 2's ratio; black wins a tie). A lightness test wrote black on pure blue
    (2.4:1); this writes white there (8.6:1). The worst case of the rule is 4.58:1, at the
    luminance where both ratios meet."""
    y = relative_luminance(rgb)
    return "#000000" if contrast_ratio(y, 0.0) >= contrast_ratio(y, 1.0) else "#ffffff"


def swatch_squares(material, size: int) -> tuple[tuple[int, int, int, int, tuple], ...]:
    """A material's swatch (beside a preset in both front ends' lists) as filled squares
    ``(x, y, width, height, rgb_bytes)`` of a ``size`` x ``size`` picture, top-left origin:
    the diffuse colour, with the specular colour in the top right quarter."""
    half = size // 2
    return (
        (0, 0, size, size, rgb_bytes(material.diffuse)),
        (half, 0, size - half, half, rgb_bytes(material.specular)),
    )
