"""Effects beyond the local model, each one object behind one interface
(:class:`~explorer.shading.effects.base.Effect`): Schlick's Fresnel (:mod:`.fresnel`), the
energy-conserving lobe (:mod:`.energy`), hard shadows (:mod:`.shadows`) and the HDR display
(:mod:`.hdr`). Every effect is off by default (see docs/effects.md).

The plan, the shader, the reference equation and the display loop over :data:`EFFECTS` in
this order (plan rows appear in it; the reference multiplies the weights in it). Adding an
effect: its module here, its entry in :data:`EFFECTS`, the kernel only if the kernel's loop
must change, and its tests. Its keys are parsed and validated where they live
(:mod:`explorer.core`).

Translucency (``opacity < 1`` on the material) changes no colour: the renderer draws the
triangles back to front (:func:`explorer.render.camera.back_to_front`), so it has no object
here.
"""

from __future__ import annotations

from explorer.shading.effects.base import LEVELS, Effect, Incident, LightTerms, Terms
from explorer.shading.effects.energy import EnergyConserving, energy_factor, specular_scale
from explorer.shading.effects.fresnel import Fresnel, schlick
from explorer.shading.effects.hdr import HDRDisplay
from explorer.shading.effects.shadows import HardShadows

#: every effect, in the order of the plan's rows and of the reference's weights
EFFECTS: tuple[Effect, ...] = (HardShadows(), Fresnel(), EnergyConserving(), HDRDisplay())

__all__ = [
    "EFFECTS",
    "LEVELS",
    "Effect",
    "EnergyConserving",
    "Fresnel",
    "HDRDisplay",
    "HardShadows",
    "Incident",
    "LightTerms",
    "Terms",
    "energy_factor",
    "schlick",
    "specular_scale",
]
