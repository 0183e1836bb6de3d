"""Plans: which terms a scene can make non-zero, and so which work the engine does.

:func:`make_plan` looks at the scene alone (never at the mesh) and decides, per light and for
the whole scene, what must be computed per vertex, what is constant, and what is skipped, with
the reason for each decision. The kernels (:mod:`explorer.shading.kernels`) follow the plan; the
test suite checks that the planned result equals the full equation (:mod:`.equation`) on random
scenes.

The effects (:mod:`explorer.shading.effects`) plan themselves: each adds its rows and a value
the kernels and the shader read back (:meth:`Plan.effect`, :meth:`LightPlan.effect`).

Light-level decisions depend on the light only (its colours, and what its class says it needs:
:meth:`explorer.core.lights.Light.work`: distance, attenuation, cone); the
term-level decisions (is there any ambient, diffuse, specular at all?) depend on the material
too. The interactive :class:`~explorer.shading.shader.Shader` keeps per-light work cached across
material changes and asks for a term only when the current material needs it.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from explorer.core.scene import Scene
from explorer.shading.effects import EFFECTS, LightTerms, Terms
from explorer.shading.kernels import CHUNK


def _nonzero(rgb) -> bool:
    return any(c != 0.0 for c in rgb)


@dataclass(frozen=True)
class LightPlan:
    """The work for one light.

    ambient, diffuse, specular : the light has that colour (non-zero)
    positional : L is computed per vertex (point and spot); else constant
    attenuation : "none" | "constant" (folded into the colours) | "per-vertex"
    spot : "none" | "cone" | "cone+exponent"
    factor : constant attenuation 1/kc folded into the light's colours
    reasons : (item, "in"|"out", why) rows for people
    effects : (name, value) of each effect planned per light
        (:meth:`explorer.shading.effects.base.Effect.plan_light`)
    """

    index: int
    kind: str
    ambient: bool
    diffuse: bool
    specular: bool
    positional: bool
    attenuation: str
    spot: str
    factor: float
    reasons: tuple = ()
    effects: tuple = ()

    @property
    def varying_weight(self) -> bool:
        """att·spot differs between vertices."""
        return self.attenuation == "per-vertex" or self.spot != "none"

    def effect(self, name: str):
        """The value the effect ``name`` planned for this light (None when it plans none)."""
        return dict(self.effects).get(name)

    @property
    def shadows(self) -> bool:
        """Shadow rays are cast for this light (the shadow effect's value)."""
        return bool(self.effect("shadows"))


@dataclass(frozen=True)
class Plan:
    """The work for a scene.

    emission, ambient, diffuse, specular : the term can be non-zero (material and lights)
    ambient_per_vertex : some light's ambient is attenuated or cut by a cone per vertex
    flat_specular : shininess 0, so the lobe is 1 wherever N·L > 0 (no H, no R, no pow)
    view : "none" | "constant" | "per-vertex" (the V vector)
    halfway : "none" | "constant" | "per-vertex" | "reflection" (how the lobe's base is found)
    two_sided : flip N where N·V < 0
    lights : one LightPlan per scene light, in scene order
    reasons : (item, "in"|"out", why) rows for the scene-level decisions
    effects : (name, value) of each effect (:meth:`explorer.shading.effects.base.Effect.plan`):
        Schlick's F0 or None, the energy-conserving factor folded into the specular colours (1
        when off), whether colours are displayed unclamped (HDR)
    cull : a run of vertices that provably gets nothing from a light (all facing away from
        it, or outside its cone) skips that light; the mesh decides which (one-sided only)
    force_all : nothing is skipped (benchmark only; same colours)
    """

    emission: bool
    ambient: bool
    ambient_per_vertex: bool
    diffuse: bool
    specular: bool
    flat_specular: bool
    view: str
    halfway: str
    two_sided: bool
    model: str
    lights: tuple[LightPlan, ...] = ()
    reasons: tuple = field(default=())
    effects: tuple = ()
    force_all: bool = False
    cull: bool = False

    def effect(self, name: str):
        """The value the effect ``name`` planned for the scene (None when it plans none)."""
        return dict(self.effects).get(name)

    @property
    def shadows(self) -> bool:
        """Some light casts shadow rays."""
        return any(lp.shadows for lp in self.lights)

    def describe(self) -> str:
        """The plan as text: one line per decision with its reason."""
        rows = [("scene", *r) for r in self.reasons]
        for lp in self.lights:
            rows += [(f"light {lp.index} ({lp.kind})", *r) for r in lp.reasons]
        w0 = max(len(r[0]) for r in rows) if rows else 0
        w1 = max(len(r[1]) for r in rows) if rows else 0
        out = []
        for who, item, state, why in rows:
            out.append(f"{who:<{w0}}  {item:<{w1}}  {state:<3}  {why}")
        return "\n".join(out)


#: what :func:`make_plan` knows of the mesh for shadows
MESH_KINDS = (None, "faces")


def make_plan(scene: Scene, *, mesh: str | None = None, force_all: bool = False) -> Plan:
    """Decide the work for ``scene`` (see the module docstring).

    mesh : what the shader knows of the mesh, for shadows: None (no faces given: nothing can
        cast a shadow) or "faces" (triangles that can cast shadows)
    force_all : skip nothing (every term of every light per vertex, shadow rays from every
        vertex, facing the light or not); the colours are the same. For the benchmark only.
    """
    if mesh not in MESH_KINDS:
        raise ValueError(f"mesh must be one of {MESH_KINDS}, got {mesh!r}")
    plan = _make_plan(scene, mesh)
    if force_all:
        plan = _forced(plan, scene, mesh)
    return plan


def _forced(plan: Plan, scene: Scene, mesh) -> Plan:
    lights = []
    for lp, lt in zip(plan.lights, scene.lights, strict=True):
        att = "per-vertex" if lp.positional else "none"
        lights.append(
            replace(
                lp,
                ambient=True,
                diffuse=True,
                specular=True,
                attenuation=att,
                factor=1.0,
                effects=tuple((e.name, e.forced_light(lt, mesh)) for e in EFFECTS),
                reasons=lp.reasons + (("forced", "in", "force_all: nothing skipped"),),
            )
        )
    flat = scene.material.shininess == 0.0
    return replace(
        plan,
        ambient=True,
        ambient_per_vertex=any(lp.varying_weight for lp in lights),
        diffuse=True,
        specular=True,
        flat_specular=flat,
        view="per-vertex" if scene.viewer.local else "constant",
        halfway="none" if flat else ("reflection" if scene.model == "phong" else "per-vertex"),
        lights=tuple(lights),
        reasons=plan.reasons + (("forced", "in", "force_all: nothing skipped (benchmark)"),),
        force_all=True,
        cull=False,
    )


class _Reasons(list):
    """(item, "in"|"out", why) rows; :meth:`why` adds one and returns the decision."""

    def why(self, item: str, on: bool, reason: str) -> bool:
        self.append((item, "in" if on else "out", reason))
        return on


def _make_plan(scene: Scene, mesh) -> Plan:
    m = scene.material
    r = _Reasons()
    terms = Terms(*_terms(scene, r))
    emission, ambient, diffuse, specular = terms
    effects = [(e, *e.plan(scene, terms)) for e in EFFECTS]  # (effect, value, rows)
    flat = specular and m.shininess == 0.0
    if specular:
        r.why(
            "lobe",
            not flat,
            "shininess 0: 0^0 = 1, the lobe is 1 wherever N·L > 0 (no H, no R, no pow)"
            if flat
            else f"pow(base, {m.shininess:g}) per vertex",
        )
    threejs = scene.model == "threejs"
    if threejs:
        r.why("model", True, "threejs: three.js's normalised Blinn-Phong, computed by the numpy "
              "tier (the compiled kernels implement OpenGL's blinn and phong)")  # fmt: skip
    needs_view = threejs and specular or any(e.needs_view(v) for e, v, _ in effects)
    view = _view(scene, specular, flat, needs_view, r)
    r.why(
        "two-sided",
        scene.two_sided,
        "flip N where N·V < 0" if scene.two_sided else "two_sided is false",
    )
    cull = r.why(
        "culling",
        not (scene.two_sided or threejs),
        "two-sided: N flips with V, so no vertex is known to face away from a light"
        if scene.two_sided
        else "the numpy tier computes every vertex-light"
        if threejs
        else f"runs of {CHUNK} vertices that all face away from a light (or lie outside a "
        "spot's cone) skip it: how many, the mesh decides",
    )
    for _, _, rows in effects:
        r.extend(rows)

    lplans = tuple(_light_plan(i, lt, scene, mesh, terms) for i, lt in enumerate(scene.lights))
    halfway = "none"
    if specular and not flat:
        if scene.model == "phong":
            halfway = "reflection"
        elif threejs:
            halfway = "per-vertex"  # the numpy tier computes H per vertex
        elif scene.viewer.local or any(lp.positional for lp in lplans if lp.specular):
            halfway = "per-vertex"
        else:
            halfway = "constant"
    return Plan(
        emission=emission,
        ambient=ambient,
        ambient_per_vertex=ambient and any(lp.ambient and lp.varying_weight for lp in lplans),
        diffuse=diffuse,
        specular=specular,
        flat_specular=flat,
        view=view,
        halfway=halfway,
        two_sided=scene.two_sided,
        model=scene.model,
        lights=lplans,
        reasons=tuple(r),
        effects=tuple((e.name, v) for e, v, _ in effects),
        cull=cull,
    )


def _terms(scene: Scene, r: _Reasons) -> tuple[bool, bool, bool, bool]:
    """Which of emission, ambient, diffuse, specular the material and lights can make
    non-zero."""
    m, lights = scene.material, scene.lights
    emission = r.why(
        "emission",
        _nonzero(m.emission),
        "material emission is non-zero" if _nonzero(m.emission) else "material emission is 0",
    )
    any_amb = _nonzero(scene.ambient) or any(_nonzero(lt.ambient) for lt in lights)
    ambient = r.why(
        "ambient",
        _nonzero(m.ambient) and any_amb,
        "material ambient 0"
        if not _nonzero(m.ambient)
        else ("scene and light ambient are 0" if not any_amb else "a_m and an ambient light"),
    )
    diffuse = _lit_term(r, "diffuse", "d", m.diffuse, lights)
    specular = _lit_term(r, "specular", "s", m.specular, lights, scene.model == "threejs")
    return emission, ambient, diffuse, specular


def _lit_term(r, term: str, symbol: str, material_rgb, lights, f90: bool = False) -> bool:
    """The diffuse or specular term: in when the material and some light both have it.
    f90 : the term has a part that does not depend on the material (the threejs model's
    Fresnel toward 1), so a light alone makes it non-zero"""
    lit = any(_nonzero(getattr(lt, term)) for lt in lights)
    if f90 and lit and not _nonzero(material_rgb):
        why = f"material {term} 0, but threejs's Schlick F rises to 1 at grazing angles"
        return r.why(term, True, why)
    if not _nonzero(material_rgb):
        reason = f"material {term} 0"
    elif not lit:
        reason = f"no light has {term} colour"
    else:
        reason = f"{symbol}_m and a light's {term}"
    return r.why(term, _nonzero(material_rgb) and lit, reason)


def _view(scene: Scene, specular: bool, flat: bool, effect_view: bool, r: _Reasons) -> str:
    """How the view vector V is found: "none", "constant" or "per-vertex".
    effect_view : an effect reads V even for a flat lobe (Fresnel)"""
    if not ((specular and not flat) or effect_view or scene.two_sided):
        r.why("view vector", False, "no lobe, no Fresnel and one-sided: V is never used")
        return "none"
    if scene.viewer.local:
        r.why("view vector", True, "local viewer: V = normalize(eye - P) per vertex")
        return "per-vertex"
    r.why("view vector", True, "infinite viewer: V is constant")
    return "constant"


def _light_plan(i: int, lt, scene: Scene, mesh, terms: Terms) -> LightPlan:
    """The light's own decisions (:meth:`explorer.core.lights.Light.work`), what the
    material, model, viewer make of its terms, and what the effects plan for it (the mesh:
    None or "faces")."""
    m = scene.material
    work = lt.work()
    r = _Reasons(work.reasons)
    amb = _nonzero(lt.ambient)
    dif = _nonzero(lt.diffuse)
    spec = _nonzero(lt.specular)
    positional = work.positional
    varying = work.attenuation == "per-vertex" or work.spot != "none"

    if not _nonzero(m.ambient):
        r.why("ambient", False, "material ambient 0")
    elif not amb:
        r.why("ambient", False, "light ambient 0")
    else:
        r.why(
            "ambient",
            True,
            "attenuated per vertex" if varying else "constant: added once to the scene ambient",
        )
    r.why(
        "diffuse",
        dif and _nonzero(m.diffuse),
        "light diffuse 0"
        if not dif
        else ("material diffuse 0" if not _nonzero(m.diffuse) else "max(N·L, 0)·d_i"),
    )
    if not spec:
        r.why("specular", False, "light specular 0")
    elif scene.model == "threejs":
        why = "three.js: max(N·L, 0)·(n/2+1)/4·(N·H)^n·F, F = s_m + (1 - s_m)·g(V·H)"
        r.why("specular", True, why)
    elif not _nonzero(m.specular):
        r.why("specular", False, "material specular 0")
    elif m.shininess == 0.0:
        r.why("specular", True, "flat lobe (shininess 0): s_i where N·L > 0")
    elif scene.model == "phong":
        r.why("specular", True, "Phong: (R·V)^n with R = 2(N·L)N - L per vertex")
    elif not positional and not scene.viewer.local:
        r.why("specular", True, "Blinn: constant H (directional light, infinite viewer), N·H")
    else:
        r.why("specular", True, "Blinn: H = normalize(L + V) per vertex")
    own = LightTerms(amb, dif, spec)
    effects = []
    for e in EFFECTS:
        value, rows = e.plan_light(lt, mesh, terms, own)
        effects.append((e.name, value))
        r.extend(rows)
    if not (amb or dif or spec):
        r.why("light", False, "all colours 0: skipped entirely")
    return LightPlan(
        i,
        lt.type,
        amb,
        dif,
        spec,
        positional,
        work.attenuation,
        work.spot,
        work.factor,
        tuple(r),
        tuple(effects),
    )
