"""A per-vertex picture against the per-pixel reference of the same view.

A per-vertex picture (:mod:`explorer.render.offscreen`: the engine lights the vertices, VTK
interpolates the colours across each triangle) is compared with the per-pixel reference of the
same camera (:mod:`explorer.render.perpixel`: the engine lights the exact surface point under
each pixel centre). Both are 8-bit pictures; the error of a pixel is the largest difference of
its three channels in 1/255 levels. Only pixels the object covers in *both* pictures count (a
coarse polygon covers fewer pixels than the sphere it approximates; the background is never
compared). Per picture:

- ``rmse`` : root mean square of the channel differences over the compared pixels;
- ``max`` : the largest pixel error ("every pixel within ``max`` levels");
- ``peak`` : the error at the highlight peak, the pixel where the reference's specular light
  is largest.

A difference of 1 level is rounding (both pictures round to 8 bits), so 1 level is the floor
any method can reach. The window's difference view uses :func:`compare_view` (or a
:class:`ViewComparer`) and :func:`heat_map`; the benchmark (:mod:`explorer.analysis.benchmark`)
uses :func:`compare` and :func:`coverage`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from explorer.core.errors import Cancelled, ExplorerError
from explorer.render.camera import camera_for
from explorer.render.faceids import MAX_FACES, FaceIdRenderer
from explorer.render.images import check_size
from explorer.render.offscreen import OffscreenRenderer
from explorer.render.perpixel import is_unit_sphere, raster_hits, reference, reference_of
from explorer.shading.display import group_vertex_colors, vertex_colors
from explorer.shading.tiers import loaded


@dataclass(frozen=True, eq=False)
class Comparison:
    """A per-vertex picture against the per-pixel reference of the same view.

    levels : (h, w) int error of each pixel (largest channel difference, 1/255 levels), 0
        outside ``mask``
    mask : (h, w) bool, the compared pixels (covered in both pictures)
    rmse, max : over the compared pixels (channels)
    peak : error at the highlight peak (None when the reference has no highlight or the
        per-vertex picture does not cover it)
    vertex_image, reference_image : the two (h, w, 3) uint8 pictures
    """

    levels: np.ndarray
    mask: np.ndarray
    rmse: float
    max: int
    peak: int | None
    vertex_image: np.ndarray
    reference_image: np.ndarray

    def metric(self, name: str) -> float | None:
        return {"rmse": self.rmse, "max": self.max, "peak": self.peak}[name]


def channel_max(image: np.ndarray) -> np.ndarray:
    """(h, w) the largest of each pixel's three channels of an (h, w, 3) picture (elementwise
    over the channel planes: a reduction over the short last axis is many times slower)."""
    return np.maximum(np.maximum(image[..., 0], image[..., 1]), image[..., 2])


def compare(vertex_image, reference, coverage, *, peak: bool = True) -> Comparison:
    """Compare a per-vertex picture with a per-pixel reference.

    vertex_image : (h, w, 3) uint8 from the renderer
    reference : a :class:`~explorer.render.perpixel.Reference` of the same camera and size
    coverage : (h, w) bool, pixels the per-vertex picture's mesh covers (:func:`coverage`)
    peak : False: leave ``peak`` None (the reference's specular sums are then not computed)
    """
    img = np.asarray(vertex_image)
    ref_img = reference.image()
    if img.shape != ref_img.shape:
        raise ExplorerError(f"pictures differ in size: {img.shape} and {ref_img.shape}")
    mask = np.asarray(coverage, bool) & reference.mask
    diff = np.abs(img.astype(np.int16) - ref_img.astype(np.int16))
    levels = channel_max(diff).astype(np.int64)
    levels[~mask] = 0
    d = diff[mask].astype(np.float64)
    rmse = float(np.sqrt(np.mean(d * d))) if d.size else 0.0
    worst = int(levels.max()) if mask.any() else 0
    at_peak = None
    p = reference.peak_index() if peak else None
    if p is not None and mask[p]:
        at_peak = int(levels[p])
    return Comparison(levels, mask, rmse, worst, at_peak, img, ref_img)


def coverage(renderer, scene, mesh, camera) -> np.ndarray:
    """(h, w) bool: the pixels ``mesh`` covers in a render by ``renderer`` (an
    :class:`~explorer.render.offscreen.OffscreenRenderer` with a black background), drawn white."""
    white = np.ones((mesh.n_vertices, 3))
    img = renderer.render(_opaque(scene), mesh, white, camera=camera)
    return channel_max(img) > 127


def _opaque(scene):
    """``scene`` with an opaque material: translucent materials are compared as if opaque."""
    return scene.replace(material=scene.material.replace(opacity=1.0))


class ViewComparer:
    """Reusable off-screen windows for :func:`compare_view` (a window toggling its heat
    map pays for the OpenGL contexts once). Use as a context manager, or call :meth:`close`.

    size : (width, height) of the pictures compared
    """

    def __init__(self, size: Sequence[int]):

        self.size = check_size(size)
        self._picture = OffscreenRenderer(self.size)
        self._cover = OffscreenRenderer(self.size, (0, 0, 0))
        self._faces = FaceIdRenderer(self.size)  # (its window opens on first use)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        self._picture.close()
        self._cover.close()
        self._faces.close()

    def compare(self, scene, mesh, *, camera=None, colors=None, method: str = "auto",
                cancelled=None, peak: bool = True, materials=None):  # fmt: skip
        """See :func:`compare_view`."""

        w, h = self.size
        if camera is None:
            camera = camera_for(scene, mesh, w / h)
        if rasterised(method, mesh):
            seen = self._faces.render(mesh, camera)
            hits = raster_hits(camera, (w, h), mesh, seen)
            ref = reference_of(scene, mesh, hits, materials=materials, cancelled=cancelled)
            cov = seen >= 0
        else:
            ref = reference(scene, mesh, (w, h), camera=camera, method=method,
                            cancelled=cancelled, materials=materials)  # fmt: skip
            cov = None
        if colors is None:
            colors = (vertex_colors(scene, mesh) if materials is None
                      else group_vertex_colors(scene, mesh, materials))  # fmt: skip
        _check(cancelled)
        img = self._picture.render(_opaque(scene), mesh, colors, camera=camera)
        if cov is None:
            cov = coverage(self._cover, scene, mesh, camera)
        return compare(img, ref, cov, peak=peak)


def rasterised(method: str, mesh) -> bool:
    """Whether :meth:`ViewComparer.compare` finds the pixels' surface points from a picture of
    triangle indices (:mod:`explorer.render.faceids`) rather than rays: ``method`` "raster", or
    "auto" for a mesh that is no built-in sphere while the compiled ray kernels are not loaded
    (a fresh install: the numpy tier's rays take seconds for a window-sized view)."""
    if method == "raster":
        return True
    return method == "auto" and not loaded() and not is_unit_sphere(mesh) and (
        mesh.n_faces <= MAX_FACES)  # fmt: skip


def _check(cancelled) -> None:
    if cancelled is not None and cancelled():
        raise Cancelled("the comparison was cancelled")


def compare_view(scene, mesh, size: Sequence[int], *, camera=None, colors=None,
                 method: str = "auto", cancelled=None, materials=None) -> Comparison:  # fmt: skip
    """The per-pixel difference of a view (the window's difference view).

    scene, mesh : what is shown
    size : (width, height) of the pictures compared
    camera : an :class:`explorer.render.camera.Camera` (default
        :func:`explorer.render.camera.camera_for`); for a live VTK camera use
        :func:`explorer.render.camera.camera_from_vtk`
    colors : (n, 3) float, the vertex colours shown (default: shaded as the renderer shades them)
    method : the per-pixel reference's (:func:`explorer.render.perpixel.hits`), or "raster":
        the surface points from a picture of triangle indices (see :func:`rasterised`, which
        also says when "auto" takes it)
    cancelled : () -> bool, asked between chunks of the reference's rays and before the
        pictures are drawn; when it returns True the work stops with
        :class:`~explorer.core.errors.Cancelled` (a window's worker cancels a stale view)
    materials : one Material per group of ``mesh.groups`` when the view shows a mesh file's own
        materials (:func:`explorer.render.perpixel.reference`; the default ``colors`` are then
        :func:`explorer.shading.display.group_vertex_colors`)

    Renders the per-vertex picture and the coverage off-screen, so the window's own overlays
    never enter the comparison; :class:`ViewComparer` keeps the windows for repeated calls.
    Translucent materials are compared as if opaque.
    """
    with ViewComparer(size) as v:
        return v.compare(scene, mesh, camera=camera, colors=colors, method=method,
                         cancelled=cancelled, materials=materials)  # fmt: skip


#: the heat map's colour ramp: 0 levels black, then blue, green, yellow, red, white at ``vmax``
_RAMP = np.array(
    [[0, 0, 0], [0, 0, 255], [0, 200, 0], [255, 255, 0], [255, 0, 0], [255, 255, 255]],
    np.float64,
)  # fmt: skip


def _ramp(lv: np.ndarray, vmax: float) -> np.ndarray:
    """(..., 3) uint8 colours of the levels ``lv`` (float64) on the heat map's ramp."""
    t = np.where(
        lv <= 0.0, 0.0, 1.0 + (len(_RAMP) - 2) * np.log(np.maximum(lv, 1.0)) / np.log(vmax)
    )
    t = np.clip(t, 0.0, len(_RAMP) - 1.0)
    i = np.minimum(t.astype(np.int64), len(_RAMP) - 2)
    f = (t - i)[..., None]
    return np.rint(_RAMP[i] * (1.0 - f) + _RAMP[i + 1] * f).astype(np.uint8)


def heat_map(levels, mask=None, *, vmax: float = 16.0, background=(0, 0, 0)) -> np.ndarray:
    """A heat map of per-pixel errors: (h, w, 3) uint8.

    levels : (h, w) errors in 1/255 levels; mask : (h, w) bool pixels to colour (others get
    ``background``, 0-255 RGB)
    vmax : the error shown white; the ramp is logarithmic: 0 black, 1 level blue, then green,
        yellow, red up to ``vmax`` (so 1-level rounding noise stays dark and a missed
        highlight glows)
    """
    if vmax <= 1.0:
        raise ExplorerError(f"heat map vmax must be above 1 level, got {vmax}")
    lv = np.asarray(levels)
    bg = np.asarray(background, np.uint8)
    if lv.dtype.kind in "iu" and lv.size and 0 <= lv.min() and lv.max() <= 255:
        # whole levels: one colour each, looked up; row 256 is the background
        table = np.vstack([_ramp(np.arange(256.0), vmax), bg[None, :]])
        return table[lv if mask is None else np.where(np.asarray(mask, bool), lv, 256)]
    out = _ramp(lv.astype(np.float64), vmax)
    if mask is not None:
        out[~np.asarray(mask, bool)] = bg
    return out
