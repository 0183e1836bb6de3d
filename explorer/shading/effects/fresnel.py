"""Schlick's Fresnel weight (``fresnel: F0`` on the material).

Each light's specular term is weighted by Schlick's approximation
``F = F0 + (1 - F0)·(1 - V·H)^5``, the W(a) of Phong's original model: the highlight grows toward
grazing angles. ``H = normalize(L + V)``, so ``V·H = sqrt((1 + V·L) / 2)`` (exactly, for unit L
and V), whichever lobe (Phong or Blinn) is used. The kernel computes F per vertex and light
(flag :data:`~explorer.core.lightrow.FRESNEL`, slot :data:`~explorer.core.lightrow.P_F0`) and
keeps it in the light's lobe weight, so a shininess change still re-runs only the lobe.
"""

from __future__ import annotations

import numpy as np

from explorer.core import lightrow as R
from explorer.shading.effects.base import Effect


def schlick(f0: float, v_dot_l) -> np.ndarray:
    """Schlick's F for unit L and V with cosine ``v_dot_l`` between them: (n,) float64."""
    c = np.sqrt(np.maximum((1.0 + np.asarray(v_dot_l, np.float64)) * 0.5, 0.0))  # V·H
    return f0 + (1.0 - f0) * (1.0 - c) ** 5


class Fresnel(Effect):
    """Value: F0 while there is a specular term to weight, else None."""

    name = "fresnel"
    invalidates = "specular"  # F is stored in each light's lobe weight

    def setting(self, scene):
        return scene.material.fresnel

    def active(self, scene) -> bool:
        return scene.material.fresnel is not None

    def plan(self, scene, terms):
        f0 = scene.material.fresnel
        if f0 is None:
            return None, [(self.name, "out", "material fresnel not set")]
        if scene.model == "threejs":
            why = f"F0 = {f0:g} not used: the threejs model has its own Fresnel (on s_m)"
            return None, [(self.name, "out", why)]
        if not terms.specular:
            return None, [
                (self.name, "out", f"F0 = {f0:g} but there is no specular term to weight")
            ]
        return f0, [(self.name, "in", f"Schlick F0 = {f0:g}: specular × F0 + (1-F0)(1-V·H)^5")]

    def needs_view(self, value) -> bool:
        return value is not None

    def pack(self, value, light_value, lp, row, flags):
        if value is None or not lp.specular:
            return flags
        row[R.P_F0] = value
        return flags | R.FRESNEL

    def weights(self, scene, light, at):
        f0 = scene.material.fresnel
        if f0 is None or scene.model == "threejs":
            return None, None
        return None, schlick(f0, np.einsum("ij,ij->i", at.V, at.L))
