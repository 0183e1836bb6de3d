"""The suite's order (tests/conftest.py): the tests that call no numba kernel run first, beside
the background compile on a cold cache, the window tests of tests/app/qt last, and the list of
the first names test modules that exist (a renamed module would quietly join the others)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

TESTS = Path(__file__).resolve().parent


def _suite_conftest(config):
    """tests/conftest.py as pytest loaded it (``import conftest`` may find another folder's)."""
    for plugin in config.pluginmanager.get_plugins():
        if getattr(plugin, "__file__", None) and Path(plugin.__file__) == TESTS / "conftest.py":
            return plugin
    raise AssertionError("tests/conftest.py is not loaded")


def test_the_tests_before_the_kernels_are_test_modules_outside_the_windows_folder(pytestconfig):
    for name in _suite_conftest(pytestconfig).BEFORE_KERNELS:
        assert (TESTS / name).is_file(), f"{name} in BEFORE_KERNELS is not a test module"
        assert Path(name).name.startswith("test_"), name
        assert not name.startswith("app/qt/"), f"{name}: the window tests run last"


def test_kernel_free_tests_run_first_and_window_tests_last():
    chosen = ["tests/app/qt/test_qtlibs.py", "tests/app/test_view.py", "tests/core/test_text.py"]
    cmd = [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider"]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    out = subprocess.run(
        [*cmd, *chosen], cwd=TESTS.parent, env=env, capture_output=True, text=True, timeout=300
    )
    assert out.returncode == 0, out.stdout + out.stderr
    modules = [line.split("::")[0] for line in out.stdout.splitlines() if "::" in line]
    order = list(dict.fromkeys(modules))
    assert order == [chosen[2], chosen[1], chosen[0]], out.stdout
