"""numba's cache of the kernels, keyed on every source they compile from
(explorer.geometry.kernelcache): an edit to an inlined module recompiles its callers with no
``touch``, an unrelated edit or a bare ``touch`` recompiles nothing; numba's private API the
locators use is pinned here."""

from __future__ import annotations

import ast
import inspect
import json
import os
import subprocess
import sys

import numba
import pytest
from numba.core import caching

from explorer.geometry import kernelcache
from explorer.shading import tiers

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# a package of three modules: a's kernel inlines b's helper; c is registered but not imported
A = """
import numba as nb
from pkg.b import helper

@nb.njit(cache=True)
def f():
    return helper()
"""
B = """
import numba as nb

@nb.njit(inline="always")
def helper():
    return {value}
"""
C = "X = {value}\n"
CHILD = """
import json, sys
from explorer.geometry import kernelcache
if sys.argv[1] == "register":
    kernelcache.register(sys.argv[2], ["pkg.a", "pkg.b", "pkg.c"])
sys.path.insert(0, sys.argv[2])
from pkg import a
value = a.f()
print(json.dumps({"value": value, "hits": sum(a.f.stats.cache_hits.values()),
                  "locator": type(a.f._cache._impl.locator).__name__}))
"""


def _package(tmp_path, b=1, c=1):
    pkg = tmp_path / "src" / "pkg"
    pkg.mkdir(parents=True, exist_ok=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text(A)
    (pkg / "b.py").write_text(B.format(value=b))
    (pkg / "c.py").write_text(C.format(value=c))
    return pkg


def _run(tmp_path, how: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=ROOT)
    env.pop("NUMBA_CACHE_LOCATOR_CLASSES", None)
    out = subprocess.run(
        [sys.executable, "-c", CHILD, how, str(tmp_path / "src")],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_an_edit_to_an_inlined_module_recompiles_its_callers(tmp_path):
    pkg = _package(tmp_path)
    first = _run(tmp_path, "register")
    assert first == {"value": 1, "hits": 0, "locator": "UserProvidedLocator"}
    assert _run(tmp_path, "register")["hits"] == 1  # the cache serves the second process
    _package(tmp_path, b=2)  # only b changes: a's file is untouched
    assert _run(tmp_path, "register") == {"value": 2, "hits": 0, "locator": "UserProvidedLocator"}
    # a module a does not import, and a bare touch of a's own file, recompile nothing
    (pkg / "c.py").write_text(C.format(value=2))
    os.utime(pkg / "a.py", ns=(1, 1))
    assert _run(tmp_path, "register") == {"value": 2, "hits": 1, "locator": "UserProvidedLocator"}


def test_numba_alone_keeps_the_stale_inlined_code(tmp_path):
    # why the locators exist: numba's own stamp is the function's file only (if numba starts
    # seeing inlined modules, this fails and the locators may be dropped)
    _package(tmp_path)
    assert _run(tmp_path, "plain")["value"] == 1
    _package(tmp_path, b=2)
    stale = _run(tmp_path, "plain")
    assert stale == {"value": 1, "hits": 1, "locator": "UserProvidedCacheLocator"}


def test_numba_private_api_the_locators_use():
    # kernelcache subclasses these locators and prepends to this list: a numba upgrade that
    # renames or reshapes any of them must fail here, not silently fall back to numba's stamps
    if numba.__version__.split(".")[:2] != ["0", "68"]:
        pytest.fail(f"numba {numba.__version__}: check explorer.geometry.kernelcache against "
                    "its numba.core.caching, then widen this pin")  # fmt: skip
    classes = caching.CacheImpl._locator_classes
    assert isinstance(classes, list)
    for name in ("UserProvidedCacheLocator", "InTreeCacheLocator", "UserWideCacheLocator"):
        base = getattr(caching, name)
        assert base in classes
        assert issubclass(base, caching._SourceFileBackedLocatorMixin)
        assert list(inspect.signature(base.from_function).parameters) == ["py_func", "py_file"]
        assert list(inspect.signature(base.__init__).parameters) == ["self", "py_func", "py_file"]
        assert "get_source_stamp" in vars(caching._SourceFileBackedLocatorMixin)
        assert "get_source_stamp" in vars(caching._CacheLocator)
    # the stamp travels from the locator into the index, compared as is at each load
    assert "get_source_stamp()" in inspect.getsource(caching.Cache.__init__)
    index = inspect.signature(caching.IndexDataCacheFile.__init__).parameters
    assert list(index) == ["self", "cache_path", "filename_base", "source_stamp"]
    assert "stamp != self._source_stamp" in inspect.getsource(caching.IndexDataCacheFile)
    assert "locator_classes = self._locator_classes" in inspect.getsource(caching.CacheImpl)
    for locator in kernelcache.LOCATORS:  # our stamp wins over numba's in the method order
        assert locator.get_source_stamp is kernelcache._SourcesStamp.get_source_stamp


def test_the_project_kernels_use_the_locators():
    from explorer.geometry import bvh
    from explorer.shading import display, kernels

    assert caching.CacheImpl._locator_classes[:3] == list(kernelcache.LOCATORS)
    for fn in (kernels.shade, kernels._block, bvh._sah_split, display._round_bytes):
        dispatcher = getattr(fn, "dispatcher", fn)  # (the wide-vector wrapper)
        locator = dispatcher._cache._impl.locator
        assert isinstance(locator, kernelcache.LOCATORS), fn
        assert locator.get_source_stamp().startswith("sources:")

    @numba.njit(cache=True)
    def elsewhere():  # a function outside the kernel files keeps numba's own locator
        return 1

    assert not isinstance(elsewhere._cache._impl.locator, kernelcache.LOCATORS)


def test_each_kernel_file_hashes_the_files_it_compiles_in():
    files = {m: kernelcache._claimed[kernelcache._key(os.path.join(ROOT, *m.split(".")) + ".py")]
             for m in kernelcache.KERNEL_MODULES + kernelcache.CONSTANT_MODULES}  # fmt: skip
    names = {
        m: {os.path.relpath(p, ROOT)[:-3].replace(os.sep, ".") for p in f} for m, f in files.items()
    }
    tol, row, codegen, layout, slots = kernelcache.CONSTANT_MODULES
    assert names["explorer.shading.kernels"] == {"explorer.shading.kernels",
        "explorer.shading.vmath", tol, row, codegen, layout, slots}  # fmt: skip
    assert names["explorer.geometry.bvh"] == {"explorer.geometry.bvh", "explorer.geometry.rays",
        "explorer.geometry.traverse", "explorer.geometry.occluders", tol}  # fmt: skip
    assert names["explorer.geometry.traverse"] == {
        "explorer.geometry.traverse", "explorer.geometry.rays", tol}  # fmt: skip


# explorer modules the kernel files import for code that numba does not compile
NOT_COMPILED = {
    "explorer.core.errors": "exceptions raised by the Python wrappers",
    "explorer.geometry.kernelcache": "this module",
    "explorer.geometry.meshes": "display.to_bytes takes a Mesh's colours (Python)",
    "explorer.shading.tiers": "display picks the tier (Python)",
    "explorer.shading.effects": "display's effects (Python)",
    "explorer.shading.shader": "display shades (Python)",
}


def test_every_explorer_module_a_kernel_file_imports_is_hashed_or_not_compiled():
    hashed = set(kernelcache.KERNEL_MODULES + kernelcache.CONSTANT_MODULES)
    for module in kernelcache.KERNEL_MODULES:
        with open(os.path.join(ROOT, *module.split(".")) + ".py", encoding="utf-8") as f:
            tree = ast.parse(f.read())
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("explorer"):
                names = [f"{node.module}.{a.name}" for a in node.names]
                names = [n for n in names if n in hashed or n in NOT_COMPILED] or [node.module]
                for name in names:
                    assert name in hashed or name in NOT_COMPILED, (module, name)


def test_the_marker_key_follows_contents_not_modification_times(tmp_path, monkeypatch):
    monkeypatch.setattr(kernelcache, "_claimed", {})
    for name in ("vmath", "kernels"):
        (tmp_path / "pkg").mkdir(exist_ok=True)
        (tmp_path / "pkg" / f"{name}.py").write_text(f"X = '{name}'\n")
    kernelcache.register(tmp_path, ["pkg.kernels", "pkg.vmath"])
    key = tiers.marker_key()
    os.utime(tmp_path / "pkg" / "vmath.py", ns=(1, 1))  # a touch, a checkout
    assert tiers.marker_key() == key
    (tmp_path / "pkg" / "vmath.py").write_text("X = 'edited'\n")
    assert tiers.marker_key() != key


@pytest.mark.parametrize(("given", "want"), [(None, "PASSIVE"), ("ACTIVE", "ACTIVE")])
def test_the_engine_s_openmp_threads_wait_asleep_unless_told_otherwise(given, want):
    """A process that loads the kernels has OMP_WAIT_POLICY=PASSIVE before numba starts its
    OpenMP threads (docs/perpixel_bench.md: spinning threads cost a loaded machine's camera
    frame twice its CPU); a user's own setting stays."""
    env = {k: v for k, v in os.environ.items() if k != "OMP_WAIT_POLICY"}
    if given is not None:
        env["OMP_WAIT_POLICY"] = given
    code = "import os, explorer.shading.kernels; print(os.environ.get('OMP_WAIT_POLICY'))"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == want
