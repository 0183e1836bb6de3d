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
sources' contents, numba's and Python's versions, the CPU and the code
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

A damaged cache is detected, set aside and rebuilt: the marker lists numba's cache files of
every kernel (:func:`cache_files`: each index, each compiled overload and its size), and the first
look for the marker checks them (a ``stat`` each): one missing, not a regular file, or of
another size (truncated) makes the marker and the kernels' cache files move into a
folder ``explorer-damaged-<time>`` beside them (:func:`set_aside`), with one notice, and the
background compile starts again; an attempt file, a marker or a lock that is not a regular file,
or an attempt file that is not a small count, is set aside the same way. The marker and the
attempt file are read with :func:`read_small` (never blocks: a FIFO or a device is refused).

The environment variable ``PHONG_EXPLORER_KERNELS`` picks the mode: ``auto``, ``compiled``
(compile in this process when needed, as numba does by default: the tests and the benchmarks)
or ``numpy`` (never compile). Colours are the engine's contract on either tier: float64 within
1e-5 of the GL 2.1 equation, float32 within 1/255 of float64 (the numpy tier computes float64
and rounds to the pass's precision).
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
import stat
import subprocess
import sys
import threading
import time
import warnings
from pathlib import Path

from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError, Notice
from explorer.core.files import NO_SUCH_FILE, UnreadableFile, read_checked
from explorer.geometry import bvh, bvh_numpy, kernelcache

#: the environment variable that picks the mode
ENV = "PHONG_EXPLORER_KERNELS"
MODES = ("auto", "compiled", "numpy")
#: modules whose numba functions the product calls
SOURCES = kernelcache.KERNEL_MODULES
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
#: the largest marker or attempt file read (bytes): the marker lists every kernel's cache files
MAX_SMALL_FILE = 1 << 20
#: what the user is told, once, when a damaged cache was set aside
DAMAGED = (
    "the compiled engine's cache was damaged ({why}); it was set aside in {where} and is "
    "rebuilt in the background; meanwhile the numpy engine serves"
)

#: vertex-lights a process serves on the numpy tier before it loads the compiled kernels from
#: numba's cache (a load costs about what the numpy tier takes for this much work, so small
#: one-shot jobs, like the quick start's render, never pay for it)
LOAD_WORTH = 2_000_000
#: the numpy tier's tree build, per triangle, and its shadow or pixel ray, per ray, in
#: vertex-lights of its shading, so that :func:`compiled` counts a pass's ray work with its
#: shading (:func:`ray_work`): benchmarks/bench_rays.py --section numpy measured 7-23 and 24-30
#: (a build 2.4-3.7 µs a triangle, a ray 4-10 µs, a vertex-light 160-425 ns, as loads varied)
BUILD_WORK = 10
RAY_WORK = 25

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
    "guarded": False,  # numba's cache reads of the kernels are guarded (guard_cache)
    "told_damaged": False,  # a kernel's unreadable cache files were set aside and said
}
#: the background compiles this process started where there is no ``sh`` to start them
#: (:data:`DETACH`), kept (a Popen dropped while its process runs warns, ResourceWarning); those
#: that ended are reaped at the next start
_children: list[subprocess.Popen] = []
#: the background compile is started through ``sh``, which starts it and ends at once
#: (waited for): the compile is then no child of this process, which may end first (a one-shot
#: render, the test session, the page's server) with no subprocess still running. It had kept
#: the compile's Popen, and a process ending before its compile printed "ResourceWarning:
#: subprocess N is still running" (after the tiers and web tests)
DETACH = ("/bin/sh", "-c", '"$@" &', "phong-explorer-compile")


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
        return m == "compiled" and guard_cache()
    if _state["loaded"]:
        return guard_cache()
    if not _ready() or _state["loading"] is not None:
        return False
    _state["numpy_work"] += int(work)
    if _state["numpy_work"] >= LOAD_WORTH:
        _state["loaded"] = True
    return _state["loaded"] and guard_cache()


def loaded() -> bool:
    """Whether the compiled kernels serve in this process now (no side effects but
    :func:`guard_cache`, once)."""
    return (mode() == "compiled" or (mode() == "auto" and _state["loaded"])) and guard_cache()


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
        _state["ready"] = os.path.lexists(marker_path())
        told = PREPARING
        if first and _state["ready"]:  # once per process: the cache it names is whole
            why = damage()
            if why is not None:
                told = DAMAGED.format(why=why, where=set_aside(why))
                _state["ready"] = False
        if first and not _state["ready"]:
            why = given_up()
            if why is None:
                _start_background(told)
            else:
                _unavailable(f"{why}; to try again, remove {attempt_path()}", stacklevel=5)
        if _state["ready"] and _state["preload"]:
            _start_loading()
    return bool(_state["ready"])


