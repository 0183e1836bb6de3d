"""What numba makes of the engine's hot loops for an ISA: vector width, calls, packing, gathers.

    python benchmarks/bench_isa_code.py --isa both      # the host's ISA and AVX2, side by side
    python benchmarks/bench_isa_code.py --asm DIR       # also write each loop's assembly to DIR

Each loop is compiled afresh in this process (an empty ``NUMBA_CACHE_DIR`` of its own: numba
cannot show code it loaded from its cache), as the kernels compile it (their options, and
inside ``kernels.wide_vectors`` with the lanes of the entry point that calls it, where that
applies), through a small wrapper that calls the loop with the arguments the benchmark's scene
gives it (``bench_engine.py``: white point lights with attenuation, Blinn, local viewer):

- ``lights``: the inline point-light loop (``kernels._light``, Blinn, grey), float32 (its lobe
  ``vmath.pow32`` in the loop) and float64 (base² rows, then ``kernels._split_lobe``: packing the
  lanes with a lobe weight where ``vmath.NATIVE_COMPRESS``, ``vmath.pow64``);
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
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import tempfile
from pathlib import Path

os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="isa-code-")  # nothing from a cache
os.environ.setdefault("PHONG_EXPLORER_KERNELS", "compiled")

import isa  # noqa: E402 - benchmarks/isa.py
import numba as nb  # noqa: E402
import numpy as np  # noqa: E402

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


def light_loop(dtype, code):
    """A wrapper compiling the light loop ``code`` alone (attenuated, with diffuse)."""

    def f(scr, m, q, y, k):
        K._light(scr, m, q, y, k, True, True, code)

    return nb.njit(**OPTS)(f), lambda: (
        np.zeros((K.N_ROWS + 1) * K.ROW, dtype),
        K.BLOCK,
        np.zeros(64, dtype),
        dtype(25.6),
        K.constants(dtype),
    )


def compose_loop(dtype, variant):
    def f(o, A, D, S, c, lo, hi):
        K._compose_block(o, A, D, S, c, lo, hi, variant)

    n = 1024
    return nb.njit(**OPTS)(f), lambda: (
        np.zeros(3 * n, dtype),
        np.zeros(0, dtype),
        np.zeros(n, dtype),
        np.zeros(n, dtype),
        np.zeros(12, dtype),
        dtype(0),
        dtype(1),
    )


def fresh(dispatcher, args_of):
    """A copy of a kernel's numba function compiled here, with its own options."""
    return nb.njit(**OPTS)(dispatcher.py_func), args_of


def loops() -> dict:
    f32, f64 = np.float32, np.float64
    blinn = K.loop_code(K.Loop(K.SRC_INLINE, K.LOBE_BLINN, True))
    n = 4096
    P = np.random.default_rng(0).normal(size=(n, 3)).astype(f32)  # (the benchmark's vertices)
    lobe_args = lambda: (  # noqa: E731 - (base, ws, params, flags, shininess, k, Sf, scr, b0, b1)
        np.random.default_rng(1).random((1, n)).astype(f32),
        np.ones((1, n), f32),
        np.zeros((1, 64), f32),
        np.zeros(1, np.int32),
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
        "lights float64: the split lobe (_split_lobe)": (
            8,
            fresh(
                K._split_lobe,
                lambda: (np.zeros((K.N_ROWS + 1) * K.ROW), K.BLOCK, 12.8, 1.0, 1.0, 1.0, True),
            ),
        ),
        "lobe float32 (_lobe_task, a shininess change)": (16, fresh(K._lobe_task, lobe_args)),
        "recompose float32 (grey D and S)": (16, compose_loop(f32, 2 | 4 | 8 | 16)),
        "prepare float32 (_prepare_blocks)": (16, fresh(K._prepare_blocks, prep(f32))),
        "prepare float64 (_prepare_blocks)": (8, fresh(K._prepare_blocks, prep(f64))),
        "extent float32 (_extent_run)": (
            16,
            fresh(K._extent_run, lambda: (P.reshape(-1), np.zeros(7))),
        ),
        "floor (_add)": (16, fresh(K._add, lambda: (np.zeros(n, f32),) * 3)),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--asm", type=Path, help="write each loop's assembly into this folder")
    ap.add_argument("--only", help="the loops whose name contains this")
    isa.add_arguments(ap)
    args = ap.parse_args(argv)
    if args.isa and not isa.in_child():
        return isa.run(__file__, sys.argv[1:] if argv is None else list(argv), args)
    print(isa.isa_line())
    keys = list(COUNTS) + ["zmm", "ymm", "xmm", "IR vectors", "IR calls"]
    print("\n| loop | " + " | ".join(keys) + " |")
    print("|---|" + "---:|" * len(keys))
    for name, (lanes, (fn, args_of)) in loops().items():
        if args.only and args.only not in name:
            continue
        with K.wide_vectors(lanes):
            fn(*args_of())
        sig = fn.signatures[0]
        asm, ir_ = fn.inspect_asm(sig), fn.inspect_llvm(sig)
        s = stats(asm, ir_)
        print(f"| {name} | " + " | ".join(str(s[k]) for k in keys) + " |", flush=True)
        for k in ("instructions", "packed fp", "scalar fp", "sqrt", "div"):
            isa.record(f"{name}: {k}", s[k], "count")
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
