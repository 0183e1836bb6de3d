"""Cold compile seconds of the engine's kernels, per entry point and precision.

    python benchmarks/bench_compile.py                  # this tree
    python benchmarks/bench_compile.py --rev cb71986    # another revision (git archive), too
    python benchmarks/bench_compile.py --warm           # the background compile, by function
    python benchmarks/bench_compile.py --warm --split   # ... in its two processes, as it runs

Each case runs in a child process with an empty ``NUMBA_CACHE_DIR`` (nothing loaded from disk),
which drives a small :class:`explorer.Shader` through what a session does (geometry, a full
pass, a material change, two shininess changes) and times the first call of each compiled entry
point on the way: ``extent``, ``prepare``, ``bounds``, ``shade``, ``fixup`` (float32:
ambiguous lanes redone in float64), ``compose``, ``lobe``, then ``display._round_bytes``. A
routine shared by two entry points is compiled by the first that calls it (``fixup`` reuses much
of ``shade``), so the column sums to the session's total, and each figure is what that call adds.

The row "shade, one light variant" compiles the same session with the light loop's variants cut
down to the one the scene uses (the kernels' :data:`explorer.shading.codegen.LIGHT_LOOPS` set to
it in the child, or the old dispatch tables replaced at revisions that had them): its
difference from "shade" is what the literal-dispatched variants cost to compile.

Wall-clock seconds on a shared machine: the load average is printed with the table.

``--split`` runs ``--warm``'s exercise as the background compile does on two cores (with its
partner process, :func:`explorer.shading.warm.exercise`): each process's CPU seconds, the
wall clock, and the kernels both compiled (none should be: numba's internal functions, which
are not cached, aside).

``--warm`` measures the whole background compile instead (``python -m explorer.shading.warm``'s
:func:`~explorer.shading.warm.exercise`, every kernel signature the product calls, in a child
with an empty ``NUMBA_CACHE_DIR``) in CPU seconds (user + system: the compile is
single-threaded, so its CPU time is what it takes on an idle core whatever the load), and each
specialisation's own share: numba's ``numba:compile`` events, a function's time less that of
the functions it compiles on the way (each kernel x signature; the light loop's variants, the
compose variants...), summed by function with the count of signatures; and LLVM's share of the
whole (its function and module passes and its machine code, numba's libraries timed; the rest
is numba's own typing and lowering, in Python).

Last results (AMD EPYC, 2 cores, AVX-512, numba 0.68.1; two runs, each child compiling alone
but beside other engineers' jobs: load average 3.4 to 8.0 during the 7552fa3 run, 1.2 to 1.6
during the other, so the comparison is rough):

| entry point | 7552fa3 float32 s | 7552fa3 float64 s | light loops float32 s | float64 s |
|---|---:|---:|---:|---:|
| prepare | 2.2 | 9.5 | 8.4 | 2.1 |
| bounds | 1.3 | 6.0 | 3.6 | 0.9 |
| shade | 176.0 | 186.5 | 105.8 | 56.1 |
| fixup | 125.0 | 0.0 | 51.9 | 0.0 |
| compose | 27.8 | 25.6 | 10.2 | 8.5 |
| lobe | 6.5 | 6.4 | 2.2 | 2.2 |
| _round_bytes | 0.4 | 0.4 | 0.1 | 0.1 |
| session total | 339.1 | 234.4 | 182.2 | 69.8 |
| shade, one light variant | 99.0 | 96.2 | 22.1 | 22.1 |
| shade: what the other variants add | 77.0 | 90.2 | 83.7 | 33.9 |

``--rev 6fec099 --precision float64`` after the float64 lobe moved into a loop of its own (load
1.3 to 2.4, beside other jobs: rough): session total 109.0 s at 6fec099, 68.0 s after; shade
88.0 / 53.2 s; the float32 loops are unchanged.

``--rev 952533b --precision float64`` after the float64 lobe packs its lanes (k11, load 1.0-1.1):
session total 70.2 s at 952533b, 71.9 s after; shade 54.8 / 56.7 s.

7552fa3 had 34 hand-listed variants (16 inline ones in float32 only); the light loops are the
18 of ``LIGHT_LOOPS`` in both precisions.

``--warm`` before and after issue 38 (one ``kernels.Source`` per precision, ``fixup`` through the
float64 pass's code; CPU seconds, each run beside other jobs, load 10-15 on the 2 cores, so a
figure moves by 10% or so; ``None.impl`` is the light loop's dispatch, ``_light_loop``):

| function | baf99d4 signatures | CPU s | after: signatures | CPU s |
|---|---:|---:|---:|---:|
| shading.kernels.shade | 6 | 56.4 | 2 | 20.6 |
| shading.kernels._light_overload.impl | 36 | 43.9 | 36 | 53.9 |
| shading.kernels._block | 3 | 25.1 | 2 | 19.7 |
| shading.kernels._task | 7 | 18.1 | 2 | 5.5 |
| shading.kernels._compose_block_overload.impl | 36 | 8.1 | 36 | 8.3 |
| shading.kernels.fixup | 2 | 6.7 | 1 | 4.4 |
| shading.kernels._split_lobe | 2 | 4.7 | 2 | 4.4 |
| shading.kernels.bounds | 6 | 4.6 | 2 | 2.7 |
| shading.kernels.compose | 2 | 4.3 | 2 | 5.0 |
| shading.kernels._reach | 3 | 3.5 | 2 | 2.7 |
| shading.kernels.prepare | 4 | 2.9 | 4 | 3.4 |
| None.impl | 2 | 2.6 | 2 | 2.9 |
| (the 101 others) | 298 | 45.4 | 286 | 57.2 |
| **the whole compile** (``/usr/bin/time``, user + system) | 407 | 238.7 | 379 | 204.5 |

The light loops' float64 variants cost more after: they are compiled with 512-bit vectors
whatever compiles them first (``fixup`` used to, with LLVM's 256-bit choice). What is left is
spread thin: 36 light loops of 1-2 s each, two ``_block`` of 10 s, and some 300 small
functions of a fraction of a second each (numba's typing and lowering, LLVM, a cache file).

Issue 38's second part (scratch rows through intrinsics instead of numba's inliner, one
``_light_run`` site in ``_block``, the compose variants through one generated dispatch; see
docs/speed.md), ``--warm``'s child with LLVM's share, 11dae47 and the change each on an empty
cache, the two runs within minutes of each other on the same 2-core VM (load 12-18 for 11dae47,
10-13 for the change: both inflated, 11dae47 by some 8 % more, by the functions neither run
changed: the BVH's, ``extent``, ``bounds``):

| function | signatures | 11dae47 CPU s | after CPU s |
|---|---:|---:|---:|
| shading.kernels._light_overload.impl (the light loops) | 36 | 57.7 | 33.3 |
| shading.kernels.shade | 2 | 22.9 | 19.8 |
| shading.kernels._block | 2 | 22.2 | 11.8 |
| the compose loops and the level that called them (``_compose_a``) | 54 / 36 | 11.4 | 11.1 |
| shading.kernels._task | 2 | 6.5 | 5.0 |
| LLVM: function passes, module passes, machine code | | 10.7, 33.0, 26.9 | 9.8, 27.0, 22.3 |
| **the whole compile** (``/usr/bin/time``, user + system) | | 213.2 | 164.8 |

(the light loops' own LLVM time, summed: 3.9 s at 11dae47 on a quieter run: their cost was
numba's typing and lowering, grown by its inliner copying ``_row``'s IR twenty times a loop).
Side by side instead (both children at once, one core each, load 3-6; the VM an Intel Xeon with
AVX-512 then): the whole compile 203.0 -> 173.6 s (0.86x), the light loops 60.1 -> 36.6 s,
``_block`` 20.2 -> 13.0 s, LLVM 62.5 -> 62.8 s (unchanged: all of the gain is numba's Python).

The light loops out of the linked chain (each ``_light_<code>`` compiled once per precision by
``kernels.loop_table`` and called through its table of entry points), 750ec5e and the change,
``--warm`` under ``/usr/bin/time -v``, each tree checked out apart, one run after the other at
load 15-20 (both inflated alike; see docs/speed.md):

| function | signatures | 750ec5e CPU s | after: signatures | CPU s |
|---|---:|---:|---:|---:|
| shading.kernels._light_overload.impl (the light loops) | 36 | 37.8 | 36 | 32.9 |
| shading.kernels.shade | 2 | 23.3 | 2 | 12.2 |
| shading.kernels._block | 2 | 13.3 | 2 | 10.7 |
| shading.kernels._compose_block_overload.impl | 36 | 12.7 | 36 | 9.7 |
| shading.kernels._task | 2 | 6.6 | 2 | 3.7 |
| None.impl (the dispatches: light loops, compose) | 4 | 4.9 | 2 | 1.5 |
| shading.kernels.fixup | 1 | 4.0 | 1 | 3.1 |
| LLVM: function passes, module passes, machine code | | 11.4, 32.1, 26.3 | | 10.9, 21.4, 19.5 |
| **the whole compile** (child CPU s; command user + sys) | | 186.4 (191.6) | | 158.7 (164.0) |

The background compile in two processes (issue 38 item 5, third step: the partner compiles the
ray kernels and the 36 light loops, the main process the shading kernels with the loops left to
it, ``explorer.shading.warm.exercise``), ``--warm`` against ``--warm --split`` on the same
2-core VM (Intel Xeon, AVX-512), CPU s of each compiling process, each run beside seven other
sessions (load 4-9 for af2b7bd, 12-19 for the split: its CPU seconds are the more inflated):

| function | af2b7bd signatures | CPU s | split: signatures | CPU s |
|---|---:|---:|---:|---:|
| shading.kernels._light_overload.impl (the light loops, the partner) | 36 | 33.3 | 36 | 41.3 |
| shading.kernels.shade | 2 | 13.1 | 2 | 14.8 |
| shading.kernels._compose_block_overload.impl | 36 | 10.7 | 36 | 12.0 |
| shading.kernels._block | 2 | 12.8 | 2 | 9.0 |
| LLVM: function passes, module passes, machine code | | 11.8, 23.4, 21.0 | | 13.5, 27.1, 24.0 |
| **the whole compile**, CPU s per process | | 166.0 | | 100.3 + 85.3 |
| wall (at that load: the others' share of the cores) | | 9:27 | | 18:53 |
| kernels compiled by both processes | | | | 0 |

The main process holds 54 % of the split's CPU: on 2 idle cores, where the one process took
134.6 s, the split should take some 75-80 s of wall clock (not measured idle here). Side by
side at load 3-5 (``python -m explorer.shading.warm`` under ``/usr/bin/time``, one process
against the split) the split lost, 169.9 s wall and 136.1 CPU s against 120.8 s and 108.8: the
other sessions held the second core (docs/engine.md, *Ready at once*).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

#: run in a child process (cwd and PYTHONPATH: the tree measured); prints one JSON object
CHILD = r"""
import json, sys, time
import numpy as np
cut = {cut!r}
dtype = {dtype!r}
t0 = time.perf_counter()
import explorer
from explorer.shading import display, kernels as K
assert explorer.__file__.startswith({root!r}), explorer.__file__
import_s = time.perf_counter() - t0
if cut:
    if hasattr(K, "LIGHT_LOOPS"):  # (the table's module: codegen, or kernels at older revisions)
        G = K if hasattr(K, "Loop") else __import__("explorer.shading.codegen", fromlist=["G"])
        K.LIGHT_LOOPS = (G.loop_code(G.Loop(G.SRC_INLINE, G.LOBE_BLINN, True)),)
    else:  # the hand-written tables of older revisions: one branch each
        import numba as nb
        from explorer.core.lightrow import POSITIONAL
        def light_any(scr, m, q, y, k, positional, mode, l_dif, l_spec):
            K._light(scr, m, K.R_DX, K.R_GD, q, y, k, 29)
        def light_inline(scr, m, dx, gd, q, y, k, atten, mode, l_spec, grey):
            K._light(scr, m, dx, gd, q, y, k, 1 | 8 | 32 | 64 | 16 | 4)
        K._light_any = nb.njit(**dict(K._LEAF, cache=False))(light_any)
        K._light_inline = nb.njit(**dict(K._LEAF, cache=False))(light_inline)
