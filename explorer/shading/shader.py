"""The engine's front: :func:`shade` for one-shot colours, :class:`Shader` for interaction.

A :class:`Shader` keeps the per-vertex light sums of
:func:`explorer.shading.equation.equation_terms` cached by what they depend on:

=====================  =======================================================================
change                 work done on the next ``colors``
=====================  =======================================================================
material colours       compose only: ``e + a_m·A + d_m·D + s_m·S`` (no dot product)
shininess              the lobe only: ``Σ ws·base^n·s`` from stored per-light bases (no
                       distances, no normalisations), then compose
viewer                 the specular sum (and, when two-sided, everything: N·V flips normals)
model (phong/blinn)    the specular sum
an effect's setting    what the effect declares (``Effect.invalidates``): the specular sum for
                       Fresnel's F0 (F is stored in each light's lobe weight), the lobe only
                       for energy_conserving (a constant per scene)
lights                 every sum the material needs (shadow visibility is kept per light
                       position and direction: only a moved light casts new rays)
geometry               every sum the material needs, and new shadow rays
=====================  =======================================================================

Shadows need the mesh's triangles: pass ``faces`` (default None: no shadows, and the plan says
so). ``force_all=True`` makes the plan skip nothing (same colours; for the benchmark only).

A term the material does not need (``s_m = 0``, say) is not computed until it is needed.
``stats`` counts each kind of pass, so tests can check that a change costs what it should.
Cached arrays are read-only.

Each pass runs on the tier :mod:`explorer.shading.tiers` picks: the compiled kernels, or, while
numba's cache does not hold them yet, the lighting equation in numpy (:mod:`.equation`, float64,
every term at once; material changes still compose only, and shadow rows are kept per light).
A shader switches to the compiled tier at its next pass once the kernels are loaded.
"""

from __future__ import annotations

import sys
from collections import Counter
from collections.abc import Iterable, Mapping

import numpy as np

from explorer.core import lightrow as R
from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError, ExplorerTypeError
from explorer.core.material import MODELS, Material
from explorer.core.presets import find_preset
from explorer.core.scene import Scene, Viewer, check_materials_dirs, load_scene
from explorer.geometry.frame import (
    check_faces,
    check_finite,
    check_vertices,
    scale_normals,
)
from explorer.shading import kernels as K
from explorer.shading import layout, tiers
from explorer.shading.effects import EFFECTS
from explorer.shading.equation import compose_terms, equation_terms
from explorer.shading.plan import Plan, make_plan
from explorer.shading.prepared import RowMemory, chunk_bounds, geometry_of, rows, vertices
from explorer.shading.prepared import readonly as _readonly
from explorer.shading.shadows import pending_work, visibility_rows

PRECISIONS = ("float64", "float32")
#: the engine's tiers (see :mod:`explorer.shading.tiers`)
TIERS = ("compiled", "numpy")
#: the specular models the compiled kernels implement; the others run on the numpy tier
COMPILED_MODELS = ("blinn", "phong")
#: chunk bounds of a pass without light culling
_NO_BOUNDS = _readonly(np.zeros((layout.N_BOUNDS, 0)))
#: what the cached sums depend on in a scene, and the work a change of it invalidates (one of
#: :data:`explorer.shading.effects.LEVELS`); each effect adds its own setting
#: (:func:`invalidated`)
UPDATES = (
    (lambda s: s.lights, "lights"),
    (lambda s: s.two_sided, "lights"),
    (lambda s: s.viewer, "specular"),
    (lambda s: s.model, "specular"),
    (lambda s: s.material.shininess, "lobe"),
)


def shade(
    scene,
    positions,
    normals,
    *,
    precision: str = "float64",
    clamp: bool = True,
    materials_dirs=(),
    faces=None,
    tier: str | None = None,
) -> np.ndarray:
    """Per-vertex colours of a mesh under a scene.

    scene : a scene-file path, a mapping in the scene schema, or a
    :class:`~explorer.core.scene.Scene`
    positions : (n, 3) float vertex positions
    normals : (n, 3) float vertex normals (any length; zero means "no normal")
    precision : "float64" (exact path) or "float32" (fast path, within 1/255 of float64)
    clamp : clamp to [0, 1] (OpenGL); False keeps the unclamped sums (>= 0) for HDR
    faces : (m, 3) int triangles, needed for shadows (None: no shadows)
    tier : "compiled", "numpy", or None: the tier :mod:`explorer.shading.tiers` picks
    Returns colours : (n, 3) float64.
    """
    s = Shader(
        scene,
        positions,
        normals,
        precision=precision,
        clamp=clamp,
        materials_dirs=materials_dirs,
        keep=False,
        faces=faces,
        tier=tier,
    )
    return np.asarray(s.colors, dtype=np.float64)


