"""How the shading kernels are generated and compiled: the Python that writes or configures
compiled code, apart from the compiled code itself (:mod:`explorer.shading.kernels`).

- The compiled variants. The light loops: :class:`Loop` (a loop's compile-time choices), its
  code (:func:`loop_code`, the literal the loop is compiled for), :data:`LIGHT_LOOPS` (every
  valid combination); the compose loops: :data:`COMPOSE_VARIANTS`. :func:`dispatch_source`
  writes the function that calls the variant a run-time code names (one test and one literal
  call per variant, from the table: no table is spelt out by hand). The comment above
  :func:`explorer.shading.kernels._light` says what each choice means to a light loop.
- The vector width: the entry points are compiled with vectors as wide as the target's registers
  (:data:`VECTOR_BITS`: 512 bits with AVX-512, 256 with AVX2; :func:`register_bits` asks LLVM),
  two vector iterations interleaved (:data:`INTERLEAVE`; :func:`wide_vectors`, :func:`wide`).

Every name here that the kernels read at compile time is frozen into the compiled code, so this
module is one of :data:`explorer.geometry.kernelcache.CONSTANT_MODULES`: an edit recompiles the
kernels that import it. Nothing here imports the kernels.
"""

from __future__ import annotations

import contextlib
import functools
import os
import sys
import tempfile
from collections.abc import Iterable
from typing import NamedTuple

import llvmlite.binding as llvm
import numba as nb
import numpy as np

# how a light's specular lobe base is found (a light loop's ``lobe``, and the kernels' run-time
# mode): shininess 0 (base^0 = 1), Blinn with a constant halfway vector, Blinn, Phong
LOBE_FLAT, LOBE_CONST_H, LOBE_BLINN, LOBE_PHONG = 0, 1, 2, 3

SRC_CONST, SRC_ROWS, SRC_INLINE = 0, 1, 2
LOBE_NONE = 4  # (after the modes a light's lobe can have)


class Loop(NamedTuple):
    """The compile-time choices of one light loop (see the comment above)."""

    source: int
    lobe: int
    grey: bool


def loop_code(loop: Loop) -> int:
    """A loop's code: the literal the light loop is compiled for (and
    :func:`explorer.shading.kernels._run_codes`'s, at run time)."""
    return loop.source | loop.lobe << 2 | int(loop.grey) << 5


def loop_of(code: int) -> Loop:
    return Loop(code & 3, (code >> 2) & 7, bool(code & 32))


def valid(loop: Loop) -> bool:
    inline = loop.source == SRC_INLINE
    return (inline or not loop.grey) and not (inline and loop.lobe == LOBE_CONST_H)


#: every light loop that is compiled (codes, see :func:`loop_code`)
LIGHT_LOOPS = tuple(
    loop_code(lp)
    for lp in (
        Loop(s, lobe, g)
        for s in (SRC_CONST, SRC_ROWS, SRC_INLINE)
        for lobe in (LOBE_NONE, LOBE_FLAT, LOBE_CONST_H, LOBE_BLINN, LOBE_PHONG)
        for g in (False, True)
    )
    if valid(lp)
)


#: every compose loop that is compiled (:func:`explorer.shading.kernels._compose_block`'s
#: variant bits: 1, 2, 4 the ambient, diffuse, specular sums present; 8, 16 the diffuse,
#: specular sums grey, one value per vertex): D and S each absent, RGB or grey, A or not
COMPOSE_VARIANTS = tuple(a | d | s for d in (0, 2, 2 | 8) for s in (0, 4, 4 | 16) for a in (0, 1))


def dispatch_source(name: str, params: str, callee: str, codes: Iterable[int]) -> str:
    """The source of function ``name(params)``, whose last parameter is a run-time code: one
    test and one call of ``callee(params)`` with the code as a literal per entry of ``codes``
    (each literal call compiles that variant). One function, not a chain of functions each
    calling the next: LLVM would optimise every variant again at each link of the chain."""
    args = [p.strip() for p in params.split(",")]
    code = args[-1]
    src = [f"def {name}({params}):"]
    for c in codes:
        call = ", ".join(args[:-1] + [str(c)])
        src += [f"    if {code} == {c}:", f"        {callee}({call})", "        return"]
    return "\n".join(src) + "\n"


#: the probe :func:`register_bits` compiles: a 16-lane integer multiply, which LLVM writes in
#: the widest integer vector registers the target has (integer, not float: AVX without AVX2 has
#: 256-bit float registers but 128-bit integer operations, and the AVX2 lane packing,
#: :mod:`explorer.shading.vmath`, needs AVX2's cross-lane permute)
_PROBE = """
define void @probe(ptr %p) {
  %a = load <16 x i32>, ptr %p, align 4
  %b = mul <16 x i32> %a, %a
  store <16 x i32> %b, ptr %p, align 4
  ret void
}
"""


@functools.cache
def register_bits() -> int:
    """The width in bits of the integer vector registers of the CPU numba compiles for: 512
    (AVX-512F), 256 (AVX2), 128 (SSE2 or AVX), 0 (not x86 or unknown). The target is numba's own
    (``NUMBA_CPU_NAME`` and ``NUMBA_CPU_FEATURES``, else the host's name and features), so a
    named CPU gets its own features (``znver3``: AVX2) less those the feature string takes off;
    LLVM compiles :data:`_PROBE` for it and the registers its assembly names say the width."""
    from numba.core.codegen import get_host_cpu_features

    try:
        llvm.initialize_native_target()
        llvm.initialize_native_asmprinter()
        cpu = nb.config.CPU_NAME or llvm.get_host_cpu_name()
        feats = nb.config.CPU_FEATURES
        if feats is None:
            feats = get_host_cpu_features()
        tm = llvm.Target.from_default_triple().create_target_machine(cpu=cpu, features=feats)
        asm = tm.emit_assembly(llvm.parse_assembly(_PROBE))
    except RuntimeError:  # llvmlite cannot target or describe this CPU: keep LLVM's choice
        return 0
    for reg, bits in (("%zmm", 512), ("%ymm", 256), ("%xmm", 128)):
        if reg in asm:
            return bits
    return 0


