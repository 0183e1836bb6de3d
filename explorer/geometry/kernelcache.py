"""numba's on-disk cache of the project's kernels, keyed on every source a kernel compiles from.

numba keys a cached function by the content of its own source file only: a function inlined
from another module (:mod:`explorer.shading.vmath` into the shading kernels,
:mod:`explorer.geometry.traverse` and :mod:`~explorer.geometry.rays` into the ray kernels) or a
constant read from one (:mod:`explorer.core.tolerances`, :mod:`explorer.core.lightrow`: numba
freezes a global's value into the compiled code) is not seen to change, and the cached kernel
keeps the old code. So the project's kernel files get a cache locator of their own
(:class:`UserProvidedLocator`, :class:`InTreeLocator`, :class:`UserWideLocator`: numba's three
locators for source files, in numba's order, same directories) whose *source stamp* is
:func:`stamp`: a hash of the file's content and of every file of :data:`KERNEL_MODULES` and
:data:`CONSTANT_MODULES` it imports, directly or through another of them. Editing any of them
invalidates exactly the cached kernels that may have compiled it in: editing ``traverse.py``
recompiles the ray kernels and not the shading ones, editing ``vmath.py`` the shading kernels
and not the ray ones.

The stamps hash contents, not modification times: a checkout, a ``touch``, or an editor that
rewrites a file unchanged costs no compile. numba still picks the cache *directory* by the
source folder's path (``NUMBA_CACHE_DIR/<folder>_<hash of its path>``, else the in-tree
``__pycache__``), so two checkouts at different paths keep caches of their own (with the same
directory, two checkouts of different sources would overwrite each other's index at each run).

:func:`install` puts the locators first in numba's list (``CacheImpl._locator_classes``, a
private name; ``tests/geometry/test_kernelcache.py`` pins every private name and signature
used here, so a numba upgrade that changes them fails there, loudly); they claim only the files
:func:`register` was given (the project's :data:`KERNEL_MODULES`, registered on import of this
module, which every one of them imports before its decorators run) and leave every other
function to numba's own locators. ``NUMBA_CACHE_LOCATOR_CLASSES``, when set, replaces the list
and so these locators too. :func:`sources_hash` (all the files at once) names the engine's
ready marker (:func:`explorer.shading.tiers.marker_key`).
"""

from __future__ import annotations

import ast
import functools
import hashlib
import os
from collections.abc import Iterable
from pathlib import Path

from numba.core import caching

#: OpenMP's worker threads (numba's "omp" threading layer: libgomp reads this when numba starts
#: its threads, at the first parallel kernel) wait for work asleep rather than spinning; a
#: user's own OMP_WAIT_POLICY wins. Spinning after each parallel region burnt a core the
#: window's other work (VTK's llvmpipe threads, the GUI) needed, and under load each short
#: pass cost several times its work in CPU: a camera frame of the live per-pixel view (100k-vertex
#: teapot, 800x600; docs/perpixel_bench.md) took 65 ms of CPU spinning, 33 ms asleep.
WAIT_POLICY = "PASSIVE"
os.environ.setdefault("OMP_WAIT_POLICY", WAIT_POLICY)

#: the directory that holds the ``explorer`` package (a checkout, or site-packages)
ROOT = Path(__file__).resolve().parents[2]
#: modules with numba functions the product compiles (each imports this module first)
KERNEL_MODULES = (
    "explorer.shading.kernels",
    "explorer.shading.vmath",
    "explorer.shading.display",
    "explorer.geometry.rays",
    "explorer.geometry.traverse",
    "explorer.geometry.occluders",
    "explorer.geometry.bvh",
    "explorer.geometry.raster",
)
#: modules whose constants the kernels read at compile time (numba freezes a global's value)
CONSTANT_MODULES = (
    "explorer.core.tolerances",
    "explorer.core.lightrow",
    "explorer.shading.codegen",
    "explorer.shading.layout",
    "explorer.core.slots",
)

