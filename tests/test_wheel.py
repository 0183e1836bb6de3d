"""The package data ships inside the wheel: build it, install it into a fresh environment outside
the source tree, load every preset from there and write the accuracy report from the shipped table
and template."""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import subprocess
import sys
import venv
import zipfile
from pathlib import Path

import pytest

from explorer.core.presets import list_presets

ROOT = Path(__file__).resolve().parents[1]

SNIPPET = r"""
import json, sys
import explorer
from explorer.core.presets import builtin_dir, find_preset, list_presets
infos = list_presets(notices=[])
print(json.dumps({
    "explorer": explorer.__file__,
    "builtin_dir": str(builtin_dir()),
    "presets": {
        p.name: {"path": str(p.path), "source": p.source,
                 "material": p.material.to_mapping(), "found": find_preset(p.name).to_mapping()}
        for p in infos
    },
}))
"""

REPORT = r"""
import sys
from explorer.analysis.advice import load_table
from explorer.analysis.report import markdown
table = load_table()
sys.stdout.buffer.write(markdown(table, plot="accuracy.png", command=table["command"]).encode())
"""


def _can_build_wheels() -> bool:
    import setuptools

    major, minor = (int(x) for x in setuptools.__version__.split(".")[:2])
    return importlib.util.find_spec("wheel") is not None or (major, minor) >= (70, 1)


def _run(cmd, **kw):
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300, **kw)
    assert proc.returncode == 0, f"{cmd} failed:\n{proc.stdout}\n{proc.stderr}"
    return proc


@pytest.mark.slow
@pytest.mark.skipif(
    not _can_build_wheels(), reason="needs the 'wheel' package (or setuptools>=70.1)"
)
def test_presets_load_from_an_installed_wheel(tmp_path):
    # 1. build from a clean copy of the project (keeps build/ and *.egg-info out of the tree)
    src = tmp_path / "src"
    src.mkdir()
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "*.nbi", "*.nbc", "*.egg-info")
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        if (ROOT / name).exists():
            shutil.copy2(ROOT / name, src / name)
    for name in ("explorer", "materials"):
        shutil.copytree(ROOT / name, src / name, ignore=ignore)
    dist = tmp_path / "dist"
    _run(
        [sys.executable, "-m", "pip", "wheel", str(src), "--no-deps", "--no-build-isolation",
         "--no-index", "-q", "-w", str(dist)],
        cwd=tmp_path,
    )  # fmt: skip
    (wheel,) = dist.glob("phong_explorer-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert "explorer/analysis/templates/accuracy.md" in names
    assert "explorer/data/accuracy.json" in names

    # 2. a fresh environment (numpy & co. come from the system site-packages, no network)
    env_dir = tmp_path / "venv"
    venv.create(env_dir, system_site_packages=True, with_pip=True)
    py = env_dir / "bin" / "python"
    _run(
        [str(py), "-m", "pip", "install", "--no-deps", "--no-index", "--ignore-installed", "-q",
         str(wheel)],
        cwd=tmp_path,
    )  # fmt: skip

    # 3. load every preset from there, run from a directory outside the source tree
    work = tmp_path / "elsewhere"
    work.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["PHONG_EXPLORER_MATERIALS"] = str(tmp_path / "no-user-presets")
    out = json.loads(_run([str(py), "-c", SNIPPET], cwd=work, env=env).stdout)

    site = str(env_dir)
    assert out["explorer"].startswith(site), out["explorer"]  # not the source tree
    assert out["builtin_dir"].startswith(site)
    expected = {p.name: p.material for p in list_presets(notices=[]) if p.source == "builtin"}
    assert sorted(out["presets"]) == sorted(expected)
    assert len(expected) == len(list((ROOT / "materials").glob("*.yaml")))
    for name, info in out["presets"].items():
        assert info["source"] == "builtin" and info["path"].startswith(site)
        assert info["material"] == expected[name].to_mapping(), name
        assert info["found"] == info["material"]

    # 4. and the console script works from there too
    proc = _run(
        [str(env_dir / "bin" / "phong-explorer"), "presets", "show", "gold"], cwd=work, env=env
    )
    assert str(Path(out["builtin_dir"]) / "gold.yaml") in proc.stdout

    # 5. the accuracy report from the installed table and template is docs/accuracy.md
    report = subprocess.run([str(py), "-c", REPORT], cwd=work, env=env, capture_output=True)
    assert report.returncode == 0, report.stderr.decode()
    assert report.stdout == (ROOT / "docs" / "accuracy.md").read_bytes()