class Shader:
    """Cached, stateful shading of one mesh (see the module docstring).

    positions, normals : (n, 3) float arrays (kept by reference for float64 re-evaluation; any
        normal outside NORMAL_RANGE is rescaled in a copy: see geometry.frame.scale_normals)
    precision : "float32" (default here: the interactive path) or "float64"
    keep : keep the light sums and the prepared geometry for cheap updates. False: one-shot
        (what :func:`shade` uses): nothing per vertex is kept, each pass prepares every block of
        vertices as it shades it (no prepared copy of the geometry: less memory and memory
        traffic); the constructor finds the frame (and NaN or infinite positions), a pass finds
        NaN or infinite normals (the same error, before any colours)
    faces : (m, 3) int triangles for shadows (None: no shadows)
    force_all : the plan skips nothing (same colours; benchmark only)
    cull : skip a light for runs of vertices that provably get nothing from it (the plan's
        ``culling``); False: every vertex-light, no chunk bounds (same colours; live pixels)
    tier : "compiled" or "numpy" for every pass of this shader; None (default): the tier
        :func:`explorer.shading.tiers.compiled` picks at each pass. The ``threejs`` model is
        always computed by the numpy tier (the kernels implement :data:`COMPILED_MODELS`).
    cancelled : () -> bool (the attribute ``cancelled``, settable), asked while the shadow
        rays' BVH is built and between chunks of rays: True stops the pass with
        :class:`~explorer.core.errors.Cancelled` (the next one starts afresh)
    """

    def __init__(
        self,
        scene,
        positions,
        normals,
        *,
        precision: str = "float32",
        clamp: bool = True,
        materials_dirs=(),
        keep: bool = True,
        faces=None,
        force_all: bool = False,
        cull: bool = True,
        tier: str | None = None,
        cancelled=None,
    ):
        self.tier = _check_options(precision, tier)
        self.cancelled = cancelled
        self._T = np.float32 if precision == "float32" else np.float64
        self.precision = precision
        self.clamp = bool(clamp)
        self.keep = bool(keep)
        self.stats: Counter = Counter()
        self.force_all = bool(force_all)
        self.cull = bool(cull)
        self._materials_dirs = check_materials_dirs(materials_dirs)
        self._scene = load_scene(scene, materials_dirs=self._materials_dirs)
        self._k = K.constants(self._T)
        self._keep_lobe = False
        self._k64, self._rows = K.constants(np.float64), RowMemory()  # (G's memory: kept)
        self.set_geometry(positions, normals, faces)

    # -- inputs ------------------------------------------------------------------------------
    @property
    def scene(self) -> Scene:
        return self._scene

    @property
    def plan(self) -> Plan:
        return self._plan

    @property
    def n(self) -> int:
        return len(self._P)

    def set_geometry(self, positions, normals, faces=None) -> None:
        """New vertices (and triangles, for shadows): every cached sum is invalid."""
        now = _compiled_now(self.tier, self._scene.model)  # prepared now: finds NaN, inf too
        P, N = check_vertices(positions, normals, scale=False, finite=not now)
        if P.dtype != N.dtype:  # one dtype for both: the kernels compile for two pairs only
            P, N = P.astype(np.float64), N.astype(np.float64)
        faces = None if faces is None else check_faces(faces, len(P))
        how = (self.keep, self.cull, self._rows)  # (the whole geometry, its bounds, G's memory)
        geometry = geometry_of(P, N, self._T, self._k, *how) if now else None
        self._P, self._N = P, N
        self._scaled = False  # whether self._N is known to lie in NORMAL_RANGE (see _normals)
        self._faces = faces
        self._vis_cache: dict = {}
        self._plan = self._make_plan(self._scene)
        n = len(self._P)
        # the frame and the compiled tier's geometry (below, or at its first pass)
        self._centre, self._scale, self._G, self._bounds = None, 1.0, None, None
        self._np = None  # the numpy tier's sums
        self._served = None  # the tier of the last pass
        self._A = self._D = self._S = None
        self._base = self._ws = None
        self._colors = None
        self._memory = _Memory()
        self._redo = np.zeros(n if self._T is np.float32 else 0, np.bool_)
        self._redo_count = np.zeros(-(-self._redo.size // K.BLOCK), np.int32)  # per block
        self._culled = np.zeros(-(-n // K.BLOCK), np.int32)  # per block
        if geometry is not None:
            self._compiled_geometry(geometry)
        self._lights_changed()

    def _compiled_geometry(self, geometry=None) -> None:
        """The compiled tier's geometry (:func:`~explorer.shading.prepared.geometry_of`;
        ``geometry``: found already); keep=False: the frame alone (each pass: :meth:`_one_shot`)."""
        if self._centre is None:
            how = (self.keep, self.cull, self._rows)  # (the whole geometry, its bounds, G's)
            geometry = geometry or geometry_of(self._P, self._N, self._T, self._k, *how)
            self._centre, self._scale, self._G, self._bounds, N = geometry
            self._N, self._scaled = (self._N, False) if N is None else (N, True)
            self.stats["geometry"] += 1

    def _normals(self) -> np.ndarray:
        """The normals scaled into NORMAL_RANGE (:func:`explorer.geometry.frame.scale_normals`:
        the same array when they lie in it already, as the compiled geometry found)."""
        if not self._scaled:
            self._N = scale_normals(self._N)
            self._scaled = True
        return self._N

    def set_scene(self, scene) -> None:
        """Apply a new scene, invalidating only what its differences touch. A bad scene raises
        before anything changes (the shader keeps its scene)."""
        new = load_scene(scene, materials_dirs=self._materials_dirs)
        old = self._scene
        if new == old:
            return
        plan = self._make_plan(new)
        self._scene, self._plan = new, plan
        changed = invalidated(new, old)
        if "lights" in changed:
            self._lights_changed()
            return
        if "specular" in changed:
            self._viewer_changed()
        if "lobe" in changed:
            self._shininess_changed()
        self._colors = None  # material colours and scene ambient: compose only
        self._aconst = ambient_constant(self._scene, self._plan)

    def set_material(self, material) -> None:
        """material : a Material, a mapping of material keys, or a preset name (looked up in
        the shader's ``materials_dirs``, then the built-ins)."""
        if isinstance(material, str):
            material = find_preset(material, self._materials_dirs)
        material = _typed("material", material, (Material, Mapping), "a Material or a mapping")
        self.set_scene(self._scene.replace(material=material))

    def set_model(self, model: str) -> None:
        """model : one of :data:`explorer.core.material.MODELS`."""
        self.set_scene(self._scene.replace(model=_typed("model", model, str, f"one of {MODELS}")))

    def set_viewer(self, viewer: Viewer) -> None:
        """viewer : a Viewer or a mapping ``{eye: [x, y, z]}`` / ``{to_viewer: [x, y, z]}``."""
        viewer = _typed("viewer", viewer, (Viewer, Mapping), "a Viewer or a mapping")
        self.set_scene(self._scene.replace(viewer=viewer))

    def set_lights(self, lights) -> None:
        """lights : a list of lights (each a Light or a mapping of light keys)."""
        lights = _typed("lights", lights, Iterable, "a list of lights", not_types=(str, Mapping))
        self.set_scene(self._scene.replace(lights=tuple(lights)))

    # -- outputs -----------------------------------------------------------------------------
    @property
    def colors(self) -> np.ndarray:
        """(n, 3) colours in the working precision, read-only."""
        if self._colors is None:
            self._update()
        return self._colors

    @property
    def terms(self) -> dict[str, np.ndarray]:
        """Per-vertex sums (n, 3), read-only: ``ambient`` (scene ambient included),
        ``diffuse``, ``specular``, so that colour = e + a_m·ambient + d_m·diffuse +
        s_m·specular (plus ``specular_f90`` under the ``threejs`` model, which adds that sum
        as it is). Terms the plan skips are zeros."""
        if not self.keep:
            raise ExplorerError("terms need a Shader with keep=True")
        # every sum the lights can produce, whatever the current material needs
        self._update(force=(True, True, True))
        if self._served == "numpy":
            return {k: _readonly(v.astype(self._T)) for k, v in self._np.items()}
        return stored_terms(self._aconst, self._A, self._D, self._S, self.n, self._T)

    # -- invalidation --------------------------------------------------------------------------
    def _lights_changed(self):
        self._np = None
        self._memory.retire(self._A, self._D, self._S)
        self._A = self._D = self._S = None
        self._base = self._ws = None
        self._spec_shininess = None
        self._colors = None
        self._params = None
        self._aconst = ambient_constant(self._scene, self._plan)

    def _viewer_changed(self):
        if self._scene.two_sided:  # N·V decides which normals flip: every sum depends on V
            self._lights_changed()
            return
        self._np = None
        self._memory.retire(self._S)
        self._S = None
        self._base = self._ws = None
        self._spec_shininess = None
        self._params = None  # constant halfway vectors depend on V
        # a moving camera changes V every frame: stop storing lobes (8 bytes per vertex and
        # light per frame) until shininess moves again
        self._keep_lobe = False

    def _shininess_changed(self):
        self._np = None
        self._memory.retire(self._S)
        self._S = None  # the stored bases and weights stay valid
        self._params = None  # an energy-conserving factor changes with n (cheap to redo)
        # from now on keep each light's base and weight, so the next shininess change only
        # re-runs the lobe (kept on demand: storing them costs 8 bytes per vertex and light)
        self._keep_lobe = True

    # -- shadows -------------------------------------------------------------------------------
    def _mesh_kind(self, scene) -> str | None:
        """What the plan knows of the mesh: None (no faces) or "faces"."""
        return None if self._faces is None else "faces"

    def _make_plan(self, scene) -> Plan:
        return make_plan(scene, mesh=self._mesh_kind(scene), force_all=self.force_all)

    def _visibility(self) -> K.Shadows:
        """The visibility rows of the lights the plan shadows (:class:`~.kernels.Shadows`)."""
        scene, shadowed = self._scene, _shadowed(self._plan)
        N = self._normals() if any(shadowed) else self._N  # (rays on the pass's tier: counted)
        rows, index, rays = visibility_rows(self._P, N, self._faces, scene.lights, shadowed,
                                            two_sided=scene.two_sided, force_all=self.force_all,
                                            cache=self._vis_cache, cancelled=self.cancelled,
                                            engine=tiers.ray_engine(tier=self.tier))  # fmt: skip
        self.stats["shadow_rays"] += rays
        return K.Shadows(rows, index)

    # -- the work ------------------------------------------------------------------------------
    def _compiled_tier(self) -> bool:
        """Whether this pass runs on the compiled kernels (see :mod:`explorer.shading.tiers`)."""
        kernels = self._scene.model in COMPILED_MODELS  # threejs: the equation computes it
        if self.tier is not None:
            return kernels and self.tier == "compiled"
        # the numpy tier's vertex-lights of this pass with its shadow rays' work (at most; they
        # follow this choice); none for a compose of kept sums (not work the kernels would save)
        work = 0 if self._np is not None else self.n * max(1, len(self._scene.lights)) + (
            pending_work(self._vis_cache, self._scene, _shadowed(self._plan), self.n,
                         self._faces, force_all=self.force_all))  # fmt: skip
        return tiers.compiled(work) and kernels

    def _update(self, force=(False, False, False)):
        if not self._compiled_tier():
            self._update_numpy()
            self._served = "numpy"
            return
        self._served = "compiled"
        self._compiled_geometry()
        plan, scene, T = self._plan, self._scene, self._T
        self._colors = None
        self._out = self._memory.colour_buffer(self.n, self._T)
        need_amb = plan.ambient_per_vertex or force[0]
        need_dif = plan.diffuse or force[1]
        need_spec = plan.specular or force[2]
        shininess = scene.material.shininess
        do_amb = need_amb and self._A is None
        do_dif = need_dif and self._D is None
        do_spec = need_spec and self._S is None
        flat = shininess == 0.0
        if do_spec and self._ws is not None and (flat or self._base is not None):
            # the lobe alone: bases and weights are stored, only n changed
            params, flags, _ = self._params_for(T)
            S = self._memory.fresh((self.n, 3), self._T)
            base = self._base if self._base is not None else self._ws
            K.lobe(base, self._ws, params, flags, kernel_shininess(shininess, T), self._k, S)
            self._S = S
            self._spec_shininess = shininess
            self.stats["lobe"] += 1
            do_spec = False
        mat = material_vector(self._scene.material, T)
        aconst = self._aconst.astype(T)
        if do_amb or do_dif or do_spec:
            self._run(do_amb, do_dif, do_spec, flat, mat, aconst)
        else:
            kept = ((self._A, need_amb), (self._D, need_dif), (self._S, need_spec))
            sums = [x if x is not None and need else np.zeros((0, 3), T) for x, need in kept]
            K.compose(mat, aconst, *sums, self.clamp, self._k, self._out)
            self.stats["compose"] += 1
        self._colors = _readonly(self._out)
        self._out = None

    def _update_numpy(self):
        """A pass on the numpy tier: the equation's three sums (kept until the lights, viewer,
        model or shininess change), composed with the material."""
        self._colors = None
        if self._np is None:
            rows, index = self._visibility()
            vis = [rows[i] if i >= 0 else None for i in index]  # a row per light, or None
            self._np = equation_terms(self._scene, self._P, self._normals(), visibility=vis)
            self.stats["numpy"] += 1
        else:
            self.stats["compose"] += 1
        c = compose_terms(self._scene.material, self._np, self.clamp)
        self._colors = _readonly(c.astype(self._T, copy=False))

    def _params_for(self, dtype):
        if self._params is None:
            self._params = {}
        if dtype not in self._params:
            # built once in float64 (the float64 redo of ambiguous lanes needs those too)
            if np.float64 not in self._params:
                self._params[np.float64] = light_params(
                    self._scene, self._plan, self._centre, self._scale
                )
            params, flags, view = self._params[np.float64]
            self._params[dtype] = (params.astype(dtype), flags, view.astype(dtype))
        return self._params[dtype]

    def _run(self, do_amb, do_dif, do_spec, flat, mat, aconst):
        """One fused pass of the shading kernel over every vertex (+ float64 fix-ups)."""
        scene, T, n = self._scene, self._T, self.n
        params, flags, view = self._params_for(T)
        keep = self.keep
        opts = pass_options(scene, self._plan, flat, (do_amb, do_dif, do_spec), T)
        opts[layout.O_STORE] = keep
        opts[layout.O_STORE_LOBE] = keep and do_spec and self._keep_lobe
        opts[layout.O_CLAMP] = self.clamp
        empty3 = np.zeros((0, 3), T)

        def cache(current, do, grey=False):
            if not keep:
                return empty3
            if do:
                return self._memory.fresh((n, 1 if grey else 3), T)
            return current if current is not None else empty3

        # a pass whose diffuse and specular sums are grey stores them as (n, 1) (the kernel
        # decides alike, from the diffuse sum it is given when that is not recomputed)
        D = None if do_dif else cache(self._D, False)
        diffuse_grey = D is None or D.shape[0] == 0 or D.shape[1] == 1
        grey = keep and K.grey_pass(flags, opts, diffuse_grey)
        A = cache(self._A, do_amb)
        D = cache(self._D, True, grey) if do_dif else D
        S = cache(self._S, do_spec, grey)
        base, ws = self._memory.lobe_rows((len(params), n if opts[layout.O_STORE_LOBE] else 0), T)
        vis = self._visibility()
        inputs = (
            K.Lights(params, flags, view, K.loop_table(T, K.pass_loops(flags, opts))),
            opts,
            K.Surface(mat, aconst, kernel_shininess(scene.material.shininess, T)),
            self._k,
            K.Sums(A, D, S),
            K.Lobes(base, ws),
        )
        if self._G is not None:
            self._pass(rows(self._G), self._bounds, vis, inputs)
        else:
            self._one_shot(vis, inputs)
        self.stats["pass"] += 1
        for name, do in (("ambient", do_amb), ("diffuse", do_dif), ("specular", do_spec)):
            self.stats[name] += int(bool(do))
        if keep:  # the sums recomputed now are the cached ones
            self._A, self._D = A if do_amb else self._A, D if do_dif else self._D
            if do_spec:
                self._S, self._spec_shininess = S, scene.material.shininess
                if opts[layout.O_STORE_LOBE]:
                    self._base, self._ws = None if flat else base, ws

    def _one_shot(self, vis, inputs) -> None:
        """A one-shot shader's pass: the kernel prepares each block of the caller's vertices as
        it reaches it (:func:`~explorer.shading.prepared.vertices`: no prepared copy). Normals
        outside NORMAL_RANGE, which that pass finds, are scaled into it and the pass runs
        again; NaN or infinite ones raise check_finite's error naming the first, no colours."""
        for scaled in (False, True):  # (scaled ones lie inside: the second pass is the last)
            src = vertices(self._P, self._N, self._centre, self._scale, self._k.dtype)
            bounds = chunk_bounds(src, self._k) if self._plan.cull and self.cull else _NO_BOUNDS
            if not self._pass(src, bounds, vis, inputs) or scaled:
                break
            check_finite("normals", self._N)
            self._N = scale_normals(self._N)

    def _pass(self, src, bounds, vis, inputs) -> int:
        """The kernel over every vertex (+ the float64 redo of marked float32 lanes): ``src``
        the geometry (the prepared G, or :func:`~explorer.shading.prepared.vertices`),
        ``bounds`` its chunk bounds; ``vis``, ``inputs`` (lights, options, surface, constants,
        sums, lobes). Returns how many blocks hold a normal outside NORMAL_RANGE (vertices
        only): when some do, nothing more is done (the colours are not to be used)."""
        lights, opts, surface, k, sums, lobes = inputs
        marks = K.Marks(self._redo, self._redo_count)
        cull = bounds if self._plan.cull and self.cull else bounds[:, :0]
        args = (src, lights, opts, surface, k, sums, lobes, vis, marks, self._out)
        outside = K.shade(*args, K.Culling(cull, self._culled))
        if outside:
            return outside
        self._scaled = True  # (every normal was tested: inside NORMAL_RANGE)
        self.stats["culled"] += int(self._culled.sum())  # vertex-lights skipped
        if opts[layout.O_TRACK]:  # the ambiguous lanes again, in float64
            src64 = vertices(self._P, self._N, self._centre, self._scale, np.float64)
            params64, flags, view64 = self._params_for(np.float64)
            surface64 = kernel_surface(self._scene.material, self._aconst, np.float64)
            loops64 = K.loop_table(np.float64, K.pass_loops(flags, opts))
            fix = (K.Lights(params64, flags, view64, loops64), opts, surface64, self._k64)
            self.stats["fixup_vertices"] += K.fixup(
                marks, src64, *fix, sums, lobes, vis, self._out, _NO_BOUNDS
            )
        return 0


def _shadowed(plan: Plan) -> list[bool]:
    """Which lights the plan casts shadow rays for, one bool per light."""
    return [bool(plan.shadows and lp.shadows) for lp in plan.lights]


def _compiled_now(tier: str | None, model: str) -> bool:
    """Whether a shader prepares the compiled geometry with its vertices (and leaves their test
    for NaN and inf to those passes): the compiled tier serves its passes (``tier``; None:
    :mod:`explorer.shading.tiers` has the kernels loaded) and computes ``model``."""
    if tier == "numpy" or model not in COMPILED_MODELS:
        return False
    return tier == "compiled" or tiers.loaded()


def kept_sums(shader: Shader) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The light sums as a :class:`Shader` keeps them, without the copies its ``terms`` make
    (the term strip's recompose, :func:`explorer.shading.strip.shader_strip_bytes`):
    ``(aconst, sums)``. ``aconst`` (3,) in the working precision is the constant ambient
    ``terms`` adds to ``sums["ambient"]`` (in that precision; zeros on the numpy tier,
    whose ambient sum holds it); ``sums``: ``ambient`` (n, 3), ``diffuse`` and
    ``specular`` (n, 3) or (n, 1) grey (every channel that value), and ``specular_f90``
    under ``threejs``. Computes what is missing first (as ``terms`` does); read-only."""
    if not shader.keep:
        raise ExplorerError("terms need a Shader with keep=True")
    if shader._served == "numpy":
        ready = shader._np is not None
    else:
        kept = (shader._A, shader._D, shader._S)
        ready = shader._served == "compiled" and all(x is not None for x in kept)
    if not ready or shader._colors is None:
        shader._update(force=(True, True, True))
    if shader._served == "numpy":
        sums = {k: _readonly(v.astype(shader._T, copy=False)) for k, v in shader._np.items()}
        return _readonly(np.zeros(3, shader._T)), sums
    sums = {"ambient": shader._A, "diffuse": shader._D, "specular": shader._S}
    return _readonly(shader._aconst.astype(shader._T)), sums


def stored_terms(aconst, A, D, S, n: int, dtype) -> dict[str, np.ndarray]:
    """The compiled tier's sums as :attr:`Shader.terms` gives them: (n, 3) read-only each, the
    constant ambient ``aconst`` (3,) added to the per-vertex ambient ``A``, sums not computed
    (None) as zeros, grey sums (n, 1) shown as (n, 3) (every channel the same, a view)."""
    ambient = np.broadcast_to(aconst.astype(dtype), (n, 3)).copy()
    if A is not None:
        ambient += A
    zero = np.zeros((n, 1), dtype)
    out = {
        "ambient": ambient,
        "diffuse": zero if D is None else D,
        "specular": zero if S is None else S,
    }
    return {k: _readonly(np.broadcast_to(v, (n, 3))) for k, v in out.items()}


def invalidated(new: Scene, old: Scene) -> set[str]:
    """The cached work (:data:`explorer.shading.effects.LEVELS`) that the differences between
    two scenes invalidate: :data:`UPDATES` and each effect's setting."""
    updates = UPDATES + tuple((e.setting, e.invalidates) for e in EFFECTS)
    return {level for setting, level in updates if setting(new) != setting(old)}


def ambient_constant(scene: Scene, plan: Plan) -> np.ndarray:
    """Scene ambient plus the ambient of lights whose weight is constant, (3,) float64."""
    a = np.asarray(scene.ambient, dtype=np.float64).copy()
    for lp, light in zip(plan.lights, scene.lights, strict=True):
        if lp.ambient and not lp.varying_weight:
            a += lp.factor * np.asarray(light.ambient)
    return a


def light_params(scene: Scene, plan: Plan, centre, scale) -> tuple:
    """Kernel inputs for the lights and viewer in the normalised frame ``centre`` (3,),
    ``scale``, float64: params (L, N_PARAMS) and flags (L,) int32, one row per light (each light
    packs its own: :meth:`explorer.core.lights.Light.kernel_row`, then each effect adds its
    slots and flags), and the view (3,): the eye, or V for an infinite viewer."""
    if scene.viewer.local:
        view = np.asarray(scene.viewer.framed(centre, scale))  # (the far-viewer policy)
    else:
        view = np.asarray(scene.viewer.to_viewer, dtype=np.float64)
    constant_h = scene.model == "blinn" and not scene.viewer.local and not plan.force_all
    halfway_view = tuple(float(v) for v in view) if constant_h else None
    values = [plan.effect(e.name) for e in EFFECTS]
    specular_scale = 1.0
    for e, v in zip(EFFECTS, values, strict=True):
        specular_scale *= e.specular_factor(v)
    rows, flags = [], []
    for lp, light in zip(plan.lights, scene.lights, strict=True):
        row, f = light.kernel_row(
            lp, centre, scale, halfway_view=halfway_view, specular_scale=specular_scale
        )
        for e, v in zip(EFFECTS, values, strict=True):
            f = e.pack(v, lp.effect(e.name), lp, row, f)
        rows.append(row)
        flags.append(f)
    params = np.array(rows, dtype=np.float64).reshape(len(rows), R.N_PARAMS)
    return params, np.array(flags, np.int32), view


def kernel_shininess(shininess: float, dtype):
    """The specular exponent the kernels receive in ``dtype`` (float32 or float64): the
    shininess, but at least :data:`~explorer.core.tolerances.MIN_KERNEL_SHININESS` when it is
    positive (so that a lobe base of 0 stays 0**n = 0, as on the numpy tier: the float64 kernels
    halve the exponent, and a float32 subnormal may round to 0); 0 stays 0 (0**0 = 1)."""
    t = np.dtype(dtype).type
    if shininess <= 0.0:
        return t(shininess)
    return max(t(shininess), t(tol.MIN_KERNEL_SHININESS[np.dtype(dtype).name]))


def kernel_surface(material: Material, aconst, dtype) -> K.Surface:
    """The kernels' :class:`~explorer.shading.kernels.Surface` of ``material`` in ``dtype``
    (the float64 redo of a float32 pass), with the scene's constant ambient ``aconst``."""
    shininess = kernel_shininess(material.shininess, dtype)
    return K.Surface(material_vector(material, dtype), aconst, shininess)


def pass_options(scene: Scene, plan: Plan, flat: bool, do: tuple, dtype) -> np.ndarray:
    """(N_OPTS,) int64 options of a shading pass that follow from the scene and plan: viewer,
    sidedness, model, flat lobe, the sums ``do`` = (ambient, diffuse, specular) recomputed,
    ambiguity tracking (float32) and V rows for an effect that reads V (Fresnel); storing and
    clamping are the caller's."""
    opts = np.zeros(layout.N_OPTS, np.int64)
    opts[layout.O_LOCAL] = scene.viewer.local
    opts[layout.O_TWO_SIDED] = scene.two_sided
    opts[layout.O_PHONG] = scene.model == "phong"
    opts[layout.O_FLAT] = flat
    opts[layout.O_DO_AMB], opts[layout.O_DO_DIF], opts[layout.O_DO_SPEC] = do
    opts[layout.O_COMPOSE] = 1
    opts[layout.O_TRACK] = dtype is np.float32
    opts[layout.O_VIEW] = any(e.needs_view(plan.effect(e.name)) for e in EFFECTS)
    return opts


class _Memory:
    """Arrays reused instead of allocated: colour buffers, and the memory of invalidated sums.

    Reuse saves the page faults of fresh memory (three 12 MB sums per light change at 1M
    vertices). An array is reused only once no array handed out (``colors``, ``terms``) still
    views it: colours already returned are never overwritten."""

    def __init__(self):
        self.colours: list[np.ndarray] = []
        self.spares: list[np.ndarray] = []
        self.lobes: tuple = ()

    def lobe_rows(self, shape: tuple, dtype) -> tuple:
        """(base, ws) rows of a lobe store, ``shape`` (L, n), or (L, 0): none stored; the memory
        of the previous ones (now invalid: a pass that stores lobes writes every row the lobe
        kernel reads) when it has that shape (no page faults)."""
        if not self.lobes or self.lobes[0].shape != shape or self.lobes[0].dtype != dtype:
            self.lobes = (np.empty(shape, dtype), np.empty(shape, dtype))
        return self.lobes

    def retire(self, *sums) -> None:
        """Keep the memory of invalidated sums for the next pass (see :meth:`fresh`)."""
        for a in sums:
            if a is not None and len(self.spares) < 5:
                self.spares.append(a)

    def fresh(self, shape: tuple, dtype) -> np.ndarray:
        """An array for a sum being recomputed, (n, 3), or (n, 1) for a grey one (every channel
        the same, see :func:`explorer.shading.kernels.grey_pass`): retired memory of that shape
        that nothing views any more, else a new one."""
        for i in range(len(self.spares)):
            buf = self.spares[i]  # (not enumerate: its tuple would hold one more reference)
            # references: the list, ``buf``, getrefcount's argument
            if buf.shape == shape and buf.dtype == dtype and sys.getrefcount(buf) <= 3:
                return self.spares.pop(i)
        return np.empty(shape, dtype)

    def colour_buffer(self, n: int, dtype) -> np.ndarray:
        """An (n, 3) colour buffer that no array handed out still views."""
        for buf in self.colours:
            # references: the list, the loop variable, getrefcount's argument
            if sys.getrefcount(buf) <= 3:
                return buf
        buf = np.empty((n, 3), dtype)
        if len(self.colours) < 2:
            self.colours.append(buf)
        return buf


def _check_options(precision, tier):
    """Check a shader's ``precision`` and ``tier`` arguments; returns the tier."""
    _typed("precision", precision, str, f"one of {PRECISIONS}")
    if precision not in PRECISIONS:
        raise ExplorerError(f"precision must be one of {PRECISIONS}, got {precision!r}")
    if tier not in (None, *TIERS):
        raise ExplorerError(f"tier must be None or one of {TIERS}, got {tier!r}")
    return tier


def material_vector(material: Material, dtype) -> np.ndarray:
    """(12,) the material's emission, ambient, diffuse and specular colours, as the kernels
    read them."""
    m = material
    return np.concatenate([m.emission, m.ambient, m.diffuse, m.specular]).astype(dtype)


def _typed(name: str, value, types, wanted: str, not_types=()):
    """``value`` if it is one of ``types`` and none of ``not_types``, else an
    :class:`ExplorerTypeError` naming the argument ``name`` and what it must be (``wanted``)."""
    if not isinstance(value, types) or isinstance(value, not_types):
        shown = f"{value!r:.60}"
        raise ExplorerTypeError(f"{name} must be {wanted}, got {type(value).__name__} {shown}")
    return value