#: the vector width in bits the entry points' loops are compiled with (16 float32 or 8 float64
#: lanes at 512, 8 or 4 at 256), the target's register width (:func:`register_bits`) where it
#: has AVX-512 or AVX2, else 0: LLVM's own choice. LLVM's tunings for many x86 cores prefer
#: 256-bit vectors on AVX-512 (512-bit ones shade about 12% faster here in float32, and the
#: float64 light loop, whose power is long, gains more), and its cost model for AMD Zen 3 left
#: loops scalar that are faster in 8 lanes (a spot light's ``_to_light``: 256 bits forced made
#: the spot lights 1.37x faster on AVX2, the shininess change 1.54x, full passes 1.08x; see
#: docs/speed.md). Set the environment variable PHONG_EXPLORER_WIDE_VECTORS=0 to keep LLVM's
#: choice (numba's on-disk cache keeps whichever was compiled first: clear it, or use another
#: NUMBA_CACHE_DIR, to compare).
VECTOR_BITS = register_bits() if os.environ.get("PHONG_EXPLORER_WIDE_VECTORS", "1") != "0" else 0
VECTOR_BITS = VECTOR_BITS if VECTOR_BITS >= 256 else 0
#: whether the loops' vector width is forced (:data:`VECTOR_BITS`)
WIDE_VECTORS = VECTOR_BITS > 0


def lanes(itemsize: int) -> int:
    """How many lanes of ``itemsize`` bytes a vector of :data:`VECTOR_BITS` holds (0: none
    forced)."""
    return VECTOR_BITS // (8 * itemsize)


@contextlib.contextmanager
def quiet_llvm_remarks():
    """Drop the "remark: ... loop not vectorized" lines LLVM writes to the process's stderr
    (file descriptor 2) for loops it leaves scalar once a vector width is forced; any other
    output is passed on."""
    try:
        sys.stderr.flush()
        saved = os.dup(2)
    except (OSError, ValueError):  # no usable stderr: nothing to filter
        yield
        return
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            yield
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            tmp.seek(0)
            rest = [ln for ln in tmp.read().splitlines(True) if not ln.startswith(b"remark: ")]
            if rest:
                os.write(2, b"".join(rest))


#: and their loops run two vector iterations interleaved (LLVM's -force-vector-interleave): a
#: light loop is one long dependency chain per iteration (two square roots, pow), which the
#: out-of-order core overlaps too little on its own; two independent chains side by side make
#: the light loop about 15% faster here (LLVM picks 1 for a loop that large), at 512 bits and at
#: 256 alike
INTERLEAVE = 2


@contextlib.contextmanager
def wide_vectors(n: int = 0):
    """Compile numba code inside this block with ``n``-lane vectors (default: float32 lanes of
    :data:`VECTOR_BITS`, 16 at 512 bits, 8 at 256) where :data:`WIDE_VECTORS` (else a no-op).
    LLVM's ``-force-vector-width`` is a process-wide option: it is set for the block only and
    reset to 0 (LLVM's own choice) after, so other numba code is not affected."""
    if not WIDE_VECTORS:
        yield
        return
    with quiet_llvm_remarks():
        llvm.set_option("", f"-force-vector-width={n or lanes(4)}")
        llvm.set_option("", f"-force-vector-interleave={INTERLEAVE}")
        try:
            yield
        finally:
            llvm.set_option("", "-force-vector-width=0")
            llvm.set_option("", "-force-vector-interleave=0")


def kind(a):
    """What of a kernel argument decides numba's signature, roughly: an array's dtype, number
    of dimensions and writability, a tuple's members' kinds, else the type."""
    if isinstance(a, np.ndarray):
        return a.dtype, a.ndim, a.flags.writeable
    if isinstance(a, tuple):
        return tuple(kind(x) for x in a)
    return type(a)


def wide(kernel, dtype_arg: int, item: int = 0):
    """Call ``kernel`` so that a signature it meets for the first time (by the :func:`kind` of
    its first argument, the data, and the dtype of positional argument ``dtype_arg``, float
    data) is compiled with vectors of :data:`VECTOR_BITS` (:func:`wide_vectors` around such
    first calls, which compile or load from numba's cache); later calls go straight to the
    kernel. ``item``: the lanes' size in bytes instead of the dtype's (8: a kernel whose
    arithmetic is float64 whatever its data)."""
    if not WIDE_VECTORS:
        return kernel
    seen: set = set()

    @functools.wraps(kernel.py_func)
    def call(*args):
        dt = args[dtype_arg].dtype
        key = (kind(args[0]), dt)
        if key in seen:
            return kernel(*args)
        if dt not in (np.float32, np.float64):
            seen.add(key)
            return kernel(*args)
        with wide_vectors(lanes(item or dt.itemsize)):
            try:
                return kernel(*args)
            finally:
                seen.add(key)

    call.dispatcher = kernel  # the numba dispatcher itself (signatures, inspection)
    return call
