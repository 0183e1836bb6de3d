"""Starting: ``import explorer`` loads nothing heavy, its public names load on first use, and the
``phong-explorer`` command is inside its own error handling before the engine loads."""

from __future__ import annotations

import importlib
import os
import subprocess
import sys

import pytest
from helpers.interrupt import interrupt_start

import explorer


@pytest.mark.parametrize("module", ["explorer", "explorer.cli"])
def test_import_loads_neither_numpy_nor_numba(module):
    code = f"import sys, {module}; print(sorted({{'numpy', 'numba'}} & set(sys.modules)))"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"


def test_every_public_name_loads_from_its_module():
    assert set(explorer.__all__) == {*explorer._EXPORTS, "__version__"}
    for name, module in explorer._EXPORTS.items():
        assert getattr(explorer, name) is getattr(importlib.import_module(module), name)
        assert name in dir(explorer)
    from explorer import Scene, shade  # from-imports go through the same loader

    assert shade is explorer.shading.shader.shade and Scene is explorer.core.scene.Scene


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'shader_of'"):
        explorer.shader_of  # noqa: B018 - the lookup is the test


def test_ctrl_c_while_the_command_starts_is_one_line(tmp_path):
    out = tmp_path / "out.png"
    lines, chunks, status = interrupt_start(["render", "--preset", "gold", "--out", str(out)])
    assert lines == ["error: interrupted (Ctrl-C)"]
    assert chunks == 0  # stopped in the first subcommand's import
    assert status == 130
    assert not out.exists()
