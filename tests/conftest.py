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

The cold compile beside the tests: on a cache that lacks kernels (CI's fresh clone), the kernels'
compile (minutes of one core) would run inside the pytest process, test after test, while the
second core waits. So a run that collects both the tests of :data:`BEFORE_KERNELS` (no numba
kernel in the pytest process nor in the commands they start) and others starts the background
compile's passes (:func:`explorer.shading.warm.exercise`) in a process of its own at once, runs
:data:`BEFORE_KERNELS` first, and lets the first other test wait for that process: by then it
has filled numba's cache and the tests load the kernels instead of compiling them. On a warm
cache nothing is started; the order is the same either way.

Two workers (pytest-xdist, ``-n 2`` in pyproject.toml's addopts; ``-n 0``: one process): the
pytest process starts the background compile as above and hands out whole modules in the order
above (tests/helpers/workers.py); the first test of each worker outside :data:`BEFORE_KERNELS`
waits for the compile (its end is a file in a folder the workers are given), and the summary
line gives each worker's wait.
"""

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

os.environ["PHONG_EXPLORER_KERNELS"] = "compiled"  # before the package is imported

import pytest
from helpers import imagecompare
from helpers.processes import running_children
from hypothesis import settings

settings.register_profile("default", max_examples=100, deadline=None)
settings.register_profile("thorough", max_examples=2000, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))

#: size of the shared ``renderer`` fixture's pictures (width, height)
RENDER_SIZE = (400, 400)

TESTS = Path(__file__).resolve().parent
#: test modules and folders (relative to tests/) that call no numba kernel, neither in the pytest
#: process nor in the commands they start (page servers run the numpy tier, tests/app/web's
#: webserver.py): they run first, while the cold compile runs beside them (module docstring).
#: Found with a per-test count of the kernels' signatures on a warm cache; a module listed here
#: that comes to call a kernel only costs time (it compiles what it needs itself).
BEFORE_KERNELS = (
    "app/web/test_jupyter_proxy.py",
    "app/web/test_web_direct.py",
    "app/web/test_web_intents.py",
    "app/web/test_web_layout.py",
    "app/web/test_web_maps.py",
    "app/web/test_web_parity.py",
    "app/web/test_web_pictures.py",
    "app/web/test_web_rows.py",
    "app/web/test_web_security.py",
    "app/web/test_web_wire.py",
    "app/web/test_webfiles.py",
    "app/web/test_webdirect.py",
    "app/web/test_webguard.py",
    "app/web/test_webwire.py",
    "app/test_model.py",
    "app/test_panelmodel.py",
    "core/test_atomic.py",
    "core/test_controls.py",
    "core/test_errors.py",
    "core/test_files.py",
    "core/test_formats.py",
    "core/test_lights.py",
    "core/test_material.py",
    "core/test_mtl.py",
    "core/test_presets.py",
    "core/test_scene.py",
    "core/test_text.py",
    "core/test_texture.py",
    "core/test_yamlio.py",
    "docs/test_site.py",
    "test_architecture.py",
    "test_bench_isa.py",
    "test_lint.py",
    "test_start.py",
    "test_strict.py",
    "test_suite_order.py",
    "test_types.py",
    "test_wheel.py",
)
#: the background compile's process, while it runs (see the module docstring)
_COMPILE: dict = {}


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
    return imagecompare.is_golden_test_name(getattr(item, "name", ""))


def _before_kernels(item) -> bool:
    return _in_before_kernels(item.path)


def _before_kernels_id(config, nodeid: str) -> bool:
    return _in_before_kernels(config.rootpath / nodeid.split("::", 1)[0])


def _in_before_kernels(path: Path) -> bool:
    try:
        where = path.resolve().relative_to(TESTS).as_posix()
    except ValueError:  # a test outside tests/ (tests/test_strict.py's own runs)
        return False
    return where in BEFORE_KERNELS


def pytest_sessionstart(session):
    """A run of folders (the whole suite, CI) starts the background compile before collecting,
    which takes a while (see pytest_collection_modifyitems for the others)."""
    base = session.config.invocation_params.dir
    if any((base / arg).is_dir() for arg in session.config.args):
        _start_compile(session.config)


def pytest_collection_modifyitems(session, config, items):
    """The tests of :data:`BEFORE_KERNELS` run first (the others keep their order: the window
    tests of tests/app/qt stay last, tests/app/conftest.py), with the background compile beside
    them on a cold cache (ended at once when no test is left that calls a kernel); the check
    for unused goldens runs last, after every test that uses one."""
    first = [i for i in items if _before_kernels(i)]
    if len(first) == len(items):
        _end_compile(stop=True)
    elif first:
        _start_compile(config)
    last = [i for i in items if getattr(i, "originalname", None) == "test_golden_files_all_used"]
    rest = [i for i in items if i not in set(first) and i not in last]
    items[:] = first + rest + last
    tests_dir = imagecompare.GOLDEN_DIR.parent
    base = config.invocation_params.dir
    whole = False
    for arg in config.args:
        path = (base / arg.split("::")[0]).resolve()
        whole |= "::" not in arg and (path == tests_dir or path in tests_dir.parents)
    if not whole:
        imagecompare.INCOMPLETE.append(f"collected {config.args}, not the whole of {tests_dir}")


def _cold_kernels() -> bool:
    """Whether numba's cache lacks the kernels of some kernel module for the current sources:
    no function of the module has an index entry for them (a fresh clone, or an edited kernel
    file; numba keys a module's functions by one stamp, explorer.geometry.kernelcache). Per
    module, as helpers that are only ever inlined have no entry of their own."""
    from explorer.shading import warm

    cached: dict[str, bool] = {}
    for name, d in warm.dispatchers().items():
        cache = getattr(d._cache, "_cache_file", None)  # numba's IndexDataCacheFile
        if cache is not None:
            module = name.rsplit(".", 1)[0]
            cached[module] = cached.get(module, False) or bool(cache._load_index())
    return not all(cached.values())


def _start_compile(config) -> None:
    """On a cold cache, :func:`explorer.shading.warm.exercise` in a process of its own (the
    engine's compiled tier, numba's cache of this session), its output in a file; once per
    session, in the pytest process (with workers: the one that hands out the tests). The file
    ``started`` in :func:`_shared_folder` says it runs, ``ended`` that it ended."""
    if "checked" in _COMPILE or _worker(config) or config.option.collectonly:
        return
    _COMPILE["checked"] = True
    if not _cold_kernels():
        return
    (_shared_folder() / "started").touch()
    # closed in _end_compile, read and removed in pytest_terminal_summary
    log = tempfile.NamedTemporaryFile(prefix="explorer-compile-", suffix=".log", delete=False)  # noqa: SIM115
    code = "from explorer.shading import warm; print(warm.exercise(), 'passes')"
    proc = subprocess.Popen(
        [sys.executable, "-c", code], stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT
    )
    started = time.monotonic()

    def note_the_end():
        proc.wait()
        _COMPILE["ran"] = time.monotonic() - started
        (_shared_folder() / "ended").write_text(str(proc.returncode))

    noting = threading.Thread(target=note_the_end, daemon=True)
    noting.start()
    _COMPILE.update(proc=proc, log=log, waited=None, noting=noting)


def _end_compile(stop: bool = False) -> None:
    """Wait for the background compile (``stop``: end it instead); then it is done with."""
    proc = _COMPILE.get("proc")
    if proc is None or _COMPILE.get("waited") is not None:
        return
    t = time.monotonic()
    if stop and proc.poll() is None:
        proc.terminate()
    try:
        proc.wait(timeout=COMPILE_TIMEOUT)
    except subprocess.TimeoutExpired:  # the tests compile what they need themselves
        proc.kill()
        proc.wait()
    _COMPILE["noting"].join()
    _COMPILE["waited"] = time.monotonic() - t
    _COMPILE["log"].close()


#: how long the first test after :data:`BEFORE_KERNELS` waits for the background compile at most:
#: against a hung process only. Ending a slow one gains nothing (the tests would compile the
#: rest themselves, no faster) and loses the kernel it was compiling: on a machine loaded 20
#: deep the compile took more than 900 s
COMPILE_TIMEOUT = 3600


def _worker(config) -> bool:
    """Whether this process is a pytest-xdist worker (which is given the shared folder)."""
    return hasattr(config, "workerinput")


def _shared_folder() -> Path:
    """The pytest process's folder of the background compile's ``started`` and ``ended`` files,
    which its workers look at (made on first use; removed at the end of the session)."""
    if "folder" not in _COMPILE:
        _COMPILE["folder"] = Path(tempfile.mkdtemp(prefix="explorer-compile-ends-"))
    return _COMPILE["folder"]


def _called_kernels() -> list[str]:
    """The kernels this process called so far (the tests of BEFORE_KERNELS should call none)."""
    from explorer.shading import warm

    return sorted(name for name, sigs in warm.signatures().items() if sigs)


def _wait_in_worker(config) -> None:
    """A worker's first test outside BEFORE_KERNELS: wait while the background compile runs;
    the wait and the kernels called before it go back to the pytest process."""
    folder = Path(config.workerinput["explorer_compile"])
    _COMPILE["waited"] = 0.0
    if not (folder / "started").exists():
        return
    called, t = _called_kernels(), time.monotonic()
    while not (folder / "ended").exists() and time.monotonic() - t < COMPILE_TIMEOUT:
        time.sleep(0.2)
    config.workeroutput["explorer_compile"] = {"waited": time.monotonic() - t, "called": called}


def pytest_runtest_setup(item):
    if _before_kernels(item):
        return
    if _worker(item.config):
        if "waited" not in _COMPILE and "explorer_compile" in item.config.workerinput:
            _wait_in_worker(item.config)
    elif _COMPILE.get("proc") and _COMPILE["waited"] is None:
        # kernels the tests before this one called: BEFORE_KERNELS names a module it should not
        _COMPILE["called"] = _called_kernels()
        _end_compile()


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):
    """A worker is given the folder that says whether the background compile runs."""
    node.workerinput["explorer_compile"] = str(_shared_folder())
    _COMPILE.setdefault("workers", {})


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_node_collection_finished(node, ids):
    """With workers, the pytest process collects nothing itself: the background compile starts
    (or not) here as pytest_collection_modifyitems says, before the first test is handed out."""
    first = sum(1 for nodeid in ids if _before_kernels_id(node.config, nodeid))
    if first == len(ids):
        _end_compile(stop=True)
    elif first:
        _start_compile(node.config)


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    """A worker's wait for the background compile, for the summary line."""
    out = getattr(node, "workeroutput", {}).get("explorer_compile")
    if out is not None:
        _COMPILE.setdefault("workers", {})[node.gateway.id] = out


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """Whole modules to the workers, in the suite's order (tests/helpers/workers.py); xdist's
    own for a ``--dist`` other than its default, ``load``."""
    if config.getoption("dist") != "load":
        return None
    from helpers.workers import ModuleScheduling

    return ModuleScheduling(config, log)


def pytest_sessionfinish(session, exitstatus):
    if not _worker(session.config):
        _end_compile(stop=True)


def pytest_terminal_summary(terminalreporter):
    """One line on the background compile: how long it ran, how long the tests waited for it."""
    proc = _COMPILE.get("proc")
    if proc is None:
        return
    log = Path(_COMPILE["log"].name)
    out = log.read_text(errors="replace").strip().splitlines()
    last = out[-1] if out else "no output"
    ran = _COMPILE.get("ran", float("nan"))
    workers = _COMPILE.get("workers")
    if proc.returncode == -signal.SIGTERM:  # no test that calls a kernel was left to wait
        how = "stopped at the end of the run"
    elif workers == {}:  # with workers, none of which ran a test outside BEFORE_KERNELS
        how = "no worker waited for it"
    elif workers:
        waits = ", ".join(f"{w['waited']:.1f} s ({name})" for name, w in sorted(workers.items()))
        how = f"the workers waited {waits} for it"
        _COMPILE["called"] = sorted({k for w in workers.values() for k in w["called"]})
    else:
        how = f"the tests waited {_COMPILE['waited']:.1f} s for it"
    terminalreporter.write_line(
        f"the kernels' cold compile beside the tests: exit {proc.returncode} ({last}) after "
        f"{ran:.1f} s; {how}"
    )
    if _COMPILE.get("called"):
        called = ", ".join(_COMPILE["called"])
        terminalreporter.write_line(f"the tests of BEFORE_KERNELS called kernels: {called}")
    if proc.returncode not in (0, -signal.SIGTERM):
        terminalreporter.write_line("\n".join(out[-20:]))
    log.unlink(missing_ok=True)


def pytest_unconfigure(config):
    if "folder" in _COMPILE:
        shutil.rmtree(_COMPILE.pop("folder"), ignore_errors=True)


def pytest_deselected(items):
    names = [i.nodeid for i in items if _is_golden_test(i)]
    if names:
        imagecompare.INCOMPLETE.append(f"deselected golden tests: {names[:3]}...")


def pytest_runtest_logreport(report):
    if report.skipped and "golden" in report.nodeid.rsplit("::", 1)[-1]:
        imagecompare.INCOMPLETE.append(f"skipped golden test: {report.nodeid}")


@pytest.fixture(scope="session", autouse=True)
def no_child_left():
    """At the session's end, after its other fixtures have ended (this one is the session's
    first, so it ends last), no process this one started still runs: the fixtures end and
    wait for theirs (the Xvfb of the Qt tests, the page servers, the browsers' drivers). One
    left running was a ResourceWarning at the process's end ("subprocess N is still
    running", from its Popen). The background compile is the pytest process's own until
    pytest_sessionfinish ends it."""
    yield
    compile_ = _COMPILE.get("proc")
    left = [c for c in running_children() if compile_ is None or c[0] != compile_.pid]
    assert not left, f"processes the session's fixtures left running: {left}"


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
