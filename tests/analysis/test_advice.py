"""The shipped accuracy table, mesh_for_error against it, and the window's advice line
(explorer.analysis.advice)."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

import explorer
from explorer.analysis import advice as A
from explorer.analysis.benchmark import BENCH_MESHES, VARIANTS, BenchConfig, run_bench
from explorer.core.errors import ExplorerError

TABLE = A.load_table()


def _groups(table):
    groups: dict = {}
    for r in table["rows"]:
        key = (r["variant"], r["mesh"], r["shininess"], r["side"])
        groups.setdefault(key, []).append(r)
    return groups


def test_shipped_table_is_complete():
    assert not TABLE["quick"]
    m = TABLE["machine"]
    assert m["cpu"] and m["cores"] and m["versions"]["vtk"]
    labels = {x["label"] for x in TABLE["scene"]["materials"]}
    shin = sorted(x["shininess"] for x in TABLE["scene"]["materials"])
    assert shin == [10.0, 76.8, 89.6, 1000.0]
    assert len(labels) == 4
    groups = _groups(TABLE)
    for variant in VARIANTS:
        for mesh, resolutions in BENCH_MESHES:
            for n in shin:
                got = [r["resolution"] for r in groups[(variant, mesh, n, A.MAIN_SIDE)]]
                assert got == list(resolutions)
    for r in TABLE["rows"]:
        assert r["rmse"] >= 0 and r["max"] >= 0 and r["shade_ms"] > 0 and r["render_ms"] > 0
        assert r["max"] >= r["rmse"] - 1e-9 or r["max"] == 0
        if r["path"] == "float32":
            assert r["vs_float64"] <= 255 * explorer.core.tolerances.FLOAT32_MAX_ABS_ERROR
        if r["path"] == "plan off":
            assert r["vs_float64"] <= 255 * 1e-6


@pytest.mark.parametrize("metric", A.METRICS)
@pytest.mark.parametrize("mesh", ["sphere", "icosphere"])
@pytest.mark.parametrize("model", ["blinn", "phong"])
def test_mesh_for_error_against_the_measured_table(metric, mesh, model):
    """At every measured shininess and size: the recommendation's measured error is within the
    bound, the next coarser tessellation's is not; none is recommended only when even the
    finest is off."""
    checked = 0
    for (variant, m, n, side), rows in _groups(TABLE).items():
        if variant != model or m != mesh:
            continue
        rows = sorted(rows, key=lambda r: r["resolution"])
        errors = [r[metric] for r in rows]
        if any(e is None for e in errors):
            continue
        for bound in (1.0, 2.0, 3.0, 4.0, 8.0, 16.0, 0.5):
            rec = A.mesh_for_error(n, (side, side), bound, metric=metric, model=model, mesh=mesh)
            assert rec.exact
            if rec.resolution is None:
                assert errors[-1] > bound
                assert "no measured" in rec.describe()
                continue
            i = [r["resolution"] for r in rows].index(rec.resolution)
            assert rows[i]["vertices"] == rec.vertices
            assert errors[i] <= bound and rec.error == errors[i]
            assert all(e <= bound for e in errors[i:])  # it stays within from there on
            if i > 0:
                assert errors[i - 1] > bound
            checked += 1
    assert checked > 20


def test_mesh_for_error_between_measured_values():
    """Interpolated answers lie between the neighbours' answers, and size matters only
    through the table."""
    for metric in ("max", "rmse"):
        for lo, hi in ((10.0, 76.8), (89.6, 1000.0)):
            for bound in (1.0, 2.0, 4.0):
                a = A.mesh_for_error(lo, (400, 400), bound, metric=metric)
                b = A.mesh_for_error(hi, (400, 400), bound, metric=metric)
                mid = A.mesh_for_error(math.sqrt(lo * hi), (400, 400), bound, metric=metric)
                assert not mid.exact
                big = 10**9
                ra, rb, rm = (x.resolution if x.resolution is not None else big
                              for x in (a, b, mid))  # fmt: skip
                assert min(ra, rb) <= rm <= max(ra, rb)
    # clamped outside the measured shininess range and sizes
    assert A.mesh_for_error(2.0, (400, 400), 2.0).resolution == (
        A.mesh_for_error(10.0, (400, 400), 2.0).resolution
    )
    beyond = A.mesh_for_error(76.8, (3000, 3000), 2.0)
    largest = A.mesh_for_error(76.8, (max(TABLE["sides"]),) * 2, 2.0)
    assert (beyond.resolution, beyond.error) == (largest.resolution, largest.error)
    wide = A.mesh_for_error(76.8, (800, 200), 2.0)
    assert wide.size == (800, 200) and wide.exact  # the smaller side frames the sphere


def test_mesh_for_error_rejects_bad_questions():
    with pytest.raises(ExplorerError, match="metric"):
        A.mesh_for_error(10, metric="mean")
    with pytest.raises(ExplorerError, match="model"):
        A.mesh_for_error(10, model="cook")
    with pytest.raises(ExplorerError, match="max_error"):
        A.mesh_for_error(10, max_error=-1)
    with pytest.raises(ExplorerError, match="shininess"):
        A.mesh_for_error(float("nan"))
    with pytest.raises(ExplorerError, match="image size"):
        A.mesh_for_error(10, size=(4, 4))
    with pytest.raises(ExplorerError, match="no 'phong float32' rows"):
        A.mesh_for_error(10, model="phong", precision="float32")


def test_advice_line_names_the_recommendations():
    line = A.advice(76.8, (400, 400))
    assert line.startswith("shininess 76.8 (blinn), error within 1 level: RMSE from ")
    head, tail = line.split("; every pixel: ")
    for text, metric in ((head, "rmse"), (tail, "max")):
        for mesh in ("sphere", "icosphere"):
            rec = A.mesh_for_error(76.8, (400, 400), 1.0, metric=metric, mesh=mesh)
            if rec.resolution is not None:
                assert f"{rec.mesh} {rec.resolution} (" in text
            else:
                assert f"{rec.mesh} {rec.finest[0]}" in text
    assert "levels" in A.advice(1000, (200, 200), model="phong", max_error=4)
    three = A.advice(76.8, (400, 400), model="threejs")
    assert three == line.replace("(blinn)", "(threejs, from blinn's measurements)")


def test_interpolated_recommendation_holds_when_measured():
    """For a shininess between the measured ones (n = 32), the RMSE recommendation is within
    its bound when measured fresh, and the next coarser tessellation is not (the RMSE falls
    smoothly with the tessellation, so interpolating it is sound)."""
    n, side, bound = 32.0, 200, 2.0
    rec = A.mesh_for_error(n, (side, side), bound, metric="rmse")
    assert rec.resolution is not None and not rec.exact
    resolutions = dict(BENCH_MESHES)["sphere"]
    i = resolutions.index(rec.resolution)
    config = BenchConfig(
        materials=(("chrome n=32", "chrome", n),),
        meshes=(("sphere", resolutions[max(i - 1, 0) : i + 1]),),
        sides=(side,),
        repeats=1,
    )
    rows = [r for r in run_bench(config)["rows"] if r["variant"] == "blinn"]
    measured = {r["resolution"]: r["rmse"] for r in rows}
    assert measured[rec.resolution] <= bound
    if i > 0:
        assert measured[resolutions[i - 1]] > bound


def test_the_windows_api_leaves_the_benchmark_and_the_report_out():
    """The window imports the comparison and the advice; neither brings in the benchmark, the
    report, matplotlib or VTK."""
    code = (
        "import sys, explorer.analysis.advice, explorer.analysis.comparison; "
        "bad = [m for m in ('explorer.analysis.benchmark', 'explorer.analysis.report', "
        "'matplotlib', 'vtk', 'vtkmodules', 'pyvista') if m in sys.modules]; "
        "print(bad); sys.exit(1 if bad else 0)"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
