"""The lighting equation in plain numpy, float64: every term for every light, no plan.

This is the engine's specification in code. It computes each term whether or not it can be
non-zero, so the planned fast path (:mod:`explorer.shading.kernels`) is tested against it. It
applies the same documented policies (:mod:`explorer.core.tolerances`) for the cases the equation
leaves undefined.

    c = e_m + a_m·a_scene
      + Σ_i att_i · spot_i · ( a_m·a_i
                               + vis_i · ( max(N·L_i, 0)·d_m·d_i
                                           + f_i·F_i·E·max(N·H_i, 0)^n · s_m·s_i ) )

with the per-vertex weights of the effects (:mod:`explorer.shading.effects`, each
:meth:`~explorer.shading.effects.base.Effect.weights`, multiplied in the order of ``EFFECTS``):
``vis_i`` the shadow visibility (1 without ``shadows: true`` or without faces; rays from every
vertex, even on a convex mesh), ``F_i`` Schlick's Fresnel weight (1 without ``fresnel``) and
``E`` the energy-conserving normalisation (1 without ``energy_conserving``).

The ``threejs`` model is three.js's MeshPhongMaterial (``BRDF_BlinnPhong`` in three.js's
``src/renderers/shaders/ShaderChunk/bsdfs.glsl.js``, ``RE_Direct_BlinnPhong`` in
``lights_phong_pars_fragment.glsl.js``), with each light's intensity π times the OpenGL one (what
three.js's legacy light mode did by itself), so that its diffuse ``(d_m/π)·π·(N·L)·d_i`` and
ambient terms are OpenGL's and only the specular term differs::

    f_i·F_i·E·(N·H)^n·s_m·s_i   becomes   max(N·L, 0)·(n/2 + 1)/4·max(N·H, 0)^n·F·s_i
    F = s_m·(1 - g) + g,   g = 2^((-5.55473·(V·H) - 6.98316)·(V·H))

(D = (n/2 + 1)/π·(N·H)^n, G = 1/4, Schlick's F on the specular colour toward 1 with Epic's
exponential form of (1 - V·H)^5, times π·(N·L)). ``g`` does not depend on the material, so the
specular term splits into ``s_m·specular + specular_f90``: even a black specular colour shows a
highlight at grazing angles. The material's ``fresnel`` and ``energy_conserving`` do not apply
(the model has both built in); the ambient term keeps the material's ambient colour (three.js has
none: an AmbientLight there reflects the diffuse colour; ``presets show --as threejs`` says so).
"""

from __future__ import annotations

import numpy as np

from explorer.core import tolerances as tol
from explorer.core.lights import unit_rows
from explorer.core.scene import Scene
from explorer.geometry.frame import check_vertices, frame_of
from explorer.shading.effects import EFFECTS, Incident

#: three.js's F_Schlick: g = 2^((A·c + B)·c) for c = V·H, Epic's fit of (1 - c)^5 (bsdfs.glsl.js)
THREEJS_FRESNEL = (-5.55473, -6.98316)