def ray_work(triangles: int, rays: int) -> int:
    """The ray work of building a tree over ``triangles`` (0: the tree is kept already) and
    casting ``rays`` through it, in vertex-lights of the numpy tier (what :func:`compiled`
    counts): the numpy tier builds a tree at :data:`BUILD_WORK` and casts a ray at
    :data:`RAY_WORK` vertex-lights' time."""
    return BUILD_WORK * int(triangles) + RAY_WORK * int(rays)


def ray_engine(work: int = 0, tier: str | None = None):
    """The module that casts rays: :mod:`explorer.geometry.bvh` (compiled) or
    :mod:`explorer.geometry.bvh_numpy` (the same answers, no compile). Both have
    ``build_bvh``, ``any_hit``, ``nearest_hits`` and ``surface_points``.

    tier : "compiled" or "numpy" is obeyed; None: the compiled casts when :func:`compiled`
    says so for ``work`` vertex-lights (:func:`ray_work`: so a large cast loads the kernels
    from a warm cache at once), else numpy
    """
    if tier is not None:
        return bvh if tier == "compiled" and guard_cache() else bvh_numpy
    return bvh if compiled(work) else bvh_numpy


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
    """What names the ready marker: a hash of the kernel sources' contents (the hash numba's
    cache index keys them by, :func:`explorer.geometry.kernelcache.sources_hash`), the versions
    and the code generation target."""
    import llvmlite
    import llvmlite.binding as llvm
    import numba

    parts = [numba.__version__, llvmlite.__version__, sys.version, platform.machine()]
    parts.append(kernelcache.sources_hash())
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
    """Write the ready marker (after every kernel compiled), atomically, with the cache files it
    vouches for (:func:`cache_files`); the attempts are forgotten."""
    info = {"seconds": round(seconds, 1), "written": time.strftime("%Y-%m-%d %H:%M:%S"),
            "files": cache_files()}  # fmt: skip
    path = write_atomic(marker_path(), json.dumps(info).encode(), overwrite=True)
    attempt_path().unlink(missing_ok=True)
    return path


# -- a damaged cache -----------------------------------------------------------------------------
class _NotRegular(OSError):
    """A small file of the cache that is not a regular file (a FIFO, a device, a directory), or
    too large to be one."""


def read_small(path, limit: int = MAX_SMALL_FILE) -> bytes:
    """The bytes of a small regular file of the cache, never blocking, through the product's
    one checked open (:func:`explorer.core.files.read_checked`: ``O_NONBLOCK``, a regular file
    only, at most ``limit`` bytes read). FileNotFoundError when there is none (no marker yet is
    the normal case); :class:`_NotRegular` (an OSError) for anything else it refuses."""
    try:
        return read_checked(path, cap=limit, what="compile cache file")
    except UnreadableFile as exc:
        if exc.reason == NO_SUCH_FILE:
            raise FileNotFoundError(os.fspath(path)) from None
        raise _NotRegular(str(exc)) from None


def _json(path) -> dict:
    """A small JSON object file (:func:`read_small`); ValueError when it is not one (numbers
    such as Infinity and NaN refused)."""

    def refuse(name):
        raise ValueError(f"{name} is not a number JSON allows")

    info = json.loads(read_small(path), parse_constant=refuse)
    if not isinstance(info, dict):
        raise ValueError("not a JSON object")
    return info


def cache_files() -> dict[str, int]:
    """numba's cache files of every kernel the product calls, as they are now: each
    dispatcher's index (``.nbi``) and compiled overloads (``.nbc``), path -> size in bytes."""
    from explorer.shading import warm  # (warm imports this module)

    found = {}
    for d in warm.dispatchers().values():
        impl = getattr(d._cache, "_cache_file", None)  # numba's IndexDataCacheFile
        if impl is None:  # a function numba does not cache
            continue
        for path in _files_of(impl):
            try:
                found[path] = os.stat(path).st_size
            except OSError:
                pass
    return found


