"""The accuracy measurement (explorer.analysis.accuracy), mesh_for_error against the measured table,
and ``phong-explorer bench accuracy``."""

from __future__ import annotations

import io
import json
import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import explorer
from explorer.analysis import accuracy as A
from explorer.cli import bench as cli_bench
from explorer.cli import main
from explorer.core.errors import ExplorerError
from explorer.core.presets import builtin_dir, load_material_file
from explorer.core.scene import Viewer
from explorer.geometry import meshes as M
from explorer.render.camera import camera_for, sphere_camera
from explorer.render.offscreen import OffscreenRenderer
from explorer.render.perpixel import Hits, Reference, is_unit_sphere, point_colors, reference

TABLE = A.load_table()


# -- comparing pictures ----------------------------------------------------------------------


def _reference(mask, colors, specular):
    hits = Hits(mask, np.zeros((mask.sum(), 3)), np.zeros((mask.sum(), 3)), "sphere")
    return Reference(hits, np.asarray(colors, float), np.asarray(specular, float))


def test_compare_by_definition():
    rng = np.random.default_rng(1)
    h, w = 12, 10
    mask = np.zeros((h, w), bool)
    mask[2:10, 3:8] = True
    k = int(mask.sum())
    colors = rng.random((k, 3))
    spec = rng.random(k)
    ref = _reference(mask, colors, spec)
    ref_img = ref.image()
    vertex = ref_img.astype(int) + rng.integers(-6, 7, size=ref_img.shape)
    vertex = np.clip(vertex, 0, 255).astype(np.uint8)
    cover = mask.copy()
    cover[2, 3:8] = False  # a row the per-vertex picture does not cover
    cover[0, 0] = True  # background pixel "covered": still not compared (reference misses it)
    c = A.compare(vertex, ref, cover)
    both = mask & cover
    d = np.abs(vertex.astype(int) - ref_img.astype(int))
    assert np.array_equal(c.mask, both)
    assert math.isclose(c.rmse, float(np.sqrt(np.mean(d[both].astype(float) ** 2))))
    assert c.max == d[both].max()
    assert np.array_equal(c.levels[both], d.max(axis=2)[both])
    assert np.all(c.levels[~both] == 0)
    rows, cols = np.nonzero(mask)
    p = int(np.argmax(spec))
    peak = (rows[p], cols[p])
    assert c.peak == (d.max(axis=2)[peak] if both[peak] else None)


def test_compare_peak_outside_coverage_and_no_highlight():
    mask = np.ones((4, 4), bool)
    ref = _reference(mask, np.full((16, 3), 0.5), np.arange(16.0))
    img = ref.image()
    cover = mask.copy()
    cover[3, 3] = False  # the peak (largest specular is the last pixel)
    assert A.compare(img, ref, cover).peak is None
    assert A.compare(img, ref, mask).peak == 0
    flat = _reference(mask, np.full((16, 3), 0.5), np.zeros(16))
    assert A.compare(img, flat, mask).peak is None


def test_heat_map():
    levels = np.array([[0, 1, 2, 4], [8, 16, 100, 3]])
    mask = np.ones_like(levels, bool)
    mask[1, 3] = False
    img = A.heat_map(levels, mask, vmax=16, background=(10, 20, 30))
    assert img.shape == (2, 4, 3) and img.dtype == np.uint8
    assert img[0, 0].tolist() == [0, 0, 0]
    assert img[0, 1].tolist() == [0, 0, 255]  # one level: blue
    assert img[1, 1].tolist() == [255, 255, 255] == img[1, 2].tolist()  # vmax and beyond
    assert img[1, 3].tolist() == [10, 20, 30]
    # logarithmic ramp: each doubling of the error (up to vmax = 16) is the next colour
    assert img[0, 2].tolist() == [0, 200, 0]  # 2 levels: green
    assert img[0, 3].tolist() == [255, 255, 0]  # 4: yellow
    assert img[1, 0].tolist() == [255, 0, 0]  # 8: red
    between = A.heat_map(np.array([[3]]), vmax=16)[0, 0]  # between green and yellow
    assert 0 < between[0] < 255 and 200 < between[1] < 255 and between[2] == 0
    with pytest.raises(ExplorerError):
        A.heat_map(levels, vmax=1.0)


