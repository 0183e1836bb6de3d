"""What accuracy costs in time: per-vertex shading against the per-pixel reference, measured.

A per-vertex picture (:mod:`explorer.render`: the engine lights the vertices, VTK interpolates
the colours across each triangle) is compared with the per-pixel reference of the same view
(:mod:`explorer.render.perpixel`: the engine lights the exact surface point under each pixel
centre). Both are 8-bit pictures from the same camera; the error of a pixel is the largest
difference of
its three channels in 1/255 levels. Only pixels the object covers in *both* pictures count (a
coarse polygon covers fewer pixels than the sphere it approximates; the background is never
compared). Per picture:

- ``rmse`` : root mean square of the channel differences over the compared pixels;
- ``max`` : the largest pixel error ("every pixel within ``max`` levels");
- ``peak`` : the error at the highlight peak, the pixel where the reference's specular light
  is largest.

:func:`run_bench` (``phong-explorer bench accuracy``) measures a table of them with the
shading and render times; the table ships with the package (``explorer/data/accuracy.json``)
and answers :func:`mesh_for_error`. The GUI's comparison uses :func:`compare_view`,
:func:`heat_map` and :func:`advice`.

Numbers here are 1/255 levels of the 8-bit pictures; a difference of 1 level is rounding (both
pictures round to 8 bits), so 1 level is the floor any method can reach.
"""

from __future__ import annotations

import json
import math
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from explorer import data
from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError
from explorer.core.lights import DirectionalLight
from explorer.core.presets import builtin_dir, load_material_file
from explorer.core.scene import Scene
from explorer.core.version import __version__
from explorer.geometry.meshes import Mesh, get_mesh
from explorer.render.camera import camera_for, sphere_camera
from explorer.render.images import check_size
from explorer.render.offscreen import OffscreenRenderer
from explorer.render.perpixel import (
    is_unit_sphere,
    point_colors,
    reference,
    sphere_hits,
)
from explorer.render.vtk import headless_egl
from explorer.shading.display import vertex_colors
from explorer.shading.equation import reference_shade
from explorer.shading.shader import shade

# -- what the bench measures -----------------------------------------------------------------

#: the bench's one light: directional, white, from the upper left front. A generic direction
#: (not along the view or a mesh axis) so the highlight does not sit on a vertex of every
#: tessellation.
BENCH_LIGHT = (-0.4, 0.6, 1.0)
#: (label, built-in preset, shininess override or None): low to high shininess
BENCH_MATERIALS: tuple[tuple[str, str, float | None], ...] = (
    ("white rubber", "white_rubber", None),  # shininess 10
    ("chrome", "chrome", None),  # 76.8
    ("polished silver", "polished_silver", None),  # 89.6
    ("chrome n=1000", "chrome", 1000.0),
)
#: built-in sphere tessellations measured: (mesh name, resolutions)
BENCH_MESHES: tuple[tuple[str, tuple[int, ...]], ...] = (
    ("sphere", (8, 12, 16, 24, 32, 48, 64, 96, 128, 192, 256, 384, 512, 768, 1024)),
    ("icosphere", (0, 1, 2, 3, 4, 5, 6, 7)),
)
#: picture side (pixels, square pictures) of the main table, and the sides of the size sweep
MAIN_SIDE = 400
SIZE_SWEEP = (100, 200, 400, 800)
#: the quick run (tests): small pictures, few meshes, two materials, one repeat
QUICK_MATERIALS = BENCH_MATERIALS[:2]
QUICK_MESHES: tuple[tuple[str, tuple[int, ...]], ...] = (
    ("sphere", (8, 16, 32, 64)),
    ("icosphere", (1, 2, 3)),
)
QUICK_SIDES = (96,)
#: metrics of a row, and the error criteria :func:`mesh_for_error` understands
METRICS = ("max", "rmse", "peak")

#: variant -> (model, exponent factor, reference model, path); the per-pixel reference uses
#: the material's shininess n with the reference model. "blinn 4n" is Blinn with exponent 4n
#: against Phong's n: the notes' (N·H)^(4n) ≈ (R·V)^n.
VARIANTS: dict[str, tuple[str, float, str, str]] = {
    "blinn": ("blinn", 1.0, "blinn", "float64"),
    "blinn float32": ("blinn", 1.0, "blinn", "float32"),
    "blinn plan off": ("blinn", 1.0, "blinn", "plan off"),
    "phong": ("phong", 1.0, "phong", "float64"),
    "blinn 4n": ("blinn", 4.0, "phong", "float64"),
}
#: variants measured at every size of the sweep (the others only at the main size)
SWEEP_VARIANTS = ("blinn", "phong")
#: adaptive refinement (:func:`refine_highlights`, Blinn float64, main size only): the base
#: mesh and the edge-midpoint thresholds (levels)
ADAPTIVE_BASE = ("icosphere", 3)
ADAPTIVE_THRESHOLDS = (8.0, 4.0, 2.0, 1.0)
QUICK_ADAPTIVE_THRESHOLDS = (4.0,)

DATA_FILE = "accuracy.json"
TABLE_VERSION = 1


def bench_scene(material, model: str = "blinn"):
    """The bench's scene: ``material``, one white directional light (:data:`BENCH_LIGHT`),
    OpenGL's scene ambient, the default infinite viewer on +z (parallel projection)."""

    return Scene(material=material, model=model, lights=(DirectionalLight(to_light=BENCH_LIGHT),))


def bench_material(preset: str, shininess: float | None = None):
    """A built-in preset (never a user's file of the same name), optionally re-exponented."""

    m = load_material_file(builtin_dir() / f"{preset}.yaml")
    return m if shininess is None else m.replace(shininess=float(shininess))


# -- comparing two pictures ------------------------------------------------------------------


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


def compare(vertex_image, reference, coverage) -> Comparison:
    """Compare a per-vertex picture with a per-pixel reference.

    vertex_image : (h, w, 3) uint8 from the renderer
    reference : a :class:`explorer.Reference` of the same camera and size
    coverage : (h, w) bool, pixels the per-vertex picture's mesh covers (:func:`coverage`)
    """
    img = np.asarray(vertex_image)
    ref_img = reference.image()
    if img.shape != ref_img.shape:
        raise ExplorerError(f"pictures differ in size: {img.shape} and {ref_img.shape}")
    mask = np.asarray(coverage, bool) & reference.mask
    diff = np.abs(img.astype(np.int16) - ref_img.astype(np.int16))
    levels = diff.max(axis=2).astype(np.int64)
    levels[~mask] = 0
    d = diff[mask].astype(np.float64)
    rmse = float(np.sqrt(np.mean(d * d))) if d.size else 0.0
    worst = int(levels.max()) if mask.any() else 0
    peak = None
    p = reference.peak_index()
    if p is not None and mask[p]:
        peak = int(levels[p])
    return Comparison(levels, mask, rmse, worst, peak, img, ref_img)


def coverage(renderer, scene, mesh, camera) -> np.ndarray:
    """(h, w) bool: the pixels ``mesh`` covers in a render by ``renderer`` (an
    :class:`~explorer.render.offscreen.OffscreenRenderer` with a black background), drawn white."""
    white = np.ones((mesh.n_vertices, 3))
    img = renderer.render(scene.replace(material=scene.material.replace(opacity=1.0)), mesh,
                          white, camera=camera)  # fmt: skip
    return img.max(axis=2) > 127


