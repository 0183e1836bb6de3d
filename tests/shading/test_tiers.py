"""The engine's tiers (explorer.shading.tiers): the numpy tier's colours, caching and switch,
mode auto on a cold cache (no compile in the foreground, one notice, the background compile
started), and the background compile's coverage of every kernel signature the product calls."""

from __future__ import annotations

import fcntl
import json
import os
import re
import subprocess
import sys
import textwrap
import threading
import time
from contextlib import contextmanager

import numpy as np
import pytest
from helpers.scenes import scenes, vertices
from hypothesis import given
from hypothesis import strategies as st

import explorer
from explorer.core.errors import ExplorerError
from explorer.geometry.meshes import sphere, teapot, torus
from explorer.shading import tiers, warm
from explorer.shading.display import to_bytes
from explorer.shading.equation import equation_shade
from explorer.shading.shader import Shader

SHADOWED = {
    "material": {"diffuse": [0.8, 0.6, 0.4], "specular": [0.5, 0.5, 0.5], "shininess": 20.0},
    "lights": [
        {"type": "point", "position": [1.5, 2.0, 1.0], "shadows": True},
        {"type": "directional", "to_light": [-0.5, 1.0, 0.2], "shadows": True},
    ],
    "viewer": {"eye": [0.0, 1.0, 4.0]},
}


@given(scene=scenes(), seed=st.integers(0, 2**16), prec=st.sampled_from(["float32", "float64"]))
def test_numpy_tier_is_the_equation_and_agrees_with_the_kernels(scene, seed, prec):
    P, N = vertices(seed)
    numpy_tier = Shader(scene, P, N, precision=prec, tier="numpy").colors
    kernels = Shader(scene, P, N, precision="float64", tier="compiled").colors
    assert numpy_tier.dtype == np.dtype(prec)
    exact = equation_shade(explorer.load_scene(scene), P, N)
    if prec == "float64":
        np.testing.assert_array_equal(numpy_tier, exact)
        np.testing.assert_allclose(kernels, numpy_tier, rtol=0, atol=1e-5)
    else:  # float64 values rounded to float32
        np.testing.assert_allclose(numpy_tier, exact, rtol=0, atol=1e-6)


def test_numpy_tier_shadows_equal_the_equations_rays():
    mesh = torus(24)
    for prec in ("float64", "float32"):
        s = Shader(SHADOWED, mesh.positions, mesh.normals, faces=mesh.faces, precision=prec,
                   tier="numpy")  # fmt: skip
        exact = equation_shade(explorer.load_scene(SHADOWED), mesh.positions, mesh.normals,
                               faces=mesh.faces)  # fmt: skip
        np.testing.assert_allclose(s.colors, exact, rtol=0, atol=1e-6)
        compiled = Shader(SHADOWED, mesh.positions, mesh.normals, faces=mesh.faces,
                          precision="float64", tier="compiled").colors  # fmt: skip
        np.testing.assert_allclose(compiled, s.colors, rtol=0, atol=1e-5)
    assert s.stats["shadow_rays"] > 0 and (exact < s.colors.max()).any()


def test_numpy_tier_keeps_its_sums_for_a_material_change():
    mesh = sphere(16)
    s = Shader(SHADOWED, mesh.positions, mesh.normals, tier="numpy")
    _ = s.colors
    s.set_material({"diffuse": [0.1, 0.9, 0.1], "specular": [0.5, 0.5, 0.5], "shininess": 20.0})
    green = s.colors
    assert s.stats["numpy"] == 1 and s.stats["compose"] == 1  # composed, not recomputed
    s.set_material({"diffuse": [0.1, 0.9, 0.1], "specular": [0.5, 0.5, 0.5], "shininess": 60.0})
    _ = s.colors
    assert s.stats["numpy"] == 2  # shininess changes the specular sum
    assert s.stats["pass"] == 0  # no kernel ran
    expected = Shader(s.scene.replace(material=s.scene.material.replace(shininess=20.0)),
                      mesh.positions, mesh.normals, tier="compiled").colors  # fmt: skip
    np.testing.assert_allclose(green.astype(np.float64), expected, atol=1 / 255)


def test_terms_on_the_numpy_tier():
    mesh = sphere(12)
    s = Shader(SHADOWED, mesh.positions, mesh.normals, tier="numpy")
    k = Shader(SHADOWED, mesh.positions, mesh.normals, tier="compiled", precision="float64")
    for name, value in s.terms.items():
        assert not value.flags.writeable
        np.testing.assert_allclose(value, k.terms[name], atol=1e-5)


