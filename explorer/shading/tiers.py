"""Which engine serves a shading pass: the compiled kernels, or numpy while they are prepared.

numba compiles the engine's kernels (:mod:`explorer.shading.kernels`, the display's byte
rounding, the ray casts) the first time they run and keeps them in its on-disk cache; on a fresh
install that first compile takes minutes. So the engine has two tiers:

``compiled``
    the numba kernels (planned, blocked, float32 or float64: the fast path), loaded from numba's
    cache in well under a second once it holds them;
``numpy``
    the lighting equation of :mod:`explorer.shading.equation` in float64 numpy: the
    specification itself, exact, ready at once, slower on large meshes (it computes every term of
    every light; the plan still decides which lights cast shadow rays).

Mode ``auto`` (the default) uses the compiled tier when numba's cache holds every kernel the
product calls: :mod:`explorer.shading.warm` compiles them all and then writes a *ready marker*
into numba's cache directory, named by everything that invalidates numba's cache (the kernel
sources' size and modification time, numba's and Python's versions, the CPU and the code
generation options). Until the marker is there, passes run on the numpy tier, and the first one
starts ``python -m explorer.shading.warm`` in the background (detached: it outlives the command
that started it; a lock keeps one at a time per cache directory) and says so once, as a
:class:`~explorer.core.errors.Notice` (the CLI prints it as one ``notice:`` line on stderr, the
window shows :func:`status` in its status line). Each background compile counts itself in an
*attempt* file beside the marker (:func:`attempt_path`, with its error if it raised one); when
:data:`MAX_ATTEMPTS` of them ended without the marker (an error, a crash of the compiler, a
killed process) and none is running, no other is started: the numpy tier serves on, and the
first pass says why, once, and how to try again.

Loading the kernels from numba's cache costs a process about half a second to a second, more
than the numpy tier takes for a small mesh: so a process loads them once it has served
:data:`LOAD_WORTH` vertex-lights on the numpy tier (the pass that crosses it loads them and runs
compiled), and a one-shot render of a small mesh never loads them at all. A process that lives
on (the window) calls :func:`preload`: the kernels load in a thread as soon as the cache holds
them (at start, or when the background compile finishes while the window is open) and the
shaders switch at their next pass, so no pass waits on a load.

The environment variable ``PHONG_EXPLORER_KERNELS`` picks the mode: ``auto``, ``compiled``
(compile in this process when needed, as numba does by default: the tests and the benchmarks)
or ``numpy`` (never compile). Colours are the engine's contract on either tier: float64 within
1e-5 of the GL 2.1 equation, float32 within 1/255 of float64 (the numpy tier computes float64
and rounds to the pass's precision).
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import os
import platform
import subprocess
import sys
import threading
import time
import warnings
from pathlib import Path

from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError, Notice
from explorer.geometry import bvh, bvh_numpy

#: the environment variable that picks the mode
ENV = "PHONG_EXPLORER_KERNELS"
MODES = ("auto", "compiled", "numpy")
#: modules whose numba functions the product calls (their sources name the marker)
SOURCES = (
    "explorer.shading.kernels",
    "explorer.shading.vmath",
    "explorer.shading.display",
    "explorer.geometry.rays",
    "explorer.geometry.traverse",
    "explorer.geometry.occluders",
    "explorer.geometry.bvh",
)
#: environment variables that change what numba compiles (so they name the marker too)
CODEGEN_ENV = ("NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES", "NUMBA_OPT", "PHONG_EXPLORER_WIDE_VECTORS")
#: seconds between two looks for the marker while the numpy tier serves (a stat per look)
POLL = 0.25
#: what the user is told, once, when the background compile starts
PREPARING = (
    "preparing the compiled engine in the background (once per install, a few minutes); "
    "meanwhile the numpy engine serves: the same colours, slower on large meshes"
)

#: background compiles that may end without the ready marker before no other is started
MAX_ATTEMPTS = 2

#: vertex-lights a process serves on the numpy tier before it loads the compiled kernels from
#: numba's cache (a load costs about what the numpy tier takes for this much work, so small
#: one-shot jobs, like the quick start's render, never pay for it)
LOAD_WORTH = 2_000_000

_lock = threading.Lock()
_state = {
    "mode": None,  # set by set_mode, else read from ENV at first use
    "ready": None,  # numba's cache holds the kernels (the marker): None until first looked for
    "loaded": False,  # this process uses the compiled tier from now on
    "numpy_work": 0,  # vertex-lights the numpy tier served while the kernels were ready
    "preload": False,  # load the kernels in a thread as soon as they are ready (a window)
    "started": False,  # the background compile was started by this process
    "loading": None,  # the loader thread, once started
    "checked": 0.0,  # when the marker was last looked for
    "failed": None,  # why the compiled engine is unavailable
}
#: the background compiles this process started, kept (a Popen dropped while its process runs
#: warns, ResourceWarning); those that ended are reaped at the next start
_children: list[subprocess.Popen] = []


def mode() -> str:
    """The mode: :func:`set_mode`'s, else the environment variable :data:`ENV` (default auto).
    A value outside :data:`MODES` raises an :class:`ExplorerError` naming the variable."""
    if _state["mode"] is None:
        value = os.environ.get(ENV, "auto").strip().lower() or "auto"
        if value not in MODES:
            raise ExplorerError(
                f"environment variable {ENV}={value!r}: must be one of {', '.join(MODES)}"
            )
        _state["mode"] = value
    return _state["mode"]


def set_mode(value: str | None) -> None:
    """Pick the mode for this process (None: read :data:`ENV` again). Forgets what the last
    mode decided."""
    if value is not None and value not in MODES:
        raise ExplorerError(f"kernels mode must be one of {', '.join(MODES)}, got {value!r}")
    with _lock:
        _state.update(mode=value, ready=None, loaded=False, numpy_work=0, checked=0.0)


def compiled(work: int = 0) -> bool:
    """True when a pass of ``work`` vertex-lights should run on the compiled kernels (see the
    module docstring). In mode auto: once they are loaded in this process; else when numba's
    cache holds them and this process has served :data:`LOAD_WORTH` vertex-lights on the numpy
    tier (a pass that decides so loads them). May start the background compile (and tell the
    user once) or the loader thread; never waits for either."""
    m = mode()
    if m != "auto":
        return m == "compiled"
    if _state["loaded"]:
        return True
    if not _ready() or _state["loading"] is not None:
        return False
    _state["numpy_work"] += int(work)
    if _state["numpy_work"] >= LOAD_WORTH:
        _state["loaded"] = True
    return _state["loaded"]


def loaded() -> bool:
    """Whether the compiled kernels serve in this process now (no side effects)."""
    return mode() == "compiled" or (mode() == "auto" and _state["loaded"])


def preload() -> None:
    """For a process that lives on (the window): load the compiled kernels in a thread as soon
    as numba's cache holds them (now, or when the background compile has filled it), and switch
    to them when loaded; the numpy tier serves meanwhile. Call it again now and then (it looks
    for the marker at most every :data:`POLL` seconds) to notice the background compile end."""
    if mode() != "auto" or _state["loaded"]:
        return
    _state["preload"] = True
    if _ready():
        _start_loading()


def _ready() -> bool:
    """Whether numba's cache holds the kernels: the marker, looked for at most every
    :data:`POLL` seconds. The first look that finds none starts the background compile."""
    if _state["ready"]:
        return True
    now = time.monotonic()
    if _state["ready"] is None or now - _state["checked"] >= POLL:
        first = _state["ready"] is None
        _state["checked"] = now
        _state["ready"] = marker_path().exists()
        if first and not _state["ready"]:
            why = given_up()
            if why is None:
                _start_background()
            else:
                _unavailable(f"{why}; to try again, remove {attempt_path()}", stacklevel=5)
        if _state["ready"] and _state["preload"]:
            _start_loading()
    return bool(_state["ready"])


def ray_engine():
    """The module that casts rays now: :mod:`explorer.geometry.bvh` (compiled) once the kernels
    serve (:func:`loaded`), else :mod:`explorer.geometry.bvh_numpy` (the same answers, no
    compile). Both have ``build_bvh``, ``any_hit`` and ``nearest_hits``."""
    return bvh if loaded() else bvh_numpy


def status() -> str | None:
    """A short line for a status bar while the numpy tier serves in mode auto for want of the
    compiled kernels, else None."""
    if mode() != "auto" or _state["loaded"]:
        return None
    if _state["failed"]:
        return f"numpy engine (the compiled engine is unavailable: {_state['failed']})"
    if _state["loading"] is not None:
        return "numpy engine; loading the compiled engine"
    if _state["ready"] is False:
        return "numpy engine; preparing the compiled engine in the background"
    return None


# -- the ready marker ------------------------------------------------------------------------------
def cache_dir() -> Path:
    """The directory numba caches :mod:`explorer.shading.kernels` in (``NUMBA_CACHE_DIR`` when
    set, else the in-tree ``__pycache__`` when writable, else numba's user-wide directory)."""
    from explorer.shading import kernels  # numba decides the directory when it decorates

    dispatcher = getattr(kernels.shade, "dispatcher", kernels.shade)  # wide-vector wrapper
    return Path(dispatcher._cache._cache_path)


def marker_key() -> str:
    """What names the ready marker: a hash of the kernel sources' stamps (as numba's own cache
    index keys them), the versions and the code generation target."""
    import llvmlite
    import llvmlite.binding as llvm
    import numba

    parts = [numba.__version__, llvmlite.__version__, sys.version, platform.machine()]
    for name in SOURCES:
        origin = importlib.util.find_spec(name).origin
        st = os.stat(origin)
        parts.append(f"{origin}:{st.st_mtime_ns}:{st.st_size}")
    try:
        parts.append(llvm.get_host_cpu_name())
        parts.append(llvm.get_host_cpu_features().flatten())
    except RuntimeError:  # llvmlite cannot read this host: the CPU name alone
        parts.append(platform.processor())
    parts += [f"{k}={os.environ.get(k, '')}" for k in CODEGEN_ENV]
    return hashlib.sha256("\n".join(parts).encode()).hexdigest()[:20]


def marker_path() -> Path:
    """The ready marker for this machine and these sources (see :func:`marker_key`)."""
    return cache_dir() / f"explorer-ready-{marker_key()}.json"


def lock_path() -> Path:
    """The lock the background compile holds while it runs."""
    return cache_dir() / "explorer-warm.lock"


def log_path() -> Path:
    """Where the background compile writes what it did (and any error)."""
    return cache_dir() / "explorer-warm.log"


def write_marker(seconds: float) -> Path:
    """Write the ready marker (after every kernel compiled), atomically; the attempts are
    forgotten."""
    info = {"seconds": round(seconds, 1), "written": time.strftime("%Y-%m-%d %H:%M:%S")}
    path = write_atomic(marker_path(), json.dumps(info).encode(), overwrite=True)
    attempt_path().unlink(missing_ok=True)
    return path


def attempt_path() -> Path:
    """Where the background compiles for this marker count themselves (see the module
    docstring): JSON ``{"attempts": n, "error": "..." or null}``."""
    return cache_dir() / f"explorer-attempt-{marker_key()}.json"


def attempts() -> dict:
    """The attempt file's record; ``{"attempts": 0, "error": None}`` when there is none or it
    cannot be read."""
    try:
        info = json.loads(attempt_path().read_text())
        return {"attempts": int(info["attempts"]), "error": info.get("error")}
    except (OSError, ValueError, KeyError, TypeError):
        return {"attempts": 0, "error": None}


def record_attempt() -> None:
    """Count one more background compile (it starts)."""
    _write_attempts(attempts()["attempts"] + 1, None)


def record_error(error: str) -> None:
    """Write the error the current background compile ended with (the count stays)."""
    _write_attempts(attempts()["attempts"], error)


def _write_attempts(n: int, error: str | None) -> None:
    info = {"attempts": n, "error": error}
    write_atomic(attempt_path(), json.dumps(info).encode(), overwrite=True)


def compile_running() -> bool:
    """Whether a background compile holds the lock now (False where locks are not available)."""
    try:
        import fcntl
    except ImportError:
        return False
    try:
        lock = open(lock_path(), "a+")  # noqa: SIM115 - closed below
    except OSError:  # no cache directory: nothing runs there
        return False
    with lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)  # released when closed
        except OSError:
            return True
    return False


