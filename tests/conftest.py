"""Shared pytest settings, options and fixtures of the whole test suite.

Hypothesis profiles: ``default`` (100 examples) and ``thorough`` (2,000; run with
``HYPOTHESIS_PROFILE=thorough``). Both keep every health check on. Deadlines are off
(``deadline=None``): the first example of a property test compiles its numba kernels or loads
them from numba's cache, which takes seconds, so a per-example deadline would measure the
compiler rather than the test. A test whose examples are legitimately slow to generate says so
with its own ``@settings(suppress_health_check=[HealthCheck.too_slow])`` and a reason.

Slow tests (more than a few seconds each, warm) carry ``@pytest.mark.slow``. The full run
(README's test command, ``.ci/run``) runs them; skip them locally with::

    python -m pytest -m "not slow"

Golden files (tests/golden/, see tests/helpers/imagecompare.py): ``--regenerate-goldens`` (or
``PHONG_EXPLORER_REGENERATE_GOLDENS=1``) rewrites them from the current results; the hooks
below tell tests/test_goldens.py whether this session ran every golden test, which it needs to
find the golden files no test uses.

Fixtures: ``renderer``, one 400×400 off-screen window per test module.

The engine runs on its compiled tier throughout (``PHONG_EXPLORER_KERNELS=compiled``, inherited
by the commands the tests start): the tests check the kernels, so a pass never falls back to the
numpy tier while numba's cache is cold. tests/shading/test_tiers.py tests the tiers and mode
``auto`` themselves.
"""

import os
import sys

os.environ["PHONG_EXPLORER_KERNELS"] = "compiled"  # before the package is imported

import pytest
from helpers import imagecompare
from hypothesis import settings

settings.register_profile("default", max_examples=100, deadline=None)
settings.register_profile("thorough", max_examples=2000, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))

#: size of the shared ``renderer`` fixture's pictures (width, height)
RENDER_SIZE = (400, 400)


def pytest_addoption(parser):
    parser.addoption(
        "--regenerate-goldens",
        action="store_true",
        help="rewrite the golden files from the current results (same as "
        f"{imagecompare.REGENERATE_ENV}=1) and remove the ones no test uses; review the diff "
        "before committing",
    )


def pytest_configure(config):
    if config.getoption("--regenerate-goldens"):
        os.environ[imagecompare.REGENERATE_ENV] = "1"


def _is_golden_test(item) -> bool:
    return "golden" in getattr(item, "name", "")


def pytest_collection_modifyitems(session, config, items):
    """The check for unused goldens runs last, after every test that uses one."""
    last = [i for i in items if getattr(i, "originalname", None) == "test_golden_files_all_used"]
    items[:] = [i for i in items if i not in last] + last
    tests_dir = imagecompare.GOLDEN_DIR.parent
    base = config.invocation_params.dir
    whole = False
    for arg in config.args:
        path = (base / arg.split("::")[0]).resolve()
        whole |= "::" not in arg and (path == tests_dir or path in tests_dir.parents)
    if not whole:
        imagecompare.INCOMPLETE.append(f"collected {config.args}, not the whole of {tests_dir}")


def pytest_deselected(items):
    names = [i.nodeid for i in items if _is_golden_test(i)]
    if names:
        imagecompare.INCOMPLETE.append(f"deselected golden tests: {names[:3]}...")


def pytest_runtest_logreport(report):
    if report.skipped and "golden" in report.nodeid.rsplit("::", 1)[-1]:
        imagecompare.INCOMPLETE.append(f"skipped golden test: {report.nodeid}")


@pytest.fixture(scope="module")
def renderer():
    """An off-screen window of RENDER_SIZE, shared by the tests of one module."""
    # VTK is imported only by the tests that draw
    from explorer.render.offscreen import OffscreenRenderer

    with OffscreenRenderer(RENDER_SIZE) as r:
        yield r


@pytest.fixture
def cold_tiers(monkeypatch, tmp_path):
    """The engine's tiers in mode auto on a cache that holds no kernels yet: yields the ready
    marker's path (absent; write it to say the background compile finished). The background
    compile is a process that does nothing, and the marker is looked for at every pass."""
    from explorer.shading import tiers

    marker = tmp_path / "explorer-ready-test.json"
    monkeypatch.setattr(tiers, "marker_path", lambda: marker)
    monkeypatch.setattr(tiers, "cache_dir", lambda: tmp_path)
    monkeypatch.setattr(tiers, "warm_command", lambda: [sys.executable, "-c", "pass"])
    monkeypatch.setattr(tiers, "POLL", 0.0)
    tiers.set_mode("auto")
    yield marker
    loader = tiers._state["loading"]
    if loader is not None:
        loader.join(timeout=600)
    tiers.set_mode(None)
    tiers._state.update(started=False, loading=None, failed=None, preload=False)


@pytest.fixture
def no_hang():
    """A test that would block (a reader waiting on a FIFO) fails instead of stopping the suite
    (``pytestmark = pytest.mark.usefixtures("no_hang")``): after 20 s, and every second after
    that, the blocked call is interrupted with an exception; should the code under test swallow
    it (trimesh catches BaseException around its side files), the test still fails at its end."""
    import signal

    fired = []

    def hung(signum, frame):
        fired.append(True)
        raise AssertionError("blocked: still waiting after 20 s")

    previous = signal.signal(signal.SIGALRM, hung)
    signal.setitimer(signal.ITIMER_REAL, 20.0, 1.0)
    yield
    signal.setitimer(signal.ITIMER_REAL, 0.0)
    signal.signal(signal.SIGALRM, previous)
    assert not fired, "the test blocked for more than 20 s"
