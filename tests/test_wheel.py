"""The package as an index and its users get it: build the sdist and, from it, the wheel (as
``python -m build`` does); both carry the licence, ``py.typed``, the presets, the data and the
report template, and the wheel's metadata the licence expression and classifiers of
pyproject.toml. Then install the wheel into a fresh environment outside the source tree, load every
preset from there and write the accuracy report from the shipped table and template."""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import subprocess
import sys
import tarfile
import venv
import zipfile
from email.parser import HeaderParser
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
    """The build-system requirement of pyproject.toml (setuptools>=77, for the PEP 639 licence
    fields) and the ``build`` front end, installed: the test builds offline, without isolation."""
    import setuptools

    major, minor = (int(x) for x in setuptools.__version__.split(".")[:2])
    return (major, minor) >= (77, 0) and importlib.util.find_spec("build") is not None


def _run(cmd, **kw):
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300, **kw)
    assert proc.returncode == 0, f"{cmd} failed:\n{proc.stdout}\n{proc.stderr}"
    return proc


@pytest.mark.slow
@pytest.mark.skipif(
    not _can_build_wheels(),
    reason="needs setuptools>=77 (pyproject.toml's build requirement) and 'build' installed: "
    "pip install -U setuptools build",
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
    # the sdist, then the wheel from the unpacked sdist: what an index or `pip install` from a
    # source archive sees
    built = _run(
        [sys.executable, "-m", "build", "--no-isolation", "-o", str(dist), str(src)], cwd=tmp_path
    )
    # no packaging warning from setuptools (a deprecated field, a data folder it would drop)
    said = built.stdout + built.stderr
    assert "WARNING" not in said and "Deprecat" not in said, said
    (sdist,) = dist.glob("phong_explorer-*.tar.gz")
    (wheel,) = dist.glob("phong_explorer-*.whl")
    _check_sdist(sdist)
    _check_wheel(wheel)

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


PRESETS = sorted(p.name for p in (ROOT / "materials").glob("*.yaml"))
SHIPPED = (
    "explorer/py.typed",
    "explorer/data/accuracy.json",
    "explorer/analysis/templates/accuracy.md",
)


def _check_sdist(sdist: Path) -> None:
    with tarfile.open(sdist) as tar:
        names = tar.getnames()
    (top,) = {n.split("/", 1)[0] for n in names}
    inner = {n.split("/", 1)[1] for n in names if "/" in n}
    for name in ("LICENSE", "README.md", "pyproject.toml", *SHIPPED):
        assert name in inner, f"{name} missing from the sdist {sdist.name}: {sorted(inner)}"
    assert sorted(n for n in inner if n.startswith("materials/") and n.endswith(".yaml")) == [
        f"materials/{p}" for p in PRESETS
    ]


def _check_wheel(wheel: Path) -> None:
    names = zipfile.ZipFile(wheel).namelist()
    for name in SHIPPED:
        assert name in names, f"{name} missing from the wheel {wheel.name}: {names}"
    assert sorted(
        n for n in names if n.startswith("explorer/materials/") and n.endswith(".yaml")
    ) == [f"explorer/materials/{p}" for p in PRESETS]
    # only the package and its metadata: no tests, benchmarks or docs
    assert {n.split("/", 1)[0] for n in names} == {"explorer", _dist_info(names)}
    info = _dist_info(names)
    licence = zipfile.ZipFile(wheel).read(f"{info}/licenses/LICENSE")
    assert licence == (ROOT / "LICENSE").read_bytes()
    meta = HeaderParser().parsestr(zipfile.ZipFile(wheel).read(f"{info}/METADATA").decode())
    assert meta["License-Expression"] == "MIT"
    assert meta.get_all("License-File") == ["LICENSE"]
    if sys.version_info < (3, 11):
        return  # tomllib: the rest compares with pyproject.toml
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert meta["License-Expression"] == project["license"]
    assert meta.get_all("Classifier") == project["classifiers"]
    assert meta["Keywords"] == ",".join(project["keywords"])


def _dist_info(names: list[str]) -> str:
    (info,) = {n.split("/", 1)[0] for n in names if n.split("/", 1)[0].endswith(".dist-info")}
    return info
