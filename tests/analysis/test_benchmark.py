"""The accuracy benchmark (explorer.analysis.benchmark) and ``phong-explorer bench accuracy``."""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
from pathlib import Path

import pytest

from explorer.analysis import benchmark as B
from explorer.analysis import report as R
from explorer.analysis.advice import MAIN_SIDE, data_path, load_table
from explorer.cli import bench as cli_bench
from explorer.cli import main

TABLE = load_table()


@pytest.mark.slow
def test_a_fresh_measurement_reproduces_the_table():
    """The shipped table is what the code measures now (renders are deterministic): re-measure
    a few rows and compare."""
    config = B.BenchConfig(
        materials=(B.BENCH_MATERIALS[1],),
        meshes=(("sphere", (32, 96)), ("icosphere", (3,))),
        sides=(200,),
        main_side=MAIN_SIDE,  # not measured here: only the sweep variants
        repeats=1,
    )
    fresh = B.run_bench(config)
    assert {r["variant"] for r in fresh["rows"]} == set(B.SWEEP_VARIANTS)
    for r in fresh["rows"]:
        (old,) = [
            x for x in TABLE["rows"]
            if all(x[k] == r[k] for k in ("material", "variant", "mesh", "resolution", "side"))
        ]  # fmt: skip
        assert r["vertices"] == old["vertices"]
        assert abs(r["rmse"] - old["rmse"]) <= 0.02 * old["rmse"] + 0.01
        assert abs(r["max"] - old["max"]) <= 1
        assert r["peak"] is None or abs(r["peak"] - old["peak"]) <= 1


# -- the command -----------------------------------------------------------------------------------


@pytest.mark.slow
def test_quick_bench_writes_table_doc_and_plot(tmp_path):
    out = tmp_path
    assert main(["bench", "accuracy", "--quick", "--out-dir", str(out)]) == 0
    table = json.loads((out / "accuracy.json").read_text())
    assert table["quick"] and table["command"] == "phong-explorer bench accuracy --quick"
    assert table["machine"]["cpu"] and "load_after" in table["machine"]
    assert table["machine"]["opengl"]["renderer"]  # e.g. llvmpipe: what drew the pictures
    n_mesh = sum(len(r) for _, r in B.QUICK_MESHES)
    uniform = [r for r in table["rows"] if r["mesh"] != "adaptive"]
    adaptive = [r for r in table["rows"] if r["mesh"] == "adaptive"]
    assert len(uniform) == n_mesh * len(B.QUICK_MATERIALS) * len(B.VARIANTS)
    assert len(adaptive) == len(B.QUICK_ADAPTIVE_THRESHOLDS) * len(B.QUICK_MATERIALS)
    assert "## Adaptive refinement" in (out / "accuracy.md").read_text()
    for label, _, _ in B.QUICK_MATERIALS:
        rows = [r for r in table["rows"] if r["material"] == label and r["variant"] == "blinn"
                and r["mesh"] == "sphere"]  # fmt: skip
        rmse = [r["rmse"] for r in rows]
        assert rmse == sorted(rmse, reverse=True)  # finer spheres, smaller errors
        assert rmse[0] > 5 * rmse[-1]
    doc = (out / "accuracy.md").read_text()
    assert "## Machine" in doc and table["machine"]["cpu"] in doc
    assert "Quick run" in doc and "![error against time" in doc and "(accuracy.png)" in doc
    for label, _, _ in B.QUICK_MATERIALS:
        assert f"### {label}" in doc
    png = (out / "accuracy.png").read_bytes()
    assert png.startswith(b"\x89PNG")


@pytest.fixture
def fake_bench(monkeypatch):
    """``bench accuracy`` with the measurement replaced by a copy of the shipped table; the
    configs it was asked to measure are recorded."""
    configs = []

    def run_bench(config, progress=None):
        configs.append(config)
        return json.loads(json.dumps(TABLE))

    monkeypatch.setattr(cli_bench, "run_bench", run_bench)
    return configs


def test_bench_writes_into_the_current_directory(fake_bench, tmp_path, monkeypatch, capsys):
    shipped = data_path().read_bytes()
    monkeypatch.chdir(tmp_path)
    assert main(["bench", "accuracy", "--repeats", "3"]) == 0
    assert fake_bench[0] == dataclasses.replace(B.BenchConfig(), repeats=3)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "accuracy.json",
        "accuracy.md",
        "accuracy.png",
    ]
    table = json.loads((tmp_path / "accuracy.json").read_text())
    assert table == {**TABLE, "command": "phong-explorer bench accuracy"}
    assert (tmp_path / "accuracy.json").read_bytes() == R.table_bytes(table)
    doc = (tmp_path / "accuracy.md").read_text(encoding="utf-8")
    assert doc == R.markdown(table, plot="accuracy.png", command=table["command"])
    assert (tmp_path / "accuracy.png").read_bytes().startswith(b"\x89PNG")
    assert data_path().read_bytes() == shipped  # never the installed package's table
    out = capsys.readouterr().out
    assert "wrote accuracy.json" in out and "wrote accuracy.md" in out


