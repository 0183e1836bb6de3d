"""docs/examples/explorer.ipynb: kept without outputs, and run whole by nbmake (the explorer
served inline by ``explorer.app.web.show``, its state read back and set from Python)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.web
NOTEBOOK = Path(__file__).resolve().parents[3] / "docs" / "examples" / "explorer.ipynb"


def test_the_notebook_is_kept_without_outputs():
    nb = json.loads(NOTEBOOK.read_text(encoding="utf-8"))
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert code
    for c in code:
        assert c["outputs"] == [] and c["execution_count"] is None, c["source"]


def test_the_notebook_runs_under_nbmake(tmp_path):
    pytest.importorskip("nbmake")
    pytest.importorskip("trame")
    env = dict(os.environ, PHONG_EXPLORER_MATERIALS=str(tmp_path / "presets"))
    out = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--nbmake",
         "--nbmake-timeout=300", str(NOTEBOOK)],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert out.returncode == 0, out.stdout[-4000:] + out.stderr[-2000:]
    assert "1 passed" in out.stdout, out.stdout[-2000:]
