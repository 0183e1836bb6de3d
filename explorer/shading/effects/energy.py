"""Energy-conserving specular (``energy_conserving: true`` on the material).

The lobe is multiplied by the constant that makes its cosine-weighted integral over the
hemisphere independent of ``n``::

    Phong  (R·V)^n :  (n + 2) / (2π)
    Blinn  (N·H)^n :  (n + 8) / (8π)      (the usual approximation, Akenine-Möller et al.)

so raising shininess narrows the highlight and raises its peak instead of dimming it. The
factor is a constant per scene: the kernel gets it folded into each light's specular colour.
"""

from __future__ import annotations

import math

from explorer.shading.effects.base import Effect


def energy_factor(model: str, shininess: float) -> float:
    """The lobe normalisation for ``model`` ("phong" or "blinn") at exponent n."""
    n = float(shininess)
    if model == "phong":
        return (n + 2.0) / (2.0 * math.pi)
    return (n + 8.0) / (8.0 * math.pi)


def specular_scale(scene) -> float:
    """The constant the scene's specular lobe is multiplied by (1 when the option is off)."""
    m = scene.material
    if not m.energy_conserving or scene.model == "threejs":  # threejs: normalised already
        return 1.0
    return energy_factor(scene.model, m.shininess)


class EnergyConserving(Effect):
    """Value: the factor folded into the specular colours (1 when off or without specular)."""

    name = "energy"
    invalidates = "lobe"  # a constant per scene, as a shininess change

    def setting(self, scene):
        return scene.material.energy_conserving

    def active(self, scene) -> bool:
        return scene.material.energy_conserving

    def plan(self, scene, terms):
        scale = specular_scale(scene)
        if not scene.material.energy_conserving:
            return 1.0, [(self.name, "out", "material energy_conserving is false")]
        if scene.model == "threejs":
            why = "energy_conserving not used: the threejs lobe is normalised, (n/2+1)/4"
            return 1.0, [(self.name, "out", why)]
        if not terms.specular:
            why = "energy_conserving, but there is no specular term to normalise"
            return 1.0, [(self.name, "out", why)]
        form = "(n+2)/(2π)" if scene.model == "phong" else "(n+8)/(8π)"
        why = f"energy_conserving: {form} = {scale:.4g} folded into s_i"
        return scale, [(self.name, "in", why)]

    def specular_factor(self, value) -> float:
        return value

    def weights(self, scene, light, at):
        return None, specular_scale(scene)
