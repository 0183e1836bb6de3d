"""The Python examples the documentation shows run as written.

Every ```python block of a docs page runs in a fresh interpreter in an empty folder (with the
``scene.yaml`` the render page's example reads), so an example that names a module or a
function the package no longer has fails here, not in a user's shell. The page's example of
the web page in Jupyter is left out: it serves a page (tests/app/web tests ``show()``).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

#: pages whose examples need a server or a notebook: where each is tested instead
NOT_RUN = {"web.md": "serves a page; tests/app/web/test_web_life.py runs show()"}

BLOCK = re.compile(r"^```python\n(.*?)^```", re.S | re.M)


def _examples() -> list[tuple[str, int, str]]:
    found = []
    for page in sorted((ROOT / "docs").glob("*.md")):
        if page.name in NOT_RUN:
            continue
        for k, match in enumerate(BLOCK.finditer(page.read_text(encoding="utf-8"))):
            found.append((page.name, k, match.group(1)))
    return found


def test_the_docs_have_python_examples():
    pages = {page for page, _, _ in _examples()}
    assert {"render.md", "engine.md", "accuracy_summary.md"} <= pages


@pytest.mark.parametrize(("page", "k", "code"), _examples(), ids=lambda v: str(v)[:20])
def test_a_docs_example_runs_as_written(page, k, code, tmp_path):
    (tmp_path / "scene.yaml").write_text("material: gold\nmesh: sphere\n", encoding="utf-8")
    path = os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])
    env = {**os.environ, "PYTHONPATH": path}
    done = subprocess.run(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, f"docs/{page} example {k}:\n{done.stderr[-2000:]}"
