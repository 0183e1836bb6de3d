"""The code keeps the project's style: ``ruff check`` and ``ruff format --check`` on the whole
repository (the rules and exclusions are pyproject.toml's [tool.ruff]). The suite runs them, so
README's test command (what .ci/run runs) fails on a lint or format slip."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _ruff(*args: str) -> subprocess.CompletedProcess:
    if importlib.util.find_spec("ruff") is None:
        pytest.fail("ruff not found: pip install -e '.[test]'")
    cmd = [sys.executable, "-m", "ruff", *args, "--no-cache", "."]
    return subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=120)


def test_ruff_check_is_clean():
    r = _ruff("check")
    assert r.returncode == 0, (
        f"ruff check . found problems (fix: ruff check --fix .):\n{r.stdout}{r.stderr}"
    )


def test_ruff_format_is_clean():
    r = _ruff("format", "--check")
    assert r.returncode == 0, f"ruff format --check . (fix: ruff format .):\n{r.stdout}{r.stderr}"
