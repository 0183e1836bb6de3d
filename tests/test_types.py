"""The public API type-checks: ``mypy`` (the version pinned in the test extra) on the files
pyproject.toml's [tool.mypy] names (``explorer/__init__.py``, ``explorer/core``,
``explorer/app/model.py``) exits clean. The rest of the package is gradual: the checked files
see its annotations, and its own bodies are not checked."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def test_public_api_type_checks():
    if importlib.util.find_spec("mypy") is None:
        pytest.fail("mypy not found: pip install -e '.[test]'")
    # the files and settings come from pyproject.toml; the cache goes to .mypy_cache
    cmd = [sys.executable, "-m", "mypy", "--no-error-summary", "--hide-error-context"]
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, f"mypy (scope: pyproject.toml [tool.mypy]):\n{r.stdout}{r.stderr}"