@given(st.lists(st.tuples(st.floats(0, 100), st.floats(0, 100)), min_size=1, max_size=40))
def test_pareto_front_by_brute_force(points):
    t = [p[0] for p in points]
    e = [p[1] for p in points]
    front = A.pareto_front(t, e)
    for i in range(len(points)):
        dominated = any(
            (t[j] <= t[i] and e[j] <= e[i]) and (t[j] < t[i] or e[j] < e[i])
            for j in range(len(points))
        )
        if dominated:
            assert i not in front
    kept = {(t[i], e[i]) for i in front}
    for i in range(len(points)):
        if not any((t[j] <= t[i] and e[j] <= e[i]) and (t[j], e[j]) != (t[i], e[i])
                   for j in range(len(points))):  # fmt: skip
            assert (t[i], e[i]) in kept  # every undominated point is on the front once
    assert len(kept) == len(front)
    assert [t[i] for i in front] == sorted(t[i] for i in front)


def test_progress_bar_only_on_a_terminal():
    class Tty(io.StringIO):
        def isatty(self):
            return True

    tty, pipe = Tty(), io.StringIO()
    for stream in (tty, pipe):
        p = A.Progress(4, stream=stream)
        for i in range(4):
            p.step(f"item {i}")
        p.close()
    assert pipe.getvalue() == ""
    out = tty.getvalue()
    assert out.count("\r") == 4 and "100%" in out and "item 3" in out and out.endswith("\n")


# -- the shipped table and mesh_for_error --------------------------------------------------------


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
    for variant in A.VARIANTS:
        for mesh, resolutions in A.BENCH_MESHES:
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


def test_a_fresh_measurement_reproduces_the_table():
    """The shipped table is what the code measures now (renders are deterministic): re-measure
    a few rows and compare."""
    config = A.BenchConfig(
        materials=(A.BENCH_MATERIALS[1],),
        meshes=(("sphere", (32, 96)), ("icosphere", (3,))),
        sides=(200,),
        main_side=A.MAIN_SIDE,  # not measured here: only the sweep variants
        repeats=1,
    )
    fresh = A.run_bench(config)
    assert {r["variant"] for r in fresh["rows"]} == set(A.SWEEP_VARIANTS)
    for r in fresh["rows"]:
        (old,) = [
            x for x in TABLE["rows"]
            if all(x[k] == r[k] for k in ("material", "variant", "mesh", "resolution", "side"))
        ]  # fmt: skip
        assert r["vertices"] == old["vertices"]
        assert abs(r["rmse"] - old["rmse"]) <= 0.02 * old["rmse"] + 0.01
        assert abs(r["max"] - old["max"]) <= 1
        assert r["peak"] is None or abs(r["peak"] - old["peak"]) <= 1


def test_interpolated_recommendation_holds_when_measured():
    """For a shininess between the measured ones (n = 32), the RMSE recommendation is within
    its bound when measured fresh, and the next coarser tessellation is not (the RMSE falls
    smoothly with the tessellation, so interpolating it is sound)."""
    n, side, bound = 32.0, 200, 2.0
    rec = A.mesh_for_error(n, (side, side), bound, metric="rmse")
    assert rec.resolution is not None and not rec.exact
    resolutions = dict(A.BENCH_MESHES)["sphere"]
    i = resolutions.index(rec.resolution)
    config = A.BenchConfig(
        materials=(("chrome n=32", "chrome", n),),
        meshes=(("sphere", resolutions[max(i - 1, 0) : i + 1]),),
        sides=(side,),
        repeats=1,
    )
    rows = [r for r in A.run_bench(config)["rows"] if r["variant"] == "blinn"]
    measured = {r["resolution"]: r["rmse"] for r in rows}
    assert measured[rec.resolution] <= bound
    if i > 0:
        assert measured[resolutions[i - 1]] > bound


def test_compare_view_for_the_gui():
    """The GUI's comparison of a live view: a coarse sphere glows, a fine one does not."""

    chrome = load_material_file(builtin_dir() / "chrome.yaml")
    scene = A.bench_scene(chrome).replace(viewer=Viewer(eye=(0.3, 0.4, 3.5)))
    size = (120, 100)
    cam = camera_for(scene, M.sphere(64), size[0] / size[1])
    coarse = A.compare_view(scene, M.sphere(12), size, camera=cam)
    fine = A.compare_view(scene, M.sphere(512), size, camera=cam)
    assert coarse.rmse > 4 * fine.rmse and coarse.max > 20
    assert fine.rmse < 1.0
    heat = A.heat_map(coarse.levels, coarse.mask)
    assert heat.shape == (100, 120, 3)
    assert (heat[coarse.mask].sum(axis=1) > 0).mean() > 0.3
    teapot = A.compare_view(scene, M.teapot(4), size)  # any mesh: ray cast reference
    assert teapot.mask.sum() > 1000 and teapot.rmse > 0
    with A.ViewComparer(size) as v:  # reused windows give the same answers
        again = [v.compare(scene, M.sphere(12), camera=cam), v.compare(scene, M.teapot(4))]
    assert np.array_equal(again[0].levels, coarse.levels)
    assert np.array_equal(again[1].levels, teapot.levels)


