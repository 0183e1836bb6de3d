"""The display pipeline: the engine's linear light sums to the colours and bytes people see.

One path for every picture the project makes (renders, the per-pixel reference, the window,
mesh exports)::

    colours (n, 3) linear, >= 0          the engine (clamp=False under hdr: engine_clamps)
      -> exposure and tone map            scenes with ``hdr`` (below); else clamp to [0, 1]
      -> sRGB encoding                    scenes with ``hdr``; OpenGL's clamp path is not encoded
      -> 8-bit                            :func:`to_bytes`, rounded to nearest

:func:`display` is the middle two steps, :func:`display_colors` (and :func:`vertex_colors` for a
mesh's vertices) the engine and :func:`display` together.

The engine's unclamped colours (``shade(..., clamp=False)``) are linear radiance-like values
``>= 0`` that may exceed 1 (several lights, an energy-conserving lobe, bright lights). A scene
with ``hdr: {exposure: E, tone_map: T}`` is displayed as::

    x = c · 2**E                      exposure in stops (E = 0: unchanged, +1: twice as bright)
    y = tone_map(x)                   into [0, 1]
    out = srgb_encode(y)              the exact sRGB OETF (IEC 61966-2-1)

Tone maps (:data:`TONE_MAPS`):

- ``clamp``: ``min(x, 1)`` (what OpenGL does; HDR then only adds exposure and sRGB);
- ``reinhard``: ``x / (1 + x)`` per channel (Reinhard et al. 2002, simple form): never clips,
  compresses highlights smoothly, darkens mid-tones (0.5 -> 0.33);
- ``aces``: Narkowicz's fit of the ACES filmic curve (2015),
  ``x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)`` clamped to [0, 1], with the input scaled by
  0.6 as in the original fit: contrasty mid-tones, highlights roll off to white.

The sRGB OETF: ``12.92·y`` for ``y <= 0.0031308``, else ``1.055·y^(1/2.4) - 0.055``.

The lecture notes' rule for HDR (keep ``kd + ks`` at most 1 per channel) is checked by
:func:`explorer.core.hdr.energy_warnings`.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from explorer.core.errors import ExplorerError
from explorer.core.hdr import HDR, TONE_MAPS
from explorer.geometry.meshes import Mesh
from explorer.shading.shader import shade

#: ACES (Narkowicz) input scale: the fit maps scene value 1/0.6 to about 0.8
ACES_INPUT_SCALE = 0.6


def expose(colors, exposure: float) -> np.ndarray:
    """colors · 2**exposure; colors : (..., 3) float >= 0."""
    return np.asarray(colors, np.float64) * (2.0 ** float(exposure))


def tone_map(x, name: str) -> np.ndarray:
    """One of :data:`TONE_MAPS` applied per channel: (..., 3) float >= 0 -> [0, 1]."""
    x = np.maximum(np.asarray(x, np.float64), 0.0)
    if name == "clamp":
        return np.minimum(x, 1.0)
    if name == "reinhard":
        return x / (1.0 + x)
    if name == "aces":
        a = x * ACES_INPUT_SCALE
        return np.clip(a * (2.51 * a + 0.03) / (a * (2.43 * a + 0.59) + 0.14), 0.0, 1.0)
    raise ValueError(f"tone map must be one of {TONE_MAPS}, got {name!r}")


def srgb_encode(y) -> np.ndarray:
    """The exact sRGB OETF: linear [0, 1] -> encoded [0, 1] (monotone, continuous)."""
    y = np.clip(np.asarray(y, np.float64), 0.0, 1.0)
    return np.where(y <= 0.0031308, 12.92 * y, 1.055 * np.power(y, 1.0 / 2.4) - 0.055)


def srgb_decode(v) -> np.ndarray:
    """The inverse of :func:`srgb_encode`."""
    v = np.clip(np.asarray(v, np.float64), 0.0, 1.0)
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def display(colors, hdr: HDR | None) -> np.ndarray:
    """The engine's colours (n, 3) -> display values in [0, 1].

    hdr : the scene's ``hdr`` (None: the engine clamped the colours, as OpenGL does, and they
        are shown as they are, the same array; else the unclamped sums go through exposure,
        tone map and sRGB encoding)
    """
    if hdr is None:
        return colors
    return srgb_encode(tone_map(expose(colors, hdr.exposure), hdr.tone_map))


def engine_clamps(scene) -> bool:
    """Whether the engine clamps the scene's colours (OpenGL's path): a scene without ``hdr``.
    A scene with ``hdr`` is shaded unclamped and shown through :func:`display`."""
    return scene.hdr is None


def display_colors(
    scene, positions, normals, *, faces=None, precision: str = "float64"
) -> np.ndarray:
    """Display colours of surface points under the scene: the engine's colours
    (:func:`explorer.shading.shader.shade`, clamped or not by :func:`engine_clamps`) through
    :func:`display`.

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
    return display(c, scene.hdr)


def vertex_colors(scene, mesh: Mesh, *, precision: str = "float64") -> np.ndarray:
    """Display colours of the mesh's vertices under the scene (:func:`display_colors`, the
    mesh's triangles included for shadows): (n, 3) float64 in [0, 1]. The renderer interpolates
    these (sRGB-encoded under ``hdr``) values across each triangle."""
    return display_colors(
        scene, mesh.positions, mesh.normals, faces=mesh.faces, precision=precision
    )


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
    _round_bytes(c.reshape(-1), rgb.reshape(-1))
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
