"""The scales the two front ends' sliders share (no Qt, no trame): the shininess slider's log
steps, the light intensity's range, and colours as text."""

from __future__ import annotations

import math

import numpy as np

from explorer.shading.display import to_bytes

#: slider steps (QSlider is integral)
STEPS = 1000
#: the shininess slider's log scale: step 0 is n = 0, steps 1..STEPS are 10**0 to 10**LOG_MAX
LOG_MAX = 3.0
#: the light intensity control's slider range (the number field takes more)
INTENSITY_RANGE = (0.0, 2.0)
MAX_INTENSITY = 1000.0


def shininess_to_step(n: float) -> int:
    """Slider step of exponent ``n`` (0 at the left end, then log10 n from 0 to 3)."""
    if n <= 0.0:
        return 0
    t = min(max(math.log10(max(n, 1.0)) / LOG_MAX, 0.0), 1.0)
    return 1 + round(t * (STEPS - 1))


def step_to_shininess(step: int) -> float:
    """Exponent of a shininess slider step, to 3 significant digits (step 0 is 0)."""
    if step <= 0:
        return 0.0
    n = 10.0 ** (LOG_MAX * (min(step, STEPS) - 1) / (STEPS - 1))
    return float(f"{n:.3g}")


def rgb_text(rgb) -> str:
    """A colour as the fields show it: ``"r, g, b"`` to three decimals."""
    return ", ".join(f"{c:.3f}" for c in rgb)


def rgb_bytes(rgb) -> tuple[int, int, int]:
    """The 8-bit colour the view draws for the value ``rgb`` (3,): each channel clamped to
    [0, 1] and times 255, rounded as :func:`~explorer.shading.display.to_bytes` rounds the
    engine's colours (no transfer function: the view shows the values as they are)."""
    c = np.clip(np.asarray(rgb, dtype=np.float64).reshape(1, 3), 0.0, 1.0)
    return tuple(int(v) for v in to_bytes(c)[0])
