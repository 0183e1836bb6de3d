"""Compiled shading kernels (numba): blocked, fused, one code for float32 and float64.

Vertices are processed in blocks of :data:`BLOCK`. Each block is converted once to the
normalised frame (:mod:`explorer.geometry.frame`) in float64 and then to the working precision ``T``
(the dtype of ``G``: float32 for the fast path, float64 for the exact path), stored as
structure-of-arrays scratch rows that stay in cache. Every light then runs a few short stage loops
over the block (direction, weight, diffuse, lobe), each a branch-free loop the compiler turns into
SIMD code; decisions the plan makes per light are taken once per block, outside those loops.

The light sums (ambient, diffuse, specular; see :func:`explorer.shading.equation.equation_terms`)
are stored when asked, so a material change only recomposes (:func:`compose`), and each light's
specular base and weight can be stored so a shininess change only re-runs the lobe
(:func:`lobe`). A pass whose lights are all grey (r = g = b) stores its diffuse and specular
sums grey, (n, 1) (:func:`grey_pass`): at 1M vertices the (n, 3) stores were a fifth of the pass.

Light culling: each run of :data:`CHUNK` consecutive vertices has a bounding sphere and a cone
of normals (:func:`bounds`, once per geometry); a light is skipped for a run that provably gets
nothing from it, every vertex facing away from it or outside its spot cone (:func:`_reach`, once
per light and parallel task). A block then runs the light over the runs it reaches only.

float32 lanes whose result hangs on the sign of a nearly-zero quantity (see
:data:`explorer.core.tolerances.AMBIGUOUS_DOT`) are marked in ``redo`` so the engine can redo
them in float64. Each lane keeps the smallest margin to such a decision (row R_TRK, a min per light,
no mask logic); the mark is "margin below 1".

(n, 3) arrays (positions, normals, the cached sums, colours) are read and written through flat
(3n,) views, indexed ``3 * i + c``: LLVM then knows the stride and vectorises the interleaved
accesses; through numba's 2-D indexing (a run-time stride) those loops stayed scalar, at half
the speed or less.

Inputs come as a few named records (:class:`Lights`, :class:`Surface`, :class:`Sums`,
:class:`Lobes`, :class:`Marks`, :class:`Culling`: numba takes named tuples of arrays), so an
entry point has about ten arguments, each with one meaning.

Light loops, variants and what they cost to compile. Each light of a pass runs its pre-passes
(:func:`_light_run`: rows L and the weight w for a positional light, its spot cone, shadow,
Fresnel, per-vertex ambient) and then one light loop (:func:`_light`), compiled for a few named
compile-time choices (:class:`explorer.shading.codegen.Loop`: where L comes from, how the lobe's
base is found, grey or RGB sums; see the comment above :func:`_light`).
:data:`explorer.shading.codegen.LIGHT_LOOPS` lists the 18 valid combinations, each a function of
its own (``_light_<code>``, :func:`_light_entry`), compiled once per precision by
:func:`loop_table` (or loaded from numba's cache) before the first pass that calls it (a pass
asks for the loops it calls, :func:`pass_loops`: a session compiles only the loops its scenes
use); a light's loop is picked at run time from its flags (:func:`_run_codes`) and called
through that table of entry points (:func:`_light_loop`, :func:`_call_light`), so no table
spells the combinations out and no kernel of the chain that calls them holds a copy of them
(numba links a called function's code into its caller, and LLVM optimised the 36 loops again
at every level: ``_light_loop``, ``_block``, ``_task``, ``shade``'s parallel loop, ``shade``,
``fixup``).
Everything cheap to decide at run time is decided there (whether a light adds diffuse, whether
it is attenuated). A new light type adds its pre-pass to :func:`_light_run` and fills the rows
the SRC_ROWS loops read; a new term goes into :func:`_light` (and the numpy reference,
:mod:`explorer.shading.equation`). numba caches every kernel on disk (``cache=True``: per
machine, keyed on the contents of this file and of those it compiles from, :mod:`.vmath`,
:mod:`.codegen`, :mod:`explorer.core.lightrow` ..., :mod:`explorer.geometry.kernelcache`; an
edit to any of them recompiles). What that costs is measured by
``benchmarks/bench_compile.py``: each entry point's cold compile, and the share of the loops a
scene does not use (its docstring keeps the last table, with the machine).

Leaf kernels are compiled without numba's reference counting (``_nrt=False``): every slice of a
shared array would otherwise be an atomic increment and decrement of its count, which the two
threads of a pass contend for (about a fifth of a full pass at 1M vertices).

The entry points are compiled with vectors as wide as the target's registers (512 bits on
AVX-512, where LLVM's tuning for many x86 cores still picks 256; 256 on AVX2, where its cost
model for Zen 3 leaves some loops scalar), two vector iterations interleaved (see
:data:`explorer.shading.codegen.VECTOR_BITS`).
"""

from __future__ import annotations

import functools
import operator
import threading
import warnings
from typing import NamedTuple

import numba as nb
import numpy as np
from llvmlite import ir
from numba import types
from numba.core.errors import NumbaIRAssumptionWarning, TypingError
from numba.extending import intrinsic, overload

from explorer.core import tolerances as tol
from explorer.core.lightrow import (  # the row layout, shared with the lights that pack it
    AMBIENT,
    ATTEN,
    CONST_H,
    DIFFUSE,
    FRESNEL,
    GREY,
    P_AMB,
    P_ATT,
    P_AXIS,
    P_COS,
    P_DIF,
    P_EXP,
    P_F0,
    P_H,
    P_POS,
    P_SPEC,
    POSITIONAL,
    SHADOW,
    SPECULAR,
    SPOT,
    SPOT_EXP,
)
from explorer.geometry import kernelcache  # noqa: F401 - before the decorators: the cache key
from explorer.shading.codegen import (  # the light loops' variants, the vector width
    COMPOSE_VARIANTS,
    LIGHT_LOOPS,
    LOBE_BLINN,
    LOBE_CONST_H,
    LOBE_FLAT,
    LOBE_NONE,
    LOBE_PHONG,
    SRC_CONST,
    SRC_INLINE,
    SRC_ROWS,
    dispatch_source,
    lanes,
    loop_of,
    wide,
    wide_vectors,
)
from explorer.shading.layout import (  # the kernels' layouts (O_, R_, K_, B_ slots)
    B_AX,
    B_AY,
    B_AZ,
    B_COS,
    B_CX,
    B_CY,
    B_CZ,
    B_R,
    B_SIN,
    CONSTANTS,
    K_ATT_FLOOR,
    K_HALF_EPS2,
    K_INF,
    K_MARGIN_DIST2,
    K_MARGIN_DOT,
    K_MARGIN_LEN2,
    K_NORMAL_EPS2,
    K_ONE,
    K_POINT_EPS,
    K_TWO,
    K_ZERO,
    N_ROWS,
    O_CLAMP,
    O_COMPOSE,
    O_DO_AMB,
    O_DO_DIF,
    O_DO_SPEC,
    O_FLAT,
    O_LOCAL,
    O_PHONG,
    O_STORE,
    O_STORE_LOBE,
    O_TRACK,
    O_TWO_SIDED,
    O_VIEW,
    R_AX,
    R_AY,
    R_AZ,
    R_BASE,
    R_DX,
    R_DY,
    R_DZ,
    R_GD,
    R_GS,
    R_LOBE,
    R_LX,
    R_LY,
    R_LZ,
    R_NV,
    R_NX,
    R_NY,
    R_NZ,
    R_PACK,
    R_PX,
    R_PY,
    R_PZ,
    R_SX,
    R_SY,
    R_SZ,
    R_TRK,
    R_VX,
    R_VY,
    R_VZ,
    R_W,
    R_WS,
)
from explorer.shading.vmath import PACK, compress8, expand8, fpow, from_key, order_key

BLOCK = 512
#: the scratch's row stride (elements): a block's rows lie ROW apart, not BLOCK. At BLOCK, a
#: float64 row is 4 KB, the span of the L1 data cache's sets, so lane i of every row falls in
#: one set: a light loop reading and writing 14 rows evicts its own lines (8 ways) and streams
#: them from L2. 16 lanes more shift each row by 64 (float32) or 128 (float64) bytes, one or two
#: sets (``benchmarks/bench_revisions.py --precision float64`` compares).
ROW = BLOCK + 16

# numba's pedantic IR check says a phi variable of the inlined power (vmath.pow64 inside the
# packed float64 lobe loop) "is not in scope" when it compiles these kernels: a note about its
# own inliner, not about the results (the kernels' tests compare them with the equation). It
# would print on every foreground compile; only that message is silenced.
warnings.filterwarnings(
    "ignore", r".*variable '_fpow_overload\S* is not in scope", NumbaIRAssumptionWarning
)
_FASTMATH = {"nsz", "arcp", "contract", "afn", "reassoc"}  # never nnan/ninf: policies test them
_OPTS = dict(fastmath=_FASTMATH, error_model="numpy", boundscheck=False, cache=True)
_LEAF = dict(_OPTS, _nrt=False)

#: vertices per culling chunk (two 16-lane vector iterations): a light is skipped for a chunk
#: that provably gets nothing from it (see :func:`bounds` and :func:`_reach`)
CHUNK = 32
CHUNKS = BLOCK // CHUNK  # chunks per block


def constants(dtype) -> np.ndarray:
    """The kernel's constants (:data:`explorer.shading.layout.CONSTANTS`, from
    :mod:`explorer.core.tolerances`) in ``dtype``, indexed by the ``K_*`` slots."""
    return np.array(CONSTANTS, dtype=dtype)


def unit(k):
    """1 in the precision of ``k`` (an array), as a compile-time constant: ``k[K_ONE]`` is a
    run-time value, so ``k[K_ONE] / np.sqrt(x)`` costs a multiply the constant does not."""
    return k.dtype.type(1)


@overload(unit, jit_options=_LEAF)
def _unit_overload(k):
    if k.dtype == types.float32:
        return lambda k: np.float32(1.0)
    return lambda k: np.float64(1.0)


def nil(k):
    """0 in the precision of ``k``, as a compile-time constant (see :func:`unit`). A square
    root's argument must be provably >= 0 (``max(x, nil(k))``, not ``max(x, k[K_ZERO])``):
    LLVM then makes it an instruction; otherwise it stays a call to libm's sqrtf (which may set
    errno), and a loop with a call does not vectorise."""
    return k.dtype.type(0)


@overload(nil, jit_options=_LEAF)
def _nil_overload(k):
    if k.dtype == types.float32:
        return lambda k: np.float32(0.0)
    return lambda k: np.float64(0.0)


def lobe_power(k):
    """What the lobe's exponent is multiplied by, with the base row holding base^(1/that): in
    float64 (the light loops that split, see the comment above :func:`_light`) the base row and
    the stored lobe bases hold base², raised to n/2 (1/2); in float32 the base itself (1)."""
    return 0.5 if k.dtype == np.float64 else 1.0


@overload(lobe_power, jit_options=_LEAF)
def _lobe_power_overload(k):
    if k.dtype == types.float32:
        return lambda k: np.float32(1.0)
    return lambda k: np.float64(0.5)


@intrinsic
def _assume(typingctx, cond):
    """Tell LLVM ``cond`` holds (``llvm.assume``): no code, only facts for the optimiser."""
    if not isinstance(cond, types.Boolean):
        return None

    def codegen(context, builder, sig, args):
        fn = builder.module.declare_intrinsic(
            "llvm.assume", fnty=ir.FunctionType(ir.VoidType(), [ir.IntType(1)])
        )
        builder.call(fn, [args[0]])
        return context.get_dummy_value()

    return types.none(cond), codegen


def _row_view(context, builder, sig, args, assume):
    """The code of ``scr[r * ROW : r * ROW + m]`` (numba's own slice, clamped to the array),
    after ``llvm.assume`` of ``(r + 1) * ROW <= len(scr)`` and ``0 <= m <= BLOCK`` when
    ``assume``. Written as an intrinsic, not a function numba inlines into its caller: a light
    loop takes some twenty rows, and numba's inliner copies and types the callee's IR again at
    every call (a tenth of the cold compile, ``benchmarks/bench_compile.py``); LLVM gets the
    same instructions either way."""
    scr_t, view_t = sig.args[0], sig.return_type
    ary = context.make_array(scr_t)(context, builder, args[0])
    intp = context.get_value_type(types.intp)
    r, m = args[1], args[2]
    start = builder.mul(r, intp(ROW))
    stop = builder.add(start, m)
    if assume:
        fn = builder.module.declare_intrinsic(
            "llvm.assume", fnty=ir.FunctionType(ir.VoidType(), [ir.IntType(1)])
        )
        n = builder.extract_value(ary.shape, 0)
        end = builder.mul(builder.add(r, intp(1)), intp(ROW))
        builder.call(fn, [builder.icmp_signed(">=", n, end)])
        builder.call(fn, [builder.icmp_signed("<=", m, intp(BLOCK))])
        builder.call(fn, [builder.icmp_signed(">=", m, intp(0))])
    make_slice = context.get_function(slice, types.slice2_type(types.intp, types.intp))
    sl = make_slice(builder, (start, stop))
    getitem = context.get_function(operator.getitem, view_t(scr_t, types.slice2_type))
    return getitem(builder, (args[0], sl))


