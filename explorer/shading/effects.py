"""Effects beyond the local model that are cheap closed forms: the energy-conserving lobe
normalisation and Schlick's Fresnel weight. Shadows are in :mod:`explorer.shading.shadows`, the HDR
display in :mod:`explorer.shading.display`. Every effect is off by default (see docs/effects.md).

Energy-conserving specular (``energy_conserving: true`` on the material) multiplies the lobe by
the constant that makes its cosine-weighted integral over the hemisphere independent of ``n``::

    Phong  (R·V)^n :  (n + 2) / (2π)
    Blinn  (N·H)^n :  (n + 8) / (8π)      (the usual approximation, Akenine-Möller et al.)

so raising shininess narrows the highlight and raises its peak instead of dimming it. The
factor is a constant per scene: the engine folds it into each light's specular colour.

Fresnel (``fresnel: F0`` on the material) weights each light's specular term by Schlick's
approximation ``F = F0 + (1 - F0)·(1 - V·H)^5``, the W(a) of Phong's original model: the
highlight grows toward grazing angles. ``H = normalize(L + V)``, so ``V·H =
sqrt((1 + V·L) / 2)`` (exactly, for unit L and V), whichever lobe (Phong or Blinn) is used.
"""

from __future__ import annotations

import math

import numpy as np


def energy_factor(model: str, shininess: float) -> float:
    """The lobe normalisation of :mod:`explorer.shading.effects` for ``model`` at exponent n."""
    n = float(shininess)
    if model == "phong":
        return (n + 2.0) / (2.0 * math.pi)
    return (n + 8.0) / (8.0 * math.pi)


def specular_scale(scene) -> float:
    """The constant folded into every light's specular colour (1 when the option is off)."""
    m = scene.material
    return energy_factor(scene.model, m.shininess) if m.energy_conserving else 1.0


def schlick(f0: float, v_dot_l) -> np.ndarray:
    """Schlick's F for unit L and V with cosine ``v_dot_l`` between them: (n,) float64."""
    c = np.sqrt(np.maximum((1.0 + np.asarray(v_dot_l, np.float64)) * 0.5, 0.0))  # V·H
    return f0 + (1.0 - f0) * (1.0 - c) ** 5
