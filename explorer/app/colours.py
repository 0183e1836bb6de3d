"""Colours as the controls of both front ends show them (no Qt, no trame): a colour value as
text, and the 8-bit colour the view draws for it."""

from __future__ import annotations

import numpy as np

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