def test_a_shader_switches_tier_at_its_next_pass(monkeypatch):
    mesh = teapot(8)
    ready = {"now": False}
    monkeypatch.setattr(tiers, "compiled", lambda work=0: ready["now"])
    s = Shader(SHADOWED, mesh.positions, mesh.normals, faces=mesh.faces, precision="float32")
    before = s.colors
    assert s.stats["numpy"] == 1 and s.stats["pass"] == 0
    rays = s.stats["shadow_rays"]
    assert rays > 0
    ready["now"] = True
    s.set_material({"diffuse": [0.9, 0.2, 0.2], "specular": [0.5, 0.5, 0.5], "shininess": 20.0})
    after = s.colors
    assert s.stats["pass"] == 1  # the compiled tier computed its own sums
    assert s.stats["shadow_rays"] == rays  # the shadow rows are kept across the switch
    expected = Shader(s.scene, mesh.positions, mesh.normals, faces=mesh.faces, tier="numpy")
    np.testing.assert_allclose(after, expected.colors, atol=1 / 255)
    assert not np.array_equal(before, after)


def test_every_module_with_numba_code_names_the_marker():
    # a module whose kernels the marker does not cover could be compiled in the foreground
    root = os.path.dirname(explorer.__file__)
    found = set()
    for folder, _, files in os.walk(root):
        for name in files:
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                with open(path, encoding="utf-8") as f:
                    if re.search(r"\bnjit\b", f.read()):  # compiles numba code
                        rel = os.path.relpath(path, os.path.dirname(root))[:-3]
                        found.add(rel.replace(os.sep, "."))
    assert found == set(tiers.SOURCES)


def test_mode_comes_from_the_environment(monkeypatch):
    monkeypatch.setenv(tiers.ENV, "numpy")
    tiers.set_mode(None)
    try:
        assert tiers.mode() == "numpy" and not tiers.compiled()
        monkeypatch.setenv(tiers.ENV, "jit")
        tiers.set_mode(None)
        with pytest.raises(ExplorerError, match="PHONG_EXPLORER_KERNELS='jit'.*auto, compiled"):
            tiers.mode()
        with pytest.raises(ExplorerError, match="kernels mode"):
            tiers.set_mode("fast")
    finally:
        monkeypatch.setenv(tiers.ENV, "compiled")
        tiers.set_mode(None)
    assert tiers.compiled()


def test_to_bytes_rounds_alike_on_both_tiers(monkeypatch):
    rng = np.random.default_rng(3)
    c = np.concatenate([rng.uniform(-0.1, 1.1, (500, 3)), np.arange(256)[:, None] / 255 * [1, 1, 1],
                        (np.arange(256)[:, None] + 0.5) / 255 * [1, 1, 1]])  # fmt: skip
    for dtype in (np.float32, np.float64):
        x = c.astype(dtype)
        compiled = to_bytes(x)
        monkeypatch.setattr(tiers, "loaded", lambda: False)
        np.testing.assert_array_equal(to_bytes(x), compiled)
        monkeypatch.undo()


def test_a_window_loads_the_kernels_in_a_thread_once_they_are_ready(cold_tiers):
    with pytest.warns(explorer.core.errors.Notice, match="preparing the compiled engine"):
        assert not tiers.compiled(10**9)  # cold: the background compile starts
    tiers.preload()
    assert "preparing" in tiers.status()
    assert not tiers.compiled(10**9)
    cold_tiers.write_text("{}")  # the background compile is done
    assert not tiers.compiled(10**9)  # seen: loading in a thread, the numpy tier serves meanwhile
    loader = tiers._state["loading"]
    assert loader is not None and "loading" in tiers.status()
    loader.join(timeout=600)
    assert tiers.compiled(1) and tiers.loaded() and tiers.status() is None