def _row_type(typingctx, scr):
    """The type of a row of ``scr`` (numba's type of ``scr[a:b]``)."""
    return typingctx.resolve_function_type(operator.getitem, (scr, types.slice2_type), {})


@intrinsic
def _row_checked(typingctx, scr, r, m):
    """:func:`_row` without telling LLVM that the row lies whole in the scratch: the slice is
    then clamped at run time, and LLVM checks a loop's rows for overlap before it enters the
    vector loop. For the inline light loops: rows at a known constant distance make LLVM refuse to
    interleave two vector iterations (it takes the distance as a limit), and interleaving is
    worth more there (0.93x without it, full pass at 1M)."""
    view = _row_type(typingctx, scr).return_type

    def codegen(context, builder, sig, args):
        return _row_view(context, builder, sig, args, False)

    return view(scr, types.intp, types.intp), codegen


@intrinsic
def _row(typingctx, scr, r, m):
    """Row ``r`` of a block's scratch, its first ``m`` lanes (m <= BLOCK). The rows lie ROW
    apart in one flat array, and LLVM is told the scratch holds row ``r`` whole: the slice is
    then the scratch's start plus a constant, not clamped at run time, so LLVM proves the rows
    of a loop disjoint (no run-time overlap checks: a loop that reads and writes many rows had
    too many to vectorise at all) and addresses them all from one register."""
    view = _row_type(typingctx, scr).return_type

    def codegen(context, builder, sig, args):
        return _row_view(context, builder, sig, args, True)

    return view(scr, types.intp, types.intp), codegen


@nb.njit(**_LEAF)
def _copy(dst, src):
    for i in range(dst.shape[0]):
        dst[i] = src[i]


@nb.njit(**_LEAF)
def _fill(a, v):
    for i in range(a.shape[0]):
        a[i] = v


@nb.njit(**_LEAF)
def _load_positions(P, centre, inv_scale, px, py, pz):
    """Positions (flat x0 y0 z0 x1 ...) into the normalised frame: subtract in float64, then
    round to T."""
    for i in range(px.shape[0]):
        px[i] = (np.float64(P[3 * i]) - centre[0]) * inv_scale
        py[i] = (np.float64(P[3 * i + 1]) - centre[1]) * inv_scale
        pz[i] = (np.float64(P[3 * i + 2]) - centre[2]) * inv_scale


@nb.njit(parallel=True, **_OPTS)
def prepare(P, N, centre, inv_scale, k, G):
    """Geometry in the normalised frame, structure of arrays, working precision.

    P, N : (n, 3) float32/float64 world positions and normals
    G : (6, n) T out: px, py, pz (frame coordinates), nx, ny, nz (unit, or 0 where absent)
    Returns how many blocks hold a normal outside :data:`explorer.core.tolerances.NORMAL_RANGE`
    (by the test of :func:`explorer.geometry.frame.scale_normals`) or a value that is not
    finite: 0, or test and scale the normals and prepare again.
    """
    n = P.shape[0]
    Pf, Nf = P.reshape(-1), N.reshape(-1)  # flat: x0 y0 z0 x1 ... (see the module docstring)
    nblocks = (n + BLOCK - 1) // BLOCK
    outside = 0
    for b in nb.prange(nblocks):
        outside += _prepare_blocks(Pf, Nf, centre, inv_scale, k, G, b, b + 1)
    return outside


@nb.njit(**_LEAF)
def _prepare_blocks(Pf, Nf, centre, inv_scale, k, G, b0, b1):
    """Blocks b0 to b1 - 1 of :func:`prepare`; returns how many hold a normal out of range."""
    n = G.shape[1]
    outside = 0
    for b in range(b0, b1):
        s = b * BLOCK
        e = min(n, s + BLOCK)
        _load_positions(Pf[3 * s : 3 * e], centre, inv_scale, G[0, s:e], G[1, s:e], G[2, s:e])
        outside += _load_normals(Nf[3 * s : 3 * e], G[3, s:e], G[4, s:e], G[5, s:e], k)
    return outside


class Source(NamedTuple):
    """A pass's geometry (``src``): ``G`` (6, n) T, the prepared rows (see :func:`prepare`),
    read as they are; or G (6, 0) and the caller's vertices, prepared block by block as the
    pass reaches them (:func:`prepare`'s arithmetic: the same values), so that no (6, n) G is
    written or read (a one-shot pass): ``P``, ``N`` (n, 3) float64 world positions and normals,
    or ``P32``, ``N32`` (n, 3) float32 (the other pair (0, 3)), read-only; ``centre`` (3,)
    float64 and ``inv_scale`` float64: the normalised frame
    (:func:`explorer.shading.prepared.vertices`, :func:`~explorer.shading.prepared.rows`).

    One record type per precision whatever the path and the caller's dtype, so that
    :func:`shade`, :func:`bounds` and what they call compile once per precision: each signature
    of ``shade`` links every light loop and optimises it again (the cold compile took 6
    signatures where it now takes 2; ``benchmarks/bench_compile.py --warm``)."""

    G: np.ndarray
    P: np.ndarray
    N: np.ndarray
    P32: np.ndarray
    N32: np.ndarray
    centre: np.ndarray
    inv_scale: float


def _vertex_count(src):  # pragma: no cover - replaced by the overload
    raise NotImplementedError


@overload(_vertex_count, jit_options=_LEAF)
def _vertex_count_overload(src):
    """How many vertices a pass's geometry holds: G (6, n) or a :class:`Source`."""
    if isinstance(src, types.Array):
        return lambda src: src.shape[1]
    return lambda src: src.G.shape[1] + src.P.shape[0] + src.P32.shape[0]  # (two are empty)


def _lanes_to_prepare(src):  # pragma: no cover - replaced by the overload
    raise NotImplementedError


@overload(_lanes_to_prepare, jit_options=_LEAF)
def _lanes_to_prepare_overload(src):
    """The lanes of a task's buffer for a block of vertices to prepare (see :func:`_geometry`):
    BLOCK, or 0 for G, whose rows the pass reads as they are."""
    if isinstance(src, types.Array):
        return lambda src: 0
    return lambda src: 0 if src.G.shape[1] else BLOCK


def _geometry(src, s, e, gb, k):  # pragma: no cover - replaced by the overload
    raise NotImplementedError


@overload(_geometry, jit_options=_LEAF)
def _geometry_overload(src, s, e, gb, k):
    """Vertices ``s`` to ``e`` of a pass's geometry as six (e - s,) T rows (px, py, pz, nx, ny,
    nz; see :func:`prepare`) and 0, or 1 when some of their normals lie outside NORMAL_RANGE or
    are not finite (as :func:`prepare` counts them). ``src``: G (6, n), or a :class:`Source`:
    its G's rows as they are, or its vertices prepared here into ``gb`` (6, >= e - s) T."""
    if isinstance(src, types.Array):

        def rows(src, s, e, gb, k):
            return (src[0, s:e], src[1, s:e], src[2, s:e], src[3, s:e], src[4, s:e], src[5, s:e]), 0

        return rows

    def prepared(src, s, e, gb, k):
        G = src.G
        if G.shape[1]:
            return (G[0, s:e], G[1, s:e], G[2, s:e], G[3, s:e], G[4, s:e], G[5, s:e]), 0
        m = e - s
        frame = (src.centre, src.inv_scale)
        if src.P.shape[0]:  # float64 vertices
            Pf, Nf = src.P.reshape(-1), src.N.reshape(-1)
            _load_positions(Pf[3 * s : 3 * e], *frame, gb[0, :m], gb[1, :m], gb[2, :m])
            outside = _load_normals(Nf[3 * s : 3 * e], gb[3, :m], gb[4, :m], gb[5, :m], k)
        else:  # float32 vertices
            Pf, Nf = src.P32.reshape(-1), src.N32.reshape(-1)
            _load_positions(Pf[3 * s : 3 * e], *frame, gb[0, :m], gb[1, :m], gb[2, :m])
            outside = _load_normals(Nf[3 * s : 3 * e], gb[3, :m], gb[4, :m], gb[5, :m], k)
        return (gb[0, :m], gb[1, :m], gb[2, :m], gb[3, :m], gb[4, :m], gb[5, :m]), outside

    return prepared


#: squared lengths that put a normal's largest component inside NORMAL_RANGE (the fast test of
#: explorer.geometry.frame.scale_normals: the largest lies between length/√3 and length)
_NN_LO, _NN_HI = 3.0 * tol.NORMAL_RANGE[0] ** 2, tol.NORMAL_RANGE[1] ** 2


@nb.njit(**_LEAF)
def _load_normals(N, nx, ny, nz, k):
    """Unit normals in T; zero where |N|² <= NORMAL_EPS² (no diffuse, no specular there).
    Returns 1 if some normal is neither zero nor inside NORMAL_RANGE (by its squared length in
    float64, see _NN_LO), else 0."""
    zero, one, eps2 = k[K_ZERO], k[K_ONE], k[K_NORMAL_EPS2]
    outside = np.int32(0)
    for i in range(nx.shape[0]):
        a = N[3 * i] * one
        b = N[3 * i + 1] * one
        c = N[3 * i + 2] * one
        nn = a * a + b * b + c * c
        ok = nn > eps2
        inv = one / np.sqrt(nn if ok else unit(k))  # (>= 0: see nil)
        nx[i] = a * inv if ok else zero
        ny[i] = b * inv if ok else zero
        nz[i] = c * inv if ok else zero
        x, y, z = np.float64(N[3 * i]), np.float64(N[3 * i + 1]), np.float64(N[3 * i + 2])
        s = x * x + y * y + z * z
        zero_row = x == 0.0 and y == 0.0 and z == 0.0  # (not s == 0: s underflows at 1e-170)
        fine = (s >= _NN_LO and s <= _NN_HI) or zero_row
        outside |= np.int32(0) if fine else np.int32(1)
    return outside


