"""What numba makes of the engine's hot loops for an ISA: vector width, calls, packing, gathers.

    python benchmarks/bench_isa_code.py --isa both      # the host's ISA and AVX2, side by side
    python benchmarks/bench_isa_code.py --asm DIR       # also write each loop's assembly to DIR
    python benchmarks/bench_isa_code.py --isa both --alternate 3 --time   # and each loop's speed

Each loop is compiled afresh in this process (an empty ``NUMBA_CACHE_DIR`` of its own: numba
cannot show code it loaded from its cache), as the kernels compile it (their options, and
inside ``codegen.wide_vectors`` with the lanes of the entry point that calls it, where that
applies), through a small wrapper that calls the loop with the arguments the benchmark's scene
gives it (``bench_engine.py``: white point lights with attenuation, Blinn, local viewer):

- ``lights``: the inline point-light loop (``kernels._light``, Blinn, grey), float32 (its lobe
  ``vmath.pow32`` in the loop) and float64 (base² rows, then ``kernels._split_lobe``: packing the
  lanes with a lobe weight where ``vmath.NATIVE_COMPRESS``, ``vmath.pow64``); the float64 lobe
  loop alone; a spot light's row path in float32 (its pre-passes, the cone's power, the loop
  reading rows);
- ``lobe``: a shininess change (``kernels._lobe_task``), float32;
- ``recompose``: a material change (``kernels._compose_block``, grey diffuse and specular sums);
- ``prepare``: a kept shader's geometry copy (``kernels._prepare_blocks``), float32 and float64;
- ``extent`` and ``bounds``: the frame's pass and the chunk bounds (geometry preparation);
- ``floor``: the bandwidth floor's loop (``kernels._add``).

For each it prints the vector registers the assembly names (zmm 512-bit, ymm 256-bit, xmm
128-bit), the widest vector types in the LLVM IR, and counts of the instructions that say where
time goes: packed and scalar floating-point arithmetic, square roots, divisions and their
approximations, gathers, compresses / expands, masked loads and stores, mask (k) registers,
branches; and the functions the IR calls beyond numba's error paths (a libm ``pow`` would be
one) and the x86 / masked intrinsics. Counts are of the whole compiled function (its vector
loop, the remainder and peeled iterations, the error paths), not of one iteration. Run with
``--isa both`` (``benchmarks/isa.py``) for the host's code beside AVX2's.

``--time`` adds each loop's speed: CPU nanoseconds per lane (per vertex-light for the light
loops, per vertex for the others), the loop repeated in compiled code on one block of data in
the caches, best of 5 (the code's own speed, on this host's cores: no memory traffic, no
threads; the engine's per-loop figures are bench_engine.py's).
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import tempfile
import time
from pathlib import Path

if __name__ == "__main__":  # (run, not imported: numba reads this when it is imported)
    os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="isa-code-")  # nothing from a cache
os.environ.setdefault("PHONG_EXPLORER_KERNELS", "compiled")

import isa  # noqa: E402 - benchmarks/isa.py
import numba as nb  # noqa: E402
import numpy as np  # noqa: E402

from explorer.shading import codegen as G  # noqa: E402
from explorer.shading import kernels as K  # noqa: E402

OPTS = dict(fastmath=K._FASTMATH, error_model="numpy", boundscheck=False, _nrt=False)

#: instruction classes counted in each loop's assembly (regular expressions on a line)
COUNTS = {
    "packed fp": r"\bv(?:add|sub|mul|fn?m(?:add|sub)\d+|max|min|and|or|xor|blendv?|cmp)\w*p[sd]\b",
    "scalar fp": r"\bv(?:add|sub|mul|fn?m(?:add|sub)\d+|max|min|cmp)\w*s[sd]\b",
    "sqrt": r"\bvsqrt\w+",
    "div": r"\bvdiv\w+",
    "rcp/rsqrt": r"\bv(?:rcp|rsqrt)\w+",
    "gathers": r"\bv(?:p?gather)\w+",
    "compress/expand": r"\bv(?:p?compress|p?expand)\w+",
    "masked mov": r"\bv(?:p?maskmov)\w+",
    "k-mask ops": r"%k[1-7]",
    "branches": r"^\s+j(?!mp)\w+",
    "instructions": r"^\s+[a-z]",
}


def functions(asm: str) -> str:
    """The assembly of the compiled functions in ``asm``, without numba's Python wrappers
    (``cpython.*``, which unpack the arguments)."""
    parts = re.split(r"^(?=\S+:\s*(?:#.*)?$)", asm, flags=re.M)
    kept = [p for p in parts if not re.match(r"\S*(?:cpython|cfunc)", p)]
    return "".join(kept)


def ir_functions(llvm_ir: str) -> str:
    """The LLVM IR of the compiled functions, without numba's Python wrappers."""
    parts = re.split(r"^(?=define )", llvm_ir, flags=re.M)
    return "".join(p for p in parts if p.startswith("define ") and "cpython" not in p.split("(")[0])