times = {{}}
def timing(name, fn):
    def call(*a, **kw):
        if name in times:
            return fn(*a, **kw)
        t = time.perf_counter()
        try:
            return fn(*a, **kw)
        finally:
            times[name] = time.perf_counter() - t
    return call
for name in ("extent", "prepare", "bounds", "shade", "fixup", "compose", "lobe"):
    if hasattr(K, name):  # (older revisions found the frame in numpy)
        setattr(K, name, timing(name, getattr(K, name)))
display._round_bytes = timing("_round_bytes", display._round_bytes)
rng = np.random.default_rng(0)
n = 3 * K.BLOCK + 5
P = rng.normal(size=(n, 3))
scene = {{
    "material": {{"diffuse": [0.6, 0.5, 0.4], "specular": [0.5, 0.5, 0.5], "shininess": 20}},
    "viewer": {{"eye": [0, 0, 6]}},
    "lights": [{{"type": "point", "position": [2, 3, 1], "attenuation": [1, 0.1, 0.01]}}],
}}
sh = explorer.Shader(scene, P, P, precision=dtype)
_ = sh.colors
sh.set_material(sh.scene.material.replace(diffuse=(0.3, 0.6, 0.2)))
_ = sh.colors
for s in (30.0, 40.0):
    sh.set_material(sh.scene.material.replace(shininess=s))
    _ = sh.colors