def test_a_one_shot_process_loads_the_kernels_only_for_enough_work(cold_tiers):
    cold_tiers.write_text("{}")  # the cache holds the kernels
    mesh = sphere(16)
    s = Shader(SHADOWED, mesh.positions, mesh.normals, keep=False)
    _ = s.colors
    assert s.stats["numpy"] == 1 and not tiers.loaded()  # a small job: no load
    served = tiers._state["numpy_work"]
    s.set_material({"diffuse": [0.2, 0.3, 0.9], "specular": [0.5, 0.5, 0.5], "shininess": 20.0})
    _ = s.colors  # a compose on the numpy tier's kept sums: no vertex-light work counted
    assert tiers._state["numpy_work"] == served and s.stats["numpy"] == 1
    assert not tiers.compiled(tiers.LOAD_WORTH // 2)
    assert tiers.compiled(tiers.LOAD_WORTH // 2)  # enough work served: load and compile
    s.set_lights(SHADOWED["lights"][:1])
    _ = s.colors
    assert s.stats["pass"] == 1 and tiers.loaded()
    assert tiers._state["loading"] is None  # loaded by the pass itself, no thread


COLD = textwrap.dedent(
    """
    import json, warnings
    import explorer
    from explorer.geometry.meshes import teapot
    from explorer.shading import warm
    from explorer.shading.display import to_bytes
    warnings.simplefilter("always")
    mesh = teapot(16)
    kinds = [{"lights": [{"type": t, "position": [1, 2, 3]}]} for t in ("point", "spot")]
    kinds += [{"model": "phong", "two_sided": True, "viewer": {"to_viewer": [0, 0, 1]}},
              {"material": {"fresnel": 0.04, "energy_conserving": True}, "hdr": True}]
    kinds += [{"lights": [{"type": "point", "position": [1, 2, 3], "shadows": True}]}]
    for scene in kinds:
        for precision in ("float32", "float64"):
            c = explorer.shade(scene, mesh.positions, mesh.normals, precision=precision,
                               faces=mesh.faces)
            to_bytes(c)
    from explorer.render.perpixel import mesh_hits
    from explorer.render.camera import camera_for
    mesh_hits(camera_for(explorer.load_scene({}), mesh), (64, 48), mesh)  # pixel rays
    print(json.dumps({k: len(v) for k, v in warm.signatures().items() if v}))
    """
)


def _empty_cache(tmp_path, path: str) -> tuple[dict, str]:
    """The environment of a process in mode auto on an empty numba cache under ``tmp_path``,
    and the path ``tiers.<path>()`` names there (its directory made)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    env[tiers.ENV] = "auto"
    probe = f"from explorer.shading import tiers; print(tiers.{path}())"
    out = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True,
                         text=True, check=True).stdout.strip()  # fmt: skip
    os.makedirs(os.path.dirname(out), exist_ok=True)
    return env, out


@contextmanager
def _cold_cache(tmp_path):
    """An empty numba cache in mode auto, with the background compile's lock held, as if one
    were running already: a background compile started meanwhile must see it and leave (it is
    waited for on exit), so no test compiles the kernels for minutes."""
    env, lock_file = _empty_cache(tmp_path, "lock_path")
    log = os.path.join(os.path.dirname(lock_file), "explorer-warm.log")
    with open(lock_file, "a+") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        yield env, log
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and "holds the lock" not in _read(log):
            time.sleep(0.1)


def _read(path) -> str:
    try:
        with open(path) as f:
            return f.read()
    except FileNotFoundError:
        return ""


def test_auto_on_a_cold_cache_compiles_nothing_in_the_foreground(tmp_path):
    with _cold_cache(tmp_path) as (env, log):
        out = subprocess.run([sys.executable, "-c", COLD], env=env, capture_output=True,
                             text=True, cwd=tmp_path, timeout=300)  # fmt: skip
        assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout.strip().splitlines()[-1]) == {}  # no kernel compiled or loaded
    assert out.stderr.count("preparing the compiled engine") == 1, out.stderr  # told once
    assert "holds the lock" in _read(log)  # the background compile started, and left


def test_the_quick_start_render_on_a_cold_cache(tmp_path):
    with _cold_cache(tmp_path) as (env, log):
        out = subprocess.run(
            [sys.executable, "-m", "explorer.cli", "render", "--preset", "bronze", "--mesh",
             "teapot", "--out", str(tmp_path / "bronze.png")],
            env=env, capture_output=True, text=True, cwd=tmp_path, timeout=300,
        )  # fmt: skip
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "bronze.png").stat().st_size > 1000
    assert out.stderr.strip().splitlines() == [f"notice: {tiers.PREPARING}"], out.stderr
    assert "holds the lock" in _read(log)


def test_the_background_compile_covers_what_the_product_calls():
    warm.exercise()
    before = warm.signatures()
    # what the product does beyond the exercise: one-shot shading of every input form, the
    # window's shader, the display pipeline
    mesh = teapot(8)
    P64, N64 = np.array(mesh.positions), np.array(mesh.normals)
    for P, N in (
        (mesh.positions, mesh.normals),
        (P64, N64),
        (P64.astype(np.float32), N64),
        (P64.tolist(), N64.tolist()),
        (P64.astype(np.float32), N64.astype(np.float32)),
    ):
        for precision in ("float64", "float32"):
            for faces in (None, mesh.faces):
                c = explorer.shade(SHADOWED, P, N, precision=precision, faces=faces)
                to_bytes(c)
                to_bytes(c.astype(np.float32), 0.5)
    s = Shader(SHADOWED, mesh.positions, mesh.normals, faces=mesh.faces)
    for shininess in (5.0, 50.0, 0.0, 128.0):
        s.set_material(s.scene.material.replace(shininess=shininess))
        to_bytes(s.colors, out=np.zeros((s.n, 3), np.uint8))
    s.set_model("phong")
    s.set_lights([{"type": "spot", "position": [0, 3, 0], "aim": [0, -1, 0], "cutoff": 30}])
    s.set_viewer({"to_viewer": [0, 0, 1]})
    _ = s.colors
    # a large tree's refit, split among the threads (occluders.refit_top, refit_unions: issue
    # 31 item 9, they were compiled in-process on first use)
    from explorer.geometry import bvh

    saved = bvh.REFIT_NODES, bvh.workers
    bvh.REFIT_NODES, bvh.workers = 0, lambda: 2
    try:
        explorer.shade(SHADOWED, mesh.positions, mesh.normals, faces=mesh.faces)
    finally:
        bvh.REFIT_NODES, bvh.workers = saved
    after = warm.signatures()
    new = {k: after[k] - before[k] for k in after if after[k] - before[k]}
    assert not new, f"kernel signatures the background compile does not make: {new}"


def test_the_shading_pass_compiles_once_per_precision():
    # each signature of shade links every light loop and optimises it again (the largest part
    # of the cold compile, benchmarks/bench_compile.py --warm): the prepared rows and the
    # caller's float32 or float64 vertices are one kernels.Source per precision
    # in a process of its own: what the product's passes compile, not what this suite's other
    # tests (kernels called with arrays of their own making) added to the dispatchers
    code = textwrap.dedent("""
        from explorer.shading import warm
        warm.exercise()
        found = warm.signatures()
        print({n: len(found[f"explorer.shading.kernels.{n}"]) for n in ("shade", "bounds")})
    """)
    env = dict(os.environ, PHONG_EXPLORER_KERNELS="compiled")
    out = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env=env,
        timeout=900,
        check=True,
    ).stdout
    assert out.strip().splitlines()[-1] == "{'shade': 2, 'bounds': 2}", out  # float32, float64


#: one half of the split background compile (explorer.shading.warm.exercise with its
#: partner), its kernels printed: the partner's whole share, or the main process's until it
#: waits for the partner's ray kernels (the passes that cast no ray, the loops elsewhere)
_HALF = textwrap.dedent(
    """
    import json, sys
    from explorer.shading import kernels, warm
    if sys.argv[1] == "partner":
        warm.main(["--partner"])
    else:
        kernels.loops_elsewhere(True)
        warm._passes(list(warm._meshes()), warm.UNSHADOWED)
    print(json.dumps(sorted(k for k, v in warm.signatures().items() if v)))
    """
)


def test_the_split_compile_s_two_processes_take_disjoint_kernels():
    # issue 38 item 5: the background compile runs in two processes (two cores): nothing may be
    # compiled by both (each would pay for it, and both would write its cache files). numba
    # compiles what a process calls: so the kernels each half calls are disjoint, and the main
    # process's ray kernels (its shadowed scenes' rays, after the partner said "rays") and
    # the partner's light loops are what the other compiled
    env = dict(os.environ, **{tiers.ENV: "compiled"})
    half = {}
    for name in ("partner", "main"):
        out = subprocess.run(
            [sys.executable, "-c", _HALF, name],
            env=env,
            capture_output=True,
            text=True,
            timeout=900,
        )
        assert out.returncode == 0, out.stderr
        half[name] = set(json.loads(out.stdout.strip().splitlines()[-1]))
    loops = {k for k in half["partner"] if ".kernels._light_" in k}
    assert len(loops) == 18
    assert all(k.startswith("explorer.geometry.") for k in half["partner"] - loops)
    assert half["partner"] - loops  # (the ray kernels)
    assert half["main"] and not half["main"] & half["partner"]


#: the background compile split in two (warm.main on two cores), its main process's passes the
#: byte rounding alone, its partner a command that aborts or one that says it is done
_HALVES = textwrap.dedent(
    """
    import sys
    import numpy as np
    from explorer.shading import display, warm
    def rounding(meshes, scenes):
        display._round_bytes(np.linspace(-0.1, 1.1, 12), np.empty(12, np.uint8))
        return 0
    partner = {"abort": "import os; os.abort()", "done": "print('rays')"}[sys.argv[1]]
    warm._passes, warm.cores = rounding, lambda: 2
    warm.partner_command = lambda: [sys.executable, "-c", partner]
    sys.exit(warm.main())
    """
)


def test_a_crash_of_one_half_of_the_compile_leaves_the_other_s_kernels_cached(tmp_path):
    # the partner process crashing (the compiler aborting) fails the background compile (no
    # marker, the error written for the next process to tell) but what the main process
    # compiled is in the cache: the next background compile loads it, compiles only the rest
    env, marker = _empty_cache(tmp_path, "marker_path")
    first = subprocess.run(
        [sys.executable, "-c", _HALVES, "abort"],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert first.returncode == 1, first.stderr
    assert not os.path.exists(marker)
    error = json.loads(_read(marker.replace("-ready-", "-attempt-")))["error"]
    assert error.startswith("RuntimeError: the partner compile ended with status"), error
    (nbc,) = (tmp_path / "numba").rglob("display._round_bytes-*.nbc")
    kept = os.stat(nbc)
    second = subprocess.run(
        [sys.executable, "-c", _HALVES, "done"],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert second.returncode == 0, second.stderr
    assert os.path.exists(marker)
    again = os.stat(nbc)  # loaded, not compiled and written again
    assert (again.st_ino, again.st_mtime_ns) == (kept.st_ino, kept.st_mtime_ns)


def test_numba_cache_writes_wait_for_the_save_lock(tmp_path):
    # numba reads a function's index, adds a signature and writes it back: two processes of
    # the split compile adding signatures of one function at once would lose one, or name one
    # data file for both. Every cache write of a guarded process holds tiers.save_lock_path
    from numba.core.caching import IndexDataCacheFile

    tiers.guard_cache()
    cache = IndexDataCacheFile(str(tmp_path), "probe", ("stamp", 1))
    with open(tiers.save_lock_path(), "a+") as held:
        fcntl.flock(held, fcntl.LOCK_EX)
        writer = threading.Thread(target=cache.save, args=("key", b"code"))
        writer.start()
        writer.join(0.5)
        assert writer.is_alive() and not (tmp_path / "probe.nbi").exists()  # it waits
    writer.join(60)
    assert not writer.is_alive() and cache.load("key") == b"code"


def test_after_failed_background_compiles_the_numpy_tier_serves_and_says_why(cold_tiers):
    # one compile that ended without the marker: another is started
    tiers.record_attempt()
    with pytest.warns(explorer.core.errors.Notice, match="preparing the compiled engine"):
        assert not tiers.compiled(10**9)
    assert tiers._state["started"]
    # two: no more; the first pass says why, once, and how to try again
    tiers.record_attempt()
    tiers.record_error("RuntimeError: LLVM ERROR")
    assert tiers.attempts() == {"attempts": 2, "error": "RuntimeError: LLVM ERROR"}
    tiers.set_mode("auto")
    tiers._state.update(started=False)
    with pytest.warns(explorer.core.errors.Notice) as told:
        assert not tiers.compiled(10**9)
        assert not tiers.compiled(10**9)
    assert len(told) == 1
    said = str(told[0].message)
    assert "cannot be prepared" in said and "LLVM ERROR" in said
    assert f"remove {tiers.attempt_path()}" in said
    assert not tiers._state["started"]  # none started
    assert "unavailable" in tiers.status() and "LLVM ERROR" in tiers.status()
    mesh = sphere(8)
    c = explorer.shade(SHADOWED, mesh.positions, mesh.normals)  # the numpy tier serves
    assert np.allclose(c, equation_shade(explorer.load_scene(SHADOWED), mesh.positions,
                                         mesh.normals, faces=None), atol=1e-12)  # fmt: skip
    # a compile that is running now (it holds the lock) is not given up on
    with open(tiers.lock_path(), "a+") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        assert tiers.given_up() is None
    assert "2 background compiles" in tiers.given_up()
    # the marker forgets the attempts
    tiers.write_marker(1.0)
    assert not tiers.attempt_path().exists() and tiers.attempts()["attempts"] == 0


CRASH = textwrap.dedent(
    """
    import os, sys
    from explorer.shading import warm
    warm.exercise = (lambda **_: os.abort()) if sys.argv[1] == "abort" else (lambda **_: 1 / 0)
    sys.exit(warm.main())
    """
)


def test_a_background_compile_that_crashes_is_counted(tmp_path):
    # the compiler aborting the process (as LLVM's assertions do) or an exception: each run
    # counted, the exception's text kept for the next process to tell
    env, path = _empty_cache(tmp_path, "attempt_path")
    first = subprocess.run([sys.executable, "-c", CRASH, "abort"], env=env, capture_output=True)
    assert first.returncode != 0
    assert json.loads(_read(path)) == {"attempts": 1, "error": None}
    second = subprocess.run([sys.executable, "-c", CRASH, "raise"], env=env, capture_output=True)
    assert second.returncode == 1
    assert json.loads(_read(path)) == {
        "attempts": 2,
        "error": "ZeroDivisionError: division by zero",
    }


def _ray_engines(shader) -> set[str]:
    """The ray engines that built the shader's shadow trees."""
    from explorer.shading.shadows import GEOMETRY_KEY

    return {k[1] for k in shader._vis_cache if isinstance(k, tuple) and k[:1] == (GEOMETRY_KEY,)}


def test_an_explicit_tier_is_obeyed_for_rays(cold_tiers):
    # issue 31 item 3: the rays followed the process's tier (tiers.loaded()), not the shader's:
    # tier="compiled" cast on the numpy BVH in mode auto, tier="numpy" on the compiled one in
    # mode compiled
    mesh = torus(16)
    cold_tiers.write_text("{}")  # a warm cache, but no work served: auto would stay on numpy
    for tier, engine in (("compiled", "explorer.geometry.bvh"),
                         ("numpy", "explorer.geometry.bvh_numpy")):  # fmt: skip
        for mode in ("auto", "compiled", "numpy"):
            tiers.set_mode(mode)
            s = Shader(SHADOWED, mesh.positions, mesh.normals, faces=mesh.faces, tier=tier)
            _ = s.colors
            assert _ray_engines(s) == {engine}, (tier, mode)
            assert s.stats["shadow_rays"] > 0
    assert tiers.ray_engine(tier="numpy").__name__ == "explorer.geometry.bvh_numpy"
    assert tiers.ray_engine(tier="compiled").__name__ == "explorer.geometry.bvh"


def test_the_tier_choice_counts_ray_work(cold_tiers, monkeypatch):
    # issue 31 item 3: a one-shot shadowed pass counted its shading (n·L vertex-lights) but
    # not its tree and rays, so it built the numpy BVH although the warm cache would pay
    cold_tiers.write_text("{}")  # the cache holds the kernels
    mesh = teapot(8)
    n = len(mesh.positions)
    work = tiers.ray_work(len(mesh.faces), n)
    assert work > 10 * n  # the rays cost more than the shading of one light
    monkeypatch.setattr(tiers, "LOAD_WORTH", 2 * n)  # more than the shading alone
    unshadowed = {**SHADOWED, "lights": [{"type": "point", "position": [1.5, 2.0, 1.0]}]}
    plain = Shader(unshadowed, mesh.positions, mesh.normals, faces=mesh.faces, keep=False)
    _ = plain.colors  # no shadows: n vertex-lights, under LOAD_WORTH
    assert plain.stats["numpy"] == 1 and not tiers.loaded()
    one = {**SHADOWED, "lights": SHADOWED["lights"][:1]}
    s = Shader(one, mesh.positions, mesh.normals, faces=mesh.faces, keep=False)
    _ = s.colors  # n vertex-lights and the ray work: the kernels load, rays and shading both
    assert s.stats["pass"] == 1 and s.stats["numpy"] == 0 and tiers.loaded()
    assert _ray_engines(s) == {"explorer.geometry.bvh"}
    np.testing.assert_allclose(
        s.colors, Shader(one, mesh.positions, mesh.normals, faces=mesh.faces, tier="numpy").colors,
        atol=1 / 255,
    )  # fmt: skip


def test_a_per_pixel_cast_counts_its_rays(cold_tiers, monkeypatch):
    # issue 31 item 3: render --per-pixel cast every pixel's ray on the numpy BVH until the
    # process had shaded LOAD_WORTH vertex-lights (8192² pixels: 14.3 GiB, then a traceback)
    from explorer.render import perpixel
    from explorer.render.camera import camera_for

    cold_tiers.write_text("{}")
    mesh = teapot(6)
    camera = camera_for(explorer.load_scene({}), mesh)
    monkeypatch.setattr(tiers, "LOAD_WORTH", tiers.ray_work(0, 40 * 30 * 4))
    perpixel.mesh_hits(camera, (40, 30), mesh)  # a few rays: the numpy casts
    assert set(perpixel._bvh_cache[mesh]) == {"explorer.geometry.bvh_numpy"}
    assert not tiers.loaded()
    hits = perpixel.mesh_hits(camera, (160, 120), mesh)  # sixteen times the rays: compiled
    assert tiers.loaded() and "explorer.geometry.bvh" in perpixel._bvh_cache[mesh]
    assert hits.mask.any()


# -- a damaged cache (issue 31 item 9) -------------------------------------------------------------
def _fake_cache(tmp_path, monkeypatch) -> dict:
    """Two kernels' cache files (an index and a compiled overload each) standing for numba's, and
    :func:`tiers.cache_files` listing them: a damaged cache simulated without compiling."""
    files = {}
    for name, size in (("kernels.shade-1.py311", 900), ("bvh.any_hit-2.py311", 400)):
        for suffix, n in ((".nbi", 64), (".1.nbc", size)):
            path = tmp_path / f"{name}{suffix}"
            path.write_bytes(b"x" * n)
            files[str(path)] = n
    monkeypatch.setattr(
        tiers, "cache_files", lambda: {p: os.path.getsize(p) for p in files if os.path.exists(p)}
    )
    return files


@pytest.mark.parametrize("damage", ["truncated", "index removed", "marker a FIFO"])
def test_a_damaged_cache_is_set_aside_with_one_notice_and_rebuilt(cold_tiers, monkeypatch, damage):
    # a truncated .nbc with the marker kept died in an UnpicklingError traceback on every large
    # render; an index removed made a 4-light render recompile for 55 s, silently
    files = _fake_cache(cold_tiers.parent, monkeypatch)
    tiers.write_marker(1.0)
    nbc = next(p for p in files if p.endswith(".nbc"))
    nbi = next(p for p in files if p.endswith(".nbi"))
    if damage == "truncated":
        os.truncate(nbc, 10)
    elif damage == "index removed":
        os.unlink(nbi)
    else:
        cold_tiers.unlink()
        os.mkfifo(cold_tiers)
    tiers.set_mode("auto")
    with pytest.warns(explorer.core.errors.Notice) as told:
        assert not tiers.compiled(10**9)  # the numpy tier serves
        assert not tiers.compiled(10**9)
    told = [w for w in told if issubclass(w.category, explorer.core.errors.Notice)]
    assert len(told) == 1, [str(w.message) for w in told]
    said = str(told[0].message)
    assert "damaged" in said and "rebuilt in the background" in said, said
    assert (nbc if damage == "truncated" else nbi if damage == "index removed" else
            cold_tiers.name) in said  # fmt: skip
    aside = list(cold_tiers.parent.glob("explorer-damaged-*"))
    assert len(aside) == 1 and (aside[0] / "why.txt").exists()
    assert not os.path.lexists(cold_tiers)  # the marker is gone
    assert not any(os.path.exists(p) for p in files)  # the kernels' files set aside
    assert tiers._state["started"]  # and the background compile rebuilds them


#: a process on a numba cache of its own: the display's byte rounding (a kernel that compiles
#: in seconds) run on the compiled tier, its bytes printed
_ROUND = textwrap.dedent(
    """
    import numpy as np
    from explorer.shading import display
    print(display.to_bytes(np.linspace(-0.1, 1.1, 12).reshape(4, 3)).ravel().tolist())
    """
)
#: the background compile (``warm.main``) whose exercise is the byte rounding alone (the whole
#: exercise compiles for minutes)
_WARM = textwrap.dedent(
    """
    import sys
    import numpy as np
    from explorer.shading import display, warm
    def rounding():
        out = np.empty(12, np.uint8)
        display._round_bytes(np.linspace(-0.1, 1.1, 12), out)
    warm._pixel_rays, warm._refits, warm._meshes = rounding, lambda: None, lambda: iter(())
    warm.cores = lambda: 1  # (one process: no partner compiling the loops for minutes)
    sys.exit(warm.main())
    """
)


def _round_bytes_files(tmp_path) -> tuple[dict, list[str]]:
    """A numba cache under ``tmp_path`` holding the byte rounding (compiled there, in a few
    seconds), the environment that uses it, and its cache files (index first)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), **{tiers.ENV: "compiled"})
    run = subprocess.run([sys.executable, "-c", _ROUND], env=env, capture_output=True,
                         text=True, timeout=600)  # fmt: skip
    assert run.returncode == 0, run.stderr
    files = sorted(str(p) for p in (tmp_path / "numba").rglob("display._round_bytes-*.nb?"))
    assert [f[-4:] for f in files] == [".nbc", ".nbi"], files
    return env, files[::-1]


def test_a_cache_file_numba_cannot_read_is_set_aside_and_compiled_again(tmp_path):
    """A truncated index or compiled overload (a full disk, a killed writer) with no marker to
    vouch for it ended the compiled mode in pickle's ``UnpicklingError`` traceback: now it is
    set aside with one notice, the kernel is compiled again, and the next run reads the new
    files without a word."""
    env, (nbi, nbc) = _round_bytes_files(tmp_path)
    want = np.rint(np.clip(np.linspace(-0.1, 1.1, 12) * 255.0, 0.0, 255.0)).tolist()
    for damaged in (nbi, nbc):
        os.truncate(damaged, 20)
        for again in (False, True):
            run = subprocess.run([sys.executable, "-c", _ROUND], env=env, capture_output=True,
                                 text=True, timeout=600)  # fmt: skip
            assert run.returncode == 0, run.stderr
            assert json.loads(run.stdout.strip().splitlines()[-1]) == want
            if again:
                assert run.stderr == "", run.stderr
                continue
            assert "Traceback" not in run.stderr
            assert run.stderr.count("numba could not read") == 1, run.stderr
            assert "_round_bytes" in run.stderr and "set aside in" in run.stderr
            assert os.path.getsize(damaged) > 20  # written anew
    aside = list((tmp_path / "numba").rglob("explorer-damaged-*"))
    assert len(aside) == 2 and all((a / "why.txt").exists() for a in aside)


def test_the_background_compile_sets_an_unreadable_cache_file_aside(tmp_path):
    """The background compile met the same ``UnpicklingError``, counted a failed attempt, and
    after two no compiled engine was ever prepared: now it sets the file aside, compiles and
    writes the ready marker."""
    env, (nbi, _) = _round_bytes_files(tmp_path)
    os.truncate(nbi, 20)
    env[tiers.ENV] = "auto"
    run = subprocess.run([sys.executable, "-c", _WARM], env=env, capture_output=True,
                         text=True, timeout=600)  # fmt: skip
    assert run.returncode == 0, run.stdout + run.stderr
    assert "numba could not read" in run.stderr and "Traceback" not in run.stdout
    assert list((tmp_path / "numba").rglob("explorer-ready-*.json"))  # the marker
    assert os.path.getsize(nbi) > 20


def test_an_intact_cache_is_used_and_an_index_may_grow(cold_tiers, monkeypatch):
    files = _fake_cache(cold_tiers.parent, monkeypatch)
    tiers.write_marker(1.0)
    nbi = next(p for p in files if p.endswith(".nbi"))
    with open(nbi, "ab") as f:  # numba added an overload it compiled later
        f.write(b"more")
    tiers.set_mode("auto")
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", explorer.core.errors.Notice)
        assert tiers.compiled(10**9)
    assert tiers.damage() is None and not list(cold_tiers.parent.glob("explorer-damaged-*"))


def test_an_attempt_file_that_is_not_a_count_is_set_aside(cold_tiers):
    # {"attempts": Infinity} gave an OverflowError traceback on every command
    path = tiers.attempt_path()
    for text in ('{"attempts": Infinity}', '{"attempts": 1e400}', '{"attempts": true}', "[1]",
                 '{"attempts": 2, "error": 5}', "\xff\xfe"):  # fmt: skip
        path.write_bytes(text.encode("utf-8", "surrogateescape"))
        assert tiers.attempts() == {"attempts": 0, "error": None}
        assert not path.exists()  # set aside
    path.write_text('{"attempts": 1, "error": "boom"}')
    assert tiers.attempts() == {"attempts": 1, "error": "boom"}


def test_an_attempt_file_that_is_a_fifo_does_not_block(cold_tiers):
    # a FIFO there hung every command
    import threading

    os.mkfifo(tiers.attempt_path())
    result = {}
    t = threading.Thread(target=lambda: result.update(a=tiers.attempts()), daemon=True)
    t.start()
    t.join(timeout=20)
    assert result.get("a") == {"attempts": 0, "error": None}
    assert not os.path.lexists(tiers.attempt_path())


def test_a_lock_path_that_cannot_be_opened(cold_tiers, monkeypatch, capsys):
    # a lock path that could not be opened made every command start a compile (which died
    # before counting itself) and say "preparing ..." forever
    tiers.lock_path().mkdir()  # a directory where the lock file goes: set aside, made anew
    assert not tiers.compile_running()
    assert tiers.lock_path().is_file()
    # a lock that cannot be made at all: the compile counts itself and says why, so that after
    # MAX_ATTEMPTS no more are started
    blocker = cold_tiers.parent / "blocker"
    blocker.write_text("")
    monkeypatch.setattr(tiers, "lock_path", lambda: blocker / "explorer-warm.lock")
    monkeypatch.setattr(os, "nice", lambda n: 0)
    for n in (1, 2):
        assert warm.main() == 1
        info = tiers.attempts()
        assert info["attempts"] == n and "cannot open the lock" in info["error"]
    assert "cannot open the lock" in tiers.given_up()


def test_a_process_ending_before_its_background_compile_leaves_no_child(tmp_path):
    """The background compile outlives the process that started it (a one-shot render, the test
    session, the page's server end first) without being its child: that process ends with no
    subprocess running, so no "ResourceWarning: subprocess N is still running" (it was printed
    after the tiers and web tests), and the compile still runs to its end."""
    done = tmp_path / "done"
    compile_ = f"import pathlib, time; time.sleep(2); pathlib.Path({str(done)!r}).write_text('')"
    code = textwrap.dedent(
        f"""
        import pathlib, sys
        from explorer.shading import tiers
        tiers.cache_dir = lambda: pathlib.Path({str(tmp_path)!r})
        tiers.warm_command = lambda: [sys.executable, "-c", {compile_!r}]
        tiers._start_background()
        """
    )
    command = [sys.executable, "-W", "error::ResourceWarning", "-c", code]
    out = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "ResourceWarning" not in out.stderr and "still running" not in out.stderr, out.stderr
    assert "preparing the compiled engine" in out.stderr  # (started, and said so)
    deadline = time.monotonic() + 60
    while not done.exists() and time.monotonic() < deadline:
        time.sleep(0.1)
    assert done.exists()  # the compile ran on after its starter ended
