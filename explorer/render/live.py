"""Per-pixel shading, live: the engine evaluated at every pixel of an interactive view, cached.

A :class:`LivePixels` draws the per-pixel picture of one mesh for any scene, camera and size
(:meth:`LivePixels.frame`), and keeps what the next frame can reuse:

- **the G-buffer** (:class:`GBuffer`): which triangle each pixel shows, from VTK's own
  rasterisation (:class:`explorer.render.faceids.FaceIdRenderer`: coverage equals the per-vertex
  picture's), then the float64 surface point and interpolated normal of each covered pixel
  (:func:`explorer.render.perpixel.raster_hits`). Made once per camera, mesh or size change
  (counted: :attr:`LivePixels.gbuffers`).
- **the light sums** of the covered pixels, in one :class:`explorer.shading.shader.Shader` over
  the hit points (its ``set_geometry``): a material change recomposes the cached sums with no
  light pass, a shininess change reruns only the specular (then only the lobe), a light change
  reruns what it invalidates, exactly as the per-vertex shader does (counted:
  :attr:`LivePixels.light_passes`, and the shader's own ``stats``).
- **the display** (:func:`explorer.shading.display.shown`, then
  :func:`~explorer.shading.display.to_bytes`): the same path as every picture of the project,
  so the bytes are those of ``phong-explorer render --per-pixel`` (which draws through this
  class) for that mesh, camera and size.

Shadows: a light that casts them is traced by the engine's own shadow rays over the mesh's
triangles, as :func:`explorer.render.perpixel.point_colors` does: the shader's points are then
the mesh's vertices followed by the pixels' hit points (the triangles index the first ones).

Per-group materials (``materials=``, a mesh file's own): each pixel in its triangle's group's
material, recomposed from the same sums (:func:`explorer.shading.display.grouped_colors`).

Texture maps (issue 40): every map of the material at each pixel, on the same kept sums
(:mod:`explorer.render.pixelmaps`): a colour or scalar map composes with no light pass; a
``bump_map`` tilts the normals the shader shades (new light sums when it changes).

VTK is imported only when a G-buffer is made (the face-id window).
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from explorer.core.errors import Cancelled, ExplorerError
from explorer.render.camera import Camera, camera_for
from explorer.render.images import check_size
from explorer.render.offscreen import BACKGROUND
from explorer.render.perpixel import METHODS as PERPIXEL_METHODS
from explorer.render.perpixel import Hits, raster_hits
from explorer.render.pixelmaps import PixelMaps, any_maps
from explorer.shading.display import engine_clamps, grouped_colors, shown, to_bytes
from explorer.shading.shader import PRECISIONS, Shader

__all__ = ["METHODS", "GBuffer", "LivePixels", "PixelFrame", "picture"]

#: where a per-pixel picture's surface points come from (``render --per-pixel-method``):
#: "raster", the rasteriser's triangles (:class:`LivePixels`, the live view's picture), then
#: the per-pixel reference's methods (:func:`explorer.render.perpixel.hits`)
METHODS = ("raster", *PERPIXEL_METHODS)


@dataclass(frozen=True)
class PixelFrame:
    """One per-pixel picture.

    rgb : (h, w, 3) uint8, the background where not covered
    mask : (h, w) bool, covered pixels
    seconds : the time this frame took (G-buffer + shading + display)
    gbuffer_made : this frame made a new G-buffer
    """

    rgb: np.ndarray
    mask: np.ndarray
    seconds: float
    gbuffer_made: bool


@dataclass(frozen=True, eq=False)
class GBuffer:
    """What the pixels of one camera and size see of one mesh.

    camera, size : what it was made for
    hits : :class:`~explorer.render.perpixel.Hits` (method "raster"): the mask, and per covered
        pixel (row-major order) the triangle, its float64 barycentrics ``(u, v)``, the float64
        position and unit normal
    """

    camera: Camera
    size: tuple[int, int]
    hits: Hits

    @property
    def pixels(self) -> np.ndarray:
        """(k,) int64 the covered pixels' indices in the picture's row-major order (made on
        first use): pixel i of the hits is ``rgb.reshape(-1, 3)[pixels[i]]``."""
        if "_pixels" not in self.__dict__:
            object.__setattr__(self, "_pixels", np.flatnonzero(self.hits.mask))
        return self.__dict__["_pixels"]


class LivePixels:
    """Per-pixel pictures of one mesh, cached for interaction (see the module docstring).

    mesh : an :class:`explorer.geometry.meshes.Mesh` (:meth:`set_mesh` changes it)
    precision : "float64" (the exact path, the numbers of ``render --per-pixel``) or "float32"
        (the shader's fast path: within one level of float64)

    Counters: :attr:`gbuffers` (G-buffers made), :attr:`light_passes` (light passes of the
    per-pixel shader: a pass that computes light sums, not a compose or a lobe); :attr:`stats`
    has the shader's passes by kind. Call :meth:`close` (or use as a context manager) to close
    the face-id window.

    One thread at a time: a front end that draws frames in a worker keeps its LivePixels
    there (its face-id window is an OpenGL context of its own). Each pixel shows the nearest
    surface: a translucent material is not blended (as ``render --per-pixel``).
    """

    def __init__(self, mesh, *, precision: str = "float64"):
        if precision not in PRECISIONS:
            raise ExplorerError(f"precision must be one of {PRECISIONS}, got {precision!r}")
        self.precision = precision
        self.mesh = mesh
        self.gbuffers = 0
        self._faceids = None  # the face-id window (of self._gbuffer's size)
        self._gbuffer: GBuffer | None = None
        self._shader: Shader | None = None
        self._shader_key = None  # (G-buffer, with the mesh's vertices, clamped)
        self._retired: Counter = Counter()  # the stats of shaders replaced
        self._bg_key, self._bg = None, None  # the background picture kept (_background)
        self._maps = PixelMaps()  # the texture maps at the pixels (explorer.render.pixelmaps)
        self._normals = None  # the normals the shader has (the hits', or bumped)

    # -- life --------------------------------------------------------------------------------
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        """Close the face-id window (a later frame opens a new one)."""
        if self._faceids is not None:
            self._faceids.close()
            self._faceids = None

    def set_mesh(self, mesh) -> None:
        """A new mesh: the next frame makes a new G-buffer and new light sums."""
        if mesh is not self.mesh:
            self.mesh = mesh
            self._gbuffer = None

    # -- counters ----------------------------------------------------------------------------
    @property
    def stats(self) -> Counter:
        """The per-pixel shader's passes by kind (``pass``, ``ambient``, ``diffuse``,
        ``specular``, ``lobe``, ``compose``, ``numpy``...), over every shader this object made."""
        out = Counter(self._retired)
        if self._shader is not None:
            out.update(self._shader.stats)
        return out

    @property
    def light_passes(self) -> int:
        """How many light passes the per-pixel shader ran (compiled ``pass`` + numpy tier
        ``numpy``; a compose or a lobe alone is not one)."""
        s = self.stats
        return int(s["pass"] + s["numpy"])

    # -- frames ------------------------------------------------------------------------------
    def gbuffer(self, camera: Camera, size: Sequence[int]) -> tuple[GBuffer, bool]:
        """The G-buffer of ``camera`` and ``size`` (w, h): the kept one when it was made for
        them, else a new one. Returns (G-buffer, whether it was made now)."""
        w, h = check_size(size)
        g = self._gbuffer
        if g is not None and g.size == (w, h) and g.camera == camera:
            return g, False
        from explorer.render.faceids import FaceIdRenderer  # (VTK: only here)

        if self._faceids is not None and self._faceids.size != (w, h):
            self.close()
        if self._faceids is None:
            self._faceids = FaceIdRenderer((w, h))
        seen = self._faceids.render(self.mesh, camera)
        g = GBuffer(camera, (w, h), raster_hits(camera, (w, h), self.mesh, seen))
        self._gbuffer = g
        self.gbuffers += 1
        return g, True

    def frame(
        self,
        scene,
        camera: Camera,
        size: Sequence[int],
        *,
        materials=None,
        cancelled=None,
        background=None,
    ) -> PixelFrame:
        """The per-pixel picture of ``scene`` on the mesh through ``camera`` at ``size`` (w, h).

        materials : one Material per group of ``mesh.groups`` (a mesh file's own), or None:
            the scene's material everywhere
        cancelled : () -> bool, asked before the G-buffer, before the shading and while the
            shadow rays are cast (True: :class:`~explorer.core.errors.Cancelled`)
        background : RGB in [0, 1] where no surface is seen (default
            :data:`explorer.render.offscreen.BACKGROUND`)
        """
        t0 = time.perf_counter()
        _check(cancelled)
        g, made = self.gbuffer(camera, size)
        _check(cancelled)
        colors = self._colors(scene, g, materials, cancelled)
        rgb = self._background(g.size, BACKGROUND if background is None else background)
        if len(colors):
            # the engine's clamped colours are the display's (shown: the same array); a display
            # effect reads float64, as display_colors gives it the engine's colours
            c = colors if engine_clamps(scene) else np.asarray(colors, np.float64)
            rgb.reshape(-1, 3)[g.pixels] = to_bytes(shown(c, scene))
        return PixelFrame(rgb, g.hits.mask, time.perf_counter() - t0, made)

    def _background(self, size: tuple[int, int], background) -> np.ndarray:
        """A new (h, w, 3) uint8 picture of the background colour (copied from a kept one)."""
        key = (size, tuple(float(c) for c in background))
        if self._bg_key != key:
            w, h = size
            self._bg = np.empty((h, w, 3), np.uint8)
            self._bg[:] = to_bytes(np.asarray(key[1], np.float64)[None, :])[0]
            self._bg_key = key
        return self._bg.copy()

    def _colors(self, scene, g: GBuffer, materials, cancelled) -> np.ndarray:
        """The engine's colours (k, 3) of the G-buffer's pixels in the working precision
        (clamped or not, as :func:`~explorer.shading.display.display_colors` has them)."""
        h, mesh = g.hits, self.mesh
        k = len(h.positions)
        if k == 0:
            return np.zeros((0, 3))
        shadows = any(getattr(lt, "shadows", False) for lt in scene.lights)
        clamp = engine_clamps(scene)
        key = (g, shadows, clamp)
        if self._shader is None or self._shader_key[1:] != key[1:]:
            if self._shader is not None:
                self._retired.update(self._shader.stats)
            self._shader = None
        first = mesh.n_vertices if shadows else 0
        textured = any_maps((scene.material,) if materials is None else materials)
        parts = self._map_parts(g, scene, materials) if textured else []
        normals = self._maps.normals(h, mesh, parts) if textured else h.normals

        def geometry():  # the points shaded (after the mesh's vertices when they cast shadows)
            if not shadows:
                return h.positions, normals, None
            P = np.vstack([mesh.positions, h.positions])
            return P, np.vstack([mesh.normals, normals]), mesh.faces

        if self._shader is None:
            P, N, faces = geometry()
            kw = {"precision": self.precision, "clamp": clamp, "faces": faces}
            self._shader = Shader(scene, P, N, cancelled=cancelled, **kw)
        else:
            self._shader.cancelled = cancelled
            self._shader.set_scene(scene)
            if self._shader_key[0] is not g or self._normals is not normals:
                self._shader.set_geometry(*geometry())
        self._shader_key, self._normals = key, normals
        if textured:  # every map at each pixel, on the kept sums
            return self._maps.colors(self._shader, h, mesh, parts, first)
        if materials is None:
            c = self._shader.colors
        else:
            c = grouped_colors(self._shader, self._group_rows(g, materials, first), materials)
        return c[first:]

    def _map_parts(self, g: GBuffer, scene, materials) -> list:
        """[(rows of the hits, material)]: which pixels wear which material's maps."""
        if materials is None:
            return [(np.arange(len(g.hits.positions)), scene.material)]
        return list(zip(self._group_rows(g, materials, 0), materials, strict=True))

    def _group_rows(self, g: GBuffer, materials, first: int) -> list[np.ndarray]:
        """The shader's rows of each group's pixels (offset by ``first``, the mesh's vertices
        ahead of them when shadows are cast)."""
        groups, mesh = self.mesh.groups, self.mesh
        if groups is None or len(materials) != len(groups.names):
            n = 0 if groups is None else len(groups.names)
            raise ExplorerError(
                f"need one material per group of the mesh ({n}), got {len(materials)}"
            )
        of_hit = groups.of_vertex[np.asarray(mesh.faces, np.int64)[g.hits.triangles, 0]]
        every = np.arange(len(of_hit)) + first
        return [every[of_hit == i] for i in range(len(groups.names))]


def picture(
    scene, mesh, size: Sequence[int], *, camera=None, background=None, precision: str = "float64"
) -> PixelFrame:
    """``render --per-pixel``'s picture: one frame of a new :class:`LivePixels` of ``mesh``
    (its face-id window closed after).

    camera : default :func:`explorer.render.camera.camera_for` (scene, mesh, w / h), the camera
        of a per-vertex render of the same scene
    """
    w, h = check_size(size)
    camera = camera_for(scene, mesh, w / h) if camera is None else camera
    with LivePixels(mesh, precision=precision) as live:
        return live.frame(scene, camera, (w, h), background=background)


def _check(cancelled) -> None:
    if cancelled is not None and cancelled():
        raise Cancelled("the per-pixel frame was cancelled")