display.to_bytes(np.asarray(sh.colors, np.float64))
print(json.dumps({{"import": import_s, **times}}))
"""

#: the background compile's processes, timed by specialisation: a ``sitecustomize`` module put
#: first on the children's path (the exercise's process and, split, its partner), which writes
#: each process's compile events, CPU seconds and LLVM's share to OUT/<pid>.json at its exit
SITE = r"""
import atexit, json, os, time
from numba.core import codegen, event
t0 = time.process_time()
llvm = {"function passes": 0.0, "module passes": 0.0, "machine code": 0.0}
def timed(cls, name, key):  # LLVM's share: numba's own typing and lowering is the rest
    real = getattr(cls, name)
    def call(self, *a, **kw):
        t = time.process_time()
        try:
            return real(self, *a, **kw)
        finally:
            llvm[key] += time.process_time() - t
    setattr(cls, name, call)
timed(codegen.CPUCodeLibrary, "_optimize_functions", "function passes")
timed(codegen.CPUCodeLibrary, "_optimize_final_module", "module passes")
timed(codegen.JITCodeLibrary, "_finalize_specific", "machine code")
stack, rows = [], []
class Listener(event.Listener):
    def on_start(self, ev):
        stack.append([time.process_time(), 0.0])
    def on_end(self, ev):
        t, inner = stack.pop()
        total = time.process_time() - t
        if stack:
            stack[-1][1] += total
        f = ev.data["dispatcher"].py_func
        sig = str(tuple(ev.data["args"]))
        rows.append((f"{f.__module__}.{f.__qualname__}", total - inner, sig))
