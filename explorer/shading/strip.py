"""The term strip: the lighting equation term by term, each as its own picture.

The lecture notes draw the equation as a row of pictures that add up::

    emission | ambient | diffuse | specular | sum
      e_m       a_m·A      d_m·D      s_m·S     e_m + a_m·A + d_m·D + s_m·S   (weighted)
      e_m         A          D          S       the same sum                  (raw)

``A``, ``D``, ``S`` are the per-vertex light sums a :class:`~explorer.shading.shader.Shader`
keeps (:attr:`~explorer.shading.shader.Shader.terms`): the strip recomposes them, no light
pass. ``weighted`` shows each term as it enters the colour (k·A, k·D, k·S); ``raw`` shows the
light sums alone, as glTF-Sample-Viewer's debug channels do (the material's coefficients set
to white). Under the ``threejs`` model the specular tile holds both parts of its specular term
(``s_m·S + specular_f90``; raw: ``S + specular_f90``, the term with a white specular colour).

The seam: :func:`compose_strip` takes the sums of any shading, ``(k, 3)`` rows of vertices or of
pixels alike (a per-pixel G-buffer's sums plug in where a shader's per-vertex ones do), and the
colours that shading shows, so the sum tile is the picture itself, bit for bit.

Each tile is what an 8-bit picture can show of its term: clamped to [0, 1] (or, under ``hdr``,
through the same exposure, tone map and sRGB encoding as the picture:
:func:`explorer.shading.display.shown`). Where the sum of the terms is more than 1 in a channel
the picture clamps it, so the 8-bit tiles add up to more than the sum tile: the strip's
``overflow`` mask marks those rows (gold's saturated highlight), and :func:`caption` says so.
Under ``hdr`` the mask marks where the display saturates instead (the tone map's output 1 for
an exposed value above 1: ``clamp`` clips there, ``aces`` from 0.6·x = 7.25, ``reinhard``
never). Plain numpy: no VTK.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from explorer.core.errors import ExplorerError
from explorer.core.material import Material
from explorer.core.scene import Scene
from explorer.shading import tiers
from explorer.shading.display import _strip_bytes, engine_clamps, shown, to_bytes
from explorer.shading.effects.hdr import expose, tone_map
from explorer.shading.shader import Shader, kept_sums

#: the strip's tiles, left to right (each the tile's label)
TERMS = ("emission", "ambient", "diffuse", "specular", "sum")
#: ``weighted``: each term as it enters the colour (k·A ...); ``raw``: the light sums alone
MODES = ("weighted", "raw")


@dataclass(frozen=True)
class Strip:
    """One strip, for ``k`` rows (vertices or pixels).

    terms : name (:data:`TERMS`) -> (k, 3) float64 linear values, unclamped; ``sum`` is the
        colour before any clamp (weighted terms add up to it)
    tiles : name -> (k, 3) float64 display values in [0, 1]; ``sum`` is the picture's own
        display colours (the colours given to :func:`compose_strip`, shown)
    overflow : (k,) bool, where the display clamped the sum (see the module docstring)
    mode : one of :data:`MODES`
    """

    terms: dict
    tiles: dict
    overflow: np.ndarray
    mode: str

    @property
    def overflow_fraction(self) -> float:
        """The fraction of rows the display clamped (0 for no rows)."""
        return float(self.overflow.mean()) if self.overflow.size else 0.0


def term_colors(material: Material, sums, mode: str = "weighted") -> dict[str, np.ndarray]:
    """The float terms of the strip from the light sums ``sums`` (``ambient``, ``diffuse``,
    ``specular``, and ``specular_f90`` under three.js; each (k, 3), as
    :attr:`~explorer.shading.shader.Shader.terms` gives them) and a material: name -> (k, 3)
    float64. ``sum`` is composed as :func:`explorer.shading.equation.compose_terms` composes
    (the same operations in the same order), unclamped."""
    if mode not in MODES:
        raise ExplorerError(f"strip mode must be one of {MODES}, got {mode!r}")
    m = material
    A = np.asarray(sums["ambient"], np.float64)
    D = np.asarray(sums["diffuse"], np.float64)
    S = np.asarray(sums["specular"], np.float64)
    f90 = sums.get("specular_f90")
    k = len(A)
    e = np.asarray(m.emission, np.float64)
    ka, kd, ks = (np.asarray(c, np.float64) for c in (m.ambient, m.diffuse, m.specular))
    weighted = {"ambient": ka * A, "diffuse": kd * D, "specular": ks * S}
    total = e + weighted["ambient"]  # the order of compose_terms
    total += weighted["diffuse"]
    total += weighted["specular"]
    if f90 is not None:
        f90 = np.asarray(f90, np.float64)
        total += f90
        weighted["specular"] = weighted["specular"] + f90
    out = {"emission": np.broadcast_to(e, (k, 3))}
    if mode == "weighted":
        out.update(weighted)
    else:
        out.update(ambient=A, diffuse=D, specular=S if f90 is None else S + f90)
    out["sum"] = total
    return out


def compose_strip(scene: Scene, sums, colors, mode: str = "weighted") -> Strip:
    """The strip of a shading: ``sums`` its light sums (see :func:`term_colors`), ``colors``
    (k, 3) the colours the engine gave for them (clamped or not as
    :func:`~explorer.shading.display.engine_clamps` says), the scene's material and display.
    Every term is recomposed; no light pass."""
    terms = term_colors(scene.material, sums, mode)
    total = terms["sum"]
    clamps = engine_clamps(scene)
    tiles = {}
    for name in TERMS[:-1]:
        t = terms[name]
        tiles[name] = shown(np.clip(t, 0.0, 1.0) if clamps else t, scene)
    tiles["sum"] = shown(np.asarray(colors, np.float64), scene)
    if clamps:
        overflow = np.any((total > 1.0) | (total < 0.0), axis=1)
    else:
        x = expose(total, scene.hdr.exposure)
        overflow = np.any((x > 1.0) & (tone_map(x, scene.hdr.tone_map) >= 1.0), axis=1)
    return Strip(terms, tiles, overflow, mode)


def shader_strip(shader: Shader, mode: str = "weighted") -> Strip:
    """The strip of a :class:`~explorer.shading.shader.Shader` (``keep=True``) in its current
    state: its cached sums recomposed (a sum the plan skipped is computed once, then kept)."""
    return compose_strip(shader.scene, shader.terms, shader.colors, mode)


def grouped_strip(shader: Shader, rows, materials, mode: str = "weighted") -> Strip:
    """The strip of a :class:`~explorer.shading.shader.Shader` (``keep=True``) whose vertices
    are drawn in several materials (a mesh file's groups): rows : one index array per group;
    materials : one Material per group. Each group's rows are :func:`shader_strip` of the
    shader with that group's material (its kept sums recomposed, as
    :func:`~explorer.shading.display.grouped_colors` makes the colours), so the sum tile is
    the picture of the mesh in its materials. The shader is left with its own material."""
    own = shader.scene.material
    n = shader.n
    terms = {name: np.zeros((n, 3), np.float64) for name in TERMS}
    tiles = {name: np.zeros((n, 3), np.float64) for name in TERMS}
    overflow = np.zeros(n, np.bool_)
    try:
        for r, material in zip(rows, materials, strict=True):
            if not len(r):
                continue
            shader.set_material(material)
            part = shader_strip(shader, mode)
            for name in TERMS:
                terms[name][r] = part.terms[name][r]
                tiles[name][r] = part.tiles[name][r]
            overflow[r] = part.overflow[r]
    finally:
        shader.set_material(own)
    return Strip(terms, tiles, overflow, mode)


def strip_bytes(scene: Scene, sums, colors, mode: str = "weighted", aconst=None) -> tuple:
    """The strip's tiles as the pictures take them: ``(tiles, overflow)``, tiles (5, k, 3)
    uint8 in :data:`TERMS`' order, each ``to_bytes`` of :func:`compose_strip`'s tile, and its
    overflow mask (k,) bool; the same values, in one compiled pass over the sums (what the
    front ends redraw on each change: <= 2 ms at 100k vertices, benchmarks/bench_strip.py).
    Under ``hdr``, or while the compiled tier is not loaded, :func:`compose_strip` computes
    them (numpy). ``aconst``: (3,) a constant ambient the sums' ambient leaves out
    (:func:`~explorer.shading.shader.kept_sums`), added in the sums' precision."""
    if mode not in MODES:
        raise ExplorerError(f"strip mode must be one of {MODES}, got {mode!r}")
    colors = np.asarray(colors)
    if not engine_clamps(scene) or not tiers.loaded():
        if aconst is not None:  # (as Shader.terms adds it: in the sums' precision)
            ambient = np.asarray(sums["ambient"])
            sums = dict(sums, ambient=ambient + np.asarray(aconst).astype(ambient.dtype))
        strip = compose_strip(scene, sums, colors, mode)
        return np.stack([to_bytes(strip.tiles[t]) for t in TERMS]), strip.overflow
    T = np.float32 if colors.dtype == np.float32 else np.float64
    m = scene.material
    ek = np.array([m.emission, m.ambient, m.diffuse, m.specular], np.float64)
    f90 = sums.get("specular_f90")
    rows = [_kernel_rows(sums[k], T) for k in ("ambient", "diffuse", "specular")]
    f90 = np.zeros((0, 3), T) if f90 is None else _kernel_rows(f90, T)
    n = len(colors)
    out, over = np.empty((len(TERMS), n, 3), np.uint8), np.empty(n, np.bool_)
    base = np.zeros(3, T) if aconst is None else np.asarray(aconst, T)
    _strip_bytes(
        ek,
        mode == "raw",
        _kernel_rows(base[None, :], T)[0],
        *rows,
        f90,
        _kernel_rows(colors, T),
        out,
        over,
    )
    return out, over