def given_up() -> str | None:
    """Why no background compile should be started any more (:data:`MAX_ATTEMPTS` ended without
    the marker and none is running), else None."""
    info = attempts()
    if info["attempts"] < MAX_ATTEMPTS or compile_running():
        return None
    what = info["error"] or f"no error written, see {log_path()}"
    return f"{info['attempts']} background compiles ended without finishing ({what})"


# -- the background compile and the loader -------------------------------------------------------
def warm_command() -> list[str]:
    """The background compile's command line."""
    return [sys.executable, "-m", "explorer.shading.warm"]


def _start_background() -> None:
    """Start the background compile (at most once per process) and tell the user once."""
    with _lock:
        if _state["started"]:
            return
        _state["started"] = True
    try:
        directory = cache_dir()
        directory.mkdir(parents=True, exist_ok=True)
        env = dict(os.environ, **{ENV: "compiled"})
        _children[:] = [p for p in _children if p.poll() is None]
        with open(log_path(), "ab") as log:
            child = subprocess.Popen(
                warm_command(),
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=subprocess.STDOUT,
                cwd=directory,  # nothing in the user's directory shadows the package
                env=env,
                start_new_session=True,  # Ctrl-C in the terminal does not stop it
                close_fds=True,
            )
        _children.append(child)
    except OSError as exc:  # no writable cache directory, no interpreter to start
        _unavailable(exc.strerror or str(exc), stacklevel=4)
        return
    warnings.warn(PREPARING, Notice, stacklevel=3)


def _unavailable(why: str, stacklevel: int) -> None:
    """The compiled engine cannot be prepared: the numpy tier serves on; tell the user once."""
    _state["failed"] = why
    warnings.warn(
        f"the compiled engine cannot be prepared on this machine ({why}); the numpy engine "
        "serves: the same colours, slower on large meshes",
        Notice,
        stacklevel=stacklevel,
    )


def _start_loading() -> None:
    """Load the compiled kernels from numba's cache in a thread; switch when they are loaded."""

    def load():
        from explorer.shading import warm  # a cycle: warm runs Shaders, which ask this module

        try:
            warm.load()
        except Exception as exc:  # noqa: BLE001 - a failed load keeps the numpy tier serving
            _state["failed"] = f"{type(exc).__name__}: {exc}"
            return
        _state["loaded"] = True

    with _lock:
        if _state["loading"] is not None:
            return
        _state["loading"] = threading.Thread(target=load, name="explorer-load", daemon=True)
    _state["loading"].start()