def stats(asm: str, llvm_ir: str) -> dict:
    asm, llvm_ir = functions(asm), ir_functions(llvm_ir)
    out = {name: len(re.findall(rx, asm, re.M)) for name, rx in COUNTS.items()}
    out.update(isa.registers(asm))
    # the vector type of most floating-point arithmetic in the IR (its lanes: the vector width)
    types = re.findall(r"= f(?:add|sub|mul|div|neg)[^<\n]*<(\d+ x (?:float|double))>", llvm_ir)
    out["IR vectors"] = f"<{max(set(types), key=types.count)}>" if types else "scalar"
    called = set(re.findall(r"call [^@\n]*@\"?([\w.$]+)", llvm_ir))
    # what the loops call: not numba's error paths (Py*, numba_*), nor the compiled functions
    # themselves (mangled names), but libm (a pow, an exp) and LLVM's x86 and masked intrinsics
    external = {c for c in called if not re.match(r"_ZN|Py|numba_|llvm\.", c)}
    intrinsics = {c for c in called if c.startswith("llvm.x86") or "masked" in c or "pow" in c}
    out["IR calls"] = ", ".join(sorted(external | intrinsics)) or "-"
    return out


def scratch(dtype, weighted: float = 0.4) -> np.ndarray:
    """A block's scratch rows with values a pass meets (positions, unit-ish normals and view
    vectors, bases in (0, 1)); row R_WS has a lobe weight on about ``weighted`` of its lanes
    (on random points about 40 % of the vertex-lights face their light)."""
    rng = np.random.default_rng(3)
    scr = (rng.random((K.N_ROWS + 1) * K.ROW) * 0.9 + 0.05).astype(dtype)
    ws = scr[K.R_WS * K.ROW : (K.R_WS + 1) * K.ROW]
    ws[rng.random(len(ws)) >= weighted] = 0
    return scr


def light_params(dtype) -> np.ndarray:
    """A white point light at (3, 2, 1) with attenuation (1, 0.1, 0.01), as the benchmark's."""
    q = np.zeros(64, dtype)
    q[K.P_POS : K.P_POS + 3] = (3.0, 2.0, 1.0)
    q[K.P_ATT : K.P_ATT + 3] = (1.0, 0.1, 0.01)
    q[K.P_DIF : K.P_DIF + 3] = q[K.P_SPEC : K.P_SPEC + 3] = 1.0
    return q


def light_loop(dtype, code):
    """A wrapper compiling the light loop ``code`` alone (attenuated, with diffuse)."""

    def f(scr, m, q, y, k):
        K._light(scr, m, q, y, k, True, True, code)

    scr, q = scratch(dtype), light_params(dtype)
    return nb.njit(**OPTS)(f), lambda: (scr, K.BLOCK, q, dtype(25.6), K.constants(dtype))


def split_lobe():
    """``kernels._split_lobe`` as a float64 light loop calls it: ``grey`` a constant there (the
    loop's), which LLVM folds once it inlines the call (passed at run time, the lobe loop keeps
    a test per lane and stays scalar)."""

    def f(scr, m, y):
        K._split_lobe(scr, m, y, 1.0, 1.0, 1.0, True)

    scr = scratch(np.float64)
    return nb.njit(**OPTS)(f), lambda: (scr, K.BLOCK, 12.8)


def spot_part(dtype, part: str):
    """A piece of :func:`spot_light` (``part``: "to_light", the pre-pass of L, d and w;
    "pre-passes", that and ``_spot``; "loop", the rows light loop), on the rows a spot light's
    pre-passes leave. (``_spot`` alone, repeated, would multiply the weights by the cone's
    factor again and again, down to subnormal numbers: slow for another reason.)"""
    code = G.loop_code(G.Loop(K.SRC_ROWS, K.LOBE_BLINN, False))

    def to_light(scr, m, q, y, k, on):
        K._to_light(scr, m, q, k, on)

    def pre_passes(scr, m, q, y, k, on):
        K._to_light(scr, m, q, k, on)
        K._spot(scr, m, q, k, on)

    def loop(scr, m, q, y, k, on):
        K._light(scr, m, q, y, k, False, True, code)

    whole, args_of = spot_light(dtype)
    done = []

    def prepared():  # (called inside wide_vectors: the pieces compile at the kernels' width)
        if not done:
            whole(*args_of())
            done.append(True)
        return args_of()

    fns = {"to_light": to_light, "pre-passes": pre_passes, "loop": loop}
    return nb.njit(**OPTS)(fns[part]), prepared


