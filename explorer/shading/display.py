"""The display pipeline: the engine's linear light sums to the colours and bytes people see.

One path for every picture the project makes (renders, the per-pixel reference, the window,
mesh exports)::

    colours (n, 3) linear, >= 0          the engine (unclamped when a display effect needs it:
                                         engine_clamps)
      -> each display effect             the HDR display (exposure, tone map, sRGB:
                                         explorer.shading.effects.hdr); else clamped to [0, 1]
                                         by the engine, as OpenGL does, and not encoded
      -> 8-bit                            :func:`to_bytes`, rounded to nearest

:func:`shown` is the middle step (every effect's
:meth:`~explorer.shading.effects.base.Effect.display`, in the order of ``EFFECTS``),
:func:`display_colors` (and :func:`vertex_colors` for a mesh's vertices) the engine and
:func:`shown` together.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from explorer.core.errors import ExplorerError
from explorer.geometry import kernelcache  # noqa: F401 - before the decorators: the cache key
from explorer.geometry.meshes import Mesh
from explorer.shading import tiers
from explorer.shading.effects import EFFECTS
from explorer.shading.shader import Shader, shade

__all__ = [
    "display_colors",
    "engine_clamps",
    "group_vertex_colors",
    "grouped_colors",
    "shown",
    "to_bytes",
    "vertex_colors",
]


def engine_clamps(scene) -> bool:
    """Whether the engine clamps the scene's colours (OpenGL's path): no display effect of the
    scene needs them unclamped (a scene with ``hdr`` does)."""
    return all(e.clamps(scene) for e in EFFECTS)


def shown(colors, scene) -> np.ndarray:
    """The engine's colours (n, 3) (clamped or not by :func:`engine_clamps`) through every
    display effect of the scene: (n, 3) display values in [0, 1] (the same array when no effect
    changes them)."""
    for e in EFFECTS:
        colors = e.display(colors, scene)
    return colors


def display_colors(
    scene, positions, normals, *, faces=None, precision: str = "float64"
) -> np.ndarray:
    """Display colours of surface points under the scene: the engine's colours
    (:func:`explorer.shading.shader.shade`, clamped or not by :func:`engine_clamps`) through
    :func:`shown`.

    positions, normals : (n, 3) float
    faces : (m, 3) int triangles over ``positions`` (shadow rays need them), or None
    Returns (n, 3) float64 in [0, 1].
    """
    c = shade(
        scene,
        positions,
        normals,
        precision=precision,
        clamp=engine_clamps(scene),
        faces=faces,
    )
    return shown(c, scene)


def vertex_colors(scene, mesh: Mesh, *, precision: str = "float64") -> np.ndarray:
    """Display colours of the mesh's vertices under the scene (:func:`display_colors`, the
    mesh's triangles included for shadows): (n, 3) float64 in [0, 1]. The renderer interpolates
    these (sRGB-encoded under ``hdr``) values across each triangle."""
    return display_colors(
        scene, mesh.positions, mesh.normals, faces=mesh.faces, precision=precision
    )


def group_vertex_colors(scene, mesh: Mesh, materials, *, precision: str = "float64") -> np.ndarray:
    """Display colours of the mesh's vertices, each group of ``mesh.groups`` in its own
    material (:func:`vertex_colors` per group): (n, 3) float64 in [0, 1].

    materials : one :class:`~explorer.core.material.Material` per name of ``mesh.groups``
    The light sums are computed once (a :class:`~explorer.shading.shader.Shader` keeps them);
    each material only recomposes them, and the shininess lobe when it changes.
    """
    groups = mesh.groups
    if groups is None or len(materials) != len(groups.names):
        n = 0 if groups is None else len(groups.names)
        raise ExplorerError(f"need one material per group of the mesh ({n}), got {len(materials)}")
    shader = Shader(
        scene,
        mesh.positions,
        mesh.normals,
        precision=precision,
        clamp=engine_clamps(scene),
        faces=mesh.faces,
    )
    rows = [groups.vertices(g) for g in range(len(groups.names))]
    return shown(grouped_colors(shader, rows, materials), scene)


def grouped_colors(shader: Shader, rows, materials) -> np.ndarray:
    """A shader's colours (n, 3) float64 with each group of vertices in its own material:
    the light sums are computed once, each material recomposes them (and re-runs the lobe when
    its shininess differs). rows : one index array per group; materials : one Material per
    group. The shader is left with its own scene's material."""
    own = shader.scene.material
    out = np.zeros((shader.n, 3), np.float64)
    for r, material in zip(rows, materials, strict=True):
        if len(r):
            shader.set_material(material)
            out[r] = shader.colors[r]
    shader.set_material(own)
    return out


