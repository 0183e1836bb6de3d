"""Fill numba's on-disk cache with every kernel the product calls: the background compile.

``python -m explorer.shading.warm`` is what :mod:`explorer.shading.tiers` starts in the
background on a machine whose cache lacks the kernels. It takes the lock
(:func:`explorer.shading.tiers.lock_path`; a second one exits at once), runs :func:`exercise`
with the compiled tier (every kind of pass the product makes, on small meshes, in both
precisions: numba compiles each kernel signature once and writes it to its cache), then writes the
ready marker. Where there are two cores it compiles in two processes (numba's compiler is
single-threaded): a partner (``python -m explorer.shading.warm --partner``, :func:`partner`)
compiles the ray kernels and the 36 light loops while this one compiles the shading kernels,
which call the loops through a table of entry points and so compile without them (see
:func:`exercise`); it is also the fastest way to fill a cold cache (CI, a benchmark machine).
It lowers its priority by :data:`NICE`. Progress and errors go to
:func:`explorer.shading.tiers.log_path`; each run counts itself first
(:func:`explorer.shading.tiers.record_attempt`; an error it raises:
:func:`~explorer.shading.tiers.record_error`), so that runs that end without the marker (an
error, a crash of the compiler) are not started again and again.

:func:`load` runs the same passes in a process whose cache already holds them: numba loads each
kernel and compiles nothing (the loader thread of a process that saw the marker appear).
tests/shading/test_tiers.py checks that the passes the product makes after :func:`exercise` meet
no kernel signature it did not compile.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
import traceback

import numpy as np

from explorer.geometry import bvh, raster
from explorer.geometry.meshes import sphere, torus
from explorer.shading import kernels, tiers
from explorer.shading.display import to_bytes
from explorer.shading.shader import Shader
from explorer.shading.strip import shader_strip_bytes

#: the lights of the exercise: one of each type, every option that takes its own kernel path
LIGHTS = (
    {"type": "point", "position": [2.0, 1.5, 3.0], "attenuation": [1.0, 0.1, 0.02]},
    {"type": "spot", "position": [-1.0, 2.0, 2.0], "aim": [0.5, -1.0, -1.0], "cutoff": 40.0,
     "exponent": 8.0, "shadows": True},
    {"type": "directional", "to_light": [0.3, 1.0, 0.5], "diffuse": [0.9, 0.8, 0.7]},
)  # fmt: skip
MATERIAL = {"diffuse": [0.7, 0.5, 0.3], "specular": [0.6, 0.6, 0.6], "shininess": 25.0}
#: scenes that between them take every kernel path: models, viewers, sidedness, effects, HDR
SCENES = (
    {"model": "blinn", "lights": LIGHTS, "viewer": {"eye": [0, 0, 5]}},
    {"model": "phong", "lights": LIGHTS, "two_sided": True},
    {"model": "blinn", "lights": LIGHTS[:1]},  # infinite viewer: a constant halfway vector
    {"model": "phong", "lights": LIGHTS, "viewer": {"eye": [0, 0, 5]}, "hdr": True,
     "material": dict(MATERIAL, fresnel=0.04, energy_conserving=True)},
    {"model": "blinn", "lights": [{"type": "point", "position": [0, 3, 0], "diffuse": [0.7] * 3,
     "specular": [0.7] * 3, "ambient": [0.1] * 3}]},  # grey lights: grey sums
)  # fmt: skip
#: the scenes whose passes cast no shadow ray, and those that do (every mesh casts its rays:
#: :mod:`explorer.shading.shadows`), apart for :func:`exercise`'s split
SHADOWED = tuple(s for s in SCENES if any(lt.get("shadows") for lt in s["lights"]))
UNSHADOWED = tuple(s for s in SCENES if s not in SHADOWED)


def dispatchers() -> dict:
    """Every numba function of :data:`explorer.shading.tiers.SOURCES`, by qualified name (the
    kernels wrapped for wide vectors through their ``dispatcher``)."""
    import importlib

    from numba.core.registry import CPUDispatcher

    found = {}
    for name in tiers.SOURCES:
        module = importlib.import_module(name)
        for attr, obj in vars(module).items():
            d = getattr(obj, "dispatcher", obj)
            if isinstance(d, CPUDispatcher):
                found[f"{name}.{attr}"] = d
    return found


def signatures() -> dict[str, set]:
    """The signatures each function of :func:`dispatchers` holds in this process (compiled or
    loaded from numba's cache)."""
    return {name: set(d.signatures) for name, d in dispatchers().items()}


def _meshes():
    """Small meshes, each as the product passes them: read-only float64 (built-ins, files) and
    writable float32 (arrays a caller made)."""
    for mesh in (sphere(12), torus(12)):  # convex (no shadow rays) and concave (rays)
        yield mesh.positions, mesh.normals, mesh.faces
        P = mesh.positions.astype(np.float32)
        yield P, mesh.normals.astype(np.float32), mesh.faces


def _changes(shader: Shader) -> None:
    """What the window and the CLI do to a shader after its first pass."""
    material = shader.scene.material
    for change in (
        {"diffuse": [0.2, 0.5, 0.9]},  # compose only
        {"shininess": 12.0},  # the specular sum
        {"shininess": 40.0},  # the lobe alone, from stored bases
        {"shininess": 0.0},  # a flat lobe
        {"specular": [0.0, 0.0, 0.0]},  # no specular term
        {"ambient": [0.0, 0.0, 0.0], "specular": [0.5, 0.5, 0.5], "shininess": 30.0},
    ):
        shader.set_material(material.replace(**change))
        to_bytes(shader.colors)
    shader.set_viewer({"eye": [0.5, 1.0, 4.0]})
    to_bytes(shader.colors)
    _ = shader.terms if shader.keep else None
    if shader.keep:  # the term strip's bytes (explorer.shading.strip)
        shader_strip_bytes(shader)


def _pixel_rays() -> None:
    """The per-pixel reference's casts (:mod:`explorer.render.perpixel`) through the compiled
    BVH: a tree of a mesh's world triangles, nearest hits of a grid of rays, the hit points and
    normals (the mesh's read-only arrays, as the reference passes them)."""
    mesh = torus(12)
    tree = bvh.build_bvh(mesh.positions[mesh.faces])
    y, x = np.mgrid[-1:1:8j, -1:1:8j]
    O = np.stack([x.ravel(), y.ravel(), np.full(x.size, 3.0)], axis=1)
    D = np.ascontiguousarray(np.broadcast_to([0.0, 0.0, -1.0], O.shape))
    t, f, u, v = bvh.nearest_hits(tree, O, D, 1e-9)
    faces = np.asarray(mesh.faces, np.int64).reshape(-1, 3)
    bvh.surface_points(O, D, t, f, u, v, faces, np.asarray(mesh.normals, np.float64))


def _gbuffer() -> None:
    """The live per-pixel view's compiled G-buffer (:func:`explorer.geometry.raster.gbuffer`)
    of a mesh's read-only arrays, one camera (perspective and parallel take the same
    signatures)."""
    mesh = torus(12)
    cam = [0, 0, 5, 1, 0, 0, 0, 1, 0, 0, 0, -1, 0.5, 0.5, 0.0, 0.0, 1.0, 10.0]
    raster.gbuffer(mesh.positions, mesh.normals, mesh.faces, cam, True, (16, 12))


def _refits() -> None:
    """The shadow rays' per-light refit of the tree (:func:`explorer.geometry.bvh.toward_light`)
    both ways: whole, and split among the threads (``occluders.refit_top``, ``refit`` and
    ``refit_unions``: the product's way for trees of ``bvh.REFIT_NODES`` nodes and more on
    several cores, which the small meshes of the exercise do not reach)."""
    mesh = torus(12)
    P = np.asarray(mesh.positions, np.float64)
    tree = bvh.build_bvh(P[np.asarray(mesh.faces, np.int64).reshape(-1, 3)])
    D = np.ascontiguousarray(np.array([2.0, 1.5, 3.0]) - P)  # toward a point light
    tmax = np.ones(len(P))
    for split in (True, False):
        bvh.toward_light(tree, P, D, tmax, split=split)


def rays() -> None:
    """The ray kernels' share of the exercise: the per-pixel reference's casts, the live view's
    G-buffer, the shadow rays' refits (:func:`_pixel_rays`, :func:`_gbuffer`, :func:`_refits`)."""
    _pixel_rays()
    _gbuffer()
    _refits()


def _passes(meshes, scenes=SCENES) -> int:
    """The shading passes of the exercise: ``scenes`` on ``meshes`` (see :func:`exercise`)."""
    passes = 0
    for P, N, faces in meshes:
        for scene in scenes:
            for precision in ("float32", "float64"):
                for keep in (True, False):
                    for clamp in (True, False):
                        s = Shader(
                            {"material": MATERIAL, **scene},
                            P,
                            N,
                            precision=precision,
                            keep=keep,
                            clamp=clamp,
                            faces=faces,
                            tier="compiled",
                        )
                        colors = s.colors
                        to_bytes(colors)
                        to_bytes(colors, 1.0)
                        to_bytes(colors, out=np.empty(colors.shape, np.uint8))
                        if keep:
                            _changes(s)
                        passes += s.stats["pass"]
    return passes


def exercise(partner: bool = False) -> int:
    """Run every kind of pass the product makes on the compiled tier; returns the passes.

    partner : split the work with a second process (:func:`partner`, started here), which
        compiles the ray kernels and then every light loop (:func:`kernels.loop_table`: the
        loops are called through a table of entry points, so the kernels that call them
        compile without them) while this one compiles the shading kernels, its passes running
        no light loop (:func:`kernels.loops_elsewhere`). The two compile disjoint sets of
        kernels: this process first runs the scenes that cast no shadow ray
        (:data:`UNSHADOWED`: they compile nearly all of the shading kernels), and waits for
        the partner's ray kernels before the others (:data:`SHADOWED`, whose rays then load
        them from the cache). numba's cache files are per function and signature; both
        processes write them under :func:`explorer.shading.tiers.guard_cache`'s lock.
        RuntimeError when the partner fails (its cache files, and this one's, stay usable)."""
    tiers.guard_cache()  # a cache file numba cannot read is set aside and compiled anew
    if not partner:
        rays()
        return _passes(_meshes())
    helper = _start_partner()
    try:
        # (no light loop runs: the lobe rows they would fill are left as allocated, and the
        # colours' byte rounding meets NaN; nothing here uses the colours)
        with np.errstate(invalid="ignore"):
            kernels.loops_elsewhere(True)
            meshes = list(_meshes())
            passes = _passes(meshes, UNSHADOWED)
            said = helper.stdout.readline().strip()  # (the partner's ray kernels are cached)
            if said != "rays":
                raise RuntimeError(_partner_failed(helper, f"said {said!r}, not 'rays'"))
            passes += _passes(meshes, SHADOWED)
        helper.stdout.read()  # (what else it says, until it ends)
        if helper.wait() != 0:
            raise RuntimeError(_partner_failed(helper))
        return passes
    finally:
        kernels.loops_elsewhere(False)
        if helper.poll() is None:  # this process failed: the partner's work is not waited for
            helper.kill()
        helper.wait()
        helper.stdout.close()


def partner_command() -> list[str]:
    """The command line of the background compile's partner process (:func:`partner`)."""
    return [sys.executable, "-m", "explorer.shading.warm", "--partner"]


def _start_partner() -> subprocess.Popen:
    """Start :func:`partner`, compiling on the compiled tier; its standard output is a pipe to
    this process (it says ``rays`` once the ray kernels are cached), its standard error this
    process's (the log, for the background compile)."""
    env = dict(os.environ, **{tiers.ENV: "compiled"})
    return subprocess.Popen(
        partner_command(), stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, env=env, text=True
    )


def _partner_failed(helper: subprocess.Popen, why: str = "") -> str:
    status = helper.wait()
    return f"the partner compile ended with status {status}" + (f" ({why})" if why else "")


def partner() -> int:
    """The background compile's partner process (:func:`exercise` with ``partner``): the ray
    kernels (:func:`rays`), then ``rays`` on standard output, then every light loop of both
    precisions (:func:`kernels.loop_table`)."""
    tiers.guard_cache()
    rays()
    print("rays", flush=True)
    for dtype in (np.float32, np.float64):
        kernels.loop_table(dtype)
    return 0


def cores() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # not Linux
        return os.cpu_count() or 1


def load() -> None:
    """Load every kernel from numba's cache (compiling what it does not hold)."""
    exercise()


#: how much the background compile lowers its priority (``os.nice``; its partner inherits it).
#: Niceness only matters when the CPUs are contended, and there it sets the share: Linux weighs
#: a nice-0 process 1024 and a nice-10 one 110, so at 10 the compile got about a tenth of a core
#: beside each busy process (3 % of a CPU on a loaded machine: the 2-minute compile took most of
#: an hour), while the user waited on the slower numpy tier all that time. At 5 (weight 335) the
#: user's own busy process keeps three quarters of its core and the compile ends within a few
#: times its idle time; on an idle machine it changes nothing.
NICE = 5


def main(argv=None) -> int:
    """The background compile (see the module docstring). Exit status 0 unless it failed.
    ``--partner``: the partner process of a split compile (:func:`partner`)."""
    args = sys.argv[1:] if argv is None else argv
    if args == ["--partner"]:
        return partner()
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock (two compiles at once only cost time)
        fcntl = None
    if hasattr(os, "nice"):
        os.nice(NICE)  # the user's own work first (see NICE)
    try:
        lock = tiers.open_lock()  # held until the process ends
    except OSError as exc:  # counted, so that no more are started when it cannot be opened
        tiers.record_attempt()
        tiers.record_error(f"cannot open the lock {tiers.lock_path()}: {exc}")
        print(f"{time.strftime('%H:%M:%S')} cannot open the lock: {exc}", flush=True)
        return 1
    try:
        if fcntl is not None:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        print(f"{time.strftime('%H:%M:%S')} another compile holds the lock: nothing to do")
        return 0
    if tiers.marker_path().exists() and tiers.damage() is None:
        return 0
    print(f"{time.strftime('%H:%M:%S')} compiling the kernels (pid {os.getpid()})", flush=True)
    tiers.record_attempt()
    t = time.perf_counter()
    try:
        passes = exercise(partner=cores() >= 2)  # (two processes where there are two cores)
    except Exception as exc:  # noqa: BLE001 - written for the next process to tell the user
        traceback.print_exc(file=sys.stdout)
        tiers.record_error(f"{type(exc).__name__}: {exc}")
        return 1
    seconds = time.perf_counter() - t
    tiers.write_marker(seconds)
    print(f"{time.strftime('%H:%M:%S')} ready: {passes} passes in {seconds:.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
