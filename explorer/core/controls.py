"""One table of the explorer's controls: every value a user sets with a slider and a number
field, with its key (the YAML key = state field = widget label), its slider range, the number
field's range when that is wider, its decimals, its scale (log for the shininess) and its unit.

The ranges are the file validators' own constants (:mod:`explorer.core.material`,
:mod:`explorer.core.lights`), so a file, a typed value and a slider agree; the Qt panel
(:mod:`explorer.app.qt.panel`) and any other front end build their controls from
:data:`CONTROLS`, and :func:`to_step` / :func:`from_step` map a value to a slider step and back.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from explorer.core.hdr import EXPOSURE_RANGE
from explorer.core.lights import SPOT_CUTOFF_RANGE, SPOT_EXPONENT_RANGE
from explorer.core.material import (
    COEFFICIENT_RANGE,
    FRESNEL_RANGE,
    OPACITY_RANGE,
    SHININESS_RANGE,
)

#: slider steps over a control's range (sliders are integral)
STEPS = 1000
#: decades of the shininess slider's log scale: step 0 is n = 0, steps 1..STEPS are 10**0 to
#: 10**LOG_DECADES (n below 1 cannot be reached by the slider, only typed)
LOG_DECADES = 3.0
#: the light's distance from the mesh centre, in mesh radii: the slider's range (a handle
#: farther out leaves the view)
DISTANCE_RANGE = (1.0, 5.0)
#: the distance a typed value may take (mesh radii)
DISTANCE_FIELD = (0.01, 1e4)
#: the intensity a typed value may take (a file takes up to lights.MAX_LIGHT_VALUE per channel;
#: the field stops at a value that is already far beyond white)
MAX_INTENSITY = 1000.0
#: the attenuation fields' range (a scene file takes any value >= 0, not all three zero)
ATTENUATION_RANGE = (0.0, 100.0)
#: the exposure slider's range in stops (x 1/16 to x 16); a typed value may take the file's
#: whole range, :data:`explorer.core.hdr.EXPOSURE_RANGE`
EXPOSURE_SLIDER = (-4.0, 4.0)
#: the lobe plot's incidence θ_i in degrees (the lit sphere's drag): from the normal to grazing
LOBE_INCIDENCE_RANGE = (0.0, 90.0)


@dataclass(frozen=True)
class Control:
    """One control: ``key``; ``lo``, ``hi`` the slider's range; ``field`` the number field's
    range (None: the slider's); ``decimals`` shown; ``scale`` ``"linear"`` or ``"log"``;
    ``unit`` a suffix for the field; ``step`` the field's arrow step (None: 10**-min(decimals,
    2))."""

    key: str
    lo: float
    hi: float
    decimals: int = 3
    scale: str = "linear"
    unit: str = ""
    field: tuple[float, float] | None = None
    step: float | None = None

    @property
    def field_range(self) -> tuple[float, float]:
        return self.field or (self.lo, self.hi)

    @property
    def field_step(self) -> float:
        return self.step if self.step is not None else 10.0 ** -min(self.decimals, 2)


def field_text(control: Control, value: float) -> str:
    """``value`` as a number field shows it: ``control.decimals`` decimals and its unit
    (``40.0°``, ``2.50 r``, ``0.300``), as the window's fields do and the page's."""
    return f"{float(value):.{control.decimals}f}{control.unit}"


def without_unit(control: Control, text: str) -> str:
    """Typed ``text`` without the control's unit at its end (``"45°"``, ``"2.5 r"``), what
    a field shows being typed back."""
    t, unit = str(text).strip(), control.unit.strip()
    return t[: -len(unit)].strip() if unit and t.endswith(unit) else t


def _controls(*items: Control) -> dict[str, Control]:
    return {c.key: c for c in items}


#: every number control of the material, the selected light and the scene, by key
CONTROLS: dict[str, Control] = _controls(
    Control("ka", *COEFFICIENT_RANGE),
    Control("kd", *COEFFICIENT_RANGE),
    Control("ks", *COEFFICIENT_RANGE),
    Control("shininess", *SHININESS_RANGE, decimals=1, scale="log"),
    Control("opacity", *OPACITY_RANGE),
    Control("intensity", 0.0, 2.0, field=(0.0, MAX_INTENSITY)),
    Control("azimuth", -180.0, 180.0, decimals=1, unit="°"),
    Control("elevation", -90.0, 90.0, decimals=1, unit="°"),
    Control("distance", *DISTANCE_RANGE, decimals=2, unit=" r", field=DISTANCE_FIELD),
    Control("cutoff", *SPOT_CUTOFF_RANGE, decimals=1, unit="°"),
    Control("exponent", *SPOT_EXPONENT_RANGE, decimals=1),
    Control("attenuation", *ATTENUATION_RANGE, step=0.05),
    Control("fresnel", *FRESNEL_RANGE),
    Control("exposure", *EXPOSURE_SLIDER, decimals=2, unit=" EV", field=EXPOSURE_RANGE),
    Control("lobe_incidence", *LOBE_INCIDENCE_RANGE, decimals=1, unit="°"),
)


def shininess_to_step(n: float) -> int:
    """Slider step of exponent ``n`` (0 at the left end, then log10 n from 0 to 3)."""
    if n <= 0.0:
        return 0
    t = min(max(math.log10(max(n, 1.0)) / LOG_DECADES, 0.0), 1.0)
    return 1 + round(t * (STEPS - 1))


def step_to_shininess(step: int) -> float:
    """Exponent of a shininess slider step, to 3 significant digits (step 0 is 0)."""
    if step <= 0:
        return 0.0
    n = 10.0 ** (LOG_DECADES * (min(step, STEPS) - 1) / (STEPS - 1))
    return float(f"{n:.3g}")


def to_step(control: Control, v: float, lo: float | None = None, hi: float | None = None) -> int:
    """The slider step (0..STEPS) showing ``v`` (clamped to the slider's range; ``lo``, ``hi``
    a range other than the table's, e.g. one scaled to the mesh)."""
    if control.scale == "log":
        return shininess_to_step(v)
    lo = control.lo if lo is None else lo
    hi = control.hi if hi is None else hi
    t = (v - lo) / (hi - lo) if hi > lo else 0.0
    return round(min(max(t, 0.0), 1.0) * STEPS)


def from_step(control: Control, step: int, lo: float | None = None,
              hi: float | None = None) -> float:  # fmt: skip
    """The value of slider step ``step`` (see :func:`to_step`)."""
    if control.scale == "log":
        return step_to_shininess(step)
    lo = control.lo if lo is None else lo
    hi = control.hi if hi is None else hi
    return lo + (hi - lo) * step / STEPS