def test_bench_replaces_files_only_with_force(fake_bench, tmp_path, capsys):
    (tmp_path / "accuracy.png").write_bytes(b"mine")
    assert main(["bench", "accuracy", "--quick", "--out-dir", str(tmp_path)]) == 2
    assert "accuracy.png: already exists; use --force" in capsys.readouterr().err
    assert not fake_bench  # refused before measuring
    assert sorted(p.name for p in tmp_path.iterdir()) == ["accuracy.png"]
    assert (tmp_path / "accuracy.png").read_bytes() == b"mine"
    assert main(["bench", "accuracy", "--quick", "--out-dir", str(tmp_path), "--force"]) == 0
    assert fake_bench == [B.BenchConfig.quick_run()]
    assert (tmp_path / "accuracy.png").read_bytes().startswith(b"\x89PNG")
    doc = (tmp_path / "accuracy.md").read_text(encoding="utf-8")
    assert "Generated by `phong-explorer bench accuracy --quick`" in doc


def test_bench_refuses_bad_arguments(fake_bench, tmp_path, capsys):
    assert main(["bench", "accuracy", "--out-dir", str(tmp_path / "nope")]) == 2
    assert "not a directory" in capsys.readouterr().err
    assert main(["bench", "accuracy", "--quick", "--out-dir", str(tmp_path), "--repeats",
                 "0"]) == 2  # fmt: skip
    assert "--repeats must be at least 1" in capsys.readouterr().err
    assert main(["bench"]) == 2
    assert "which bench" in capsys.readouterr().err
    assert not fake_bench and not any(tmp_path.iterdir())


def test_plot_is_skipped_without_matplotlib(fake_bench, tmp_path, monkeypatch, capsys):
    """matplotlib is an optional extra: without it the plot is skipped with a message and the
    document does not link a picture."""
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # import matplotlib -> ImportError
    assert R.plot(TABLE, tmp_path / "p.png") is False
    assert not (tmp_path / "p.png").exists()
    assert main(["bench", "accuracy", "--out-dir", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert "plot skipped: matplotlib is not installed" in err
    assert "phong-explorer[bench]" in err
    assert not (tmp_path / "accuracy.png").exists()
    doc = (tmp_path / "accuracy.md").read_text()
    assert "![" not in doc and "## Findings" in doc


@pytest.mark.parametrize("force", [False, True])
def test_bench_outputs_are_all_or_nothing(fake_bench, tmp_path, monkeypatch, capsys, force):
    """The plot fails after the table was measured (a full disk, a broken matplotlib): no new
    file is left, old files stay, and the same command can simply be run again."""
    if force:
        (tmp_path / "accuracy.json").write_bytes(b"old")
    args = ["bench", "accuracy", "--out-dir", str(tmp_path)] + (["--force"] if force else [])

    def broken(table):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(cli_bench, "plot_png", broken)
    with pytest.raises(OSError):
        main(args)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == (
        {"accuracy.json": b"old"} if force else {}
    )
    monkeypatch.undo()
    monkeypatch.setattr(cli_bench, "run_bench", lambda config, progress=None: dict(TABLE))
    assert main(args) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "accuracy.json",
        "accuracy.md",
        "accuracy.png",
    ]


_SIGTERM_DRIVER = """
import os, sys, time
from explorer.analysis.advice import load_table
from explorer.cli import bench, main

real_fsync = os.fsync

def slow_fsync(fd):  # the first temporary file is on disk: hold the write there
    real_fsync(fd)
    print("writing", flush=True)
    time.sleep(60)

os.fsync = slow_fsync
bench.plot_png = lambda table: b"png"
bench.run_bench = lambda config, progress=None: load_table()
sys.exit(main(["bench", "accuracy", "--out-dir", sys.argv[1]]))
"""


def test_sigterm_during_a_write_leaves_no_temporary(tmp_path):
    import os
    import signal

    proc = subprocess.Popen(
        [sys.executable, "-c", _SIGTERM_DRIVER, str(tmp_path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])},
    )
    try:
        assert proc.stdout.readline() == "writing\n"
        assert any(tmp_path.iterdir())  # the temporary file
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 143
    assert err.strip().splitlines() == ["error: terminated (SIGTERM); no unfinished file was left"]
    assert list(tmp_path.iterdir()) == []


def test_import_stays_light():
    code = (
        "import sys, explorer.analysis.benchmark, explorer.analysis.report, explorer.cli.bench; "
        "bad = [m for m in ('vtk', 'vtkmodules', 'pyvista', 'matplotlib') if m in sys.modules]; "
        "print(bad); sys.exit(1 if bad else 0)"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