def equation_terms(
    scene: Scene, positions, normals, faces=None, *, visibility=None
) -> dict[str, np.ndarray]:
    """Per-vertex light sums, independent of the material.

    Returns ``ambient``, ``diffuse``, ``specular`` : (n, 3) float64 such that the colour is
    ``e_m + a_m·ambient + d_m·diffuse + s_m·specular`` (``ambient`` includes the scene ambient),
    and for the ``threejs`` model ``specular_f90`` (n, 3) too, added as it is (the part of
    Schlick's F that does not depend on the specular colour).
    The specular sum uses the scene material's shininess and the scene's model.
    faces : (m, 3) int triangles for shadows, or None
    visibility : a sequence of L rows, each light's shadow visibility already cast, (n,) 1 lit
        and 0 shadowed (any numeric type), or None for a light that casts no shadows (the
        engine's numpy tier passes the rows it keeps per light), instead of rays from
        ``faces``; (L, n) works too; (L, 0) or None: none
    """

    P, N = check_vertices(positions, normals)
    world = P.astype(np.float64)
    P = P.astype(np.float64)
    N = N.astype(np.float64)
    n = len(P)
    centre, scale = frame_of(P)
    P = (P - centre) / scale

    # normals: unit, or zero where absent (tolerances.NORMAL_EPS)
    N, _ = unit_rows(N, tol.NORMAL_EPS, np.zeros(3))

    # viewer direction V per vertex (toward the viewer)
    if scene.viewer.local:
        eye = np.asarray(scene.viewer.framed(centre, scale))  # (the far-viewer policy)
        V, _ = unit_rows(eye - P, tol.POINT_EPS, N)  # eye at the vertex: look along N
    else:
        V = np.broadcast_to(np.asarray(scene.viewer.to_viewer, dtype=np.float64), (n, 3))

    if scene.two_sided:  # back-facing vertices are lit as the back face: N -> -N
        N = np.where((np.einsum("ij,ij->i", N, V) < 0.0)[:, None], -N, N)

    shininess = scene.material.shininess
    ambient = np.tile(np.asarray(scene.ambient, dtype=np.float64), (n, 1))
    diffuse = np.zeros((n, 3))
    specular = np.zeros((n, 3))
    threejs = scene.model == "threejs"
    f90 = np.zeros((n, 3)) if threejs else None
    rows = [None] * len(scene.lights) if visibility is None else list(visibility)
    for i, light in enumerate(scene.lights):
        L, _, w = light.incident(P, N, centre, scale)  # what arrives and from where
        dif_w, spec_w = _effect_weights(scene, light, Incident(world, faces, L, V), w)
        vis = rows[i]
        if vis is not None and len(vis):  # shadows cast by the caller
            dif_w, spec_w = dif_w * vis, spec_w * vis

        ndl = np.einsum("ij,ij->i", N, L)
        lit = ndl > 0.0  # f_i: specular only where N·L > 0
        if scene.model == "phong":
            R = 2.0 * ndl[:, None] * N - L
            base = np.einsum("ij,ij->i", R, V)
        else:
            H = L + V
            h2 = np.einsum("ij,ij->i", H, H)
            ok = h2 > tol.HALFWAY_EPS2  # H undefined for L = -V: N·H taken as 0
            base = np.where(ok, np.einsum("ij,ij->i", N, H) / np.sqrt(np.where(ok, h2, 1.0)), 0.0)
        base = np.where(base >= tol.LOBE_BASE_MIN, base, 0.0)  # noise below it: 0
        lobe = base**shininess  # numpy: 0.0 ** 0.0 == 1.0
        s_i = np.asarray(light.specular)

        ambient += w[:, None] * np.asarray(light.ambient)  # a_i (attenuated)
        diffuse += (dif_w * np.maximum(ndl, 0.0))[:, None] * np.asarray(light.diffuse)  # d_i
        if not threejs:
            specular += (spec_w * lit * lobe)[:, None] * s_i  # s_i
            continue
        g = threejs_fresnel(np.einsum("ij,ij->i", V, L))  # 1 - g weighs s_m, g weighs 1
        d = spec_w * np.maximum(ndl, 0.0) * (shininess / 2.0 + 1.0) / 4.0 * lobe  # π·(N·L)·D·G
        specular += (d * (1.0 - g))[:, None] * s_i  # s_m·(1 - g)·s_i
        f90 += (d * g)[:, None] * s_i  # g·s_i
    out = {"ambient": ambient, "diffuse": diffuse, "specular": specular}
    if threejs:
        out["specular_f90"] = f90
    return out


def threejs_fresnel(v_dot_l) -> np.ndarray:
    """three.js's Schlick weight toward 1, ``g = 2^((A·c + B)·c)`` with ``c = V·H`` (``A, B`` =
    :data:`THREEJS_FRESNEL`), for unit L and V with cosine ``v_dot_l`` between them: (n,)
    float64. ``V·H = sqrt((1 + V·L) / 2)``; for L = -V (H undefined) c = 0 and g = 1."""
    c = np.sqrt(np.maximum((1.0 + np.asarray(v_dot_l, np.float64)) * 0.5, 0.0))
    a, b = THREEJS_FRESNEL
    return np.exp2((a * c + b) * c)


def _effect_weights(scene: Scene, light, at: Incident, w: np.ndarray):
    """The light's weights on its diffuse and specular terms: ``w`` (n,) times each effect's
    weight, in the order of ``EFFECTS``. Returns two (n,) float64."""
    dif_w, spec_w = w, w
    for e in EFFECTS:
        d, s = e.weights(scene, light, at)
        if d is not None:
            dif_w = dif_w * d
        if s is not None:
            spec_w = spec_w * s
    return dif_w, spec_w


def equation_shade(
    scene: Scene, positions, normals, *, clamp: bool = True, faces=None
) -> np.ndarray:
    """Colours (n, 3) float64 by the full equation (see module docstring)."""
    return compose_terms(scene.material, equation_terms(scene, positions, normals, faces), clamp)


def compose_terms(material, terms, clamp: bool) -> np.ndarray:
    """Colours (n, 3) float64 from the sums ``terms`` of :func:`equation_terms` (ambient,
    diffuse, specular, and specular_f90 when present, each (n, 3)) and a material: clamped to
    [0, 1] when ``clamp``."""
    m = material
    c = np.asarray(m.emission, np.float64)  # e_m
    c = c + np.asarray(m.ambient) * terms["ambient"]  # a_m·(a_scene + Σ w·a_i)
    c += np.asarray(m.diffuse) * terms["diffuse"]  # d_m·Σ w·vis·(N·L)·d_i
    c += np.asarray(m.specular) * terms["specular"]  # s_m·Σ w·vis·f·(N·H)^n·s_i
    if "specular_f90" in terms:
        c += terms["specular_f90"]  # threejs: Σ w·vis·(N·L)·D·G·g·s_i
    if clamp:
        np.clip(c, 0.0, 1.0, out=c)
    return c