def _files_of(impl) -> list[str]:
    """The cache files of one function (``impl``: numba's ``IndexDataCacheFile``): its index
    (``.nbi``) and compiled overloads (``.nbc``) as they are now."""
    base = os.path.basename(impl._index_path)[: -len(".nbi")]
    try:
        names = os.listdir(impl._cache_path)
    except OSError:
        return []
    ours = [
        n for n in names if n == base + ".nbi" or (n.startswith(base + ".") and n.endswith(".nbc"))
    ]
    return [os.path.join(impl._cache_path, n) for n in ours]


def damage() -> str | None:
    """Why the cache the marker vouches for is damaged, else None: the marker is not a small
    JSON file, or one of the files it lists is missing, not a regular file, or of another size
    (an index may grow: numba adds the overloads it compiles later; it never shrinks). A marker
    of an older release (no list) is taken as it is."""
    try:
        files = _json(marker_path()).get("files", {})
        if not isinstance(files, dict):
            raise ValueError("its list of files is not an object")
    except (OSError, ValueError) as exc:
        return f"the ready marker {marker_path().name}: {exc}"
    for path, size in files.items():
        try:
            st = os.stat(path)
        except OSError:
            return f"{path} is missing"
        if not stat.S_ISREG(st.st_mode):
            return f"{path} is not a regular file"
        grows = path.endswith(".nbi")
        if st.st_size < size or (st.st_size != size and not grows):
            return f"{path} has {st.st_size} bytes, {size} when it was written"
    return None


def set_aside(why: str, paths=None) -> Path:
    """Move the marker, the attempt file and the kernels' cache files (or ``paths``)
    into a new folder ``explorer-damaged-<time>`` of the cache directory, with a note of
    ``why``; returns the folder. What cannot be moved is removed (or left, if neither can be
    done: numba then recompiles what it cannot read)."""
    where = cache_dir() / time.strftime("explorer-damaged-%Y%m%d-%H%M%S")
    n = 1
    while os.path.lexists(where):
        n += 1
        where = where.with_name(f"{where.name.split('.')[0]}.{n}")
    if paths is None:
        paths = [marker_path(), attempt_path(), *_listed(), *cache_files()]
    try:
        where.mkdir(parents=True)
        (where / "why.txt").write_text(why + "\n")
    except OSError:
        where = None
    for path in dict.fromkeys(str(p) for p in paths):
        if not os.path.lexists(path):
            continue
        try:
            if where is None:
                raise OSError
            os.replace(path, where / f"{len(os.listdir(where)):03d}-{os.path.basename(path)}")
        except OSError:
            try:
                os.unlink(path)
            except OSError:
                pass
    return where if where is not None else cache_dir()


#: what the user is told, once, when numba could not read a kernel's cache files
UNREADABLE = (
    "the compiled engine's cache was damaged (numba could not read {name}'s cache files: "
    "{error}); they were set aside in {where} and it is compiled again"
)


def guard_cache() -> bool:
    """Make numba's cache read of every kernel the product calls treat a file it cannot read
    (an index or a compiled overload cut short or garbled: pickle's ``UnpicklingError``,
    ``EOFError``...) as a miss: that kernel's cache files and the ready marker are set aside
    (:func:`set_aside`), the user is told once (:data:`UNREADABLE`, a
    :class:`~explorer.core.errors.Notice`), and numba compiles the kernel again and caches it
    anew. Installed once per process, before the compiled tier first serves (the compiled
    mode, the loader thread, the background compile); returns True."""
    if _state["guarded"]:
        return True
    from explorer.shading import warm  # (warm imports this module)

    with _lock:
        if not _state["guarded"]:
            for name, d in warm.dispatchers().items():
                if getattr(d._cache, "_cache_file", None) is not None:  # a cached function
                    d._cache.load_overload = _guarded_load(name, d._cache)
            _lock_saves()
            _state["guarded"] = True
    return True


def save_lock_path() -> Path:
    """The lock numba's cache writes take in a process that guards the cache (see
    :func:`_lock_saves`)."""
    return cache_dir() / "explorer-save.lock"


