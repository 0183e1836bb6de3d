"""Rays through the BVH against the brute force, in one run: shadow rays, scaling, the engine's
shadow update and the window's difference view.

    python benchmarks/bench_rays.py [--repeat N] [--section shadows scaling engine view numpy]
    python benchmarks/bench_rays.py --isa both --section shadows scaling   # AVX2 beside native

Sections (all by default):

- ``shadows``: the engine's shadow rays on the 100,578-vertex teapot (tessellation 56, 200,256
  triangles) toward a point light, from the vertices with N·L > -margin (the ones the engine
  casts from; the others face away and need no ray): rays per second through the BVH as the
  engine casts them (:func:`explorer.geometry.bvh.any_hit` on the light's rays, once a call,
  every thread: the boxes refitted around the triangles that can block this light, then the
  rays), the refit alone (repeated:
  its data stays in the caches; the line below the table gives its share of a cast), the rays
  alone through the refitted boxes, the same rays through the full tree (``refit=False``), the
  brute force (:func:`explorer.geometry.rays.any_hit`, every triangle, every thread) on a
  random sample of the same rays (its cost per ray does not depend on the count), and, when
  the package is installed, embreex's occlusion query on the same rays (float32, one call: its
  answers count back faces as occluders, so they differ; how many is printed), with its CPU
  time per ray beside the BVH cast's (on a loaded machine the fair comparison).
- ``scaling``: the same on tori from 1,024 to 1,048,576 triangles (a point light near the
  ring's plane, so the far side is shadowed), with the BVH's build time.
- ``engine``: a float32 :class:`explorer.Shader` on the 100k-vertex teapot with two point
  lights that cast shadows: the first colours (BVH build and both lights' rays), then one
  update after a light moves (that light's rays again), next to the same update without
  shadows.
- ``view``: the window's difference view of its default teapot (tessellation 24, 18,530
  vertices) at the window's default size (1100x720): one comparison as the window's worker
  makes it (:func:`explorer.app.difference.run_job` on kept off-screen windows: per-pixel
  reference, two off-screen renders, difference, heat map), and its steps (pixel rays through
  the BVH, the reference's colours, the two renders, the comparison). Run with ``PYTHONPATH``
  on an older checkout, it times what that checkout has (a step it lacks is left out).
- ``numpy``: the numpy tier's rays (:mod:`explorer.geometry.bvh_numpy`, what casts until the
  compiled kernels serve): its tree build per triangle and its shadow rays per ray on the 100k
  teapot, the numpy tier's shading per vertex-light (the three in vertex-lights are what
  :func:`explorer.shading.tiers.ray_work` counts: ``BUILD_WORK``, ``RAY_WORK``), and the peak
  memory of a cast (tracemalloc: nearest hits) through soups of crossing triangles, where
  every ray enters every leaf, next to the bound
  :func:`~explorer.geometry.bvh_numpy.pair_bound` states.
Every figure is wall-clock: median and best of ``--repeat`` runs after a warm-up; the machine
and its load average are printed with the tables. Compare rows of one run. One line gives the
BVH cast's CPU time per ray instead (every thread's, over ``--repeat`` casts): on a VM whose
other jobs hold a core, it says what two idle cores would do.

``--isa native|avx2|both`` (``--alternate N``, ``--cache-dir``) runs the sections in child
processes compiled for the host's ISA, for AVX2 or for both, and ends with the rays' figures side
by side (``benchmarks/isa.py``; Embree picks its own code path at run time, so its figures in
the avx2 child are its native ones: the yardstick on this machine).
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import platform
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import isa  # benchmarks/isa.py
import numpy as np
from common import cpu_name, load_average, timed

from explorer.core.scene import load_scene
from explorer.geometry.meshes import get_mesh

SECTIONS = ("shadows", "scaling", "engine", "view", "numpy")
#: the brute force's sample is sized to about this many ray-triangle tests
BRUTE_TESTS = 3e8
#: a small mesh's rays are repeated up to this many, so that a cast is not all overhead
MIN_RAYS = 65536
LIGHT = (2.0, 3.0, 1.5)


def machine() -> str:
    import numba

    try:
        from explorer.geometry.bvh import workers

        threads = f"ray threads {workers()}"
    except ImportError:  # a checkout before the BVH
        threads = f"numba threads {numba.get_num_threads()}"
    embree = "embreex " + _version("embreex") if _has("embreex") else "embreex not installed"
    return (
        f"{cpu_name()}; {os.cpu_count()} cores, {threads}; Python {platform.python_version()}, "
        f"numpy {np.__version__}, numba {numba.__version__}; {embree}; {isa.isa_line()}; "
        f"load average {load_average():.2f}"
    )


def _has(name: str) -> bool:
    return importlib.util.find_spec(name) is not None


def _version(name: str) -> str:
    from importlib.metadata import version

    return version(name)


def shadow_rays(mesh, light_position):
    """The engine's shadow rays of a point light: frame positions, directions, distances, and
    the frame triangles (m, 3, 3)."""
    from explorer.core import tolerances as tol
    from explorer.core.lights import PointLight
    from explorer.geometry.frame import frame_of

    light = PointLight(position=light_position)
    centre, scale = frame_of(mesh.positions)
    Q = (mesh.positions - centre) / scale
    lit = np.einsum("ij,ij->i", light.toward(mesh.positions), mesh.normals)
    keep = lit > -tol.SHADOW_NDL_MARGIN
    D, tmax = light.shadow_ray(Q[keep], centre, scale)
    return np.ascontiguousarray(Q[keep]), D, tmax, Q[mesh.faces]


def measure_rays(mesh, repeat: int, light=LIGHT, embree: bool = True,
                 min_rays: int = MIN_RAYS) -> dict:  # fmt: skip
    """Rays per second of the BVH, the brute force and embreex on the mesh's shadow rays (cast
    repeatedly up to ``min_rays`` when fewer: one refit for all of them)."""
    from explorer.geometry import bvh as B
    from explorer.geometry.rays import any_hit as brute

    O, D, tmax, tri = shadow_rays(mesh, light)
    B.build_bvh(tri[:64])  # load the compiled builder before timing it
    distinct = len(O)
    if len(O) < min_rays:
        reps = -(-min_rays // len(O))
        O, D, tmax = (np.ascontiguousarray(np.concatenate([a] * reps)) for a in (O, D, tmax))
    t = time.perf_counter()
    tree = B.build_bvh(tri)
    build = time.perf_counter() - t
    med, best = timed(lambda: B.any_hit(tree, O, D, tmax), repeat)
    cpu = time.process_time()  # every thread's
    for _ in range(repeat):
        hit = B.any_hit(tree, O, D, tmax)
    cpu = (time.process_time() - cpu) / repeat
    row = {"triangles": len(tri), "rays": distinct, "cast": len(O), "build_s": build,
           "bvh": len(O) / med, "bvh_best": len(O) / best, "cpu_ns": cpu / len(O) * 1e9,
           "shadowed": float(hit.mean())}  # fmt: skip
    if hasattr(B, "toward_light"):  # the refit for one light, then the rays alone
        fmed, _ = timed(lambda: B.toward_light(tree, O, D, tmax), repeat)
        light_tree = B.toward_light(tree, O, D, tmax)
        cmed, _ = timed(lambda: B.any_hit(light_tree, O, D, tmax, refit=False), repeat)
        full, _ = timed(lambda: B.any_hit(tree, O, D, tmax, refit=False), repeat)
        same = np.array_equal(B.any_hit(tree, O, D, tmax, refit=False), hit)
        row.update(refit_ms=fmed * 1e3, alone=len(O) / cmed, full=len(O) / full, same_full=same)
    k = int(np.clip(BRUTE_TESTS / len(tri), 50, len(O)))
    pick = np.random.default_rng(0).choice(len(O), k, replace=False)
    bmed, bbest = timed(lambda: brute(O[pick], D[pick], tmax[pick], tri), max(1, repeat // 3))
    row["same"] = bool(np.array_equal(brute(O[pick], D[pick], tmax[pick], tri), hit[pick]))
    row.update(brute=k / bmed, brute_rays=k)
    if embree and _has("embreex"):
        row.update(embree_rays(O, D, tmax, tri, hit, repeat))
    return row


def record_rays(mesh: str, r: dict) -> None:
    """Keep the rays' figures of :func:`measure_rays` for ``--isa``'s side-by-side table."""
    names = {
        "bvh": "BVH as the engine casts (refit + rays)",
        "alone": "BVH, rays alone",
        "full": "BVH, full tree",
        "brute": "brute force",
        "embree": "embreex occlusion",
    }
    for key, what in names.items():
        if key in r:
            isa.record(f"{mesh}: {what}", r[key] / 1e6, "M rays/s")
    isa.record(f"{mesh}: BVH CPU per ray", r["cpu_ns"], "ns")
    if "embree_cpu_ns" in r:
        isa.record(f"{mesh}: embreex occlusion CPU per ray", r["embree_cpu_ns"], "ns")
    isa.record(f"{mesh}: BVH build", r["build_s"], "s")


def embree_rays(O, D, tmax, tri, hit, repeat: int) -> dict:
    """embreex's occlusion query on the same rays (both sides occlude; float32; origins moved
    1e-5 along the ray, off the triangles around the vertex)."""
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh

    t = time.perf_counter()
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene=scene, vertices=tri.astype(np.float32))
    build = time.perf_counter() - t
    O32 = (O + 1e-5 * D).astype(np.float32)
    D32 = D.astype(np.float32)
    far = np.minimum(tmax - 2e-5, 1e30).astype(np.float32)

    def run():
        return np.asarray(scene.run(O32, D32, query="OCCLUDED", dists=far))

    med, _ = timed(run, repeat)
    cpu = time.process_time()  # (one thread: what a ray costs, whatever else runs)
    for _ in range(repeat):
        run()
    cpu = (time.process_time() - cpu) / repeat
    occluded = run() != -1  # the index of a hit geometry, -1 for none
    half = len(O) // 2
    with ThreadPoolExecutor(2) as pool:  # does a call let the other thread run?

        def both():
            parts = [(0, half), (half, len(O))]
            return list(pool.map(lambda p: scene.run(O32[p[0] : p[1]], D32[p[0] : p[1]],
                                                     query="OCCLUDED", dists=far[p[0] : p[1]]),
                                 parts))  # fmt: skip

        med2, _ = timed(both, repeat)
    front = _front_normals(tri)

    def by_the_rule():
        """Nearest hits, passing through back faces (re-cast from just beyond them) until a
        front face (shadowed) or nothing (lit): the engine's rule with Embree's queries."""
        out = np.zeros(len(O), bool)
        todo = np.arange(len(O))
        o, left = O32.copy(), far.copy()
        while len(todo):
            r = scene.run(o[todo], D32[todo], query="INTERSECT", dists=left[todo], output=1)
            prim, t = r["primID"], r["tfar"]
            got = prim >= 0
            is_front = np.zeros(len(todo), bool)
            is_front[got] = np.einsum("ij,ij->i", front[prim[got]], D32[todo[got]]) < 0
            out[todo[is_front]] = True
            back = got & ~is_front
            step = t[back] + 1e-5
            o[todo[back]] += step[:, None] * D32[todo[back]]
            left[todo[back]] -= step
            todo = todo[back]
        return out

    rmed, _ = timed(by_the_rule, repeat)
    ruled = by_the_rule()
    return {
        "embree": len(O) / med,
        "embree_cpu_ns": cpu / len(O) * 1e9,
        "embree_two_threads": len(O) / med2,
        "embree_build_s": build,
        "embree_differs": float(np.mean(occluded != hit)),
        "embree_rule": len(O) / rmed,
        "embree_rule_differs": float(np.mean(ruled != hit)),
    }


def _front_normals(tri) -> np.ndarray:
    """(m, 3) float32 e1 × e2 of each triangle: a ray with D·n < 0 meets its front side."""
    return np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]).astype(np.float32)


def section_shadows(repeat: int) -> None:
    mesh = get_mesh("teapot", 56)
    r = measure_rays(mesh, repeat, min_rays=0)  # the light's rays once, as the engine casts
    print(f"\n## Shadow rays, 100k-vertex teapot ({mesh.n_vertices:,} vertices, "
          f"{r['triangles']:,} triangles), point light at {list(LIGHT)}\n")  # fmt: skip
    print(f"{r['rays']:,} rays cast (the vertices with N·L > -margin; the other "
          f"{mesh.n_vertices - r['rays']:,} face away and need none), {r['shadowed']:.1%} "
          f"shadowed; per vertex of the mesh that is {mesh.n_vertices / r['rays']:.2f}x the "
          "rays per second below")  # fmt: skip
    print("\n| ray engine | M rays/s (median) | best | vs brute force | build s |")
    print("|---|---:|---:|---:|---:|")
    x = r["brute"]
    refit = f" (of which the refit {r['refit_ms']:.1f} ms)" if "refit_ms" in r else ""
    print(f"| BVH (numba), as the engine casts: refit for the light + rays{refit} | "
          f"{r['bvh'] / 1e6:.2f} | {r['bvh_best'] / 1e6:.2f} | {r['bvh'] / x:,.0f}x | "
          f"{r['build_s']:.2f} |")  # fmt: skip
    if "alone" in r:
        print(f"| BVH, the rays alone through the refitted boxes | {r['alone'] / 1e6:.2f} | | "
              f"{r['alone'] / x:,.0f}x | |")  # fmt: skip
        print(f"| BVH, the rays through the full tree (refit=False) | {r['full'] / 1e6:.2f} | | "
              f"{r['full'] / x:,.0f}x | |")  # fmt: skip
    print(f"| brute force (every triangle; {r['brute_rays']:,} of the rays) | "
          f"{x / 1e6:.4f} | | 1x | 0 |")  # fmt: skip
    if "embree" in r:
        print(f"| embreex occlusion (float32, one thread, back faces occlude: answers differ on "
              f"{r['embree_differs']:.1%} of the rays) | {r['embree'] / 1e6:.2f} | | "
              f"{r['embree'] / x:,.0f}x | {r['embree_build_s']:.2f} |")  # fmt: skip
        print(f"| embreex occlusion, the rays in two halves on two threads | "
              f"{r['embree_two_threads'] / 1e6:.2f} | | "
              f"{r['embree_two_threads'] / x:,.0f}x | |")  # fmt: skip
        rule = r["embree_rule"]
        print(f"| embreex nearest hits through back faces (the engine's rule; float32, one "
              f"thread: answers differ on {r['embree_rule_differs']:.2%}) | "
              f"{rule / 1e6:.2f} | | {rule / x:,.0f}x | |")  # fmt: skip
    if "alone" in r:
        within = (r["cast"] / r["bvh"] - r["cast"] / r["alone"]) * 1e3
        print(f"\nThe refit within a cast (the cast's median less the rays alone: the tree's data "
              f"as a cast finds it in the caches) {within:.1f} ms")  # fmt: skip
    print(
        f"\nCPU time of one BVH cast (every thread, refit included): {r['cpu_ns']:.0f} ns per "
        f"ray, i.e. {2e3 / r['cpu_ns']:.1f} M rays/s if two idle cores shared it evenly"
    )
    if "embree_cpu_ns" in r:
        print(
            f"CPU time of embreex's occlusion query (one thread): {r['embree_cpu_ns']:.0f} ns "
            f"per ray; the BVH cast takes {r['cpu_ns'] / r['embree_cpu_ns']:.2f}x that"
        )
    same_full = f"; with the full tree: {r['same_full']}" if "same_full" in r else ""
    print(f"\nBVH answers equal the brute force's on its sample: {r['same']}{same_full}")
    record_rays("teapot", r)


def section_scaling(repeat: int) -> None:
    print("\n## Scaling: tori, point light near the ring's plane\n")
    print(f"(a mesh with fewer than {MIN_RAYS:,} rays casts them repeatedly up to that many; "
          "BVH = as the engine casts, refit included; full tree = refit=False)\n")  # fmt: skip
    print("| triangles | rays | build s | BVH M rays/s | full tree M rays/s | brute force M rays/s "
          "| BVH / brute | shadowed | equal |")  # fmt: skip
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    for res in (32, 100, 316, 1000):
        r = measure_rays(get_mesh("torus", res), repeat, light=(2.5, 0.6, 0.5), embree=False)
        full = f"{r['full'] / 1e6:.2f}" if "full" in r else "-"
        record_rays(f"torus {r['triangles']:,} triangles", r)
        print(f"| {r['triangles']:,} | {r['rays']:,} | {r['build_s']:.3f} | {r['bvh'] / 1e6:.2f} | "
              f"{full} | {r['brute'] / 1e6:.4f} | {r['bvh'] / r['brute']:,.0f}x | "
              f"{r['shadowed']:.1%} | {r['same'] and r.get('same_full', True)} |")  # fmt: skip
        sys.stdout.flush()


def section_engine(repeat: int) -> None:
    import explorer

    mesh = get_mesh("teapot", 56)

    def lights(shadows: bool, step: int):
        a = 0.4 * step
        moved = [2.5 * np.cos(a), 2.5, 2.5 * np.sin(a)]
        return [{"type": "point", "position": moved, "shadows": shadows},
                {"type": "point", "position": [-2.5, 1.0, 1.5], "shadows": shadows}]  # fmt: skip

    print(f"\n## Engine: float32 Shader, {mesh.n_vertices:,}-vertex teapot, two point lights\n")
    print("| case | median ms | best ms |")
    print("|---|---:|---:|")
    for shadows in (True, False):
        scene = load_scene({"material": "gold", "lights": lights(shadows, 0)})
        t = time.perf_counter()
        sh = explorer.Shader(scene, mesh.positions, mesh.normals, faces=mesh.faces,
                             precision="float32")  # fmt: skip
        _ = sh.colors
        first = time.perf_counter() - t
        step = [0]

        def move(sh=sh, shadows=shadows, step=step):
            step[0] += 1  # a new place every time: no cached rays
            sh.set_lights(lights(shadows, step[0]))
            return sh.colors

        med, best = timed(move, repeat)
        what = "shadows: true" if shadows else "no shadows"
        work = " (BVH build, every light's rays)" if shadows else ""
        print(f"| first colours, {what}{work} | {first * 1e3:.1f} | |")
        print(f"| one light moved, {what} | {med * 1e3:.1f} | {best * 1e3:.1f} |")
        isa.record(f"engine, teapot: one light moved, {what}", med * 1e3)
        if shadows:
            before = sh.stats["shadow_rays"]
            move()
            rays = sh.stats["shadow_rays"] - before
            print(f"| (shadow rays cast per move: {rays:,}) | | |")


def section_view(repeat: int) -> None:
    from explorer.analysis import comparison as C
    from explorer.render import perpixel as PP
    from explorer.render.camera import camera_for
    from explorer.shading.display import vertex_colors

    mesh = get_mesh("teapot", 24)
    size = (1100, 720)
    scene = load_scene({"material": "gold", "lights": [{"type": "point", "position": [2, 3, 2]}]})
    cam = camera_for(scene, mesh, size[0] / size[1])
    colors = vertex_colors(scene, mesh)
    print(f"\n## Difference view: {mesh.n_vertices:,}-vertex teapot at {size[0]}x{size[1]}\n")
    print("| step | median ms | best ms |")
    print("|---|---:|---:|")

    def row(what, f):
        med, best = timed(f, repeat)
        print(f"| {what} | {med * 1e3:.0f} | {best * 1e3:.0f} |")
        isa.record(f"difference view: {what}", med * 1e3)
        sys.stdout.flush()

    with C.ViewComparer(size) as v:
        try:
            from explorer.app.difference import Job, run_job
        except ImportError:  # a checkout without the window
            run_job = None
        if run_job is not None:
            job = Job(0, scene, mesh, colors, cam, size, (0.1, 0.1, 0.1))
            try:
                run_job(job, comparer=v)
                row("one comparison as the window's worker makes it (windows kept)",
                    lambda: run_job(job, comparer=v))  # fmt: skip
            except TypeError:  # a worker that makes new windows for every comparison
                row("one comparison as the window's worker makes it (new windows)",
                    lambda: run_job(job))  # fmt: skip
        row("comparison (reference + 2 off-screen renders + difference), windows kept",
            lambda: v.compare(scene, mesh, camera=cam, colors=colors))  # fmt: skip
        h = PP.mesh_hits(cam, size, mesh)
        row(f"step: pixel rays through the BVH, hit points and normals ({len(h.positions):,} "
            "hits)", lambda: PP.mesh_hits(cam, size, mesh))  # fmt: skip
        row("step: the reference's colours",
            lambda: PP.point_colors(scene, h.positions, h.normals, mesh=mesh))  # fmt: skip
        row("step: the specular sums (the highlight peak; the window does not show it)",
            lambda: PP.specular_sums(scene, h.positions, h.normals))  # fmt: skip
        row("step: the two off-screen renders (picture and coverage)",
            lambda: (v._picture.render(C._opaque(scene), mesh, colors, camera=cam),
                     C.coverage(v._cover, scene, mesh, cam)))  # fmt: skip
        img = v._picture.render(C._opaque(scene), mesh, colors, camera=cam)
        cov = C.coverage(v._cover, scene, mesh, cam)
        ref = PP.reference(scene, mesh, size, camera=cam)
        _ = ref.specular
        row("step: the difference of the pictures", lambda: C.compare(img, ref, cov))


def _crossing_soup(m: int, seed: int = 0):
    """``m`` large triangles with their corners on the unit sphere: every box of a tree over them
    holds the centre, so a ray through it enters every leaf."""
    c = np.random.default_rng(seed).normal(size=(m, 3, 3))
    return c / np.linalg.norm(c, axis=2, keepdims=True)


def section_numpy(repeat: int) -> None:
    import tracemalloc

    import explorer
    from explorer.geometry import bvh_numpy as NB
    from explorer.shading import tiers

    mesh = get_mesh("teapot", 56)
    O, D, tmax, tri = shadow_rays(mesh, LIGHT)
    print(f"\n## The numpy tier's rays, {mesh.n_vertices:,}-vertex teapot, point light at "
          f"{list(LIGHT)}\n")  # fmt: skip
    bmed, _ = timed(lambda: NB.build_bvh(tri), max(1, repeat // 3))
    tree = NB.build_bvh(tri)
    cmed, _ = timed(lambda: NB.any_hit(tree, O, D, tmax), max(1, repeat // 3))
    scene = load_scene({"lights": [{"type": "point", "position": list(LIGHT)}]})
    smed, _ = timed(lambda: explorer.shade(scene, mesh.positions, mesh.normals, tier="numpy"),
                    repeat)  # fmt: skip
    vl = smed / mesh.n_vertices  # one light
    build, ray = bmed / len(tri), cmed / len(O)
    print("| numpy tier | median | in vertex-lights of its shading | tiers counts |")
    print("|---|---:|---:|---:|")
    print(f"| shading, per vertex-light | {vl * 1e9:.0f} ns | 1 | 1 |")
    counts = (getattr(tiers, "BUILD_WORK", "-"), getattr(tiers, "RAY_WORK", "-"))
    print(f"| tree build, per triangle ({len(tri):,}) | {build * 1e6:.2f} µs | "
          f"{build / vl:.0f} | {counts[0]} |")  # fmt: skip
    print(f"| shadow ray, per ray ({len(O):,}) | {ray * 1e6:.2f} µs | {ray / vl:.0f} | "
          f"{counts[1]} |")  # fmt: skip
    print(
        "\nPeak memory of a numpy cast through crossing triangles (every ray enters every "
        "leaf: nearest hits, no early end), 500 rays through the centre, tracemalloc:\n"
    )
    print("| triangles | (ray, triangle) pairs | nearest_hits s | peak MiB | stated bound MiB |")
    print("|---:|---:|---:|---:|---:|")
    rng = np.random.default_rng(1)
    k = 500
    O = rng.normal(size=(k, 3)) * 3.0
    D = -O + rng.normal(scale=0.05, size=(k, 3))
    for m in (2000, 8000, 32000):
        tree = NB.build_bvh(_crossing_soup(m))
        tracemalloc.start()
        t = time.perf_counter()
        NB.nearest_hits(tree, O, D, 1e-9)
        seconds = time.perf_counter() - t
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        bound = NB.pair_bound(tree) / 2**20 if hasattr(NB, "pair_bound") else float("nan")
        print(f"| {m:,} | {k * m:,} | {seconds:.2f} | {peak / 2**20:.1f} | {bound:.1f} |")
        sys.stdout.flush()


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=7, help="timed runs per figure (default 7)")
    p.add_argument("--section", nargs="+", choices=SECTIONS, default=list(SECTIONS))
    isa.add_arguments(p)
    args = p.parse_args(argv)
    if args.isa and not isa.in_child():
        return isa.run(__file__, sys.argv[1:] if argv is None else list(argv), args)
    print("machine:", machine())
    for name in args.section:
        globals()[f"section_{name}"](args.repeat)
        sys.stdout.flush()
    print("\nload average after:", f"{load_average():.2f}")
    isa.record("load average at the end", load_average(), "")
    isa.write_results()
    return 0


if __name__ == "__main__":
    sys.exit(main())