def spot_light(dtype, flags_fixed: bool = False):
    """A spot light's row path: the pre-passes (``kernels._to_light``: L, d, w;
    ``kernels._spot``: the cone and its exponent; their flags at run time, as ``_light_run``
    passes them) and the row-source Blinn light loop."""
    code = G.loop_code(G.Loop(K.SRC_ROWS, K.LOBE_BLINN, False))

    def f(scr, m, q, y, k, on):  # (on: the run-time flags, as _light_run passes them)
        K._to_light(scr, m, q, k, on)
        K._spot(scr, m, q, k, on)
        K._light(scr, m, q, y, k, False, True, code)

    def fixed(scr, m, q, y, k, on):  # the flags as constants (the fix's item 2, docs/speed.md)
        K._to_light(scr, m, q, k, True)
        K._spot(scr, m, q, k, True)
        K._light(scr, m, q, y, k, False, True, code)

    scr, q = scratch(dtype), light_params(dtype)
    q[K.P_AXIS : K.P_AXIS + 3] = -q[K.P_POS : K.P_POS + 3] / np.linalg.norm(
        q[K.P_POS : K.P_POS + 3]
    )
    q[K.P_COS], q[K.P_EXP] = np.cos(np.radians(40.0)), 8.0
    fn = nb.njit(**OPTS)(fixed if flags_fixed else f)
    return fn, lambda: (scr, K.BLOCK, q, dtype(25.6), K.constants(dtype), True)


def compose_loop(dtype, variant):
    def f(o, A, D, S, c, lo, hi):
        K._compose_block(o, A, D, S, c, lo, hi, variant)

    n, rng = 4096, np.random.default_rng(4)
    D, S = rng.random(n).astype(dtype), rng.random(n).astype(dtype)
    c = rng.random(12).astype(dtype)
    return nb.njit(**OPTS)(f), lambda: (
        np.zeros(3 * n, dtype),
        np.zeros(0, dtype),
        D,
        S,
        c,
        dtype(0),
        dtype(1),
    )


def fresh(dispatcher, args_of):
    """A copy of a kernel's numba function compiled here, with its own options."""
    return nb.njit(**OPTS)(dispatcher.py_func), args_of