# -- the command ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    code = main(["bench", "accuracy", "--quick", "--out-dir", str(out)])
    return code, out


def test_quick_bench_writes_table_doc_and_plot(quick, capsys):
    code, out = quick
    assert code == 0
    table = json.loads((out / "accuracy.json").read_text())
    assert table["quick"] and table["command"] == "phong-explorer bench accuracy --quick"
    assert table["machine"]["cpu"] and "load_after" in table["machine"]
    assert table["machine"]["opengl"]["renderer"]  # e.g. llvmpipe: what drew the pictures
    n_mesh = sum(len(r) for _, r in A.QUICK_MESHES)
    uniform = [r for r in table["rows"] if r["mesh"] != "adaptive"]
    adaptive = [r for r in table["rows"] if r["mesh"] == "adaptive"]
    assert len(uniform) == n_mesh * len(A.QUICK_MATERIALS) * len(A.VARIANTS)
    assert len(adaptive) == len(A.QUICK_ADAPTIVE_THRESHOLDS) * len(A.QUICK_MATERIALS)
    assert "## Adaptive refinement" in (out / "accuracy.md").read_text()
    for label, _, _ in A.QUICK_MATERIALS:
        rows = [r for r in table["rows"] if r["material"] == label and r["variant"] == "blinn"
                and r["mesh"] == "sphere"]  # fmt: skip
        rmse = [r["rmse"] for r in rows]
        assert rmse == sorted(rmse, reverse=True)  # finer spheres, smaller errors
        assert rmse[0] > 5 * rmse[-1]
    doc = (out / "accuracy.md").read_text()
    assert "## Machine" in doc and table["machine"]["cpu"] in doc
    assert "Quick run" in doc and "![error against time" in doc and "(accuracy.png)" in doc
    for label, _, _ in A.QUICK_MATERIALS:
        assert f"### {label}" in doc
    png = (out / "accuracy.png").read_bytes()
    assert png.startswith(b"\x89PNG")


def test_bench_never_replaces_user_files(quick, tmp_path, capsys):
    code, out = quick
    before = (out / "accuracy.md").read_bytes()
    assert main(["bench", "accuracy", "--quick", "--out-dir", str(out)]) == 2
    assert "already exists; use --force" in capsys.readouterr().err
    assert (out / "accuracy.md").read_bytes() == before
    assert main(["bench", "accuracy", "--quick"]) == 2
    assert "give --out-dir" in capsys.readouterr().err
    assert main(["bench", "accuracy", "--out-dir", str(tmp_path / "nope")]) == 2
    assert "not a directory" in capsys.readouterr().err
    assert main(["bench", "accuracy", "--quick", "--out-dir", str(tmp_path), "--repeats",
                 "0"]) == 2  # fmt: skip
    assert main(["bench"]) == 2
    assert "which bench" in capsys.readouterr().err


def test_default_outputs_are_the_checkouts(monkeypatch):
    ns = type("Args", (), {"out_dir": None, "quick": False, "force": False})()
    paths, overwrite = cli_bench.outputs(ns)
    root = cli_bench.checkout_root()
    assert overwrite and root is not None
    assert paths["md"] == root / "docs" / "accuracy.md"
    assert paths["png"] == root / "docs" / "accuracy.png"
    assert paths["json"] == A.data_path()
    monkeypatch.setattr(cli_bench, "checkout_root", lambda: None)
    with pytest.raises(ExplorerError, match="source checkout"):
        cli_bench.outputs(ns)