def _lock_saves() -> None:
    """Make numba's cache writes (``IndexDataCacheFile.save``: read the function's index, add
    the signature with the next free data file's name, write the index, write the data) hold
    an exclusive lock on :func:`save_lock_path` (``flock``), in every process that guards the
    cache: the two processes of the background compile (:mod:`explorer.shading.warm`), and a
    compiled-mode process beside it. Each file numba writes is whole (a temporary file
    renamed), but the index is read, changed and written again: two processes adding
    signatures of one function at once would each write an index without the other's entry,
    or name one data file for two signatures, one's index pointing at the other's code."""
    try:
        import fcntl
    except ImportError:  # not POSIX: writes unlocked, as numba's own
        return
    from numba.core.caching import IndexDataCacheFile

    save = IndexDataCacheFile.save
    if getattr(save, "locked", False):
        return
    path = save_lock_path()

    def locked_save(self, key, data):
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0), 0o666)
        except OSError:  # (no lock file to be had: written as numba writes)
            return save(self, key, data)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
            return save(self, key, data)
        finally:
            os.close(fd)  # (the lock goes with it)

    locked_save.locked = True  # type: ignore[attr-defined]
    IndexDataCacheFile.save = locked_save


def _guarded_load(name: str, cache):
    """``cache.load_overload`` (numba's ``Cache``) with an unreadable file taken as a miss."""
    load = cache.load_overload

    def load_overload(sig, target_context):
        try:
            return load(sig, target_context)
        except Exception as exc:  # noqa: BLE001 - any failure to read the cache: compile anew
            error = f"{type(exc).__name__}: {exc}"
            where = set_aside(f"numba could not read {name}'s cache: {error}",
                              [marker_path(), *_files_of(cache._cache_file)])  # fmt: skip
            if not _state["told_damaged"]:
                _state["told_damaged"] = True
                told = UNREADABLE.format(name=name, error=error, where=where)
                warnings.warn(told, Notice, stacklevel=2)
            return None

    return load_overload


def _listed() -> list[str]:
    """The files the marker lists (none when it cannot be read)."""
    try:
        files = _json(marker_path()).get("files", {})
        return list(files) if isinstance(files, dict) else []
    except (OSError, ValueError):
        return []


def open_lock():
    """The background compile's lock file, opened for locking (``a+``). A lock path that is not
    a regular file (a directory, a FIFO, a dangling symlink...) is set aside and made anew;
    OSError when it still cannot be opened."""
    path = lock_path()
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        st = None
    if st is not None and not stat.S_ISREG(st.st_mode):
        set_aside(f"{path} is not a regular file", [path])
    fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_APPEND | getattr(os, "O_NONBLOCK", 0)
                 | getattr(os, "O_NOFOLLOW", 0), 0o666)  # fmt: skip
    return os.fdopen(fd, "a+")


def attempt_path() -> Path:
    """Where the background compiles for this marker count themselves (see the module
    docstring): JSON ``{"attempts": n, "error": "..." or null}``."""
    return cache_dir() / f"explorer-attempt-{marker_key()}.json"


def attempts() -> dict:
    """The attempt file's record; ``{"attempts": 0, "error": None}`` when there is none or it
    cannot be read. One that is not a small JSON count (``Infinity``, a FIFO, a directory) is
    set aside (:func:`set_aside`) and counts none."""
    path = attempt_path()
    try:
        info = _json(path)
        n, error = info["attempts"], info.get("error")
        if type(n) is not int or not 0 <= n <= 1000 or not isinstance(error, str | None):
            raise ValueError(f"attempts {n!r}, error {error!r}")
        return {"attempts": n, "error": error}
    except FileNotFoundError:
        pass
    except (OSError, ValueError, KeyError, TypeError) as exc:
        set_aside(f"{path}: {exc}", [path])
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
        lock = open_lock()
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


def _start_background(told: str = PREPARING) -> None:
    """Start the background compile (at most once per process) and tell the user once
    (``told``)."""
    with _lock:
        if _state["started"]:
            return
        _state["started"] = True
    try:
        directory = cache_dir()
        directory.mkdir(parents=True, exist_ok=True)
        env = dict(os.environ, **{ENV: "compiled"})
        _children[:] = [p for p in _children if p.poll() is None]
        detach = os.access(DETACH[0], os.X_OK)
        with open(log_path(), "ab") as log:
            child = subprocess.Popen(
                [*DETACH, *warm_command()] if detach else warm_command(),
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=subprocess.STDOUT,
                cwd=directory,  # nothing in the user's directory shadows the package
                env=env,
                start_new_session=True,  # Ctrl-C in the terminal does not stop it
                close_fds=True,
            )
        if detach:
            child.wait()  # (sh: the compile started, in the background)
        else:
            _children.append(child)
    except OSError as exc:  # no writable cache directory, no interpreter to start
        _unavailable(exc.strerror or str(exc), stacklevel=4)
        return
    warnings.warn(told, Notice, stacklevel=3)


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
