"""The interface every effect implements, and the types its hooks see.

An effect is one small object; the plan (:mod:`explorer.shading.plan`), the shader
(:mod:`explorer.shading.shader`), the reference equation (:mod:`explorer.shading.equation`) and
the display (:mod:`explorer.shading.display`) loop over :data:`explorer.shading.effects.EFFECTS`
and call these hooks; none of them names an effect. Every hook has a neutral default, so an effect
overrides only what it does. The keys an effect reads are parsed and validated where they live
(material, light, scene: :mod:`explorer.core`).
"""

from __future__ import annotations

from typing import ClassVar, NamedTuple

import numpy as np

#: the Shader's cached work, cheapest first: what a change of a setting invalidates
#: (compose: colours only; lobe: the specular lobe from stored bases; specular: the specular
#: sum; lights: every sum)
LEVELS = ("compose", "lobe", "specular", "lights")


class Terms(NamedTuple):
    """The plan's scene-level decisions an effect may depend on: each term can be non-zero."""

    emission: bool
    ambient: bool
    diffuse: bool
    specular: bool


class LightTerms(NamedTuple):
    """A light's own colours: each is non-zero."""

    ambient: bool
    diffuse: bool
    specular: bool


class Incident(NamedTuple):
    """What the reference equation knows at the vertices for one light.

    world : (n, 3) float64 positions in world space; faces : (m, 3) int triangles, or None
    L : (n, 3) unit vectors toward the light; V : (n, 3) unit vectors toward the viewer
    """

    world: np.ndarray
    faces: np.ndarray | None
    L: np.ndarray
    V: np.ndarray


Row = tuple[str, str, str]  # (item, "in"|"out", why): one row of the plan's text


class Effect:
    """One effect beyond the local model (see the module docstring).

    Its planned state is a value (``None`` or a neutral value when off) that the plan stores
    under :attr:`name`: for the whole scene (:meth:`plan`) or per light (:meth:`plan_light`).
    The other hooks receive that value, never the scene keys again.
    """

    #: the plan's key for the effect's value, and the item of its plan rows
    name: ClassVar[str] = ""
    #: the Shader's cached work a change of :meth:`setting` invalidates (one of :data:`LEVELS`)
    invalidates: ClassVar[str] = "compose"

    # -- the scene ---------------------------------------------------------------------------
    def setting(self, scene):
        """The scene's keys for this effect (compared between scenes by the Shader)."""
        return None

    def active(self, scene) -> bool:
        """The scene switches the effect on (whether or not the plan can use it)."""
        return False

    # -- the plan ----------------------------------------------------------------------------
    def plan(self, scene, terms: Terms) -> tuple[object, list[Row]]:
        """The scene-level value and the plan rows that explain it."""
        return None, []

    def plan_light(self, light, mesh, terms: Terms, own: LightTerms) -> tuple[object, list[Row]]:
        """The value for one light and its rows. mesh : None (no faces) or "faces"."""
        return None, []

    def forced_light(self, light, mesh):
        """The value for one light in a plan that skips nothing (benchmark)."""
        return None

    def needs_view(self, value) -> bool:
        """The effect reads V per vertex even for a flat lobe."""
        return False

    # -- the kernel --------------------------------------------------------------------------
    def specular_factor(self, value) -> float:
        """A constant folded into every light's specular colour."""
        return 1.0

    def pack(self, value, light_value, lp, row: list, flags: int) -> int:
        """Write the effect's slots of a light's kernel row (:mod:`explorer.core.lightrow`);
        returns the flags with its bits added. lp : the light's
        :class:`~explorer.shading.plan.LightPlan`."""
        return flags

    # -- the reference equation --------------------------------------------------------------
    def weights(self, scene, light, at: Incident):
        """Per-vertex weights on one light's (diffuse, specular) terms in the reference: each
        (n,) float64, a float, or None (1). Read from the scene alone: the reference applies the
        effect wherever the scene sets it, whether or not a plan could skip it."""
        return None, None

    # -- the display -------------------------------------------------------------------------
    def clamps(self, scene) -> bool:
        """The engine may clamp colours to [0, 1] (False: the display needs them unclamped)."""
        return True

    def display(self, colors, scene):
        """Colours (n, 3) after shading -> colours for the next display step."""
        return colors