def loops() -> dict:
    f32, f64 = np.float32, np.float64
    blinn = G.loop_code(G.Loop(K.SRC_INLINE, K.LOBE_BLINN, True))
    n = 4096
    P = np.random.default_rng(0).normal(size=(n, 3)).astype(f32)  # (the benchmark's vertices)
    lobe_args = lambda: (  # noqa: E731 - (base, ws, params, flags, shininess, k, Sf, scr, b0, b1)
        np.random.default_rng(1).random((1, n)).astype(f32),
        np.ones((1, n), f32),
        light_params(f32)[None],
        np.full(1, K.SPECULAR, np.int32),
        f32(25.6),
        K.constants(f32),
        np.zeros(3 * n, f32),
        np.zeros((K.N_ROWS + 1) * K.ROW, f32),
        0,
        n // K.BLOCK,
    )

    def prep(dt):
        flat, frame = P.reshape(-1), (np.zeros(3), 1.0, K.constants(dt))
        return lambda: (flat, flat, *frame, np.zeros((6, n), dt), 0, n // K.BLOCK)

    return {
        "lights float32 (inline point, Blinn, grey)": (16, light_loop(f32, blinn)),
        "lights float64 (inline point, Blinn, grey; base² rows)": (8, light_loop(f64, blinn)),
        "lights float64: the split lobe (as a light loop calls it)": (8, split_lobe()),
        "lights float32 rows (spot pre-pass + light loop, Blinn)": (16, spot_light(f32)),
        "lights float32 rows, spot flags constant": (16, spot_light(f32, flags_fixed=True)),
        "lights float32 rows: _to_light alone": (16, spot_part(f32, "to_light")),
        "lights float32 rows: _to_light and _spot": (16, spot_part(f32, "pre-passes")),
        "lights float32 rows: the rows light loop alone": (16, spot_part(f32, "loop")),
        "lobe float32 (_lobe_task, a shininess change)": (16, fresh(K._lobe_task, lobe_args)),
        "recompose float32 (grey D and S)": (16, compose_loop(f32, 2 | 4 | 8 | 16)),
        "prepare float32 (_prepare_blocks)": (16, fresh(K._prepare_blocks, prep(f32))),
        "prepare float64 (_prepare_blocks)": (8, fresh(K._prepare_blocks, prep(f64))),
        "extent float32 (_extent_run)": (
            16,
            fresh(K._extent_run, lambda: (P.reshape(-1), np.zeros(7))),
        ),
        "floor (_add)": (16, fresh(K._add, lambda: tuple(np.zeros(n, f32) for _ in range(3)))),
    }


#: lanes one call of each loop handles (vertex-lights, or vertices): the divisor of its time
LANES = {"lights": K.BLOCK, "lobe": 4096, "recompose": 4096, "prepare": 4096, "extent": 4096}


def lanes_of(name: str) -> int:
    return next((v for k, v in LANES.items() if name.startswith(k)), 4096)


def repeated(fn, nargs: int):
    """``rep(reps, *args)``: ``fn(*args)`` ``reps`` times in compiled code (no Python call per
    run; ``fn`` already compiled for these arguments)."""
    names = ", ".join(f"a{i}" for i in range(nargs))
    space = {"fn": fn}
    exec(f"def rep(reps, {names}):\n    for _ in range(reps):\n        fn({names})\n", space)  # noqa: S102
    return nb.njit(**OPTS)(space["rep"])


def cpu_ns_per_lane(fn, args: tuple, lanes: int, budget: float = 0.15, rounds: int = 5) -> float:
    """The best of ``rounds`` CPU-time measurements of ``fn(*args)`` repeated for about
    ``budget`` seconds, in ns per lane (one thread: the loop itself, data in cache)."""
    rep = repeated(fn, len(args))
    rep(1, *args)  # (compile the repeat loop)
    t = time.process_time()
    rep(10, *args)
    reps = max(10, int(budget / max(time.process_time() - t, 1e-6) * 10))
    best = float("inf")
    for _ in range(rounds):
        t = time.process_time()
        rep(reps, *args)
        best = min(best, (time.process_time() - t) / reps / lanes * 1e9)
    return best


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--asm", type=Path, help="write each loop's assembly into this folder")
    ap.add_argument("--only", help="the loops whose name contains this")
    ap.add_argument(
        "--time",
        action="store_true",
        help="also each loop's CPU ns per lane (one thread, data in cache, best of 5)",
    )
    ap.add_argument(
        "--width",
        type=int,
        choices=(128, 256, 512),
        help="force this vector width in bits (and interleave 2) instead of the target's own "
        "(codegen.VECTOR_BITS: 512 with AVX-512, 256 with AVX2): the loops' code with it",
    )
    isa.add_arguments(ap)
    args = ap.parse_args(argv)
    if args.isa and not isa.in_child():
        return isa.run(__file__, sys.argv[1:] if argv is None else list(argv), args)
    if args.width:  # (codegen.wide_vectors sets LLVM's options only where this is true)
        G.WIDE_VECTORS, G.VECTOR_BITS = True, args.width
    print(isa.isa_line() + (f"; loops forced to {args.width}-bit vectors" if args.width else ""))
    keys = list(COUNTS) + ["zmm", "ymm", "xmm", "IR vectors", "IR calls"]
    keys += ["CPU ns per lane"] if args.time else []
    print("\n| loop | " + " | ".join(keys) + " |")
    print("|---|" + "---:|" * len(keys))
    for name, (lanes, (fn, args_of)) in loops().items():
        if args.only and args.only not in name:
            continue
        with G.wide_vectors(lanes * (G.VECTOR_BITS or 512) // 512):
            fn(*args_of())
        sig = fn.signatures[0]
        asm, ir_ = fn.inspect_asm(sig), fn.inspect_llvm(sig)
        s = stats(asm, ir_)
        if args.time:
            ns = cpu_ns_per_lane(fn, args_of(), lanes_of(name))
            s["CPU ns per lane"] = f"{ns:.3f}"
            isa.record(f"{name}: CPU ns per lane", ns, "ns")
        print(f"| {name} | " + " | ".join(str(s[k]) for k in keys) + " |", flush=True)
        isa.record(f"{name}: instructions", s["instructions"], "count")
        if args.asm:
            args.asm.mkdir(parents=True, exist_ok=True)
            tag = os.environ.get(isa.CHILD, "in-process")
            safe = re.sub(r"\W+", "_", name).strip("_")
            (args.asm / f"{tag}-{safe}.s").write_text(asm)
            (args.asm / f"{tag}-{safe}.ll").write_text(ir_)
    isa.write_results()
    return 0


if __name__ == "__main__":
    sys.exit(main())