class ViewComparer:
    """Reusable off-screen windows for :func:`compare_view` (a GUI toggling its heat map
    pays for the OpenGL contexts once). Use as a context manager, or call :meth:`close`.

    size : (width, height) of the pictures compared
    """

    def __init__(self, size: Sequence[int]):

        self.size = check_size(size)
        self._picture = OffscreenRenderer(self.size)
        self._cover = OffscreenRenderer(self.size, (0, 0, 0))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        self._picture.close()
        self._cover.close()

    def compare(self, scene, mesh, *, camera=None, colors=None, method: str = "auto"):
        """See :func:`compare_view`."""

        w, h = self.size
        if camera is None:
            camera = camera_for(scene, mesh, w / h)
        if colors is None:
            colors = vertex_colors(scene, mesh)
        opaque = scene.replace(material=scene.material.replace(opacity=1.0))
        img = self._picture.render(opaque, mesh, colors, camera=camera)
        cov = coverage(self._cover, scene, mesh, camera)
        ref = reference(scene, mesh, (w, h), camera=camera, method=method)
        return compare(img, ref, cov)


def compare_view(scene, mesh, size: Sequence[int], *, camera=None, colors=None,
                 method: str = "auto") -> Comparison:  # fmt: skip
    """The per-pixel difference of a view (the GUI's heat map toggle).

    scene, mesh : what is shown; colors : (n, 3) the vertex colours shown (default: shaded
    as the renderer shades them)
    size : (width, height) of the picture to compare camera : an
    :class:`explorer.render.camera.Camera` (default :func:`explorer.render.camera.camera_for`);
        for a live VTK camera use :func:`explorer.camera_from_vtk`
    method : the per-pixel reference's (:func:`explorer.hits`)
    Renders the per-vertex picture and the coverage off-screen, so the GUI's own overlays
    never enter the comparison; :class:`ViewComparer` keeps the windows for repeated calls.
    Translucent materials are compared as if opaque.
    """
    with ViewComparer(size) as v:
        return v.compare(scene, mesh, camera=camera, colors=colors, method=method)


#: the heat map's colour ramp: 0 levels black, then blue, green, yellow, red, white at ``vmax``
_RAMP = np.array(
    [[0, 0, 0], [0, 0, 255], [0, 200, 0], [255, 255, 0], [255, 0, 0], [255, 255, 255]],
    np.float64,
)  # fmt: skip


def heat_map(levels, mask=None, *, vmax: float = 16.0, background=(0, 0, 0)) -> np.ndarray:
    """A heat map of per-pixel errors: (h, w, 3) uint8.

    levels : (h, w) errors in 1/255 levels; mask : (h, w) bool pixels to colour (others get
    ``background``, 0-255 RGB)
    vmax : the error shown white; the ramp is logarithmic: 0 black, 1 level blue, then green,
        yellow, red up to ``vmax`` (so 1-level rounding noise stays dark and a missed
        highlight glows)
    """
    lv = np.asarray(levels, np.float64)
    if vmax <= 1.0:
        raise ExplorerError(f"heat map vmax must be above 1 level, got {vmax}")
    t = np.where(
        lv <= 0.0, 0.0, 1.0 + (len(_RAMP) - 2) * np.log(np.maximum(lv, 1.0)) / np.log(vmax)
    )
    t = np.clip(t, 0.0, len(_RAMP) - 1.0)
    i = np.minimum(t.astype(np.int64), len(_RAMP) - 2)
    f = (t - i)[..., None]
    out = np.rint(_RAMP[i] * (1.0 - f) + _RAMP[i + 1] * f).astype(np.uint8)
    if mask is not None:
        out[~np.asarray(mask, bool)] = np.asarray(background, np.uint8)
    return out


# -- timing, progress, machine ----------------------------------------------------------------


def median_ms(fn: Callable[[], object], repeats: int) -> float:
    """Median wall time of ``fn()`` in milliseconds over ``repeats`` calls (after one untimed
    warm-up call, which compiles and fills caches)."""
    fn()
    times = []
    for _ in range(max(1, int(repeats))):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1000.0 * statistics.median(times)