#: a claimed file (its real path) -> the real paths of the files its stamp hashes
_claimed: dict[str, tuple[str, ...]] = {}


def _key(path: str | os.PathLike) -> str:
    return os.path.normcase(os.path.realpath(path))


def _imports(path: str, package: str) -> set[str]:
    """The dotted names a source file imports (``from a import b`` gives ``a`` and ``a.b``:
    ``b`` may be a module), anywhere in it (imports inside functions too)."""
    with open(path, "rb") as f:
        tree = ast.parse(f.read(), filename=path)
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:  # relative: from the file's package upwards
                parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(parts + ([base] if base else []))
            names.add(base)
            names.update(f"{base}.{alias.name}" for alias in node.names)
    return names


def register(root: str | os.PathLike, modules: Iterable[str]) -> None:
    """Claim the files of ``modules`` (dotted names under ``root``) for the locators: each
    one's stamp hashes it and every file of ``modules`` it imports, transitively."""
    files = {m: str(Path(root, *m.split(".")).with_suffix(".py")) for m in modules}
    files = {m: p for m, p in files.items() if os.path.isfile(p)}
    direct = {m: _imports(p, m.rpartition(".")[0]) & files.keys() for m, p in files.items()}
    for module, path in files.items():
        seen, todo = {module}, [module]
        while todo:
            for dep in direct[todo.pop()] - seen:
                seen.add(dep)
                todo.append(dep)
        _claimed[_key(path)] = tuple(sorted(_key(files[m]) for m in seen))


@functools.cache
def _digest(path: str, mtime_ns: int, size: int) -> str:
    # keyed on the file's mtime and size too (as numba's own): an edit while the process runs
    # is hashed again
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def _hash(paths: Iterable[str]) -> str:
    h = hashlib.sha256()
    for path in paths:
        st = os.stat(path)
        rel = os.path.relpath(path, ROOT) if path.startswith(str(ROOT)) else os.path.basename(path)
        h.update(
            f"{rel.replace(os.sep, '/')}:{_digest(path, st.st_mtime_ns, st.st_size)}\n".encode()
        )
    return h.hexdigest()


def stamp(py_file: str | os.PathLike) -> str:
    """The source stamp of a claimed file: ``sources:`` and the hash of its sources' contents
    (never equal to numba's own stamps, bytes, so an index numba wrote is not read as ours)."""
    return "sources:" + _hash(_claimed[_key(py_file)])


def sources_hash() -> str:
    """The hash of every claimed file's content (the ready marker's name includes it)."""
    return _hash(sorted(_claimed))


class _SourcesStamp:
    """What the three locators add to numba's: only claimed files, stamped by :func:`stamp`."""

    _py_file: str

    def get_source_stamp(self):
        return stamp(self._py_file)

    @classmethod
    def from_function(cls, py_func, py_file):
        if _key(py_file) not in _claimed:
            return None
        return super().from_function(py_func, py_file)  # type: ignore[misc]


class UserProvidedLocator(_SourcesStamp, caching.UserProvidedCacheLocator):
    """``NUMBA_CACHE_DIR`` when set."""


class InTreeLocator(_SourcesStamp, caching.InTreeCacheLocator):
    """The ``__pycache__`` beside the source, when writable."""


class UserWideLocator(_SourcesStamp, caching.UserWideCacheLocator):
    """numba's user-wide cache directory."""


LOCATORS = (UserProvidedLocator, InTreeLocator, UserWideLocator)


def install() -> None:
    """Put :data:`LOCATORS` first in numba's locator list (once)."""
    classes = caching.CacheImpl._locator_classes
    if classes[: len(LOCATORS)] != list(LOCATORS):
        classes[:] = list(LOCATORS) + [c for c in classes if c not in LOCATORS]


install()
register(ROOT, KERNEL_MODULES + CONSTANT_MODULES)
