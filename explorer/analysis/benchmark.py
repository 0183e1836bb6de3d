"""The accuracy benchmark: what per-vertex shading's accuracy costs in time, measured.

:func:`run_bench` (``phong-explorer bench accuracy``) shades each built-in sphere tessellation
per vertex, renders it off-screen and compares it with the per-pixel reference
(:mod:`explorer.analysis.comparison`), for a few materials, shading variants (Blinn and Phong,
float64 and float32, the plan off) and picture sizes, and times the shading and the render;
adaptive refinement (:mod:`explorer.analysis.refine`) is measured alongside. The result is the
table :mod:`explorer.analysis.advice` answers from (shipped as ``explorer/data/accuracy.json``)
and :mod:`explorer.analysis.report` turns into ``accuracy.md``. The machine it ran on is
recorded with it (:func:`machine_info`).
"""

from __future__ import annotations

import os
import platform
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from importlib import metadata

import numpy as np

from explorer.analysis.advice import MAIN_SIDE, TABLE_VERSION
from explorer.analysis.comparison import compare, coverage
from explorer.analysis.refine import refine_highlights
from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError
from explorer.core.files import read_text_checked
from explorer.core.lights import DirectionalLight
from explorer.core.presets import builtin_dir, load_material_file
from explorer.core.progress import Progress
from explorer.core.scene import Scene
from explorer.core.version import __version__
from explorer.geometry.meshes import get_mesh
from explorer.render.camera import sphere_camera
from explorer.render.offscreen import OffscreenRenderer
from explorer.render.perpixel import point_colors, reference, sphere_hits
from explorer.render.vtk import headless_egl
from explorer.shading.display import vertex_colors
from explorer.shading.equation import equation_shade
from explorer.shading.shader import shade

# -- what the bench measures -----------------------------------------------------------------------

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
#: picture sides of the size sweep (square pictures); :data:`~explorer.analysis.advice.MAIN_SIDE`
#: gets every variant
SIZE_SWEEP = (100, 200, 400, 800)
#: the quick run (tests): small pictures, few meshes, two materials, one repeat
QUICK_MATERIALS = BENCH_MATERIALS[:2]
QUICK_MESHES: tuple[tuple[str, tuple[int, ...]], ...] = (
    ("sphere", (8, 16, 32, 64)),
    ("icosphere", (1, 2, 3)),
)
QUICK_SIDES = (96,)

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
#: adaptive refinement (:func:`~explorer.analysis.refine.refine_highlights`, Blinn float64,
#: main size only): the base mesh and the edge-midpoint thresholds (levels)
ADAPTIVE_BASE = ("icosphere", 3)
ADAPTIVE_THRESHOLDS = (8.0, 4.0, 2.0, 1.0)
QUICK_ADAPTIVE_THRESHOLDS = (4.0,)


def bench_scene(material, model: str = "blinn"):
    """The bench's scene: ``material``, one white directional light (:data:`BENCH_LIGHT`),
    OpenGL's scene ambient, the default infinite viewer on +z (parallel projection)."""

    return Scene(material=material, model=model, lights=(DirectionalLight(to_light=BENCH_LIGHT),))


def bench_material(preset: str, shininess: float | None = None):
    """A built-in preset (never a user's file of the same name), optionally re-exponented."""

    m = load_material_file(builtin_dir() / f"{preset}.yaml")
    return m if shininess is None else m.replace(shininess=float(shininess))


# -- timing, machine ---------------------------------------------------------------------


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


def _cpu_model() -> str:
    try:
        text = read_text_checked("/proc/cpuinfo", cap=tol.MAX_DATA_FILE_BYTES)
        for line in text.splitlines():
            if line.lower().startswith("model name"):
                return line.split(":", 1)[1].strip()
    except ExplorerError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def _memory() -> str | None:
    try:
        text = read_text_checked("/proc/meminfo", cap=tol.MAX_DATA_FILE_BYTES)
        for line in text.splitlines():
            if line.startswith("MemTotal:"):
                kb = int(line.split()[1])
                return f"{kb / 1024 / 1024:.1f} GiB"
    except (ValueError, IndexError):  # ExplorerError is a ValueError
        pass
    return None


def _versions() -> dict[str, str]:
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
        import pyvista as pv  # heavy and optional here: only when the bench asks

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


# -- the bench -------------------------------------------------------------------------------------


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
    """The timed shading call of a variant's path (the engine's compiled tier, compiled in this
    process first if numba's cache lacks it: its speed is what is measured)."""
    if path == "plan off":
        return lambda: equation_shade(scene, P, N)
    return lambda: shade(scene, P, N, precision=path, tier="compiled")


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
            "light": {"type": "directional", "to_light": list(BENCH_LIGHT)},
            "viewer": {"to_viewer": [0.0, 0.0, 1.0]},
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