class Progress:
    """A one-line progress bar on a terminal (stderr); silent when the stream is not a TTY."""

    def __init__(self, total: int = 1, stream=None, width: int = 30, enabled: bool | None = None):
        self.total = max(1, int(total))
        self.done = 0
        self.stream = sys.stderr if stream is None else stream
        self.width = width
        if enabled is None:
            enabled = bool(getattr(self.stream, "isatty", lambda: False)())
        self.enabled = enabled
        self.t0 = time.perf_counter()

    def step(self, label: str = "") -> None:
        self.done += 1
        if not self.enabled:
            return
        frac = min(1.0, self.done / self.total)
        bar = "#" * int(round(frac * self.width))
        elapsed = time.perf_counter() - self.t0
        eta = elapsed / frac - elapsed if frac > 0 else 0.0
        self.stream.write(
            f"\r[{bar:<{self.width}}] {100 * frac:3.0f}%  {elapsed:5.0f}s  eta {eta:4.0f}s  "
            f"{label[:40]:<40}"
        )
        self.stream.flush()

    def close(self) -> None:
        if self.enabled:
            self.stream.write("\n")
            self.stream.flush()


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.lower().startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def _memory() -> str | None:
    try:
        with open("/proc/meminfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("MemTotal:"):
                    kb = int(line.split()[1])
                    return f"{kb / 1024 / 1024:.1f} GiB"
    except (OSError, ValueError, IndexError):
        pass
    return None


def _versions() -> dict[str, str]:
    from importlib import metadata

    out = {"python": platform.python_version()}
    for dist in ("numpy", "numba", "vtk", "pyvista", "trimesh"):
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[dist] = "not installed"

    out["phong-explorer"] = __version__
    return out


def _opengl() -> dict[str, str]:
    """OpenGL vendor/renderer/version of an off-screen window (pyvista's GPU report)."""
    try:
        import pyvista as pv

        with headless_egl():
            info = pv.GPUInfo()
        return {"vendor": info.vendor, "renderer": info.renderer, "version": info.version}
    except Exception:  # noqa: BLE001 - only informative
        return {}


def machine_info(opengl: bool = False) -> dict:
    """The machine a measurement ran on: CPU, cores, memory, OS, versions, OpenGL, load."""
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        usable = os.cpu_count()
    info = {
        "cpu": _cpu_model(),
        "cores": os.cpu_count(),
        "usable_cores": usable,
        "memory": _memory(),
        "os": platform.platform(),
        "versions": _versions(),
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
    }
    if opengl:
        info["opengl"] = _opengl()
    try:
        info["load_before"] = [round(x, 2) for x in os.getloadavg()]
    except OSError:
        pass
    return info


# -- the bench --------------------------------------------------------------------------------


@dataclass(frozen=True)
class BenchConfig:
    """What :func:`run_bench` measures.

    materials : (label, preset, shininess or None) rows; meshes : (name, resolutions)
    sides : picture sides (square pictures); ``main_side`` gets every variant, the others
        :data:`SWEEP_VARIANTS`
    repeats : timed calls per median
    adaptive : thresholds of the adaptive rows (main side only; empty: none)
    """

    materials: tuple = BENCH_MATERIALS
    meshes: tuple = BENCH_MESHES
    sides: tuple[int, ...] = SIZE_SWEEP
    main_side: int = MAIN_SIDE
    repeats: int = 5
    quick: bool = False
    adaptive: tuple[float, ...] = ADAPTIVE_THRESHOLDS

    @classmethod
    def quick_run(cls) -> BenchConfig:
        return cls(QUICK_MATERIALS, QUICK_MESHES, QUICK_SIDES, QUICK_SIDES[0], 1, True,
                   QUICK_ADAPTIVE_THRESHOLDS)  # fmt: skip


class _References:
    """Per-pixel references of one picture size and camera, computed once per (material,
    model)."""

    def __init__(self, camera, size):

        self.camera, self.size = camera, size
        self._sphere = get_mesh("sphere", 8)  # names the closed-form sphere
        self._cache: dict = {}

    def __call__(self, material, model: str):

        key = (material, model)
        if key not in self._cache:
            scene = bench_scene(material, model)
            self._cache[key] = reference(
                scene, self._sphere, self.size, camera=self.camera, method="sphere"
            )
        return self._cache[key]


def _shade_fn(scene, path: str, P, N) -> Callable[[], np.ndarray]:
    """The timed shading call of a variant's path."""
    if path == "plan off":
        return lambda: reference_shade(scene, P, N)
    return lambda: shade(scene, P, N, precision=path)


def _measure_mesh(r, refs, cov, mesh, mats, main: bool, repeats: int) -> list[dict]:
    """Every variant of every material on one mesh at one picture size."""
    rows = []
    camera = refs.camera
    for label, preset, material in mats:
        n = material.shininess
        f64 = None
        for variant, (model, factor, ref_model, path) in VARIANTS.items():
            if not main and variant not in SWEEP_VARIANTS:
                continue
            scene = bench_scene(material.replace(shininess=n * factor), model)
            shade = _shade_fn(scene, path, mesh.positions, mesh.normals)
            colors = shade()
            shade_ms = median_ms(shade, repeats)
            img = r.render(scene, mesh, colors, camera=camera)
            cmp = compare(img, refs(material, ref_model), cov)
            row = {
                "material": label,
                "preset": preset,
                "shininess": n,
                "variant": variant,
                "model": model,
                "exponent": n * factor,
                "reference": ref_model,
                "path": path,
                "mesh": mesh.name,
                "vertices": mesh.n_vertices,
                "side": refs.size[0],
                "shade_ms": round(shade_ms, 4),
                "rmse": round(cmp.rmse, 4),
                "max": cmp.max,
                "peak": cmp.peak,
            }
            if variant == "blinn":
                f64 = colors
            elif path in ("float32", "plan off") and f64 is not None:
                row["vs_float64"] = round(float(np.abs(colors - f64).max()) * 255, 9)
            rows.append(row)
    return rows


def _measure_per_pixel(refs, mats, repeats: int) -> tuple[list[dict], list[dict]]:
    """The per-pixel reference's own cost, and Blinn 4n against Phong n per pixel."""

    cost, match = [], []
    camera, size = refs.camera, refs.size
    for label, _preset, material in mats:
        n = material.shininess
        scene = bench_scene(material, "blinn")

        def per_pixel_shade(s=scene):
            h = sphere_hits(camera, size)
            return point_colors(s, h.positions, h.normals)

        ms = median_ms(per_pixel_shade, repeats)
        ref = refs(material, "blinn")
        cost.append(
            {
                "material": label,
                "shininess": n,
                "side": size[0],
                "pixels": int(ref.mask.sum()),
                "shade_ms": round(ms, 4),
            }
        )
        blinn4 = refs(material.replace(shininess=4.0 * n), "blinn")
        cmp = compare(blinn4.image(), refs(material, "phong"), blinn4.mask)
        match.append(
            {
                "material": label,
                "shininess": n,
                "side": size[0],
                "rmse": round(cmp.rmse, 4),
                "max": cmp.max,
                "peak": cmp.peak,
            }
        )
    return cost, match


def _measure_adaptive(r, rc, refs, mats, thresholds, repeats: int) -> list[dict]:
    """Adaptive refinement of :data:`ADAPTIVE_BASE` (Blinn, float64): the shading time is
    refinement plus shading (a refined mesh is only good for the scene it was refined for)."""

    base_name, base_res = ADAPTIVE_BASE
    base = get_mesh(base_name, base_res)
    rows = []
    for label, preset, material in mats:
        scene = bench_scene(material, "blinn")
        for thr in thresholds:

            def make(s=scene, t=thr):
                mesh = refine_highlights(s, base, t)
                return mesh, vertex_colors(s, mesh)

            mesh, colors = make()
            shade_ms = median_ms(make, repeats)
            img = r.render(scene, mesh, colors, camera=refs.camera)
            render_ms = median_ms(
                lambda m=mesh, c=colors, s=scene: r.render(s, m, c, camera=refs.camera), repeats
            )
            cmp = compare(img, refs(material, "blinn"), coverage(rc, scene, mesh, refs.camera))
            rows.append(
                {
                    "material": label,
                    "preset": preset,
                    "shininess": material.shininess,
                    "variant": "blinn",
                    "model": "blinn",
                    "exponent": material.shininess,
                    "reference": "blinn",
                    "path": "float64",
                    "mesh": "adaptive",
                    "base": f"{base_name} {base_res}",
                    "resolution": thr,
                    "vertices": mesh.n_vertices,
                    "side": refs.size[0],
                    "shade_ms": round(shade_ms, 4),
                    "render_ms": round(render_ms, 4),
                    "rmse": round(cmp.rmse, 4),
                    "max": cmp.max,
                    "peak": cmp.peak,
                }
            )
    return rows


def run_bench(config: BenchConfig = BenchConfig(), *, progress: Progress | None = None) -> dict:
    """Measure the accuracy table (see the module docstring). Returns the table as a dict
    (the content of ``accuracy.json``): ``machine``, ``scene``, ``rows`` (per-vertex),
    ``per_pixel`` (the reference's own cost) and ``model_match`` (Blinn 4n against Phong n,
    both per pixel)."""

    mats = [(label, preset, bench_material(preset, n)) for label, preset, n in config.materials]
    meshes = [(name, res) for name, resolutions in config.meshes for res in resolutions]
    if progress is None:
        progress = Progress(enabled=False)
    progress.total = max(1, len(config.sides) * len(meshes) + 2)
    rows: list[dict] = []
    per_pixel: list[dict] = []
    model_match: list[dict] = []
    machine = None
    mesh_cache: dict = {}
    base = bench_scene(mats[0][2])
    for side in config.sides:
        size = (side, side)
        main = side == config.main_side
        refs = _References(sphere_camera(base, 1.0), size)
        with OffscreenRenderer(size) as r, OffscreenRenderer(size, (0, 0, 0)) as rc:
            if machine is None:
                machine = machine_info(opengl=True)
            for name, res in meshes:
                if (name, res) not in mesh_cache:
                    mesh_cache[(name, res)] = get_mesh(name, res)
                mesh = mesh_cache[(name, res)]
                cov = coverage(rc, base, mesh, refs.camera)
                colors = vertex_colors(base, mesh)
                render_ms = median_ms(
                    lambda m=mesh, c=colors, cam=refs.camera: r.render(base, m, c, camera=cam),
                    config.repeats,
                )
                for row in _measure_mesh(r, refs, cov, mesh, mats, main, config.repeats):
                    row["resolution"] = res
                    row["render_ms"] = round(render_ms, 4)
                    rows.append(row)
                progress.step(f"{side}px {name} {res}")
            if main and config.adaptive:
                rows += _measure_adaptive(r, rc, refs, mats, config.adaptive, config.repeats)
                progress.step(f"{side}px adaptive")
        if main:
            cost, match = _measure_per_pixel(refs, mats, config.repeats)
            per_pixel += cost
            model_match += match
            progress.step(f"{side}px per-pixel")
    progress.close()
    try:
        machine["load_after"] = [round(x, 2) for x in os.getloadavg()]
    except OSError:
        pass
    return {
        "version": TABLE_VERSION,
        "quick": config.quick,
        "repeats": config.repeats,
        "machine": machine,
        "scene": {
            "light": {"type": "directional", "direction": list(BENCH_LIGHT)},
            "viewer": {"direction": [0.0, 0.0, 1.0]},
            "ambient": list(base.ambient),
            "camera": "parallel projection framing the unit sphere (render.camera_for)",
            "materials": [
                {
                    "label": label,
                    "preset": preset,
                    "shininess": m.shininess,
                    "specular": list(m.specular),
                    "diffuse": list(m.diffuse),
                }
                for label, preset, m in mats
            ],  # fmt: skip
        },
        "main_side": config.main_side,
        "sides": list(config.sides),
        "rows": rows,
        "per_pixel": per_pixel,
        "model_match": model_match,
    }


# -- the table and its question ---------------------------------------------------------------


def data_path() -> Path:
    """The measured table shipped with the package (``explorer/data/accuracy.json``)."""

    return Path(data.__file__).resolve().parent / DATA_FILE


_TABLE_CACHE: dict = {}


def load_table(path=None) -> dict:
    """The measured table (default: the one shipped with the package)."""
    p = Path(path) if path is not None else data_path()
    key = (str(p), p.stat().st_mtime_ns if p.exists() else None)
    if key not in _TABLE_CACHE:
        if not p.is_file():
            raise ExplorerError(
                f"{p}: no accuracy table; run 'phong-explorer bench accuracy' to measure one"
            )
        try:
            table = json.loads(p.read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            raise ExplorerError(f"{p}: not a readable accuracy table: {exc}") from None
        if not isinstance(table, dict) or table.get("version") != TABLE_VERSION:
            raise ExplorerError(f"{p}: accuracy table of another version; measure it again")
        _TABLE_CACHE.clear()
        _TABLE_CACHE[key] = table
    return _TABLE_CACHE[key]


@dataclass(frozen=True)
class Recommendation:
    """The answer of :func:`mesh_for_error`.

    mesh : "sphere" or "icosphere"; resolution : the coarsest measured tessellation that
        stays within ``max_error`` (None: none of the measured ones does)
    vertices : its vertex count; error : its error by the table (interpolated between the
        measured shininess values and picture sizes, exact at a measured pair)
    finest : (resolution, vertices, error) of the finest measured tessellation
    exact : the query's shininess and size are both measured (no interpolation)
    """

    shininess: float
    size: tuple[int, int]
    max_error: float
    metric: str
    model: str
    mesh: str
    resolution: int | None
    vertices: int | None
    error: float | None
    finest: tuple[int, int, float]
    exact: bool
    curve: tuple[tuple[int, int, float], ...] = field(default=(), repr=False)

    def describe(self) -> str:
        what = {"max": "every pixel", "rmse": "the RMSE", "peak": "the highlight peak"}
        crit = f"{what[self.metric]} within {self.max_error:g} level" + (
            "s" if self.max_error != 1 else ""
        )
        if self.resolution is None:
            r, v, e = self.finest
            return (
                f"{crit}: no measured {self.mesh} is fine enough (the finest, {self.mesh} "
                f"{r} with {v:,} vertices, is off by {e:.3g}); use per-pixel lighting"
            )
        return f"{crit}: {self.mesh} {self.resolution} ({self.vertices:,} vertices)"


def _interp(x: float, xs: Sequence[float]) -> list[tuple[int, float]]:
    """Linear interpolation weights of ``x`` over sorted ``xs`` (clamped at the ends)."""
    if x <= xs[0]:
        return [(0, 1.0)]
    if x >= xs[-1]:
        return [(len(xs) - 1, 1.0)]
    j = int(np.searchsorted(xs, x))
    if xs[j] == x:
        return [(j, 1.0)]
    f = (x - xs[j - 1]) / (xs[j] - xs[j - 1])
    return [(j - 1, 1.0 - f), (j, f)]


def mesh_for_error(
    shininess: float,
    size: Sequence[int] = (MAIN_SIDE, MAIN_SIDE),
    max_error: float = 1.0,
    *,
    metric: str = "max",
    model: str = "blinn",
    mesh: str = "sphere",
    precision: str = "float64",
    table: dict | None = None,
) -> Recommendation:
    """How fine must a sphere be to stay within ``max_error`` levels of the per-pixel picture?

    shininess : the material's exponent; size : (width, height) of the picture, the sphere
        framed as ``phong-explorer render`` frames it (its diameter is about min(w, h) / 1.08)
    max_error : the bound in 1/255 levels; metric : "max" (every pixel), "rmse" or "peak"
    model : "blinn" or "phong" (per-vertex and reference alike)
    mesh : "sphere" (UV sphere, resolution = segments) or "icosphere" (subdivisions)
    precision : "float64" or "float32" (blinn only; float32 is within a level of float64)

    The answer comes from the measured table (:func:`load_table`): the error of each measured
    tessellation is interpolated linearly in log(shininess) and log(picture side) between the
    measured values (clamped outside them), and the recommendation is the coarsest
    tessellation from which every finer measured one stays within the bound (errors do not
    always fall monotonically: where a highlight falls relative to the vertices matters). At a
    measured shininess and size it is read off the table exactly.
    """
    if metric not in METRICS:
        raise ExplorerError(f"metric must be one of {METRICS}, got {metric!r}")
    if model not in ("blinn", "phong"):
        raise ExplorerError(f"model must be blinn or phong, got {model!r}")
    if not (isinstance(max_error, (int, float)) and math.isfinite(max_error) and max_error >= 0):
        raise ExplorerError(f"max_error must be a number of levels >= 0, got {max_error!r}")
    if not (math.isfinite(float(shininess)) and float(shininess) >= 0):
        raise ExplorerError(f"shininess must be >= 0, got {shininess!r}")

    w, h = check_size(size)
    side = min(w, h)
    table = load_table() if table is None else table
    variant = model if precision == "float64" else f"{model} {precision}"
    rows = [
        r for r in table["rows"]
        if r["variant"] == variant and r["mesh"] == mesh and r[metric] is not None
    ]  # fmt: skip
    if not rows:
        raise ExplorerError(
            f"the accuracy table has no {variant!r} rows for {mesh!r} ({metric}); "
            "measure them with 'phong-explorer bench accuracy'"
        )
    shin = sorted({r["shininess"] for r in rows})
    sides = sorted({r["side"] for r in rows})
    grid: dict = {}
    verts: dict = {}
    for r in rows:
        grid[(r["shininess"], r["side"], r["resolution"])] = float(r[metric])
        verts[r["resolution"]] = r["vertices"]
    ws = [
        (shin[i], sides[j], a * b)
        for i, a in _interp(math.log(max(float(shininess), 1e-9)), [math.log(s) for s in shin])
        for j, b in _interp(math.log(side), [math.log(s) for s in sides])
    ]
    exact = len(ws) == 1 and ws[0][0] == float(shininess) and ws[0][1] == side
    curve = []
    for res in sorted(verts):
        keys = [(s, d, res) for s, d, _ in ws]
        if all(k in grid for k in keys):
            curve.append((res, verts[res], sum(wt * grid[(s, d, res)] for s, d, wt in ws)))
    if not curve:
        raise ExplorerError(f"the accuracy table has no complete {mesh} rows to interpolate")
    chosen = None
    for res, v, e in reversed(curve):  # finest first: walk coarser while all stay within
        if e <= max_error + 1e-12:
            chosen = (res, v, e)
        else:
            break
    finest = curve[-1]
    return Recommendation(
        shininess=float(shininess),
        size=(w, h),
        max_error=float(max_error),
        metric=metric,
        model=model,
        mesh=mesh,
        resolution=None if chosen is None else chosen[0],
        vertices=None if chosen is None else chosen[1],
        error=None if chosen is None else chosen[2],
        finest=finest,
        exact=exact,
        curve=tuple(curve),
    )


def advice(shininess: float, size: Sequence[int], *, model: str = "blinn",
           max_error: float = 1.0, table: dict | None = None) -> str:  # fmt: skip
    """One line for the GUI: which tessellation keeps the error within ``max_error`` levels for
    this shininess and picture size: the RMSE (the picture as a whole), then every pixel
    (:func:`mesh_for_error` with ``metric="rmse"`` and ``"max"``, UV sphere and icosphere)."""
    try:
        recs = {
            (metric, mesh): mesh_for_error(
                shininess, size, max_error, model=model, metric=metric, mesh=mesh, table=table
            )  # fmt: skip
            for metric in ("rmse", "max")
            for mesh in ("sphere", "icosphere")
        }
    except ExplorerError as exc:
        return f"accuracy: {exc}"
    lv = f"{max_error:g} level" + ("s" if max_error != 1 else "")

    def both(metric: str) -> str:
        a, b = recs[(metric, "sphere")], recs[(metric, "icosphere")]
        if a.resolution is None and b.resolution is None:
            return f"no measured mesh (finest: {a.mesh} {a.finest[0]}, {b.mesh} {b.finest[0]})"
        names = [
            f"{r.mesh} {r.resolution} ({_count(r.vertices)} vertices)"
            if r.resolution is not None
            else f"finer than {r.mesh} {r.finest[0]}"
            for r in (a, b)
        ]
        return " or ".join(names)

    return (
        f"shininess {float(shininess):g} ({model}), error within {lv}: RMSE from {both('rmse')}; "
        f"every pixel: {both('max')}"
    )


def _count(n: int | None) -> str:
    if n is None:
        return "?"
    if n >= 10_000:
        return f"{n / 1000:.0f}k"
    return f"{n:,}"


# -- adaptive refinement ------------------------------------------------------------------------

#: vertex budget of :func:`refine_highlights`
REFINE_MAX_VERTICES = 400_000


def _split_longest_edge(faces: np.ndarray, mid: np.ndarray, longest: np.ndarray) -> np.ndarray:
    """Split triangles by longest-edge bisection (Rivara): a triangle with marked edges is
    first cut from its longest edge's midpoint to the opposite corner, then each half is cut
    again if its outer edge is marked. Triangles keep their winding and their angles stay
    bounded (no slivers); an edge is split in both of its triangles, so no cracks.

    faces : (m, 3) int; mid : (m, 3) int, the new vertex on edge k = (v_k, v_k+1) or -1 where
    the edge is kept (the longest edge of every triangle with a marked edge is marked);
    longest : (m,) which edge (0, 1, 2) is each triangle's longest. Returns (m', 3) int.
    """
    split = (mid >= 0).any(1)
    out = [faces[~split]]
    sel = np.flatnonzero(split)
    if len(sel):
        rows = np.arange(len(sel))[:, None]
        idx = (np.arange(3)[None, :] + longest[sel][:, None]) % 3  # longest edge -> edge 0
        V = faces[sel][rows, idx]
        E = mid[sel][rows, idx]
        a, b, c = V[:, 0], V[:, 1], V[:, 2]
        m, mbc, mca = E[:, 0], E[:, 1], E[:, 2]
        one = mca < 0  # the half (a, m, c), cut again along c->a when marked
        out += [np.stack([a, m, c], 1)[one]]
        out += [np.stack([m, c, mca], 1)[~one], np.stack([m, mca, a], 1)[~one]]
        two = mbc < 0  # the half (m, b, c), cut again along b->c when marked
        out += [np.stack([m, b, c], 1)[two]]
        out += [np.stack([m, b, mbc], 1)[~two], np.stack([m, mbc, c], 1)[~two]]
    return np.concatenate(out).astype(np.int64)


def _seen_on_sphere(viewer, points: np.ndarray, normals: np.ndarray):
    """Where the line of sight through each point (inside the unit sphere) leaves the sphere
    toward the viewer: the sphere point a pixel showing that point sees, (k, 3) float64; and
    (k,) bool, True where the surface there (``normals``) faces the viewer (elsewhere the
    line of sight shows another part of the sphere)."""
    if viewer.local:
        v = np.asarray(viewer.eye, np.float64) - points
        v /= np.maximum(np.linalg.norm(v, axis=1, keepdims=True), 1e-300)
    else:
        v = np.broadcast_to(np.asarray(viewer.to_viewer, np.float64), points.shape)
    b = np.einsum("ij,ij->i", points, v)
    c = np.einsum("ij,ij->i", points, points) - 1.0
    t = -b + np.sqrt(np.maximum(b * b - c, 0.0))
    q = points + t[:, None] * v
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return q, np.einsum("ij,ij->i", normals, v) > 0.0


def refine_highlights(scene, mesh, max_error: float = 1.0, *, min_edge: float = 0.0,
                      max_rounds: int = 16, max_vertices: int = REFINE_MAX_VERTICES):  # fmt: skip
    """Refine a mesh only where per-vertex shading misses: the adaptive alternative to a
    uniformly finer mesh (it splits at the highlight, the terminator and the clip at 1).

    Each round shades every edge's midpoint exactly and compares it with the average of the
    edge's two vertex colours (what Gouraud interpolation shows there); the edges off by more
    than ``max_error`` levels (largest channel) are split by longest-edge bisection (no
    cracks, no slivers). A built-in unit sphere's new vertices go onto the sphere; any other
    mesh's stay on the triangle with the normalised average of the two normals (the
    interpolated normal the per-pixel ray caster uses). Stops when no edge is off, after
    ``max_rounds`` rounds, or before the mesh would exceed ``max_vertices``. On a sphere the
    comparison is with what the pixel showing the edge's midpoint sees on the true sphere, so
    the silhouette, where the flat triangles lag behind the sphere, is refined too; give
    ``min_edge`` (world units, about a pixel) so edges smaller than a pixel stay whole.

    Returns a new :class:`~explorer.geometry.meshes.Mesh` (same name) whose first vertices are the
    original ones. The result depends on the scene (lights, viewer, material): refine again
    when they change.
    """

    sphere = is_unit_sphere(mesh)
    P = np.array(mesh.positions)
    N = np.array(mesh.normals)
    F = np.array(mesh.faces)
    colors = point_colors(scene, P, N, mesh=mesh)
    for _ in range(max_rounds):
        if not len(F):
            break
        edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
        unique, inverse = np.unique(np.sort(edges, axis=1), axis=0, return_inverse=True)
        tri_edge = inverse.ravel().reshape(3, -1).T  # (m, 3): edges 01, 12, 20
        mid_n = N[unique[:, 0]] + N[unique[:, 1]]
        length = np.linalg.norm(mid_n, axis=1, keepdims=True)
        mid_n = np.divide(mid_n, length, out=np.zeros_like(mid_n), where=length > 1e-12)
        chord = 0.5 * (P[unique[:, 0]] + P[unique[:, 1]])
        mid_p = mid_n.copy() if sphere else chord
        exact = point_colors(scene, mid_p, mid_n, mesh=mesh)
        seen = exact
        if sphere:  # what the pixel showing the chord's midpoint sees on the true sphere
            q, front = _seen_on_sphere(scene.viewer, chord, mid_n)
            if front.any():
                seen = exact.copy()
                seen[front] = point_colors(scene, q[front], q[front], mesh=mesh)
        lerp = 0.5 * (colors[unique[:, 0]] + colors[unique[:, 1]])
        elen = np.linalg.norm(P[unique[:, 0]] - P[unique[:, 1]], axis=1)
        marked = (np.abs(seen - lerp).max(axis=1) * 255.0 > max_error) & (elen > min_edge)
        if not marked.any():
            break
        # each triangle's longest edge (ties broken by edge number), marked with any other
        key = elen[tri_edge] * (1.0 + 1e-12 * tri_edge / max(len(unique), 1))
        longest = np.argmax(key, axis=1)
        longest_id = tri_edge[np.arange(len(F)), longest]
        while True:
            need = marked[tri_edge].any(1) & ~marked[longest_id]
            if not need.any():
                break
            marked[longest_id[need]] = True
        n_new = int(marked.sum())
        if len(P) + n_new > max_vertices:
            break
        new_index = np.full(len(unique), -1, np.int64)
        new_index[marked] = len(P) + np.arange(n_new)
        F = _split_longest_edge(F, new_index[tri_edge], longest)
        P = np.vstack([P, mid_p[marked]])
        N = np.vstack([N, mid_n[marked]])
        colors = np.vstack([colors, exact[marked]])
    return Mesh(P, N, F, mesh.name)


# -- reading the table --------------------------------------------------------------------------


def pareto_front(times: Sequence[float], errors: Sequence[float]) -> list[int]:
    """Indices of the points no other point beats in both time and error (lower is better
    in both), ordered by time. A point equal to another in both is kept once."""
    pts = sorted(range(len(times)), key=lambda i: (times[i], errors[i]))
    front = []
    best = math.inf
    for i in pts:
        if errors[i] < best:
            front.append(i)
            best = errors[i]
    return front


def _fmt(x, digits: int = 3) -> str:
    if x is None:
        return "–"
    if isinstance(x, int):
        return str(x)
    if x == 0:
        return "0"
    if abs(x) >= 100:
        return f"{x:.0f}"
    return f"{x:.{digits}g}"


def _rows(table, *, adaptive: bool = False, **match) -> list[dict]:
    """Rows matching every ``key=value``; adaptive rows only with ``adaptive=True``."""
    return [
        r
        for r in table["rows"]
        if all(r.get(k) == v for k, v in match.items()) and (r["mesh"] == "adaptive") == adaptive
    ]


def markdown(table: dict, *, plot: str | None, command: str) -> str:
    """docs/accuracy.md from a measured table. ``plot`` is the picture's relative path (None:
    not drawn)."""
    m = table["machine"] or {}
    v = m.get("versions", {})
    gl = m.get("opengl", {})
    main = table["main_side"]
    out: list[str] = []
    add = out.append
    add("# What accuracy costs in time")
    add("")
    add(
        f"Generated by `{command}` on {m.get('date', '?')}. The command replaces this file, its "
        "plot and the table shipped with the package (`explorer/data/accuracy.json`); do not "
        "edit them by hand."
        + (" **Quick run: a small table for tests, not a measurement.**" if table["quick"] else "")
    )
    add("")
    add("## Machine")
    add("")
    add(f"- CPU: {m.get('cpu', '?')}, {m.get('cores', '?')} cores "
        f"({m.get('usable_cores', '?')} usable), memory {m.get('memory', '?')}")  # fmt: skip
    add(f"- OS: {m.get('os', '?')}")
    if gl:
        add(f"- OpenGL: {gl.get('renderer', '?')} ({gl.get('version', '?')}), off-screen")
    add("- Versions: " + ", ".join(f"{k} {val}" for k, val in v.items()))
    la, lb = m.get("load_before"), m.get("load_after")
    if la or lb:
        add(f"- Load average (1, 5, 15 min): {la} before, {lb} after")
        add(
            "- Timing under load: each call of the engine's parallel kernels waits until all "
            "its threads have had a core, so while other work runs (load averages above; the "
            "'after' figure includes this run) the shading times of small meshes show "
            "scheduler waits (multiples of a few ms) rather than work. Errors are unaffected."
        )
    runs = "1 run" if table["repeats"] == 1 else f"{table['repeats']} runs"
    add(f"- Times are wall-clock medians of {runs} after a warm-up run.")
    add("")
    add("## What is measured")
    add("")
    sc = table["scene"]
    add(
        "Each built-in sphere tessellation is shaded per vertex by the engine and drawn by VTK "
        "(colours interpolated across the triangles, lighting off, no anti-aliasing), then "
        "compared with the **per-pixel reference** of the same camera: the same engine "
        "lighting evaluated at the exact sphere point under each pixel centre, with the exact "
        "normal (closed-form ray-sphere intersection; `phong-explorer render --per-pixel`). "
        "Both are 8-bit pictures; a pixel's error is its largest channel difference in 1/255 "
        "levels, over the pixels the object covers in both (the background never counts). "
        "**RMSE** is over those pixels' channels, **max** the worst pixel, **peak** the error "
        "at the pixel where the reference's specular light is largest (0 where both saturate). "
        "One level is rounding: the floor of any 8-bit comparison."
    )
    add("")
    add(
        f"Scene: one white directional light toward {sc['light']['direction']}, scene ambient "
        f"{sc['ambient']}, infinite viewer on +z (parallel projection), pictures {main}x{main} "
        "unless stated. **Shade** is `explorer.shade` (one call: plan, kernel, colours) or, for "
        "*plan off*, the full-generality numpy reference "
        "`explorer.shading.equation.reference_shade`; "
        "**render** is one off-screen VTK frame with new vertex colours (upload, draw, read back)."
    )
    add("")
    add("Materials (built-in presets): " + "; ".join(
        f"{x['label']} (shininess {x['shininess']:g}, specular {x['specular'][0]:g}, "
        f"diffuse {x['diffuse'][0]:g})" for x in sc["materials"]) + ".")  # fmt: skip
    add("")
    if plot:
        add(f"![error against time per frame, Pareto front marked]({plot})")
        add("")
        add(
            "Error against time per frame (shade + render) at "
            f"{main}x{main}; the line joins the Pareto front (nothing else is both faster and "
            "more accurate). The dashed line is the per-pixel reference's own shading time."
        )
        add("")
    add("## Findings")
    add("")
    for line in findings(table):
        add(f"- {line}")
    add("")
    labels = [x["label"] for x in sc["materials"]]
    add(f"## Tessellation: per-vertex Blinn against per-pixel Blinn ({main}x{main})")
    add("")
    add(
        "Shade times for the float64 path (plan on), the float32 path and the plan off; "
        "errors of the float64 path, then of float32 (`f32 max`) and the largest float32 - "
        "float64 vertex colour difference (`f32-f64`, levels). The plan-off colours equal the "
        "float64 path's (largest difference in the `plan off Δ` column)."
    )
    for label in labels:
        add("")
        add(f"### {label}")
        add("")
        add("| mesh | vertices | shade f64 ms | shade f32 ms | plan off ms | render ms | RMSE "
            "| max | peak | f32 max | f32-f64 | plan off Δ |")  # fmt: skip
        add("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for r in _rows(table, material=label, variant="blinn", side=main):
            key = dict(material=label, side=main, mesh=r["mesh"], resolution=r["resolution"])
            f32 = _rows(table, variant="blinn float32", **key)
            off = _rows(table, variant="blinn plan off", **key)
            f32 = f32[0] if f32 else {}
            off = off[0] if off else {}
            add(
                f"| {r['mesh']} {r['resolution']} | {r['vertices']:,} | {_fmt(r['shade_ms'])} "
                f"| {_fmt(f32.get('shade_ms'))} | {_fmt(off.get('shade_ms'))} "
                f"| {_fmt(r['render_ms'])} | {_fmt(r['rmse'])} | {r['max']} | {_fmt(r['peak'])} "
                f"| {_fmt(f32.get('max'))} | {_fmt(f32.get('vs_float64'))} "
                f"| {_fmt(off.get('vs_float64'))} |"
            )
    pp = table["per_pixel"]
    if pp:
        add("")
        add("Per-pixel reference itself (ray-sphere hits and engine shading of every covered "
            "pixel, no VTK):")  # fmt: skip
        add("")
        add("| material | pixels | shade ms |")
        add("|---|---:|---:|")
        for x in pp:
            add(f"| {x['material']} | {x['pixels']:,} | {_fmt(x['shade_ms'])} |")
    adaptive = _rows(table, adaptive=True, side=main)
    if adaptive:
        add("")
        add(f"## Adaptive refinement ({main}x{main}, Blinn, float64)")
        add("")
        add(
            f"`explorer.analysis.accuracy.refine_highlights(scene, mesh, max_error)` starting from "
            f"{adaptive[0]['base']}: each round shades every edge's midpoint exactly and splits "
            "the edges where the interpolated colour is off by more than the threshold "
            "(levels), by longest-edge bisection (no cracks, no slivers), new vertices on the "
            "sphere. On a sphere the midpoint is compared with what its pixel shows of the true "
            "sphere, so the silhouette is refined as well as the highlight, the terminator and "
            "the clip at 1. **Shade** is refinement plus shading: a refined mesh fits one scene "
            "(lights, viewer, material)."
        )
        for label in labels:
            add("")
            add(f"### {label}")
            add("")
            add("| threshold | vertices | refine + shade ms | render ms | RMSE | max | peak |")
            add("|---:|---:|---:|---:|---:|---:|---:|")
            for r in _rows(table, adaptive=True, side=main, material=label):
                add(
                    f"| {r['resolution']:g} | {r['vertices']:,} | {_fmt(r['shade_ms'])} "
                    f"| {_fmt(r['render_ms'])} | {_fmt(r['rmse'])} | {r['max']} "
                    f"| {_fmt(r['peak'])} |"
                )
    add("")
    add(f"## Phong against Blinn with the exponent matched ({main}x{main})")
    add("")
    add(
        "Per-vertex Phong (`(R·V)^n`) and per-vertex Blinn with exponent 4n (`(N·H)^(4n)`, the "
        "notes' approximation), both against the per-pixel **Phong** picture. The first line of "
        "each table is the approximation alone: per-pixel Blinn 4n against per-pixel Phong n."
    )
    for label in labels:
        add("")
        add(f"### {label}")
        add("")
        add("| mesh | vertices | phong shade ms | render ms | phong RMSE | phong max | phong "
            "peak | blinn 4n shade ms | 4n RMSE | 4n max | 4n peak |")  # fmt: skip
        add("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for x in table["model_match"]:
            if x["material"] == label:
                add(f"| per pixel | – | – | – | 0 | 0 | 0 | – | {_fmt(x['rmse'])} | {x['max']} "
                    f"| {_fmt(x['peak'])} |")  # fmt: skip
        for r in _rows(table, material=label, variant="phong", side=main):
            b = _rows(table, material=label, variant="blinn 4n", side=main, mesh=r["mesh"],
                      resolution=r["resolution"])  # fmt: skip
            b = b[0] if b else {}
            add(
                f"| {r['mesh']} {r['resolution']} | {r['vertices']:,} | {_fmt(r['shade_ms'])} "
                f"| {_fmt(r['render_ms'])} | {_fmt(r['rmse'])} | {r['max']} | {_fmt(r['peak'])} "
                f"| {_fmt(b.get('shade_ms'))} | {_fmt(b.get('rmse'))} | {_fmt(b.get('max'))} "
                f"| {_fmt(b.get('peak'))} |"
            )
    sides = table["sides"]
    if len(sides) > 1:
        add("")
        add("## Picture size (per-vertex Blinn, float64)")
        add("")
        add("The same tessellations at every picture size: `RMSE / max` in levels. The sphere "
            "fills about side / 1.08 pixels.")  # fmt: skip
        for label in labels:
            add("")
            add(f"### {label}")
            add("")
            add("| mesh | vertices | " + " | ".join(f"{s}x{s}" for s in sides) + " |")
            add("|---|---:|" + "---:|" * len(sides))
            for r in _rows(table, material=label, variant="blinn", side=main):
                cells = []
                for s in sides:
                    x = _rows(table, material=label, variant="blinn", side=s, mesh=r["mesh"],
                              resolution=r["resolution"])  # fmt: skip
                    cells.append(f"{_fmt(x[0]['rmse'])} / {x[0]['max']}" if x else "–")
                add(f"| {r['mesh']} {r['resolution']} | {r['vertices']:,} | "
                    + " | ".join(cells) + " |")  # fmt: skip
    add("")
    add("## How fine must the mesh be?")
    add("")
    add(
        "`explorer.analysis.accuracy.mesh_for_error(shininess, size=(w, h), max_error=1.0, "
        "metric=..., "
        "model=..., mesh=...)` answers from this table (interpolating between the measured "
        "shininess values and sizes). For the measured materials at "
        f"{main}x{main}, per-vertex Blinn:"
    )
    add("")
    add("| shininess | every pixel ≤ 1 | every pixel ≤ 2 | every pixel ≤ 4 | RMSE ≤ 1 |")
    add("|---:|---|---|---|---|")
    for x in sc["materials"]:
        n = x["shininess"]
        cells = []
        for metric, bound in (("max", 1), ("max", 2), ("max", 4), ("rmse", 1)):
            parts = []
            for mesh in ("sphere", "icosphere"):
                try:
                    rec = mesh_for_error(n, (main, main), bound, metric=metric, mesh=mesh,
                                         table=table)  # fmt: skip
                except ExplorerError:
                    continue
                parts.append(
                    f"{mesh} {rec.resolution} ({_count(rec.vertices)})"
                    if rec.resolution is not None
                    else f"> {mesh} {rec.finest[0]}"
                )
            cells.append("<br>".join(parts) or "–")
        add(f"| {n:g} | " + " | ".join(cells) + " |")
    add("")
    add(
        "In parentheses: vertices. `> sphere 1024` means no measured tessellation stays within "
        "the bound. Files and options: `phong-explorer bench accuracy --help`; the default "
        "outputs (this file, `docs/accuracy.png`, `explorer/data/accuracy.json`) belong to the "
        "command and are replaced; with `--out-dir DIR` it writes `DIR/accuracy.md`, "
        "`DIR/accuracy.png` and `DIR/accuracy.json` and refuses to replace existing files "
        "without `--force`."
    )
    add("")
    return "\n".join(out)


def findings(table: dict) -> list[str]:
    """Sentences with numbers from the table (so the text always matches the data)."""
    main = table["main_side"]
    out = []
    labels = [x["label"] for x in table["scene"]["materials"]]
    for label in labels:
        rows = _rows(table, material=label, variant="blinn", side=main, mesh="sphere")
        if not rows:
            continue
        n = rows[0]["shininess"]
        coarse, fine = rows[0], rows[-1]
        rec1 = mesh_for_error(n, (main, main), 1.0, metric="rmse", table=table)
        recm = mesh_for_error(n, (main, main), 2.0, metric="max", table=table)
        s = (
            f"{label} (n = {n:g}): sphere {coarse['resolution']} is off by {coarse['max']} "
            f"levels at worst (RMSE {_fmt(coarse['rmse'])}), sphere {fine['resolution']} by "
            f"{fine['max']} (RMSE {_fmt(fine['rmse'])}); "
        )
        s += (
            f"RMSE within 1 level from sphere {rec1.resolution} ({rec1.vertices:,} vertices), "
            if rec1.resolution is not None
            else "no measured sphere has RMSE within 1 level, "
        )
        s += (
            f"every pixel within 2 levels from sphere {recm.resolution}."
            if recm.resolution is not None
            else f"no measured sphere keeps every pixel within 2 levels "
            f"(sphere {recm.finest[0]}: {recm.finest[2]:g})."
        )
        out.append(s)
    f32 = [r for r in table["rows"] if r["path"] == "float32" and "vs_float64" in r]
    if f32:
        worst = max(r["vs_float64"] for r in f32)
        pairs = []
        for r in f32:
            b = _rows(table, variant="blinn", material=r["material"], side=r["side"],
                      mesh=r["mesh"], resolution=r["resolution"])  # fmt: skip
            if b and r["vertices"] >= 10_000:
                pairs.append(b[0]["shade_ms"] / max(r["shade_ms"], 1e-9))
        s = f"float32 colours are within {_fmt(worst)} levels of float64 at every vertex"
        if pairs:
            s += (
                f"; on meshes of 10k+ vertices float32 shades {statistics.median(pairs):.2g}x "
                "as fast (median)"
            )
        out.append(s + ".")
    off = [r for r in table["rows"] if r["path"] == "plan off"]
    if off:
        ratios = []
        for r in off:
            b = _rows(table, variant="blinn", material=r["material"], side=r["side"],
                      mesh=r["mesh"], resolution=r["resolution"])  # fmt: skip
            if b and r["vertices"] >= 10_000:
                ratios.append(r["shade_ms"] / max(b[0]["shade_ms"], 1e-9))
        worst = max(r.get("vs_float64", 0.0) for r in off)
        s = f"the plan changes no colour (plan-off differs by at most {worst:.2g} levels)"
        if ratios:
            s += (
                f"; the full-generality numpy path takes {statistics.median(ratios):.2g}x the "
                "planned float64 time on 10k+ vertices (median)"
            )
        out.append(s + ".")
    for label in labels:
        ada = _rows(table, adaptive=True, side=main, material=label)
        uni = _rows(table, variant="blinn", side=main, material=label)
        if not ada or not uni:
            continue
        best = min(ada, key=lambda r: r["rmse"])
        match = [r for r in uni if r["rmse"] <= best["rmse"]]
        s = (
            f"{label}, adaptive: threshold {best['resolution']:g} gives RMSE "
            f"{_fmt(best['rmse'])} (worst pixel {best['max']}) with {best['vertices']:,} "
            f"vertices in {_fmt(best['shade_ms'])} ms; "
        )
        if match:
            u = min(match, key=lambda r: r["vertices"])
            s += (
                f"the smallest uniform mesh as good, {u['mesh']} {u['resolution']}, has "
                f"{u['vertices']:,} vertices (worst pixel {u['max']})."
            )
        else:
            s += "no measured uniform mesh is as good."
        out.append(s)
    sizes = sorted(table["sides"])
    if len(sizes) > 1:
        lo, hi = sizes[0], sizes[-1]
        change, growth = [], []
        for r in _rows(table, variant="blinn", side=lo):
            (h,) = _rows(table, variant="blinn", side=hi, material=r["material"],
                         mesh=r["mesh"], resolution=r["resolution"]) or (None,)  # fmt: skip
            if h is not None and r["rmse"] >= 0.5:
                change.append(abs(h["rmse"] / r["rmse"] - 1.0))
                growth.append(h["max"] - r["max"])
        if change:
            out.append(
                f"picture size: between {lo}x{lo} and {hi}x{hi} the RMSE of a tessellation "
                f"changes by {100 * statistics.median(change):.2g}% (median; at most "
                f"{100 * max(change):.2g}%): the error belongs to the surface, not to the "
                f"pixels; the worst pixel grows by up to {max(growth)} levels with the size "
                "(more pixels sample the worst spot)."
            )
    for x in table["model_match"]:
        out.append(
            f"{x['material']}: Blinn with exponent 4n against Phong n, both per pixel: RMSE "
            f"{_fmt(x['rmse'])}, worst pixel {x['max']} levels."
        )
    render = _rows(table, variant="blinn", side=main, material=labels[0]) if labels else []
    if render:
        big = max(render, key=lambda r: r["vertices"])
        small = min(render, key=lambda r: r["vertices"])
        out.append(
            f"a {main}x{main} VTK frame takes {_fmt(small['render_ms'])} ms with "
            f"{small['vertices']:,} vertices and {_fmt(big['render_ms'])} ms with "
            f"{big['vertices']:,}; shading the largest mesh (float64) takes "
            f"{_fmt(big['shade_ms'])} ms."
        )
    pp = table["per_pixel"]
    if pp:
        out.append(
            f"the per-pixel reference costs {_fmt(statistics.median(x['shade_ms'] for x in pp))} "
            f"ms per {main}x{main} picture here (numpy ray-sphere hits + engine shading of "
            f"{pp[0]['pixels']:,} pixels), no VTK."
        )
    return out


def plot(table: dict, path, *, overwrite: bool = False) -> bool:
    """Draw docs/accuracy.png: error against time per frame for each material, the Pareto
    front marked; written atomically to ``path`` (an existing file only with ``overwrite``).
    Returns False (and writes nothing) when matplotlib is not installed (it is the optional
    ``bench`` extra)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.ticker import FuncFormatter, NullFormatter
    except ImportError:
        return False
    plain = FuncFormatter(lambda x, _pos: f"{x:g}")
    main = table["main_side"]
    labels = [x["label"] for x in table["scene"]["materials"]]
    series = [
        ("sphere", "blinn", "o", "C0", "UV sphere, float64"),
        ("sphere", "blinn float32", "s", "C1", "UV sphere, float32"),
        ("sphere", "blinn plan off", "x", "C3", "UV sphere, plan off"),
        ("icosphere", "blinn", "^", "C2", "icosphere, float64"),
        ("icosphere", "blinn float32", "v", "C4", "icosphere, float32"),
        ("adaptive", "blinn", "*", "k", "adaptive (refine_highlights)"),
    ]
    fig, axes = plt.subplots(2, len(labels), figsize=(4.2 * len(labels), 7.5), squeeze=False)
    for col, label in enumerate(labels):
        pp = [x for x in table["per_pixel"] if x["material"] == label]
        for row, metric in enumerate(("rmse", "max")):
            ax = axes[row][col]
            ts, es = [], []
            for mesh, variant, marker, color, name in series:
                rows = _rows(table, material=label, variant=variant, side=main, mesh=mesh,
                             adaptive=mesh == "adaptive")  # fmt: skip
                t = [r["shade_ms"] + r["render_ms"] for r in rows]
                e = [max(float(r[metric]), 0.05) for r in rows]
                ax.scatter(t, e, marker=marker, color=color, s=22, label=name, alpha=0.8)
                ts += t
                es += e
            if ts:
                front = pareto_front(ts, es)
                ax.step([ts[i] for i in front], [es[i] for i in front], where="post",
                        color="k", lw=1.0, label="Pareto front")  # fmt: skip
                ax.scatter([ts[i] for i in front], [es[i] for i in front], s=70,
                           facecolors="none", edgecolors="k", lw=1.0)  # fmt: skip
            if pp:
                ax.axvline(pp[0]["shade_ms"], color="grey", ls="--", lw=1.0,
                           label="per-pixel shading")  # fmt: skip
            ax.axhline(1.0, color="grey", ls=":", lw=0.8)
            ax.set_xscale("log")
            ax.set_yscale("log")
            for axis in (ax.xaxis, ax.yaxis):
                axis.set_major_formatter(plain)
                axis.set_minor_formatter(NullFormatter())
            ax.grid(True, which="both", alpha=0.2)
            if row == 0:
                n = table["scene"]["materials"][col]["shininess"]
                ax.set_title(f"{label} (n = {n:g})")
            if row == 1:
                ax.set_xlabel("shade + render per frame (ms)")
            if col == 0:
                ax.set_ylabel(("RMSE" if metric == "rmse" else "worst pixel") + " (1/255 levels)")
    handles, names = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, names, loc="lower center", ncol=len(names), fontsize=8, frameon=False)
    m = table["machine"] or {}
    fig.suptitle(
        f"Per-vertex shading against the per-pixel reference, {main}x{main} "
        f"({m.get('cpu', '?')}, {m.get('usable_cores', '?')} cores)",
        fontsize=10,
    )
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)

    write_atomic(path, buf.getvalue(), overwrite=overwrite)
    return True


def table_bytes(table: dict) -> bytes:
    return (json.dumps(table, indent=1, sort_keys=False) + "\n").encode("utf-8")