def shader_strip_bytes(shader: Shader, mode: str = "weighted") -> tuple:
    """:func:`strip_bytes` of a :class:`~explorer.shading.shader.Shader` (``keep=True``) in its
    current state: its cached sums as it keeps them (no copies), no light pass."""
    aconst, sums = kept_sums(shader)
    return strip_bytes(shader.scene, sums, shader.colors, mode, aconst)


def _kernel_rows(v, dtype) -> np.ndarray:
    """A sum as the strip's kernel takes it: (k, 3) C-contiguous, or (k, 1) for a grey one
    (every channel one value: the shader's (k, 1) sums shown as (k, 3) views), read-only."""
    v = np.asarray(v)
    if v.ndim == 2 and v.shape[1] == 3 and v.strides[1] == 0:
        v = v[:, :1]
    v = np.ascontiguousarray(v, dtype=dtype).view()
    v.flags.writeable = False  # one signature for every caller's array
    return v


def light_scene(scene: Scene, index: int) -> Scene:
    """The scene with its light ``index`` alone and no scene ambient or emission: what that
    light adds to the colour (a strip row per light)."""
    if not 0 <= index < len(scene.lights):
        raise ExplorerError(f"light index must be 0 to {len(scene.lights) - 1}, got {index}")
    material = scene.material.replace(emission=(0.0, 0.0, 0.0))
    return scene.replace(lights=(scene.lights[index],), ambient=(0.0, 0.0, 0.0), material=material)


def caption(strip: Strip) -> str:
    """One line for the person: how much of the sum the picture clamped, and what it means."""
    f = strip.overflow_fraction
    if f == 0.0:
        return "overflow: none: the 8-bit tiles add up to the sum tile"
    return (
        f"overflow: {100.0 * f:.1f}% of the surface: there the terms add up to more than 1 "
        "and the sum tile saturates (clamped), so the 8-bit tiles add up to more than it"
    )
