"""Colours as the controls of both front ends show them (no Qt, no trame): a colour value as
text, and the 8-bit colour the view draws for it."""

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