event.register("numba:compile", Listener())
@atexit.register
def dump():
    path = os.path.join(os.environ["BENCH_COMPILE_OUT"], f"{os.getpid()}.json")
    with open(path, "w") as f:
        json.dump({"cpu": time.process_time() - t0, "rows": rows, "llvm": llvm}, f)
"""

#: the background compile's exercise (``split``: with its partner process)
WARM = r"""
import explorer
assert explorer.__file__.startswith({root!r}), explorer.__file__
from explorer.shading import warm
warm.exercise({split})
"""


def warm_table(root: Path, label: str, top: int = 25, split: bool = False) -> list[str]:
    """The background compile's CPU seconds at ``root``, by function (see the docstring)."""
    with tempfile.TemporaryDirectory() as tmp:
        cache, out_dir, site = Path(tmp, "cache"), Path(tmp, "out"), Path(tmp, "site")
        for d in (cache, out_dir, site):
            d.mkdir()
        (site / "sitecustomize.py").write_text(SITE)
        env = dict(os.environ, PYTHONPATH=f"{site}{os.pathsep}{root}", NUMBA_CACHE_DIR=str(cache))
        env.update(PHONG_EXPLORER_KERNELS="compiled", BENCH_COMPILE_OUT=str(out_dir))
        t = time.perf_counter()
        code = WARM.format(root=str(root), split="partner=True" if split else "")
        out = subprocess.run([sys.executable, "-c", code], cwd=root, env=env,
                             capture_output=True, text=True)  # fmt: skip
        wall = time.perf_counter() - t
        if out.returncode != 0:
            sys.exit(f"{root}: the child failed:\n{out.stderr[-3000:]}")
        procs = [json.loads(p.read_text()) for p in sorted(out_dir.glob("*.json"))]
    by: dict[str, list] = {}
    seen: dict[tuple, int] = {}
    for res in procs:
        for name, s, sig in res["rows"]:
            name = name.replace("explorer.", "").replace("<locals>.", "")
            by.setdefault(name, [0, 0.0])
            by[name][0] += 1
            by[name][1] += s
            seen[(name, sig)] = seen.get((name, sig), 0) + 1
    cpu = [res["cpu"] for res in procs]
    llvm = {k: sum(res["llvm"][k] for res in procs) for k in procs[0]["llvm"]}
    split_llvm = ", ".join(f"{k} {v:.1f}" for k, v in llvm.items())
    twice = sorted(k for k, n in seen.items() if n > 1 and not k[0].startswith("numba."))
    lines = [
        f"\n{label}: {sum(cpu):.1f} CPU s in all, {len(procs)} process(es) of "
        f"{', '.join(f'{c:.1f}' for c in cpu)} CPU s, {wall:.1f} s wall (LLVM: {split_llvm}); "
        f"compiled in both processes: {len(twice)} {twice[:8]}\n"
    ]
    lines.append("| function | signatures | CPU s |")
    lines.append("|---|---:|---:|")
    ranked = sorted(by.items(), key=lambda kv: -kv[1][1])
    for name, (n, s) in ranked[:top]:
        lines.append(f"| {name} | {n} | {s:.1f} |")
    rest = ranked[top:]
    lines.append(f"| (the {len(rest)} others) | {sum(n for _, (n, _) in rest)} | "
                 f"{sum(s for _, (_, s) in rest):.1f} |")  # fmt: skip
    return lines