def test_plot_is_skipped_without_matplotlib(quick, tmp_path, monkeypatch, capsys):
    """matplotlib is an optional extra: without it the plot is skipped with a message and the
    document does not link a picture."""
    _, out = quick
    table = json.loads((out / "accuracy.json").read_text())
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # import matplotlib -> ImportError
    assert A.plot(table, tmp_path / "p.png") is False
    assert not (tmp_path / "p.png").exists()
    monkeypatch.setattr(A, "run_bench", lambda config, progress=None: dict(table))
    assert main(["bench", "accuracy", "--quick", "--out-dir", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert "plot skipped: matplotlib is not installed" in err
    assert "phong-explorer[bench]" in err
    assert not (tmp_path / "accuracy.png").exists()
    doc = (tmp_path / "accuracy.md").read_text()
    assert "![" not in doc and "## Findings" in doc


def test_import_stays_light():
    code = (
        "import sys, explorer.analysis.accuracy, explorer.render.perpixel, explorer.cli.bench; "
        "bad = [m for m in ('vtk', 'vtkmodules', 'pyvista', 'matplotlib') if m in sys.modules]; "
        "print(bad); sys.exit(1 if bad else 0)"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr


# -- adaptive refinement -----------------------------------------------------------------------


def _edge_counts(faces):
    e = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return counts


def test_refine_highlights_on_a_sphere():
    chrome = A.bench_material("chrome", 1000.0)
    scene = A.bench_scene(chrome)
    base = M.icosphere(2)
    fine = A.refine_highlights(scene, base, 2.0)
    assert base.n_vertices < fine.n_vertices < M.icosphere(5).n_vertices
    assert np.array_equal(fine.positions[: base.n_vertices], base.positions)
    assert is_unit_sphere(fine)  # new vertices on the sphere: still the exact reference
    assert np.all(_edge_counts(fine.faces) == 2)  # closed, no cracks or T-junctions
    cross = np.cross(
        fine.positions[fine.faces[:, 1]] - fine.positions[fine.faces[:, 0]],
        fine.positions[fine.faces[:, 2]] - fine.positions[fine.faces[:, 0]],
    )
    assert np.all(np.einsum("ij,ij->i", cross, fine.positions[fine.faces].mean(1)) > 0)
    # every edge now passes the test that split the others: the Gouraud colour at the chord's
    # midpoint against the exact colour of the sphere point the same pixel shows (seen along
    # +z), or of the edge's own midpoint on the back
    e = np.unique(np.sort(np.concatenate([fine.faces[:, [0, 1]], fine.faces[:, [1, 2]],
                                          fine.faces[:, [2, 0]]]), axis=1), axis=0)  # fmt: skip
    c = point_colors(scene, fine.positions, fine.normals)
    chord = 0.5 * (fine.positions[e[:, 0]] + fine.positions[e[:, 1]])
    q = chord / np.linalg.norm(chord, axis=1, keepdims=True)
    front = q[:, 2] > 0
    q[front, 2] = np.sqrt(1.0 - (chord[front, :2] ** 2).sum(axis=1))
    q[front, :2] = chord[front, :2]
    exact = point_colors(scene, q, q)
    gouraud = 0.5 * (c[e[:, 0]] + c[e[:, 1]])
    assert (np.abs(exact - gouraud).max(axis=1) * 255).max() <= 2.0
    # edges shorter than min_edge are never split
    length = np.linalg.norm(base.positions[base.faces[:, 0]] - base.positions[base.faces[:, 1]],
                            axis=1)  # fmt: skip
    assert A.refine_highlights(scene, base, 2.0, min_edge=2 * length.max()).n_vertices == (
        base.n_vertices
    )
    # the new vertices sit where the light is: near the highlight's direction H
    h = np.add(scene.lights[0].to_light, (0, 0, 1))
    h /= np.linalg.norm(h)
    new = fine.positions[base.n_vertices :]
    assert np.median(new @ h) > 0.9
    # and the picture is closer to the per-pixel one than the base mesh's

    size = (120, 120)
    cam = sphere_camera(scene)
    ref = reference(scene, base, size, camera=cam)
    with OffscreenRenderer(size) as r, OffscreenRenderer(size, (0, 0, 0)) as rc:
        errs = [
            A.compare(r.render(scene, m, camera=cam), ref, A.coverage(rc, scene, m, cam))
            for m in (base, fine)
        ]
    assert errs[1].rmse < 0.5 * errs[0].rmse and errs[1].max < errs[0].max


def test_refine_a_flat_mesh_keeps_it_flat_and_respects_the_budget():
    plane = M.plane(4)
    scene = explorer.Scene(
        material=A.bench_material("chrome"),
        lights=(explorer.PointLight(position=(0.2, 0.1, 0.5)),),
        viewer=explorer.Viewer(eye=(0.0, 0.0, 3.0)),
    )
    fine = A.refine_highlights(scene, plane, 1.0)
    assert fine.n_vertices > plane.n_vertices
    assert np.allclose(fine.positions[:, 2], 0.0) and np.allclose(fine.normals, [0, 0, 1])
    P, F = fine.positions, fine.faces
    area = np.linalg.norm(np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]]), axis=1) / 2
    assert math.isclose(area.sum(), 4.0) and area.min() > 0
    counts = _edge_counts(fine.faces)
    assert set(counts.tolist()) <= {1, 2}  # boundary edges once, inner edges twice
    small = A.refine_highlights(scene, plane, 0.01, max_vertices=60)
    assert plane.n_vertices <= small.n_vertices <= 60