@nb.njit(parallel=True, **_OPTS)
def extent(P):
    """The smallest and largest coordinates of positions ``P`` (n, 3) float32/float64: (2, 3)
    float64, row 0 the smallest x, y, z, row 1 the largest (see
    :func:`explorer.geometry.frame.frame_from_extent`); n >= 1. Every value NaN when some
    coordinate is not finite (the one pass over the positions is their finiteness test too)."""
    n = P.shape[0]
    Pf = P.reshape(-1)
    ntasks = _tasks((n + BLOCK - 1) // BLOCK)
    part = np.empty((ntasks, 7))
    for t in nb.prange(ntasks):
        s, e = t * n // ntasks, (t + 1) * n // ntasks
        _extent_run(Pf[3 * s : 3 * e], part[t])
    out = np.empty((2, 3))
    for c in range(3):
        out[0, c], out[1, c] = part[0, c], part[0, 3 + c]
        for t in range(1, ntasks):
            out[0, c] = min(out[0, c], part[t, c])
            out[1, c] = max(out[1, c], part[t, 3 + c])
    bad = 0.0
    for t in range(ntasks):
        bad += part[t, 6]
    for c in range(3):
        out[0, c] += bad
        out[1, c] += bad
    return out


@nb.njit(**_LEAF)
def _extent_run(Pf, out):
    """Smallest and largest x, y, z of flat positions Pf (3m,), m >= 1, into out[:6]; out[6]
    0, or NaN when some coordinate is not finite."""
    # on order keys (vmath.order_key): a float min/max reduction stays scalar without nnan,
    # an integer one vectorises (2.5x faster in float32)
    lx = hx = order_key(Pf[0])
    ly = hy = order_key(Pf[1])
    lz = hz = order_key(Pf[2])
    for i in range(Pf.shape[0] // 3):
        x, y, z = order_key(Pf[3 * i]), order_key(Pf[3 * i + 1]), order_key(Pf[3 * i + 2])
        lx, hx = min(lx, x), max(hx, x)
        ly, hy = min(ly, y), max(hy, y)
        lz, hz = min(lz, z), max(hz, z)
    # the finiteness test: a second pass over the run, in cache and contiguous (inside the loop
    # above it cost half as much as the whole loop); x·0 is 0, or NaN for a NaN or an infinite
    # x (not folded to 0: the kernels never allow nnan/ninf; x - x would be, by reassociation)
    bad = Pf[0] * 0
    for i in range(Pf.shape[0]):
        bad += Pf[i] * 0
    out[0], out[1], out[2] = from_key(lx), from_key(ly), from_key(lz)
    out[3], out[4], out[5] = from_key(hx), from_key(hy), from_key(hz)
    out[6] = bad


@nb.njit(**_LEAF)
def _view(px, py, pz, nx, ny, nz, ex, ey, ez, vx, vy, vz, trk, k):
    """V = normalize(eye - P) for a local viewer; V = N where the eye is at the vertex (a lane
    near the eye is marked, as one near a light: "at the vertex" is decided in float64)."""
    one, eps2, c_dist2 = unit(k), k[K_POINT_EPS] * k[K_POINT_EPS], k[K_MARGIN_DIST2]
    for i in range(px.shape[0]):
        x = ex - px[i]
        y = ey - py[i]
        z = ez - pz[i]
        d2 = x * x + y * y + z * z
        at = d2 < eps2
        inv = one / np.sqrt(max(d2, eps2))  # (a reciprocal square root: no divide)
        a, b, c = nx[i], ny[i], nz[i]
        vx[i] = a if at else x * inv
        vy[i] = b if at else y * inv
        vz[i] = c if at else z * inv
        trk[i] = min(trk[i], d2 * c_dist2)


@nb.njit(**_LEAF)
def _dot(ax, ay, az, bx, by, bz, out):
    for i in range(out.shape[0]):
        out[i] = ax[i] * bx[i] + ay[i] * by[i] + az[i] * bz[i]


@nb.njit(**_LEAF)
def _two_sided(nx, ny, nz, vx, vy, vz, trk, k):
    """N -> -N where N·V < 0 (the vertex shows its back face)."""
    zero, c_dot = k[K_ZERO], k[K_MARGIN_DOT]
    for i in range(nx.shape[0]):
        ndv = nx[i] * vx[i] + ny[i] * vy[i] + nz[i] * vz[i]
        s = ndv < zero
        nx[i] = -nx[i] if s else nx[i]
        ny[i] = -ny[i] if s else ny[i]
        nz[i] = -nz[i] if s else nz[i]
        trk[i] = min(trk[i], abs(ndv) * c_dot)


@nb.njit(parallel=True, **_OPTS)
def bounds(src, k, out, step):
    """What light culling knows of each chunk of :data:`CHUNK` consecutive vertices.

    src : the pass's geometry: G (6, n) T prepared (see :func:`prepare`), or a
    :class:`Source` (of vertices: each chunk prepared here as :func:`prepare` would: the same
    bounds); k : constants(T)
    out : (N_BOUNDS, ceil(n / CHUNK)) float64: the bounding sphere of the chunk's positions
    (centre of its box, radius to the farthest vertex) and the cone of its normals (axis: their
    mean direction; half-angle: the widest normal from it), both widened by
    :data:`explorer.core.tolerances.CULL_GUARD`. A cone of 90° or more, or a chunk with an absent
    (zero) normal, gets cosine -1: never culled.
    step : every chunk (1), or every ``step``-th one (columns 0, step, 2·step ...; the others
    are left as they were): a sample, to see whether culling can pay before finding them all
    """
    nj = (out.shape[1] + step - 1) // step
    ntasks = max(1, min(nj, TASKS))
    for t in nb.prange(ntasks):
        gb = np.empty((6, CHUNK), k.dtype)  # (a chunk of vertices, prepared: once per task)
        _bounds_run(src, k, out, step, t * nj // ntasks, (t + 1) * nj // ntasks, gb)


@nb.njit(**_LEAF)
def _bounds_run(src, k, out, step, j0, j1, gb):
    """Columns j0·step, (j0 + 1)·step ... (j1 - 1)·step of :func:`bounds`' ``out``: the rows
    :func:`_geometry` gives are views without reference counts, used here only."""
    n = _vertex_count(src)
    for j in range(j0, j1):
        s = j * step * CHUNK
        e = min(n, s + CHUNK)
        g, _ = _geometry(src, s, e, gb, k)
        _chunk_bounds(g, j * step, out)


@nb.njit(**_LEAF)
def _chunk_bounds(g, c, out):
    """Column ``c`` of :func:`bounds`' ``out`` from the chunk's geometry ``g``: six (m,) rows,
    m <= CHUNK (positions, unit normals; see :func:`prepare`)."""
    gx, gy, gz, gnx, gny, gnz = g
    guard = tol.CULL_GUARD
    # (scalars, not small arrays: an allocation per chunk cost more than the chunk)
    lx = ly = lz = np.inf
    hx = hy = hz = -np.inf
    ax = ay = az = 0.0
    for i in range(gx.shape[0]):
        x, y, z = np.float64(gx[i]), np.float64(gy[i]), np.float64(gz[i])
        lx, ly, lz = min(lx, x), min(ly, y), min(lz, z)
        hx, hy, hz = max(hx, x), max(hy, y), max(hz, z)
        ax += np.float64(gnx[i])
        ay += np.float64(gny[i])
        az += np.float64(gnz[i])
    cx, cy, cz = 0.5 * (lx + hx), 0.5 * (ly + hy), 0.5 * (lz + hz)
    r2 = 0.0
    for i in range(gx.shape[0]):
        x = np.float64(gx[i]) - cx
        y = np.float64(gy[i]) - cy
        z = np.float64(gz[i]) - cz
        r2 = max(r2, x * x + y * y + z * z)
    r = np.sqrt(r2) * (1.0 + guard) + guard
    la = np.sqrt(ax * ax + ay * ay + az * az)
    ct = -1.0
    if la > 0.0:
        ax, ay, az = ax / la, ay / la, az / la
        ct = 1.0
        for i in range(gx.shape[0]):
            nn = ax * gnx[i] + ay * gny[i] + az * gnz[i]
            ct = min(ct, nn)  # an absent normal gives 0: never culled
        ct -= guard
    if ct <= 0.0:
        ct = -1.0
    out[B_CX, c], out[B_CY, c], out[B_CZ, c], out[B_R, c] = cx, cy, cz, r
    out[B_AX, c], out[B_AY, c], out[B_AZ, c] = ax, ay, az
    out[B_COS, c] = ct
    out[B_SIN, c] = np.sqrt(max(1.0 - ct * ct, 0.0)) + guard


@nb.njit(**_LEAF)
def _reach(bd, c0, nc, q, fl, back, act):
    """Which of chunks ``c0`` to ``c0 + nc - 1`` light ``q`` can reach: ``act[j]`` 1 if chunk
    c0 + j may get something from it, 0 if provably nothing (returns how many may).

    bd : (N_BOUNDS, nchunks) float64, every chunk's bounds (see :func:`bounds`; whole, not a
    slice: a C-contiguous array's rows have a known unit stride, and the loop vectorises)
    back : skip chunks whose every vertex faces away from the light (N·L <= -AMBIGUOUS_DOT):
    their diffuse and specular are 0 in either precision (not when the light's ambient varies
    per vertex: that does not depend on N·L). Chunks wholly outside a spot's cone (by
    AMBIGUOUS_DOT in the cosine) are skipped always: the spot factor zeroes everything.
    The light must be farther than AMBIGUOUS_DIST from every vertex (else "at the vertex"
    lights it fully), so no margin the float32 pass keeps is lost by skipping.
    """
    eps, dist = tol.AMBIGUOUS_DOT, tol.AMBIGUOUS_DIST
    positional, cone = (fl & POSITIONAL) != 0, (fl & SPOT) != 0
    qx, qy, qz = np.float64(q[P_POS]), np.float64(q[P_POS + 1]), np.float64(q[P_POS + 2])
    if not positional:  # toward a directional light, as a unit vector
        ql = np.sqrt(qx * qx + qy * qy + qz * qz)
        qx, qy, qz = qx / ql, qy / ql, qz / ql
    sx, sy, sz = np.float64(q[P_AXIS]), np.float64(q[P_AXIS + 1]), np.float64(q[P_AXIS + 2])
    cosc = np.float64(q[P_COS]) - eps
    back_on = 1 if back else 0
    count = 0
    # branch-free (each test computed, combined as integers), so that it vectorises
    for j in range(nc):
        r, ct, st = bd[B_R, c0 + j], bd[B_COS, c0 + j], bd[B_SIN, c0 + j]
        ax, ay, az = bd[B_AX, c0 + j], bd[B_AY, c0 + j], bd[B_AZ, c0 + j]
        if positional:  # u = light - centre; N·(q - p) <= max over the cone of N·u, + r
            ux, uy, uz = qx - bd[B_CX, c0 + j], qy - bd[B_CY, c0 + j], qz - bd[B_CZ, c0 + j]
            uu = ux * ux + uy * uy + uz * uz
            t = ax * ux + ay * uy + az * uz  # |u|·cos(angle from the axis)
            # away: t·cos + sqrt(uu - t²)·sin + r + eps·(|u| + r) <= 0, without a square root:
            # h = t·cos + r + eps·(|u| + r) <= 0 and h² >= (uu - t²)·sin² (|u| <= (uu + 1) / 2)
            h = t * ct + r + eps * (0.5 * (uu + 1.0) + r)
            far = 1 if uu > (r + dist) * (r + dist) else 0
            tilt = max(uu - t * t, 0.0) * st * st
            away = (
                far & (1 if ct > 0.0 else 0) & (1 if h <= 0.0 else 0) & (1 if h * h >= tilt else 0)
            )
            outside = 0
            if cone:  # every direction light -> vertex at least cutoff (+ eps) off the axis
                sw = -(sx * ux + sy * uy + sz * uz)  # |u|·cos(axis, centre seen from the light)
                rr = np.sqrt(max(uu - r * r, 0.0))  # |u|·cos(the sphere's angular radius)
                rim = sw * rr + np.sqrt(max(uu - sw * sw, 0.0)) * r - cosc * uu
                outside = far & (1 if sw <= rr else 0) & (1 if rim <= 0.0 else 0)
        else:
            t = ax * qx + ay * qy + az * qz  # (as above, with |u| = 1 and r = 0)
            h = t * ct + eps
            tilt = max(1.0 - t * t, 0.0) * st * st
            away = (1 if ct > 0.0 else 0) & (1 if h <= 0.0 else 0) & (1 if h * h >= tilt else 0)
            outside = 0
        a = 1 - ((back_on & away) | outside)
        act[j] = a
        count += a
    return count


# --------------------------------------------------------------------------------------------
# One light over one block: the light loop. It is specialised at compile time on a few named
# choices (a :class:`~explorer.shading.codegen.Loop`), so that each combination is a loop that
# holds exactly the terms it needs and no run-time test:
#
# - ``source``, where L and the weight w come from: SRC_CONST (a directional light: L constant,
#   w = 1), SRC_ROWS (rows the light's pre-passes filled: L, w = attenuation · spot · shadow ...,
#   see :func:`_light_run`), SRC_INLINE (a plain point light: L and the attenuation computed in
#   the loop itself, no rows written or read);
# - ``lobe``, how the specular lobe's base is found: LOBE_FLAT (shininess 0: base^0 = 1),
#   LOBE_CONST_H (Blinn with a constant halfway vector), LOBE_BLINN, LOBE_PHONG, or LOBE_NONE
#   (no specular: the diffuse alone);
# - ``grey`` (inline only): the light's diffuse and specular colours are grey (r = g = b, as most
#   lights are): it adds one number per vertex to a grey row instead of three to the RGB rows; the
#   block adds the grey rows to every channel once.
#
# Every valid combination is in :data:`~explorer.shading.codegen.LIGHT_LOOPS`; :func:`_light_loop`
# calls the one a light needs (its code from :func:`_run_codes`) through the table of entry
# points :func:`loop_table` fills: no table is written by hand, and each loop is compiled once,
# on its own (the module docstring gives the cost). What is cheap to decide
# at run time is not a variant: whether the light adds diffuse (a specular-only pass adds w·N·L
# times a zero colour), whether it is attenuated (1, 0, 0 otherwise: w = 1 exactly).
#
# Inline loops keep l = position - P unnormalised (N·L = (N·l)/|l|, L + V = l/|l| + V in one
# fused step each) and take N·H's numerator as N·L + N·V, with N·V computed once per block (row
# R_NV). On the float32 path (ambiguity tracking on) they drop the exact policies inside the
# ambiguity bands (a light at the vertex, L = -V): there they only keep every value finite and
# mark the lane, which the engine redoes in float64. On the float64 path they apply the policies
# with selects (L = N at the vertex; a zero lobe where L = -V), as the row pre-passes do. Every
# light that stores its lobe (the first pass of a shininess drag) writes base and weight rows
# from the same arithmetic as a pass that does not, so a shininess change and a fresh pass agree
# bit for bit in the base. On the float64 path a loop with a lobe stops at those rows, and a
# second loop adds w·f·base^n·s_i from them: the float64 chain of one lane (square roots,
# divisions, pow64) is too long for the core to overlap two lanes' chains within one loop
# (``benchmarks/bench_revisions.py --precision float64`` compares); float32 keeps the lobe in the
# one loop (its chain is shorter). That second loop (:func:`_split_lobe`) raises to the power
# only the lanes with a lobe weight when many have none (the vertices facing away from the light).
# The float64 loops that split write the base's square to the base row (see :func:`lobe_power`):
# base^n = (base²)^(n/2), and Blinn's base² = (N·u)²/|u|² with u = l + |l|·V = |l|·(L + V) needs
# neither 1/|L + V| (a square root and a division) nor 1/|l|; the inline loop then divides
# twice and takes one square root per vertex-light, where it took two of each.


@nb.njit(inline="always", **_LEAF)
def _add_light(G, X, Y, Z, i, t, r, g, b, grey):
    """Lane i of a sum += t·(r, g, b): of the grey row G (r = g = b), or of the rows X, Y, Z
    (``grey`` is a compile-time constant where the light loops call it)."""
    if grey:
        G[i] += t * r
    else:
        X[i] += t * r
        Y[i] += t * g
        Z[i] += t * b


def _light(scr, m, q, y, k, atten, l_dif, code):  # pragma: no cover - replaced by the overload
    raise NotImplementedError


@overload(_light, prefer_literal=True, jit_options=_LEAF)
def _light_overload(scr, m, q, y, k, atten, l_dif, code):
    """The light loop for a literal ``code`` (see the comment above)."""
    if not isinstance(code, types.IntegerLiteral):
        raise TypingError("_light needs a literal code")
    loop = loop_of(code.literal_value)
    inline, const = loop.source == SRC_INLINE, loop.source == SRC_CONST
    spec = loop.lobe != LOBE_NONE
    mode = loop.lobe
    lobe_on = spec and mode != LOBE_FLAT
    grey = loop.grey
    track = scr.dtype == types.float32  # only the float32 path marks ambiguous lanes
    # float64: the lobe (base^n) in a second loop over the rows B and WS the first writes (see
    # the comment above)
    split = lobe_on and not track
    # float64 inline Blinn: the base row's base² found without 1/|L + V| (see the comment above)
    square = split and inline and mode == LOBE_BLINN
    # inline loops take rows LLVM checks for overlap at run time (see _row_checked), so that
    # it interleaves them; the row-path loops read and write too many rows for such checks
    row = _row_checked if inline else _row
    # float64's smallest normal number, LOBE_BASE_MIN² (compared with base² where it splits)
    tiny2 = float(np.finfo(np.float64).tiny)

    def impl(scr, m, q, y, k, atten, l_dif, code):
        # rows as separate 1-D arrays: lets the compiler vectorise
        px, py, pz = row(scr, R_PX, m), row(scr, R_PY, m), row(scr, R_PZ, m)
        nx, ny, nz = row(scr, R_NX, m), row(scr, R_NY, m), row(scr, R_NZ, m)
        vx, vy, vz, NV = row(scr, R_VX, m), row(scr, R_VY, m), row(scr, R_VZ, m), row(scr, R_NV, m)
        Lx, Ly, Lz, W = row(scr, R_LX, m), row(scr, R_LY, m), row(scr, R_LZ, m), row(scr, R_W, m)
        Dx, Dy, Dz = row(scr, R_DX, m), row(scr, R_DY, m), row(scr, R_DZ, m)
        Sx, Sy, Sz = row(scr, R_SX, m), row(scr, R_SY, m), row(scr, R_SZ, m)
        B, WS, TRK = row(scr, R_BASE, m), row(scr, R_WS, m), row(scr, R_TRK, m)
        GD, GS = row(scr, R_GD, m), row(scr, R_GS, m)
        zero, one, two = k[K_ZERO], unit(k), k[K_TWO]
        # (squares and abs: provably >= 0, which keeps the square roots vectorisable; see nil)
        h_eps2, p_eps2, floor = abs(k[K_HALF_EPS2]), k[K_POINT_EPS] ** 2, k[K_ATT_FLOOR]
        c_dot, c_len2, c_dist2 = k[K_MARGIN_DOT], k[K_MARGIN_LEN2], k[K_MARGIN_DIST2]
        # not attenuated: 1 / max(1 + 0·d, floor) = 1
        kc = q[P_ATT] if atten else one
        kl = q[P_ATT + 1] if atten else zero
        kq = q[P_ATT + 2] if atten else zero
        # a specular-only pass adds 0 to the diffuse sums it does not recompute
        dr, dg, db = (q[P_DIF], q[P_DIF + 1], q[P_DIF + 2]) if l_dif else (zero, zero, zero)
        sr, sg, sb = q[P_SPEC], q[P_SPEC + 1], q[P_SPEC + 2]
        qx, qy, qz = q[P_POS], q[P_POS + 1], q[P_POS + 2]
        hx, hy, hz = q[P_H], q[P_H + 1], q[P_H + 2]
        for i in range(m):
            a, b, c = nx[i], ny[i], nz[i]
            # margin: how far this lane is from every decision that hangs on a nearly-zero
            # quantity, in units of its ambiguity band (< 1: inside a band; see TRK)
            margin = k[K_INF]
            if inline:  # l = position - P, unnormalised; L = l / |l|
                x = qx - px[i]
                yy = qy - py[i]
                z = qz - pz[i]
                d2 = x * x + yy * yy + z * z
                if track:
                    inv = one / np.sqrt(max(d2, p_eps2))  # finite even at the light (marked)
                    d = d2 * inv
                    w = one / max(kc + (kl + kq * d) * d, floor)  # 1 / (kc + kl·d + kq·d²)
                else:  # the policy: at the light, L = N (l = N, |l| taken as 1), d = 0
                    at = d2 < p_eps2
                    d = zero if at else np.sqrt(d2)
                    r = one if at else d
                    x = a if at else x
                    yy = b if at else yy
                    z = c if at else z
                    # one division for 1/|l| and w = 1 / (kc + kl·d + kq·d²): 1 / (|l|·att)
                    att = max(kc + (kl + kq * d) * d, floor)
                    rcp = one / (r * att)
                    inv = att * rcp
                    w = r * rcp if atten else one
                nl = a * x + b * yy + c * z  # N·l
                ndl = nl * inv  # N·L
                margin = d2 * c_dist2
            else:
                if const:  # directional: constant L, never attenuated
                    lx, ly, lz, w = qx, qy, qz, one
                else:  # L and w from the pre-pass rows
                    lx, ly, lz, w = Lx[i], Ly[i], Lz[i], W[i]
                ndl = a * lx + b * ly + c * lz  # N·L
            _add_light(GD, Dx, Dy, Dz, i, w * max(ndl, zero), dr, dg, db, grey)  # w·(N·L)⁺·d_i
            if spec:
                ws = w if ndl > zero else zero  # f_i: specular only where N·L > 0
                margin = min(margin, abs(ndl) * c_dot)
                lob = one  # flat lobe: 0**0 = 1
                if lobe_on:
                    if mode == LOBE_CONST_H:  # Blinn, constant H: N·H
                        base = a * hx + b * hy + c * hz
                    elif mode == LOBE_PHONG:  # Phong: R·V, R = 2(N·L)N - L
                        ex, ey, ez = vx[i], vy[i], vz[i]
                        if inline:  # N·V from the block's row, L·V from l
                            ldv = (x * ex + yy * ey + z * ez) * inv
                            base = two * ndl * NV[i] - ldv
                        else:
                            ndv = a * ex + b * ey + c * ez
                            base = two * ndl * ndv - (lx * ex + ly * ey + lz * ez)
                    elif square:  # Blinn, float64 inline: base² (see the comment above)
                        # u = l + |l|·V (|l| = 1 at the light, where l = N); |L + V|² below
                        # its epsilon is |u|² below it times |l|²
                        ux = x + r * vx[i]
                        uy = yy + r * vy[i]
                        uz = z + r * vz[i]
                        ndu = nl + r * NV[i]
                        h2 = ux * ux + uy * uy + uz * uz
                        ok = (h2 > h_eps2 * (r * r)) & (ndu > zero)
                        base = ndu * ndu / (h2 if ok else one) if ok else zero
                    else:  # Blinn: N·normalize(L + V); 0 where L = -V
                        if inline:  # u = L + V; N·u = N·L + N·V (the block's row)
                            ux = x * inv + vx[i]
                            uy = yy * inv + vy[i]
                            uz = z * inv + vz[i]
                            ndu = ndl + NV[i]
                        else:
                            ux = lx + vx[i]
                            uy = ly + vy[i]
                            uz = lz + vz[i]
                            ndu = a * ux + b * uy + c * uz
                        h2 = ux * ux + uy * uy + uz * uz
                        if track:  # lanes near L = -V are marked and redone in float64
                            base = ndu * (one / np.sqrt(max(h2, h_eps2)))
                        else:
                            ok = h2 > h_eps2
                            hn = one / np.sqrt(h2 if ok else one)
                            base = ndu * hn if ok else zero
                        margin = min(margin, h2 * c_len2)
                    margin = min(margin, abs(base) * c_dot)
                    base = max(base, zero)
                    # kept for a lobe store (and the lobe loop below): squared where it splits,
                    # 0 below float64's smallest normal number (tolerances.LOBE_BASE_MIN)
                    b2 = base * base if split and not square else base
                    B[i] = (b2 if b2 >= tiny2 else zero) if split else b2
                    if not split:
                        lob = fpow(base, y)  # base^n
                if not split:
                    _add_light(GS, Sx, Sy, Sz, i, ws * lob, sr, sg, sb, grey)  # w·f·base^n·s_i
                WS[i] = ws
            if track and (spec or inline):
                TRK[i] = min(TRK[i], margin)
        if split:  # (the base row holds base²: see lobe_power)
            _split_lobe(scr, m, y * lobe_power(k), sr, sg, sb, grey)

    return impl


#: the float64 lobe loop packs the lanes that have a lobe weight before it takes their powers
#: when they are at most this share of its lanes (see :func:`_split_lobe`; 1/2 against 3/4 was
#: faster on random points and on a mesh in its own order: ``benchmarks/bench_revisions.py``).
#: AVX2 packs by a table-driven permute (:data:`explorer.shading.vmath.PACK`) and takes its
#: powers in 4 lanes, so packing pays up to a larger share there: 3/4 (the lobe loop alone,
#: ``benchmarks/bench_isa_code.py``'s: packing every run was faster up to about 80 % of the
#: lanes weighted, 1.75 against 3.04 ns a lane at 40 %). Without either the packing is written
#: out lane by lane and costs more than it saves: there only a run with no weight at all skips
#: its powers (0)
PACK_SHARE = {"compress": 0.5, "permute": 0.75}.get(PACK, 0.0)


@nb.njit(**_LEAF)
def _split_lobe(scr, m, y, sr, sg, sb, grey):
    """The float64 light loops' lobe: S += ws·base^n·s_i from the rows R_BASE and R_WS
    (``y``: the exponent for what the base row holds, n/2 for base², see :func:`lobe_power`).

    A lane whose weight ws is 0 (facing away from the light, outside its cone, in shadow) adds
    0 whatever its power, and the power is most of the loop's work: when such lanes are at least
    1 - PACK_SHARE of the run, the others are packed to the front of row R_PACK
    (:func:`explorer.shading.vmath.compress8`), raised to the power there, and put back in their
    lanes of row R_LOBE (:func:`explorer.shading.vmath.expand8`; 0 elsewhere). Every lane gets
    the same value as from the loop over all lanes."""
    B, WS = _row(scr, R_BASE, m), _row(scr, R_WS, m)
    GS, Sx, Sy, Sz = _row(scr, R_GS, m), _row(scr, R_SX, m), _row(scr, R_SY, m), _row(scr, R_SZ, m)
    kept = 0.0
    for i in range(m):
        kept += 1.0 if WS[i] > 0.0 else 0.0
    if kept > PACK_SHARE * m:
        for i in range(m):
            _add_light(GS, Sx, Sy, Sz, i, WS[i] * fpow(B[i], y), sr, sg, sb, grey)
        return
    C, E = _row(scr, R_PACK, m), _row(scr, R_LOBE, m)
    whole = m - m % 8  # lanes in whole groups of 8; the rest one by one
    nc = 0
    for i in range(0, whole, 8):
        nc += compress8(B, WS, i, C, nc)
    for i in range(whole, m):
        if WS[i] > 0.0:
            C[nc] = B[i]
            nc += 1
    for j in range(nc):
        C[j] = fpow(C[j], y)
    k = 0
    for i in range(0, whole, 8):
        k += expand8(C, k, WS, i, E)
    for i in range(whole, m):
        E[i] = C[k] if WS[i] > 0.0 else 0.0
        k += 1 if WS[i] > 0.0 else 0
    for i in range(m):
        _add_light(GS, Sx, Sy, Sz, i, WS[i] * E[i], sr, sg, sb, grey)


def _light_entry(code: int):
    """The light loop of ``code`` as a function of its own, ``_light_<code>`` (a numba
    dispatcher, cached on its own like any kernel; its source is written here, one line that
    calls :func:`_light` with the literal code)."""
    name = f"_light_{code}"
    params = "scr, m, q, y, k, atten, l_dif"
    src = f"def {name}({params}):\n    _light({params}, {code})\n"
    space = {"__name__": __name__, "_light": _light}
    exec(compile(src, __file__, "exec"), space)  # noqa: S102
    return nb.njit(**_LEAF)(space[name])


# every light loop, a module global each (so that the cache's guard and its list of files,
# :func:`explorer.shading.warm.dispatchers`, find them as they find every kernel)
for _code in LIGHT_LOOPS:
    globals()[f"_light_{_code}"] = _light_entry(_code)


def light_signature(dtype) -> tuple:
    """The numba types a light loop is compiled for (and :func:`_call_light` calls it with):
    scratch, lanes, the light's parameter row, the exponent, the constants, attenuated,
    adds diffuse."""
    T = nb.from_dtype(np.dtype(dtype))
    row = types.Array(T, 1, "C", readonly=True)
    return (types.Array(T, 1, "C"), types.intp, row, T, row, types.boolean, types.boolean)


_tables: dict = {}  # precision -> its table (read only)
_filled: dict = {}  # precision -> the array its table views, written by loop_table alone
_tables_lock = threading.Lock()


def loop_table(dtype, codes=None) -> np.ndarray:
    """The table of the light loops of a precision: (64,) int64, read only, the entry point of
    each code of :data:`~explorer.shading.codegen.LIGHT_LOOPS` compiled so far (0 for the
    others), given to the kernels with the lights (:class:`Lights`). One table per precision
    and process, filled as passes ask: each loop of ``codes`` (None: every loop) that it lacks
    is compiled, or loaded from numba's cache, first (a pass asks for the loops it calls,
    :func:`pass_loops`; a kernel that meets a 0 runs no loop for that light). While
    :func:`loops_elsewhere` is on, nothing is compiled (the table stays as it is).

    The kernels call a light loop through this table (:func:`_call_light`), not as a function
    numba links in: numba copies every function a kernel calls into the kernel's own code, and
    LLVM optimises and generates all of it again for each kernel of the chain that calls it
    (``_light_loop``, :func:`_block`, :func:`_task`, the parallel loop of :func:`shade`,
    :func:`shade`, :func:`fixup`): the 36 light loops were most of the cold compile's LLVM time.
    So each loop compiles on its own, once, when a scene first needs it: a session of point
    lights compiles a few of the 36, and the background compile's partner process compiles them
    all while the other compiles the chain (:mod:`explorer.shading.warm`).
    Compiled with the target's vectors in the precision's lanes (16 float32 or 8 float64 at
    512 bits, 8 or 4 at 256: :func:`explorer.shading.codegen.lanes`,
    :func:`explorer.shading.codegen.wide_vectors`)."""
    dt = np.dtype(dtype)
    table = _tables.get(dt)
    wanted = LIGHT_LOOPS if codes is None else codes
    if table is not None and (_elsewhere[0] or all(table[c] for c in wanted)):
        return table
    with _tables_lock:
        table = _tables.get(dt)
        if table is None:  # (a read-only view of an array that is filled below)
            _filled[dt] = np.zeros(64, np.int64)
            table = _tables[dt] = _filled[dt].view()
            table.flags.writeable = False
        missing = [] if _elsewhere[0] else [c for c in wanted if not table[c]]
        if missing:
            sig = light_signature(dt)
            with wide_vectors(lanes(dt.itemsize)):
                for code in missing:
                    d = globals()[f"_light_{code}"]
                    d.compile(sig)
                    cres = d.overloads[sig]
                    fn = cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name)
                    if not fn:  # pragma: no cover - numba lost a symbol
                        raise RuntimeError(f"the light loop {code} has no entry point")
                    # (entries only go from 0 to an address: a pass reading the table in another
                    # thread meanwhile sees either, and calls only loops it asked for)
                    _filled[dt][code] = fn
    return table


#: whether :func:`loop_table` leaves the loops to another process (see :func:`loops_elsewhere`)
_elsewhere = [False]


def loops_elsewhere(on: bool) -> None:
    """Make :func:`loop_table` compile no light loop (``on``) or compile as passes ask again: for
    the background compile's main process, whose passes compile the kernels that call the loops
    while its partner process compiles the loops themselves (:mod:`explorer.shading.warm`); its
    passes then run no light loop (their colours are not used). Turning it off forgets the
    tables filled meanwhile."""
    with _tables_lock:
        _elsewhere[0] = bool(on)
        _tables.clear()
        _filled.clear()


@intrinsic
def _call_light(typingctx, fn, scr, m, q, y, k, atten, l_dif):
    """Call the light loop at address ``fn`` (an entry of :func:`loop_table`) with numba's own
    calling convention, the arguments cast to :func:`light_signature`: an indirect call, so the
    caller's code holds no copy of the loop."""
    if not isinstance(fn, types.Integer) or not isinstance(scr, types.Array):
        return None
    target = light_signature(scr.dtype.name)

    def codegen(context, builder, sig, args):
        given = zip(args[1:], sig.args[1:], target, strict=True)
        vals = [context.cast(builder, v, t, to) for v, t, to in given]
        fnty = context.call_conv.get_function_type(types.none, target)
        callee = builder.inttoptr(args[0], fnty.as_pointer())
        context.call_conv.call_function(builder, callee, types.none, target, vals)
        return context.get_dummy_value()

    return types.none(fn, scr, m, q, y, k, atten, l_dif), codegen


@nb.njit(**_LEAF)
def _light_loop(loops, scr, m, q, y, k, atten, l_dif, code):
    """Run the light loop of the run-time ``code`` (see
    :func:`explorer.shading.codegen.loop_code`) from ``loops`` (:func:`loop_table`)."""
    fn = loops[code]
    if fn != 0:
        _call_light(fn, scr, m, q, y, k, atten, l_dif)


@nb.njit(**_LEAF)
def _to_light(scr, m, q, k, atten):
    """Positional pre-pass: rows L = normalize(q - P) (L = N at the vertex) and the weight
    w = 1 / max(kc + kl·d + kq·d², floor) when ``atten`` (kl, kq scaled to the frame), else 1."""
    one, eps2, c_dist2 = unit(k), k[K_POINT_EPS] * k[K_POINT_EPS], k[K_MARGIN_DIST2]
    floor = k[K_ATT_FLOOR]
    kc, kl, kq = q[P_ATT], q[P_ATT + 1], q[P_ATT + 2]
    qx, qy, qz = q[P_POS], q[P_POS + 1], q[P_POS + 2]
    px, py, pz = _row(scr, R_PX, m), _row(scr, R_PY, m), _row(scr, R_PZ, m)
    nx, ny, nz = _row(scr, R_NX, m), _row(scr, R_NY, m), _row(scr, R_NZ, m)
    Lx, Ly, Lz, W, TRK = (
        _row(scr, R_LX, m),
        _row(scr, R_LY, m),
        _row(scr, R_LZ, m),
        _row(scr, R_W, m),
        _row(scr, R_TRK, m),
    )
    if atten:
        for i in range(m):
            x = qx - px[i]
            y = qy - py[i]
            z = qz - pz[i]
            d2 = x * x + y * y + z * z
            at = d2 < eps2
            inv = one / np.sqrt(one if at else d2)
            d = k[K_ZERO] if at else d2 * inv  # at the light: distance 0 (POINT_EPS)
            a, b, c = nx[i], ny[i], nz[i]
            Lx[i] = a if at else x * inv
            Ly[i] = b if at else y * inv
            Lz[i] = c if at else z * inv
            W[i] = one / max(kc + (kl + kq * d) * d, floor)  # 1 / (kc + kl·d + kq·d²)
            TRK[i] = min(TRK[i], d2 * c_dist2)
    else:
        for i in range(m):
            x = qx - px[i]
            y = qy - py[i]
            z = qz - pz[i]
            d2 = x * x + y * y + z * z
            at = d2 < eps2
            inv = one / np.sqrt(one if at else d2)
            a, b, c = nx[i], ny[i], nz[i]
            Lx[i] = a if at else x * inv
            Ly[i] = b if at else y * inv
            Lz[i] = c if at else z * inv
            W[i] = one
            TRK[i] = min(TRK[i], d2 * c_dist2)


@nb.njit(**_LEAF)
def _spot(scr, m, q, k, exponent):
    """w *= x**exponent inside the cone (x = (-L)·axis >= cos cutoff), else 0."""
    zero, c_dot = k[K_ZERO], k[K_MARGIN_DOT]
    ax, ay, az = q[P_AXIS], q[P_AXIS + 1], q[P_AXIS + 2]
    cosc, e = q[P_COS], q[P_EXP]
    Lx, Ly, Lz, W, TRK = (
        _row(scr, R_LX, m),
        _row(scr, R_LY, m),
        _row(scr, R_LZ, m),
        _row(scr, R_W, m),
        _row(scr, R_TRK, m),
    )
    for i in range(m):
        x = -(Lx[i] * ax + Ly[i] * ay + Lz[i] * az)
        if exponent:
            f = fpow(max(x, zero), e)
            W[i] = W[i] * f if x >= cosc else zero
        else:
            W[i] = W[i] if x >= cosc else zero
        TRK[i] = min(TRK[i], abs(x - cosc) * c_dot)


@nb.njit(**_LEAF)
def _dir_rows(scr, m, q, one):
    """Directional light on the row path (shadows, Fresnel): rows L = constant, w = 1."""
    Lx, Ly, Lz, W = _row(scr, R_LX, m), _row(scr, R_LY, m), _row(scr, R_LZ, m), _row(scr, R_W, m)
    qx, qy, qz = q[P_POS], q[P_POS + 1], q[P_POS + 2]
    for i in range(m):
        Lx[i] = qx
        Ly[i] = qy
        Lz[i] = qz
        W[i] = one


@nb.njit(**_LEAF)
def _shadow(scr, m, vis):
    """w = 0 where the light is hidden: ``vis`` (m,) uint8, 1 lit, 0 shadowed (from
    explorer.shading.shadows)."""
    W = _row(scr, R_W, m)
    for i in range(m):
        if vis[i] == 0:
            W[i] = 0.0


@nb.njit(**_LEAF)
def _fresnel(scr, m, q, k):
    """w *= F = F0 + (1 - F0)(1 - V·H)^5 with V·H = sqrt((1 + V·L) / 2) (unit L, V)."""
    one = k[K_ONE]
    half = one / k[K_TWO]
    f0 = q[P_F0]
    Lx, Ly, Lz, W = _row(scr, R_LX, m), _row(scr, R_LY, m), _row(scr, R_LZ, m), _row(scr, R_W, m)
    vx, vy, vz = _row(scr, R_VX, m), _row(scr, R_VY, m), _row(scr, R_VZ, m)
    for i in range(m):
        vl = Lx[i] * vx[i] + Ly[i] * vy[i] + Lz[i] * vz[i]
        c = np.sqrt(max((one + vl) * half, nil(k)))
        x = one - c
        x2 = x * x
        W[i] = W[i] * (f0 + (one - f0) * (x2 * x2 * x))


@nb.njit(**_LEAF)
def _ambient(scr, m, q):
    """A += w·a_i (an attenuated or cone-cut light ambient)."""
    ar, ag, ab = q[P_AMB], q[P_AMB + 1], q[P_AMB + 2]
    W, Ax, Ay, Az = _row(scr, R_W, m), _row(scr, R_AX, m), _row(scr, R_AY, m), _row(scr, R_AZ, m)
    for i in range(m):
        w = W[i]
        Ax[i] += w * ar
        Ay[i] += w * ag
        Az[i] += w * ab


@nb.njit(**_LEAF)
def _load_rows(src, rx, ry, rz, zero, width=3):
    """Rows from a cached block (flat (3m,), or (m,) for a grey sum: ``width`` 1), or zeros
    when the cache is empty."""
    if src.shape[0] == 0:
        _fill(rx, zero)
        _fill(ry, zero)
        _fill(rz, zero)
    elif width == 1:
        _copy(rx, src)
        _copy(ry, src)
        _copy(rz, src)
    else:
        for i in range(rx.shape[0]):
            rx[i] = src[3 * i]
            ry[i] = src[3 * i + 1]
            rz[i] = src[3 * i + 2]


@nb.njit(**_LEAF)
def _add_grey(rx, ry, rz, g):
    for i in range(g.shape[0]):
        rx[i] += g[i]
        ry[i] += g[i]
        rz[i] += g[i]


@nb.njit(**_LEAF)
def _store_rows(dst, rx, ry, rz):
    """Rows into a flat (3m,) block of an (n, 3) array."""
    for i in range(rx.shape[0]):
        dst[3 * i] = rx[i]
        dst[3 * i + 1] = ry[i]
        dst[3 * i + 2] = rz[i]


@nb.njit(**_LEAF)
def _compose_rows(out, mat, aconst, Ax, Ay, Az, Dx, Dy, Dz, Sx, Sy, Sz, clamp, k, has_a):
    """colour = e_m + a_m·(ambient) + d_m·diffuse + s_m·specular, clamped to [0, 1]; the
    per-vertex ambient rows are read only when ``has_a`` (else the constant ambient alone)."""
    lo = k[K_ZERO]
    hi = k[K_ONE] if clamp else k[K_INF]
    e0 = mat[0] + mat[3] * aconst[0]
    e1 = mat[1] + mat[4] * aconst[1]
    e2 = mat[2] + mat[5] * aconst[2]
    a0, a1, a2, d0, d1, d2 = mat[3], mat[4], mat[5], mat[6], mat[7], mat[8]
    s0, s1, s2 = mat[9], mat[10], mat[11]
    for i in range(Dx.shape[0]):
        r = e0 + d0 * Dx[i] + s0 * Sx[i]  # e + a_m·a_const + d_m·D + s_m·S
        g = e1 + d1 * Dy[i] + s1 * Sy[i]
        b = e2 + d2 * Dz[i] + s2 * Sz[i]
        if has_a:  # + a_m·A (loop-invariant: LLVM unswitches it)
            r += a0 * Ax[i]
            g += a1 * Ay[i]
            b += a2 * Az[i]
        out[3 * i] = min(max(r, lo), hi)
        out[3 * i + 1] = min(max(g, lo), hi)
        out[3 * i + 2] = min(max(b, lo), hi)


@nb.njit(**_LEAF)
def _keep_lobe(scr, m, base, ws, flat):
    """A light's lobe base (unless the lobe is flat) and weight rows into the lobe store."""
    if not flat:
        _copy(base, _row(scr, R_BASE, m))
    _copy(ws, _row(scr, R_WS, m))


@nb.njit(**_LEAF)
def _mode(fl, flat, phong):
    """How a light's lobe base is found (LOBE_*)."""
    if flat:
        return LOBE_FLAT
    if fl & CONST_H:
        return LOBE_CONST_H
    return LOBE_PHONG if phong else LOBE_BLINN


@nb.njit(**_LEAF)
def _is_inline(fl, l_dif, l_spec, mode):
    """A plain point light: L and attenuation computed in the light loop (no pre-pass)."""
    return (
        (l_dif or l_spec)
        and (fl & AMBIENT) == 0  # the path depends on the light only, not on the pass
        and (fl & (POSITIONAL | SPOT | SHADOW)) == POSITIONAL
        and not (l_spec and (fl & FRESNEL) != 0)
        and mode != LOBE_CONST_H
    )


@nb.njit(**_LEAF)
def grey_pass(flags, opts, diffuse_grey):
    """Whether a pass keeps its diffuse and specular sums in the grey rows alone: the specular
    sum is recomputed, every diffuse or specular light is an inline grey one, and the diffuse
    sum is recomputed too or grey already (``diffuse_grey``: cached (n, 1), or absent). Decided
    once per pass; the engine asks too, and gives such a pass grey (n, 1) sums to store: a
    third of the memory traffic of (n, 3) ones."""
    if opts[O_DO_SPEC] == 0 or not (opts[O_DO_DIF] != 0 or diffuse_grey):
        return False
    flat, phong = opts[O_FLAT] != 0, opts[O_PHONG] != 0
    for li in range(flags.shape[0]):
        fl = flags[li]
        l_dif, l_spec = (fl & DIFFUSE) != 0, (fl & SPECULAR) != 0
        if (l_dif or l_spec) and not (
            (fl & GREY) != 0 and _is_inline(fl, l_dif, l_spec, _mode(fl, flat, phong))
        ):
            return False
    return True


@nb.njit(**_LEAF)
def _store_grey(dst, g, width):
    """A grey row into a block of a cached sum: as it is into a grey (n, 1) sum (``width`` 1),
    into every channel of an (n, 3) one (flat (3m,)); nothing into an empty one."""
    if dst.shape[0] == 0:
        return
    if width == 1:
        _copy(dst, g)
        return
    for i in range(g.shape[0]):
        dst[3 * i] = g[i]
        dst[3 * i + 1] = g[i]
        dst[3 * i + 2] = g[i]


@nb.njit(**_LEAF)
def _compose_grey(out, mat, aconst, Ax, Ay, Az, GD, GS, clamp, k, has_a):
    """:func:`_compose_rows` when the diffuse and specular sums are grey rows alone."""
    lo = k[K_ZERO]
    hi = k[K_ONE] if clamp else k[K_INF]
    e0 = mat[0] + mat[3] * aconst[0]
    e1 = mat[1] + mat[4] * aconst[1]
    e2 = mat[2] + mat[5] * aconst[2]
    a0, a1, a2, d0, d1, d2 = mat[3], mat[4], mat[5], mat[6], mat[7], mat[8]
    s0, s1, s2 = mat[9], mat[10], mat[11]
    for i in range(GD.shape[0]):
        gd, gs = GD[i], GS[i]
        r = e0 + d0 * gd + s0 * gs  # e + a_m·a_const + d_m·D + s_m·S
        g = e1 + d1 * gd + s1 * gs
        b = e2 + d2 * gd + s2 * gs
        if has_a:  # + a_m·A (loop-invariant: LLVM unswitches it)
            r += a0 * Ax[i]
            g += a1 * Ay[i]
            b += a2 * Az[i]
        out[3 * i] = min(max(r, lo), hi)
        out[3 * i + 1] = min(max(g, lo), hi)
        out[3 * i + 2] = min(max(b, lo), hi)


@nb.njit(inline="always", **_LEAF)
def _light_run(loops, scr, m, fl, q, shininess, k, vis, l_amb, l_dif, l_spec, mode, inline):
    """One light over the first ``m`` lanes of a scratch (a block, or a run of its chunks: then
    ``scr`` starts at the run's first lane, see _block): its pre-passes (rows L and the weight
    w), then its light loop; ``vis`` : (m,) uint8 its visibility, or (0,)."""
    atten = (fl & ATTEN) != 0
    first, second = _run_codes(fl, l_dif, l_spec, mode, inline)
    if inline:  # a plain point light (see _is_inline): no pre-pass
        _light_loop(loops, scr, m, q, shininess, k, atten, l_dif, first)
        return
    fres = l_spec and (fl & FRESNEL) != 0
    rows = (fl & (POSITIONAL | SHADOW)) != 0 or fres
    if fl & POSITIONAL:  # pre-pass: L, d and w = att·spot rows
        _to_light(scr, m, q, k, atten)
        if fl & SPOT:
            _spot(scr, m, q, k, (fl & SPOT_EXP) != 0)
        if l_amb:
            _ambient(scr, m, q)
    elif rows:  # a directional light on the row path
        _dir_rows(scr, m, q, k[K_ONE])
    if fl & SHADOW:  # after the ambient: ambient light is not shadowed
        _shadow(scr, m, vis)
    if fres:  # diffuse with w, then specular with w·F
        if first >= 0:
            _light_loop(loops, scr, m, q, shininess, k, False, True, first)
        _fresnel(scr, m, q, k)
        _light_loop(loops, scr, m, q, shininess, k, False, False, second)
    elif second >= 0:  # (the weight rows hold the attenuation: not again in the loop)
        _light_loop(loops, scr, m, q, shininess, k, False, l_dif, second)


@nb.njit(**_LEAF)
def _run_codes(fl, l_dif, l_spec, mode, inline):
    """The light loops :func:`_light_run` calls for a light, in order: (first, second), each a
    code of :data:`~explorer.shading.codegen.LIGHT_LOOPS` (as
    :func:`explorer.shading.codegen.loop_code`, at run time) or -1 for none. An inline light
    runs ``first`` alone; a Fresnel light its diffuse loop (``first``, when it adds diffuse)
    and then its specular one; any other light ``second`` alone (-1 when it adds neither
    diffuse nor specular). :func:`pass_loops` runs it as Python too (so it calls no other
    kernel), so that a pass's table holds every loop the pass calls."""
    spec_lobe = mode if l_spec else LOBE_NONE
    if inline:
        return SRC_INLINE | spec_lobe << 2 | (32 if (fl & GREY) != 0 else 0), -1
    fres = l_spec and (fl & FRESNEL) != 0
    source = SRC_ROWS if (fl & (POSITIONAL | SHADOW)) != 0 or fres else SRC_CONST
    if fres:  # the diffuse loop (no lobe), then the specular one
        return (source | LOBE_NONE << 2 if l_dif else -1), source | mode << 2
    if l_dif or l_spec:
        return -1, source | spec_lobe << 2
    return -1, -1


def pass_loops(flags, opts) -> tuple[int, ...]:
    """The codes of the light loops a pass of ``flags`` (a light's flags each) with ``opts``
    (:mod:`explorer.shading.layout`'s ``O_`` options) calls, sorted: what its table must hold
    (:func:`loop_table`). Decided by the kernels' own functions, run as Python
    (:func:`_mode`, :func:`_is_inline`, :func:`_run_codes`: the choices :func:`_block` and
    :func:`_light_run` make per light), once per set of lights and options (a few
    microseconds a light; a pass after that looks them up)."""
    flat, phong = bool(opts[O_FLAT]), bool(opts[O_PHONG])
    do_dif, do_spec = bool(opts[O_DO_DIF]), bool(opts[O_DO_SPEC])
    return _pass_loops(np.asarray(flags, np.int64).tobytes(), flat, phong, do_dif, do_spec)


@functools.lru_cache(maxsize=256)
def _pass_loops(flags: bytes, flat: bool, phong: bool, do_dif: bool, do_spec: bool) -> tuple:
    codes = set()
    for fl in np.frombuffer(flags, np.int64).tolist():
        l_dif, l_spec = do_dif and (fl & DIFFUSE) != 0, do_spec and (fl & SPECULAR) != 0
        mode = _mode.py_func(fl, flat, phong)
        inline = _is_inline.py_func(fl, l_dif, l_spec, mode)
        codes.update(_run_codes.py_func(fl, l_dif, l_spec, mode, inline))
    codes.discard(-1)
    return tuple(sorted(codes))


@nb.njit(**_LEAF)
def _block(g, lights, opts, surface, k, sums, lobes, vis, marks, out, scr, layout, act, culled):
    """One block; every array is already sliced to the block's vertices (``marks``: its lanes
    and its one-element slice of the per-block counts; ``culled``: its one-element slice of the
    skipped vertex-light counts; ``act``: (L, chunks) int32, which of its chunks each light can
    reach (see :func:`_reach`), or (L, 0): no culling; ``layout``: (grey_only, dw, sw), see
    :func:`_task`).

    g : six (m,) T rows, prepared positions and normals (read only), copied into the scratch
    rows, so that every light loop takes the scratch array alone (a call that passes a tuple of
    rows copies each row's array structure: ~1 µs per light and block)
    """
    gpx, gpy, gpz, gx, gy, gz = g
    params, flags, view, loops = lights
    mat, aconst, shininess = surface
    A, D, S = sums
    base_out, ws_out = lobes
    redo, redo_count = marks
    vrows, vindex = vis
    grey_only, dw, sw = layout
    m = gpx.shape[0]
    zero = k[K_ZERO]
    two_sided, phong, flat = opts[O_TWO_SIDED] != 0, opts[O_PHONG] != 0, opts[O_FLAT] != 0
    do_amb, do_dif, do_spec = opts[O_DO_AMB] != 0, opts[O_DO_DIF] != 0, opts[O_DO_SPEC] != 0
    store_lobe = opts[O_STORE_LOBE] != 0
    px, py, pz = _row(scr, R_PX, m), _row(scr, R_PY, m), _row(scr, R_PZ, m)
    # (two-sided flips these copies)
    nx, ny, nz = _row(scr, R_NX, m), _row(scr, R_NY, m), _row(scr, R_NZ, m)
    _copy(px, gpx)
    _copy(py, gpy)
    _copy(pz, gpz)
    _copy(nx, gx)
    _copy(ny, gy)
    _copy(nz, gz)
    vx, vy, vz = _row(scr, R_VX, m), _row(scr, R_VY, m), _row(scr, R_VZ, m)
    Ax, Ay, Az = _row(scr, R_AX, m), _row(scr, R_AY, m), _row(scr, R_AZ, m)
    Dx, Dy, Dz = _row(scr, R_DX, m), _row(scr, R_DY, m), _row(scr, R_DZ, m)
    Sx, Sy, Sz = _row(scr, R_SX, m), _row(scr, R_SY, m), _row(scr, R_SZ, m)
    trk = _row(scr, R_TRK, m)

    _fill(trk, k[K_INF])  # no lane is near a decision until a light says so
    used_grey = False  # grey lights add to the grey rows (zeroed when the first one comes)
    # grey_only (see grey_pass): the diffuse and specular sums live in the grey rows alone, so
    # there are no RGB rows to zero, add to, store or compose from
    if grey_only:
        if do_dif or D.shape[0] == 0:
            _fill(_row(scr, R_GD, m), zero)
        else:  # the cached diffuse sum (grey: see grey_pass)
            _copy(_row(scr, R_GD, m), D)
        _fill(_row(scr, R_GS, m), zero)
        used_grey = True
    if two_sided or (do_spec and (not flat or opts[O_VIEW] != 0)):  # V toward the viewer
        if opts[O_LOCAL]:
            _view(px, py, pz, nx, ny, nz, view[0], view[1], view[2], vx, vy, vz, trk, k)
        else:
            _fill(vx, view[0])
            _fill(vy, view[1])
            _fill(vz, view[2])
    if two_sided:
        _two_sided(nx, ny, nz, vx, vy, vz, trk, k)
    if do_spec and not flat:  # N·V, for the inline lobes
        _dot(nx, ny, nz, vx, vy, vz, _row(scr, R_NV, m))

    # the sums: recomputed ones start at 0, the others come from the caches
    has_a = do_amb or A.shape[0] > 0  # else no per-vertex ambient: its rows stay unused
    if has_a:
        _load_rows(A[:0] if do_amb else A, Ax, Ay, Az, zero)
    if not grey_only:
        _load_rows(D[:0] if do_dif else D, Dx, Dy, Dz, zero, dw)
        _load_rows(S[:0] if do_spec else S, Sx, Sy, Sz, zero, sw)

    nc = (m + CHUNK - 1) // CHUNK
    cull = act.shape[1] > 0  # (see _reach: decided per task)
    skipped = 0
    for li in range(params.shape[0]):
        fl = flags[li]
        q = params[li, :]
        l_amb = do_amb and (fl & AMBIENT) != 0
        l_dif = do_dif and (fl & DIFFUSE) != 0
        l_spec = do_spec and (fl & SPECULAR) != 0
        if not (l_amb or l_dif or l_spec):
            continue
        mode = _mode(fl, flat, phong)
        inline = _is_inline(fl, l_dif, l_spec, mode)  # L, attenuation inline
        if inline:
            grey = (fl & GREY) != 0
            if grey and not used_grey:
                _fill(_row(scr, R_GD, m), zero)
                _fill(_row(scr, R_GS, m), zero)
            used_grey = used_grey or grey
        reach = nc
        if cull:
            reach = 0
            for j in range(nc):
                reach += act[li, j]
        # the runs of chunks it can reach (the whole block when it reaches every chunk); the
        # others get nothing (a zero lobe weight). One call site of the inlined _light_run: a
        # second, for the whole block, cost numba as much typing again at the cold compile
        c = 0
        while c < nc:
            e = nc if reach == nc else c + 1
            while e < nc and act[li, e] == act[li, c]:
                e += 1
            s0, s1 = c * CHUNK, min(m, e * CHUNK)
            if reach == nc or act[li, c]:  # the scratch from lane s0 on: rows start at lane s0
                sub = scr[s0 : s0 + N_ROWS * ROW]
                v = vrows[max(vindex[li], 0), s0:s1]  # (read only by a light flagged SHADOW)
                _light_run(
                    loops, sub, s1 - s0, fl, q, shininess, k, v, l_amb, l_dif, l_spec, mode, inline
                )
            else:
                skipped += s1 - s0
                if store_lobe and l_spec:
                    _fill(_row(scr, R_WS, m)[s0:s1], zero)
                    _fill(_row(scr, R_BASE, m)[s0:s1], zero)
            c = e
        if store_lobe and l_spec:
            _keep_lobe(scr, m, base_out[li, :], ws_out[li, :], flat)
    culled[0] = skipped

    if opts[O_TRACK]:  # mark the lanes inside some ambiguity band, if any
        lim = unit(k)
        hit = np.int32(0)
        for i in range(m):  # (an OR: vectorises; a count does not)
            hit |= np.int32(1) if trk[i] < lim else np.int32(0)
        count = 0
        if hit:  # (the marks of a block that counts none are never read)
            for i in range(m):
                redo[i] = trk[i] < lim
                count += 1 if trk[i] < lim else 0
        redo_count[0] = count
    if grey_only:
        GD, GS = _row(scr, R_GD, m), _row(scr, R_GS, m)
        if opts[O_STORE]:
            if do_amb and A.shape[0] > 0:
                _store_rows(A, Ax, Ay, Az)
            if do_dif:
                _store_grey(D, GD, dw)
            _store_grey(S, GS, sw)
        if opts[O_COMPOSE]:
            _compose_grey(out, mat, aconst, Ax, Ay, Az, GD, GS, opts[O_CLAMP] != 0, k, has_a)
        return
    if used_grey:  # the grey sums count in every channel
        _add_grey(Dx, Dy, Dz, _row(scr, R_GD, m))
        _add_grey(Sx, Sy, Sz, _row(scr, R_GS, m))
    if opts[O_STORE]:
        if do_amb and A.shape[0] > 0:
            _store_rows(A, Ax, Ay, Az)
        if do_dif and D.shape[0] > 0:
            _store_rows(D, Dx, Dy, Dz)
        if do_spec and S.shape[0] > 0:
            _store_rows(S, Sx, Sy, Sz)
    if opts[O_COMPOSE]:
        clamp = opts[O_CLAMP] != 0
        _compose_rows(out, mat, aconst, Ax, Ay, Az, Dx, Dy, Dz, Sx, Sy, Sz, clamp, k, has_a)


@nb.njit(**_LEAF)
def _task(
    src, lights, opts, surface, k, sums, lobes, vis, marks, out, work, act, b0, b1, layout, cull
):
    """Blocks b0 to b1 - 1 of a pass (compiled without reference counting: slicing the shared
    arrays here costs no atomic operations on their counts, which both threads would contend);
    returns how many of them hold a normal outside NORMAL_RANGE (vertices to prepare only; see
    :func:`_geometry`). ``src``: the pass's geometry (see :func:`shade`); ``sums`` and ``out``
    are flat (see :func:`_flat`); ``work``: the task's scratch and its (6, BLOCK) rows for a
    block of vertices; ``layout`` is (grey_only, dw, sw): the pass keeps its sums in the grey
    rows alone (:func:`grey_pass`), and the widths of the D and S sums (1: grey); ``cull`` :
    :class:`Culling`."""
    scr, gb = work
    params, flags = lights.params, lights.flags
    A, D, S = sums
    redo, redo_count = marks
    bounds, culled = cull
    dw, sw = layout[1], layout[2]
    n = _vertex_count(src)
    # light culling: which chunks of the task's blocks each light can reach, one vectorised
    # _reach per light (per block, its 16 chunks are fewer than one vector iteration); not
    # two-sided (N flips with V)
    c0, c1 = b0 * CHUNKS, min(bounds.shape[1], b1 * CHUNKS)
    cull_on = bounds.shape[1] > 0 and opts[O_TWO_SIDED] == 0
    if cull_on:
        do_amb = opts[O_DO_AMB] != 0
        for li in range(params.shape[0]):
            fl = flags[li]
            back = not (do_amb and (fl & AMBIENT) != 0)
            _reach(bounds, c0, c1 - c0, params[li, :], fl, back, act[li, :])
    outside = 0
    for b in range(b0, b1):
        s = b * BLOCK
        e = min(n, s + BLOCK)
        g, bad = _geometry(src, s, e, gb, k)
        outside += bad
        _block(
            g,
            lights,
            opts,
            surface,
            k,
            Sums(A[3 * s : 3 * e], D[dw * s : dw * e], S[sw * s : sw * e]),
            Lobes(lobes.base[:, s:e], lobes.ws[:, s:e]),
            Shadows(vis.rows[:, s:e], vis.index),
            Marks(redo[s:e], redo_count[b : b + 1]),
            out[3 * s : 3 * e],
            scr,
            layout,
            act[:, (b - b0) * CHUNKS : (b - b0 + 1) * CHUNKS] if cull_on else act[:, :0],
            culled[b : b + 1],
        )
    return outside


#: parallel tasks of a pass: blocks are dealt out in this many contiguous runs (enough to keep
#: every thread busy to the end); a task allocates its scratch rows once, not once per block
TASKS = 64


@nb.njit(**_OPTS)
def _scratch(dtype):
    """A task's scratch: N_ROWS rows of BLOCK lanes, ROW apart, and one row more, so that the
    scratch seen from any lane of a block on (``scr[s0 : s0 + N_ROWS * ROW]``, a run of chunks)
    still holds N_ROWS whole rows."""
    return np.empty((N_ROWS + 1) * ROW, dtype)


@nb.njit(**_LEAF)
def _spread(t, ntasks):
    """The run of blocks parallel task ``t`` of ``ntasks`` shades: ``t`` with its bits reversed
    when ``ntasks`` is a power of two (else ``t``). numba's threads take the tasks in contiguous
    shares (static scheduling), and culling makes work uneven across a mesh (the half a light
    faces costs, the other half is skipped): reversed bits deal every thread runs from all over
    the mesh, so the threads finish together. Used only when culling: without it the work is
    even, and each thread streaming through one contiguous half is faster
    (``benchmarks/bench_revisions.py`` compares the two)."""
    if ntasks & (ntasks - 1):
        return t
    r = 0
    w = ntasks
    while w > 1:
        r = (r << 1) | (t & 1)
        t >>= 1
        w >>= 1
    return r


@nb.njit(**_LEAF)
def _tasks(nblocks):
    return max(1, min(nblocks, TASKS))


@nb.njit(**_OPTS)
def _flat(A, D, S, out):
    """Flat (3n,) views of the (n, 3) sums and colours (see the module docstring); a grey
    (n, 1) sum gives (n,)."""
    return A.reshape(-1), D.reshape(-1), S.reshape(-1), out.reshape(-1)


class Lights(NamedTuple):
    """A pass's lights in the normalised frame: ``params`` (L, N_PARAMS) T, one row per light
    (:mod:`explorer.core.lightrow`); ``flags`` (L,) int32; ``view`` (3,) T, the eye (local
    viewer) or V (infinite viewer); ``loops`` (64,) int64, the light loops of T
    (:func:`loop_table`)."""

    params: np.ndarray
    flags: np.ndarray
    view: np.ndarray
    loops: np.ndarray


class Surface(NamedTuple):
    """The material as the kernel reads it: ``mat`` (12,) T, e, a, d, s; ``aconst`` (3,) T, the
    constant ambient sum (scene and constant light ambient); ``shininess`` T."""

    mat: np.ndarray
    aconst: np.ndarray
    shininess: float


class Sums(NamedTuple):
    """The cached light sums, ambient ``A``, diffuse ``D``, specular ``S``: (n, 3) T, or (0, 3)
    for none; D and S may be grey, (n, 1): one value for every channel, written only by a pass
    that keeps its sums in the grey rows alone (:func:`grey_pass`, which the caller asks before
    it allocates them)."""

    A: np.ndarray
    D: np.ndarray
    S: np.ndarray


class Lobes(NamedTuple):
    """Each light's specular base and weight, (L, n) T (or (L, 0): not kept), so that a
    shininess change only re-runs the lobe (:func:`lobe`)."""

    base: np.ndarray
    ws: np.ndarray


class Marks(NamedTuple):
    """Ambiguous float32 lanes (redone in float64): ``redo`` (n,) bool, ``count`` (nblocks,)
    int32 marked lanes per block of BLOCK vertices (both (0,) when not tracking); a block that
    marks none leaves its part of ``redo`` as it was: read them with :func:`marked`."""

    redo: np.ndarray
    count: np.ndarray


class Shadows(NamedTuple):
    """Shadow visibility, kept only for the lights that cast shadows: ``rows`` (S, n) uint8,
    1 lit, 0 shadowed, one row per such light (at least one row: (1, 0) when none);
    ``index`` (L,) int64, each light's row (-1: the light casts no shadows, its visibility is
    never read: the kernel reads a row only for a light flagged SHADOW)."""

    rows: np.ndarray
    index: np.ndarray


class Culling(NamedTuple):
    """Light culling: ``bounds`` (N_BOUNDS, ceil(n / CHUNK)) float64 chunk bounds (see
    :func:`bounds`), or (N_BOUNDS, 0): no culling; ``culled`` (nblocks,) int32 out: vertex-lights
    each block skipped."""

    bounds: np.ndarray
    culled: np.ndarray


@nb.njit(parallel=True, **_OPTS)
def shade(src, lights, opts, surface, k, sums, lobes, vis, marks, out, culling):
    """Shade every vertex (see the module docstring); returns how many blocks hold a normal
    outside NORMAL_RANGE or not finite (only vertices the pass prepares: 0, or scale the
    normals and shade again; see :func:`prepare`).

    src : the geometry, a :class:`Source`: G (6, n) T prepared (see :func:`prepare`), or
    vertices, each block prepared as the pass reaches it (a one-shot pass: no G written, and the
    pass reads the caller's positions and normals instead of G's six rows); lights :
    :class:`Lights`
    opts : (N_OPTS,) int64; surface : :class:`Surface`; k : constants(T)
    sums : :class:`Sums` (read where not recomputed, written where stored); lobes :
    :class:`Lobes`; vis : :class:`Shadows`, the visibility of the lights flagged SHADOW
    marks : :class:`Marks`; out : (n, 3) colours; culling : :class:`Culling`
    """
    n = _vertex_count(src)
    nblocks = (n + BLOCK - 1) // BLOCK
    ntasks = _tasks(nblocks)
    D, S = sums.D, sums.S
    Af, Df, Sf, outf = _flat(sums.A, D, S, out)
    # once per pass: a diffuse sum not recomputed here must be grey already, or absent
    grey_only = grey_pass(lights.flags, opts, D.shape[0] == 0 or D.shape[1] == 1)
    dw, sw = D.shape[1], S.shape[1]  # 1 for a grey sum, else 3
    # a pass that is not grey writes three values per vertex: a grey sum would overflow
    if not grey_only and opts[O_STORE] != 0:
        if (opts[O_DO_DIF] != 0 and dw == 1 and D.shape[0]) or (
            opts[O_DO_SPEC] != 0 and sw == 1 and S.shape[0]
        ):
            raise ValueError("grey (n, 1) sums need a grey pass (see grey_pass)")
    culls = culling.bounds.shape[1] > 0
    L = lights.params.shape[0]
    outside = 0
    for t in nb.prange(ntasks):
        scr = _scratch(lights.params.dtype)  # once per task: no allocation per block
        gb = np.empty((6, _lanes_to_prepare(src)), k.dtype)  # (a block of vertices, prepared)
        # (dealt across the mesh only when culling: contiguous halves stream faster, 1.04x)
        r = _spread(np.int64(t), np.int64(ntasks)) if culls else np.int64(t)
        b0, b1 = r * nblocks // ntasks, (r + 1) * nblocks // ntasks
        act = np.empty((L, (b1 - b0) * CHUNKS if culls else 0), np.int32)
        flat = Sums(Af, Df, Sf)
        layout = (grey_only, dw, sw)
        outside += _task(
            src,
            lights,
            opts,
            surface,
            k,
            flat,
            lobes,
            vis,
            marks,
            outf,
            (scr, gb),
            act,
            b0,
            b1,
            layout,
            culling,
        )
    return outside


@nb.njit(**_OPTS)
def marked(redo, redo_count):
    """Indices of the lanes to redo in float64, (k,) int64, from a pass's ``redo`` marks and
    per-block ``redo_count``: only the blocks that counted some are read."""
    idx = np.empty(redo_count.sum(), np.int64)
    j = 0
    for b in range(redo_count.shape[0]):
        if redo_count[b]:
            for i in range(b * BLOCK, min(redo.shape[0], b * BLOCK + BLOCK)):
                if redo[i]:
                    idx[j] = i
                    j += 1
    return idx


@nb.njit(**_OPTS)
def _gather_sum(X, idx):
    """Rows ``idx`` of a cached sum as (m, 3) float64 (a grey (n, 1) sum in every channel), or
    (0, 3) for an empty one."""
    m = idx.shape[0] if X.shape[0] else 0
    out = np.empty((m, 3))
    for j in range(m):
        for c in range(3):
            out[j, c] = X[idx[j], c if X.shape[1] == 3 else 0]
    return out


@nb.njit(**_OPTS)
def fixup(marks, src, lights, opts, surface, k, sums, lobes, vis, out, no_bounds):
    """Redo the lanes a float32 pass marked in float64, where the policies hold exactly, and
    write the results over the float32 ones; returns how many lanes.

    marks : the pass's :class:`Marks` (see :func:`marked`)
    src : the pass's vertices as a float64 pass takes them (a :class:`Source` of float64 type:
    (n, 3) world positions and normals, float64 or float32, and the frame; no prepared rows)
    lights, surface, k : the pass's inputs in float64 (:class:`Lights`, :class:`Surface`,
    constants); opts : the pass's (ambiguity tracking is switched off here)
    sums, lobes, vis, out : the pass's float32 arrays, written at the marked lanes
    no_bounds : (N_BOUNDS, 0) float64, read-only (as a pass's bounds are): no culling
    (one compiled call: gathering, shading and scattering ~150 lanes from Python cost about as
    much as a light at 1M vertices). The lanes are shaded through the float64 pass's own
    compiled code: every argument of its :func:`_task` has the type a float64 pass gives
    (hence ``src``, ``no_bounds`` and the run-time False and 0 below: a literal types the call
    anew), so that the light loops are not linked and optimised again for a third chain.
    """
    redo, redo_count = marks
    A, D, S = sums
    base_out, ws_out = lobes
    idx = marked(redo, redo_count)
    m = idx.shape[0]
    if m == 0:
        return 0
    L = lights.params.shape[0]
    Pm, Nm = np.empty((m, 3)), np.empty((m, 3))
    wide = src.P.shape[0] > 0  # float64 vertices, else float32
    for j in range(m):
        for c in range(3):
            Pm[j, c] = src.P[idx[j], c] if wide else src.P32[idx[j], c]
            Nm[j, c] = src.N[idx[j], c] if wide else src.N32[idx[j], c]
    nblocks = (m + BLOCK - 1) // BLOCK
    G = np.empty((6, m))
    frame = (src.centre, src.inv_scale)
    _prepare_blocks(Pm.reshape(-1), Nm.reshape(-1), *frame, k, G, 0, nblocks)
    o = opts.copy()
    o[O_TRACK] = 0
    Am, Dm, Sm = _gather_sum(A, idx), _gather_sum(D, idx), _gather_sum(S, idx)
    lobes = m if base_out.shape[1] else 0
    bm, wm = np.zeros((L, lobes)), np.zeros((L, lobes))
    rows = vis.rows
    vm = np.empty((rows.shape[0], m if rows.shape[1] else 0), np.uint8)
    for r in range(vm.shape[0]):
        for j in range(vm.shape[1]):
            vm[r, j] = rows[r, idx[j]]
    om = np.empty((m, 3))
    none = Marks(np.zeros(0, np.bool_), np.zeros(0, np.int32))
    rgb = m < 0  # False: the float64 pass keeps RGB sums (a run-time bool, see above)
    layout = (rgb, Dm.shape[1], Sm.shape[1])
    _task(
        Source(G, src.P, src.N, src.P32, src.N32, src.centre, src.inv_scale),  # (G's rows)
        lights,
        o,
        surface,
        k,
        Sums(Am.reshape(-1), Dm.reshape(-1), Sm.reshape(-1)),
        Lobes(bm, wm),
        Shadows(vm, vis.index),
        none,
        om.reshape(-1),
        (_scratch(np.float64), np.empty((6, 0))),  # (G: no block to prepare)
        np.empty((L, 0), np.int32),
        np.int64(0),
        nblocks,
        layout,
        Culling(no_bounds, np.zeros(nblocks, np.int32)),  # (lanes not in chunks)
    )
    for j in range(m):
        i = idx[j]
        for c in range(3):
            out[i, c] = om[j, c]
        for c in range(A.shape[1] if A.shape[0] else 0):
            A[i, c] = Am[j, c]
        for c in range(D.shape[1] if D.shape[0] else 0):  # (a grey sum: its lights are grey)
            D[i, c] = Dm[j, c]
        for c in range(S.shape[1] if S.shape[0] else 0):
            S[i, c] = Sm[j, c]
        for li in range(L if lobes else 0):
            base_out[li, i] = np.sqrt(bm[li, j])  # (float64 rows hold base²: lobe_power)
            ws_out[li, i] = wm[li, j]
    return m


@nb.njit(**_LEAF)
def _lobe_rows(base, ws, y, flat, cr, cg, cb, Sx, Sy, Sz):
    for i in range(ws.shape[0]):
        t = ws[i] if flat else ws[i] * fpow(base[i], y)
        Sx[i] += t * cr
        Sy[i] += t * cg
        Sz[i] += t * cb


@nb.njit(parallel=True, **_OPTS)
def lobe(base, ws, params, flags, shininess, k, S):
    """S = Σ_l ws_l·base_l^n·s_l from stored per-light bases (a shininess change).

    base, ws : (L, n) T (base unused when shininess is 0; in float64 it holds base², see
    :func:`lobe_power`, as the pass that stored it wrote it); params : (L, N_PARAMS) T;
    flags : (L,) int32; S : (n, 3) T out
    """
    n = S.shape[0]
    nblocks = (n + BLOCK - 1) // BLOCK
    ntasks = _tasks(nblocks)
    Sf = S.reshape(-1)
    for t in nb.prange(ntasks):
        scr = np.empty(3 * ROW, params.dtype)
        _lobe_task(
            base,
            ws,
            params,
            flags,
            shininess,
            k,
            Sf,
            scr,
            t * nblocks // ntasks,
            (t + 1) * nblocks // ntasks,
        )


@nb.njit(**_LEAF)
def _lobe_task(base, ws, params, flags, shininess, k, Sf, scr, b0, b1):
    """Blocks b0 to b1 - 1 of :func:`lobe` (a leaf: no reference counting, see _task)."""
    n = Sf.shape[0] // 3
    flat = shininess == k[K_ZERO]
    for b in range(b0, b1):
        s = b * BLOCK
        e = min(n, s + BLOCK)
        m = e - s
        Sx, Sy, Sz = _row(scr, 0, m), _row(scr, 1, m), _row(scr, 2, m)
        _fill(Sx, k[K_ZERO])
        _fill(Sy, k[K_ZERO])
        _fill(Sz, k[K_ZERO])
        for li in range(params.shape[0]):
            if flags[li] & SPECULAR:
                _lobe_rows(
                    base[li, s:e],
                    ws[li, s:e],
                    shininess * lobe_power(k),
                    flat,
                    params[li, P_SPEC],
                    params[li, P_SPEC + 1],
                    params[li, P_SPEC + 2],
                    Sx,
                    Sy,
                    Sz,
                )
        _store_rows(Sf[3 * s : 3 * e], Sx, Sy, Sz)


@nb.njit(**_LEAF)
def _channels(X, i, grey):
    """Vertex i's three values in a flat block of a sum: (n, 3), or grey (n, 1) (one value for
    every channel)."""
    if grey:
        return X[i], X[i], X[i]
    return X[3 * i], X[3 * i + 1], X[3 * i + 2]


def _compose_block(o, A, D, S, c, lo, hi, variant):  # pragma: no cover - overloaded below
    raise NotImplementedError


@overload(_compose_block, prefer_literal=True, jit_options=_LEAF)
def _compose_block_overload(o, A, D, S, c, lo, hi, variant):
    """One fused pass: o = c0 + cA·A + cD·D + cS·S, clamped; the sums a material does not use
    are not read at all (``variant`` bits 0, 1, 2: A, D, S present; bits 3, 4: D, S grey, one
    value per vertex for every channel)."""
    if not isinstance(variant, types.IntegerLiteral):
        raise TypingError("_compose_block needs a literal variant")
    v = variant.literal_value
    has_a, has_d, has_s = bool(v & 1), bool(v & 2), bool(v & 4)
    grey_d, grey_s = bool(v & 8), bool(v & 16)

    def impl(o, A, D, S, c, lo, hi, variant):
        c0, c1, c2 = c[0], c[1], c[2]
        a0, a1, a2, d0, d1, d2, s0, s1, s2 = c[3], c[4], c[5], c[6], c[7], c[8], c[9], c[10], c[11]
        for i in range(o.shape[0] // 3):  # flat (3m,) blocks of (n, 3) arrays
            r, g, b = c0, c1, c2  # e_m + a_m·(scene and constant light ambient)
            if has_a:  # a_m·A (attenuated light ambient)
                x, y, z = _channels(A, i, False)
                r, g, b = r + a0 * x, g + a1 * y, b + a2 * z
            if has_d:  # d_m·D
                x, y, z = _channels(D, i, grey_d)
                r, g, b = r + d0 * x, g + d1 * y, b + d2 * z
            if has_s:  # s_m·S
                x, y, z = _channels(S, i, grey_s)
                r, g, b = r + s0 * x, g + s1 * y, b + s2 * z
            o[3 * i] = min(max(r, lo), hi)
            o[3 * i + 1] = min(max(g, lo), hi)
            o[3 * i + 2] = min(max(b, lo), hi)

    return impl


def _compose_any(o, A, D, S, c, lo, hi, v):  # pragma: no cover - overloaded below
    raise NotImplementedError


@overload(_compose_any, jit_options=dict(_LEAF, cache=False))  # (cached with its callers)
def _compose_any_overload(o, A, D, S, c, lo, hi, v):
    """Call the compose loop compiled for the run-time variant ``v`` (see
    :func:`_compose_block`: D and S each absent, RGB or grey, A present or not): one test and
    one literal call per entry of :data:`~explorer.shading.codegen.COMPOSE_VARIANTS`
    (:func:`~explorer.shading.codegen.dispatch_source`)."""
    params = "o, A, D, S, c, lo, hi, v"
    space = {"_compose_block": _compose_block}
    exec(dispatch_source("impl", params, "_compose_block", COMPOSE_VARIANTS), space)  # noqa: S102
    return space["impl"]


@nb.njit(parallel=True, **_OPTS)
def compose(mat, aconst, A, D, S, clamp, k, out):
    """Colours from cached sums: out = e + a_m·(aconst + A) + d_m·D + s_m·S, clamped.

    A, D, S : (n, 3) T or (0, 3) for "all zero"; D and S may be grey, (n, 1); out : (n, 3)
    """
    n = out.shape[0]
    v = (1 if A.shape[0] > 0 else 0) | (2 if D.shape[0] > 0 else 0) | (4 if S.shape[0] > 0 else 0)
    dw, sw = D.shape[1], S.shape[1]  # 1 for a grey sum, else 3
    v |= (8 if v & 2 and dw == 1 else 0) | (16 if v & 4 and sw == 1 else 0)
    lo = k[K_ZERO]
    hi = k[K_ONE] if clamp else k[K_INF]
    c = mat.copy()
    for ch in range(3):
        c[ch] = mat[ch] + mat[3 + ch] * aconst[ch]
    chunk = COMPOSE_BLOCK
    nblocks = (n + chunk - 1) // chunk
    Af, Df, Sf, outf = _flat(A, D, S, out)
    for b in nb.prange(nblocks):
        s = b * chunk
        e = min(n, s + chunk)
        _compose_any(
            outf[3 * s : 3 * e],
            Af[3 * s : 3 * e] if v & 1 else Af,
            Df[dw * s : dw * e] if v & 2 else Df,
            Sf[sw * s : sw * e] if v & 4 else Sf,
            c,
            lo,
            hi,
            v,
        )


#: vertices per parallel task of a recompose (a streaming pass: large chunks, few tasks)
COMPOSE_BLOCK = 16384


@nb.njit(parallel=True, **_OPTS)
def stream(P, N, out):
    """The memory-bandwidth floor of a recolour: read positions and normals once, write
    colours once (out = P + N). Used only by the benchmark, as the yardstick."""
    Pf, Nf, outf = P.reshape(-1), N.reshape(-1), out.reshape(-1)  # flat views (module docstring)
    n = outf.shape[0]
    chunk = 3 * COMPOSE_BLOCK
    nblocks = (n + chunk - 1) // chunk
    for b in nb.prange(nblocks):
        s = b * chunk
        e = min(n, s + chunk)
        _add(Pf[s:e], Nf[s:e], outf[s:e])


@nb.njit(**_LEAF)
def _add(p, q, o):
    for i in range(o.shape[0]):
        o[i] = p[i] + q[i]


# the entry points, each compiled with wide float32 vectors where the CPU has them (see
# explorer.shading.codegen.wide); the number is the argument whose dtype picks the precision
prepare = wide(prepare, 5)
extent = wide(extent, 0)
bounds = wide(bounds, 1, item=8)  # (float64 arithmetic; 16 lanes left its 32-lane chunks scalar)
shade = wide(shade, 4)
lobe = wide(lobe, 2)
compose = wide(compose, 7)
fixup = wide(fixup, 5, item=8)  # (float64: it shares the float64 pass's compiled code)
stream = wide(stream, 2)
