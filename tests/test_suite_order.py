"""The suite's order (tests/conftest.py): the tests that call no numba kernel run first, beside
the background compile on a cold cache, the window tests of tests/app/qt last, and the list of
the first names test modules that exist (a renamed module would quietly join the others); and
how the two workers share that order (tests/helpers/workers.py)."""

from __future__ import annotations

import os
import subprocess
import sys
import types
from pathlib import Path

import pytest

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


class _Worker:
    """A stand-in for xdist's WorkerController: keeps the test indices it is sent."""

    def __init__(self, name: str):
        self.name, self.shutting_down, self.queue, self.ran = name, False, [], []
        self.gateway = types.SimpleNamespace(id=name)

    def send_runtest_some(self, indices):
        self.queue.extend(indices)

    def shutdown(self):
        self.shutting_down = True


def test_two_workers_get_whole_modules_in_the_suites_order_and_the_goldens_together():
    """tests/helpers/workers.py (addopts' -n 2) on a collection in the suite's order: the
    kernel-free modules, a golden test, modules that call kernels, a second golden module,
    the window modules, the check of unused goldens last. Two workers run the tests they are
    sent one at a time, turn about."""
    pytest.importorskip("xdist")
    from helpers.workers import ModuleScheduling

    modules = {
        "tests/core/test_text.py": ["test_a", "test_b", "test_c"],
        "tests/app/web/test_web_rows.py": ["test_a", "test_b"],
        "tests/render/test_render.py": ["test_a", "test_golden_teapot", "test_b"],
        "tests/shading/test_vmath.py": ["test_a", "test_b", "test_c", "test_d", "test_e"],
        "tests/analysis/test_report.py": ["test_a"],
        "tests/shading/test_effects.py": ["test_golden_shadow", "test_a"],
        "tests/app/test_view.py": ["test_a", "test_b", "test_c"],
        "tests/app/qt/test_panel.py": ["test_a", "test_b", "test_c"],
        "tests/app/qt/test_window.py": ["test_a", "test_b"],
        "tests/test_goldens.py": ["test_golden_files_all_used"],
    }
    ids = [f"{m}::{t}" for m, tests in modules.items() for t in tests]
    option = types.SimpleNamespace(loadscopereorder=True)
    config = types.SimpleNamespace(option=option, getvalue={"tx": ["2*popen"]}.get)
    sched = ModuleScheduling(config)
    workers = [_Worker("gw0"), _Worker("gw1")]
    for w in workers:
        sched.add_node(w)
    for w in workers:
        sched.add_node_collection(w, ids)
    sched.schedule()
    while any(w.queue for w in workers):
        for w in workers:
            if w.queue:
                w.ran.append(ids[w.queue.pop(0)])
                sched.mark_test_complete(w, ids.index(w.ran[-1]))
    assert sorted(t for w in workers for t in w.ran) == sorted(ids), "each test runs once"
    where = {t.split("::")[0]: w.name for w in workers for t in w.ran}
    for w in workers:
        ran = [t.split("::")[0] for t in w.ran]
        assert all(where[m] == w.name for m in ran), f"a module split between workers: {ran}"
        qt = [i for i, m in enumerate(ran) if "/app/qt/" in m]
        assert not qt or qt == list(range(qt[0], len(ran))), f"{w.name}: a test after Qt: {ran}"
    golden = [w for w in workers if "tests/test_goldens.py::test_golden_files_all_used" in w.ran]
    assert len(golden) == 1
    mine = [t for t in golden[0].ran if "golden" in t]
    assert mine == [t for t in ids if "golden" in t], golden[0].ran
    assert mine[-1] == ids[-1], "the check of unused goldens runs after every golden test"
    # each worker starts with one of the two kernel-free modules, which come first
    firsts = {w.ran[0].split("::")[0] for w in workers}
    assert firsts == {"tests/core/test_text.py", "tests/app/web/test_web_rows.py"}, firsts
