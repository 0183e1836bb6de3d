"""Hard shadows (``shadows: true`` on a light): the light's diffuse and specular are weighted by
its visibility at each vertex, 1 lit or 0 shadowed (ambient light is not shadowed, as in OpenGL
practice). The rays and their rules are :mod:`explorer.shading.shadows`; the kernel multiplies
a light's visibility row (flag :data:`~explorer.core.lightrow.SHADOW`) into its weight.
"""

from __future__ import annotations

from explorer.core import lightrow as R
from explorer.shading.effects.base import Effect
from explorer.shading.shadows import visibility


class HardShadows(Effect):
    """Per light. Value: shadow rays are cast for the light (``shadows: true``, faces given,
    the light has diffuse or specular)."""

    name = "shadows"
    invalidates = "lights"

    def setting(self, scene):
        return tuple(lt.shadows for lt in scene.lights)

    def active(self, scene) -> bool:
        return any(lt.shadows for lt in scene.lights)

    def plan_light(self, light, mesh, terms, own):
        if not light.shadows:
            return False, [(self.name, "out", "shadows is false")]
        if mesh is None:
            return False, [(self.name, "out", "no mesh faces given: nothing can cast a shadow")]
        if not ((own.diffuse and terms.diffuse) or (own.specular and terms.specular)):
            return False, [(self.name, "out", "no diffuse or specular from this light to shadow")]
        why = (
            "rays toward the light from vertices with N·L > 0 (others: none), through the"
            " mesh's BVH; every mesh, convex-looking ones too (no convexity test is exact at"
            " every resolution)"
        )
        return True, [(self.name, "in", why)]

    def forced_light(self, light, mesh):
        return light.shadows and mesh is not None

    def pack(self, value, light_value, lp, row, flags):
        return flags | R.SHADOW if light_value else flags

    def weights(self, scene, light, at):
        if not (light.shadows and at.faces is not None):
            return None, None
        vis = visibility(at.world, at.faces, light)
        return vis, vis