def to_bytes(colors, opacity: float | None = None, *, out=None) -> np.ndarray:
    """Display colours in [0, 1] as 8-bit values, rounded to nearest (half to even) in float64,
    so float32 colours round exactly as their float64 values.

    colors : (n, 3) float
    opacity : adds an alpha column of ``opacity`` (then (n, 4))
    out : (n, 3) uint8 array to write into (VTK's colour array, in place), without ``opacity``
    Returns (n, 3) or (n, 4) uint8 (``out`` when given).
    """
    c = np.asarray(colors)
    if c.dtype != np.float32:
        c = c.astype(np.float64, copy=False)
    c = np.ascontiguousarray(c)
    if out is not None and opacity is not None:
        raise ExplorerError("to_bytes: out= takes no opacity")
    direct = (
        out is not None
        and out.dtype == np.uint8
        and out.shape == c.shape
        and out.flags.c_contiguous
        and out.flags.writeable
    )
    rgb = out if direct else np.empty(c.shape, np.uint8)
    if tiers.loaded():
        x = c.reshape(-1).view()
        x.flags.writeable = False  # one signature for every caller's array
        _round_bytes(x, rgb.reshape(-1))
    else:  # the numpy tier: the same float64 steps
        v = np.clip(c.astype(np.float64) * 255.0, 0.0, 255.0)
        np.rint(v, out=v)
        rgb[...] = v.astype(np.uint8)
    if out is not None:
        if not direct:
            out[...] = rgb
        return out
    if opacity is None:
        return rgb
    alpha = np.full((len(rgb), 1), int(round(float(opacity) * 255.0)), np.uint8)
    return np.hstack([rgb, alpha])


@nb.njit(cache=True, nogil=True)
def _round_bytes(x, out):
    """out[i] = x[i]·255 clamped to [0, 255] and rounded to nearest, in float64.
    x : (k,) float32 or float64; out : (k,) uint8."""
    for i in range(x.size):
        v = np.float64(x[i]) * 255.0
        if v < 0.0:
            v = 0.0
        elif v > 255.0:
            v = 255.0
        out[i] = np.uint8(np.rint(v))


@nb.njit(cache=True, nogil=True, inline="always")
def _byte(x):
    """x·255 clamped to [0, 255] and rounded to nearest, in float64 (as :func:`_round_bytes`;
    min and max, not branches: the strip's loop runs three times faster)."""
    return np.uint8(np.rint(min(max(x * 255.0, 0.0), 255.0)))


@nb.njit(cache=True, nogil=True)
def _strip_bytes(ek, raw, aconst, A, D, S, F, colors, out, over):
    """The term strip's tiles as bytes in one pass (:func:`explorer.shading.strip.strip_bytes`
    is its caller and its spec): ek (4, 3) float64 the emission, then the ambient, diffuse and
    specular colours; raw: the tiles show the sums alone; aconst (3,) the constant
    ambient added to A in the sums' precision (as Shader.terms adds it); A, D, S (k, 1) grey or
    (k, 3) sums, F (k, 3) three.js's specular_f90 or (0, 3); colors (k, 3) the engine's
    (clamped) colours; out (5, k, 3) uint8 the tiles in the strip's order, over (k,) bool: where
    the weighted sum leaves [0, 1]. Every value in float64, summed in compose_terms' order."""
    f90 = F.shape[0] > 0
    wa3, wd3, ws3 = A.shape[1] == 3, D.shape[1] == 3, S.shape[1] == 3  # (else grey: one column)
    e0, e1, e2 = _byte(ek[0, 0]), _byte(ek[0, 1]), _byte(ek[0, 2])
    for i in range(colors.shape[0]):
        flag = False
        out[0, i, 0], out[0, i, 1], out[0, i, 2] = e0, e1, e2
        for c in range(3):
            a = np.float64(aconst[c] + A[i, c if wa3 else 0])
            d = np.float64(D[i, c if wd3 else 0])
            s = np.float64(S[i, c if ws3 else 0])
            wa, wd, ws = ek[1, c] * a, ek[2, c] * d, ek[3, c] * s
            t = ek[0, c] + wa
            t += wd
            t += ws
            if f90:
                f = np.float64(F[i, c])
                t += f
                ws += f
                s += f
            if t > 1.0 or t < 0.0:
                flag = True
            out[1, i, c] = _byte(a if raw else wa)
            out[2, i, c] = _byte(d if raw else wd)
            out[3, i, c] = _byte(s if raw else ws)
            out[4, i, c] = _byte(np.float64(colors[i, c]))
        over[i] = flag