ENTRIES = ("extent", "prepare", "bounds", "shade", "fixup", "compose", "lobe", "_round_bytes")


def child(root: Path, dtype: str, cut: bool) -> dict:
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, PYTHONPATH=str(root), NUMBA_CACHE_DIR=cache)
        code = CHILD.format(root=str(root), dtype=dtype, cut=cut)
        out = subprocess.run(
            [sys.executable, "-c", code], cwd=root, env=env, capture_output=True, text=True
        )
    if out.returncode != 0:
        sys.exit(f"{root} {dtype} cut={cut}: the child failed:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def measure(root: Path, label: str, dtypes=("float32", "float64")) -> list[str]:
    res = {}
    for dtype in dtypes:
        res[dtype] = child(root, dtype, False)
        res[dtype + " cut"] = child(root, dtype, True)

    def row(name, values):
        return f"| {name} | " + " | ".join(f"{v:.1f}" for v in values) + " |"

    lines = [f"\n{label}\n", "| entry point | " + " | ".join(f"{d} s" for d in dtypes) + " |"]
    lines.append("|---|" + "---:|" * len(dtypes))
    for e in ENTRIES:
        lines.append(row(e, [res[d].get(e, 0) for d in dtypes]))
    lines.append(row("**session total**", [sum(res[d].get(e, 0) for e in ENTRIES) for d in dtypes]))
    cut = [res[d + " cut"].get("shade", 0) for d in dtypes]
    lines.append(row("shade, one light variant", cut))
    more = [res[d]["shade"] - c for d, c in zip(dtypes, cut, strict=True)]
    lines.append(row("shade: what the other variants add", more))
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rev", action="append", default=[], help="also measure a git revision")
    ap.add_argument("--skip-tree", action="store_true", help="measure the revisions only")
    ap.add_argument("--precision", choices=("float32", "float64"), help="this one only")
    ap.add_argument("--warm", action="store_true", help="the background compile, by function")
    ap.add_argument(
        "--split",
        action="store_true",
        help="--warm as the background compile runs it, with its partner",
    )
    args = ap.parse_args(argv)
    sys.path[:0] = [str(ROOT), str(HERE)]  # this tree's package, then the benchmarks
    from bench_engine import machine

    dtypes = (args.precision,) if args.precision else ("float32", "float64")
    out = [f"machine: {machine()}"]
    with tempfile.TemporaryDirectory() as tmp:
        for rev in args.rev:
            root = Path(tmp) / rev
            root.mkdir()
            arc = subprocess.run(
                ["git", "-C", str(ROOT), "archive", rev], check=True, capture_output=True
            ).stdout
            subprocess.run(["tar", "-x", "-C", str(root)], input=arc, check=True)
            out += (
                warm_table(root, f"revision {rev}", split=args.split)
                if args.warm
                else measure(root, f"revision {rev}", dtypes)
            )
        if not args.skip_tree:
            out += (
                warm_table(ROOT, "this tree", split=args.split)
                if args.warm
                else measure(ROOT, "this tree", dtypes)
            )
    out.append(f"\nload average after: {os.getloadavg()[0]:.2f}")
    print("\n".join(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
