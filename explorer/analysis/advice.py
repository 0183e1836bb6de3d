"""What the measured accuracy table advises: how fine a mesh must be for a given error.

The table (``explorer/data/accuracy.json``, measured by :mod:`explorer.analysis.benchmark`,
``phong-explorer bench accuracy``) holds, for each material, picture size and built-in sphere
tessellation, the error of the per-vertex picture against the per-pixel reference (see
:mod:`explorer.analysis.comparison`). :func:`mesh_for_error` answers from it; :func:`advice` is
the one line the window shows. This is the small API the window uses at run time: it reads the
shipped table and imports nothing of the benchmark or the report.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from explorer import data
from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError
from explorer.core.files import read_text_checked
from explorer.render.images import check_size

#: the table's file name, in the package's data (:func:`data_path`) and in the bench's output
DATA_FILE = "accuracy.json"
#: the table's format version (:func:`load_table` refuses others)
TABLE_VERSION = 1
#: picture side (pixels, square pictures) at which the table measures every variant: the
#: default size of :func:`mesh_for_error`
MAIN_SIDE = 400
#: metrics of a row, and the error criteria :func:`mesh_for_error` understands
METRICS = ("max", "rmse", "peak")


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
            text = read_text_checked(p, cap=tol.MAX_DATA_FILE_BYTES, what="accuracy table")
            table = json.loads(text)
        except ValueError as exc:  # UnreadableFile, a ValueError, names the file itself
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
    """One line for the window: which tessellation keeps the error within ``max_error`` levels for
    this shininess and picture size: the RMSE (the picture as a whole), then every pixel
    (:func:`mesh_for_error` with ``metric="rmse"`` and ``"max"``, UV sphere and icosphere).
    The table measures OpenGL's models; ``threejs`` is advised from ``blinn``'s rows (its lobe
    is Blinn's ``(N·H)^n`` times factors that vary slowly over the surface) and says so."""
    shown = model
    if model == "threejs":
        model, shown = "blinn", "threejs, from blinn's measurements"
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
            f"{r.mesh} {r.resolution} ({short_count(r.vertices)} vertices)"
            if r.resolution is not None
            else f"finer than {r.mesh} {r.finest[0]}"
            for r in (a, b)
        ]
        return " or ".join(names)

    return (
        f"shininess {float(shininess):g} ({shown}), error within {lv}: RMSE from {both('rmse')}; "
        f"every pixel: {both('max')}"
    )


def short_count(n: int | None) -> str:
    """A vertex count for a table cell: ``8,066``, ``294k`` from 10,000 up, ``?`` for None."""
    if n is None:
        return "?"
    if n >= 10_000:
        return f"{n / 1000:.0f}k"
    return f"{n:,}"
