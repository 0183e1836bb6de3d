"""Powers that vectorise: x**y for the lobe and the spot factor, in float32 and float64.

numba's ``x ** y`` calls libm's ``pow`` once per element, and a loop with a call stays scalar:
the whole light loop around it then runs one lane at a time. These are inlined polynomials and
bit manipulations with no call and no branch, so the loop around them vectorises. Both compute
x**y = 2**(y·log2 x) for x in [0, ~1] and y >= 0:

- log2 x: x = 2**k · m with m in [sqrt(1/2), sqrt(2)) from the exponent bits, then ln m;
- 2**t = 2**j · 2**f with j = rint(t), f in [-1/2, 1/2], 2**j written as exponent bits.

:func:`pow32` (the float32 path): ln m = z - z²/2 + z³·P(z), z = m - 1 (P of degree 5, fitted
like Cephes logf), 2**f by a degree-5 fit; relative error about 1e-6, results below 2**-126
flush to 0.

:func:`pow64` (the float64 path): ln m = 2·atanh(s), s = (m - 1)/(m + 1), |s| <= 0.1716, by a
polynomial in s² (degree 6), and 2**f = 1 + f·Q(f) (Q of degree 9), both fitted at Chebyshev
nodes (near-minimax; relative error of each about 1e-16, at double rounding). The rounding of
t = y·log2 x itself, |t|·2**-53, dominates: **the relative error is below (|t| + 4)·2**-51**
(for t >= -1022, the normal results; about 4.6e-13 at the smallest), which
``tests/shading/test_vmath.py`` checks against exact powers (mpmath). Subnormal x is scaled by
2**54 first, so it is as exact. Results below 2**-1022 flush to 0 (an absolute error below
2.3e-308); t is capped at 1023 (x > 1 with a huge y: the result saturates near 2**1023, finite).
As OpenGL: 0**0 = 1, 0**y = 0 for y > 0, 1**y = 1.

:func:`compress8` and :func:`expand8` pack the float64 lanes a mask keeps to the front of a row
and put them back (AVX-512's ``vcompresspd`` / ``vexpandpd``): the float64 lobe loop computes its
power only for lanes whose lobe weight is positive (:func:`explorer.shading.kernels._split_lobe`).
How, by the target numba compiles for (:data:`PACK`):

- AVX-512F (:data:`NATIVE_COMPRESS`): LLVM's register-form vector compress and masked expand
  (one instruction each);
- AVX2 (:data:`PERMUTE_PACK`): each half of 4 lanes is moved by one cross-lane permute
  (``vpermps``) whose indices a table gives for its 4 mask bits (:data:`_COMPRESS`,
  :data:`_EXPAND`: 16 entries each), the lanes beyond the kept ones zeroed; the second half is
  stored after the first's kept lanes (or read from there);
- otherwise a masked compress-store and expand-load, which LLVM writes out lane by lane (its
  generic expansion of the register form aborts on CPUs without AVX-512:
  ``tests/shading/test_portable.py``), and the kernels do not pack there
  (:data:`explorer.shading.kernels.PACK_SHARE`).

:func:`order_key` maps a float to an integer of the same order (and :func:`from_key` back):
a smallest or largest value found on the keys is a reduction LLVM vectorises without
fast-math's no-NaN promise, which the kernels never make.

An edit here recompiles the kernels that inline these functions, and only those: numba's cache
of the kernel files is keyed on every source they import (:mod:`explorer.geometry.kernelcache`).
"""

from __future__ import annotations

import numba as nb
import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic, overload

from explorer.geometry import kernelcache  # noqa: F401 - before the decorators: the cache key
from explorer.shading.codegen import register_bits

_FASTMATH = {"nsz", "arcp", "contract", "afn", "reassoc"}  # never nnan/ninf: policies test them
_LEAF = dict(fastmath=_FASTMATH, error_model="numpy", boundscheck=False, cache=True, _nrt=False)

# --------------------------------------------------------------------------------------------
# float32


@intrinsic
def i2f(typingctx, x):
    """An integer's low 32 bits read as a float32."""
    if not isinstance(x, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        v = args[0]
        if v.type.width > 32:
            v = builder.trunc(v, ir.IntType(32))
        return builder.bitcast(v, ir.FloatType())

    return types.float32(x), codegen


#: log2's split point: x = 2**k · m with m in [sqrt(1/2), sqrt(2)), so ln m = ln(1 + z) has
#: |z| <= 0.41 (the range of the polynomial below)
_SPLIT = 0x3F3504F3  # the bits of float32 sqrt(1/2)


@intrinsic
def split32(typingctx, x):
    """x = 2**k · m for a positive float32 x, m in [sqrt(1/2), sqrt(2)): (k, m) as float32.

    In 32-bit integer operations and without a branch or blend (numba's own integer arithmetic
    widens to int64, which costs cross-lane conversions in SIMD code): subtracting the bits of
    sqrt(1/2) moves the split point to an exponent boundary, so the shifted difference is k and
    the bits of x minus k's exponent bits are m. x = 0 gives k = -127, m = 1.
    """
    if x != types.float32:
        return None

    def codegen(context, builder, sig, args):
        i32 = ir.IntType(32)
        ix = builder.bitcast(args[0], i32)
        tmp = builder.sub(ix, ir.Constant(i32, _SPLIT))
        k = builder.ashr(tmp, ir.Constant(i32, 23))
        im = builder.sub(ix, builder.and_(tmp, ir.Constant(i32, -(1 << 23))))
        kf = builder.sitofp(k, ir.FloatType())
        m = builder.bitcast(im, ir.FloatType())
        return context.make_tuple(builder, sig.return_type, (kf, m))

    return types.UniTuple(types.float32, 2)(types.float32), codegen


@nb.njit(inline="always", **_LEAF)
def log2_32(x):
    """log2 x for a positive, finite float32 x (-127 for x = 0)."""
    e, f = split32(x)
    z = f - np.float32(1.0)
    p = np.float32(-0.10746953303517079)  # least-squares fit, |error| <= 3.5e-7 on the range
    p = p * z + np.float32(0.15904727806564242)
    p = p * z + np.float32(-0.16972990678158706)
    p = p * z + np.float32(0.1993995441108155)
    p = p * z + np.float32(-0.24992546983782263)
    p = p * z + np.float32(0.33333703609427834)
    ln = z + z * z * (z * p - np.float32(0.5))
    return e + ln * np.float32(1.4426950408889634)


@nb.njit(inline="always", **_LEAF)
def exp2_32(t):
    """2**t for float32 t; 0 for t <= -127."""
    t = max(t, np.float32(-127.0))
    k = np.rint(t)
    fr = t - k
    q = np.float32(0.0013390867352163702)  # 2**f = 1 + f·Q(f), least squares, rel. err 2e-7
    q = q * fr + np.float32(0.00966637369320816)
    q = q * fr + np.float32(0.05550357104250901)
    q = q * fr + np.float32(0.24022348940946955)
    q = q * fr + np.float32(0.6931471880293432)
    q = q * fr + np.float32(1.0)  # exact at f = 0: 1**y == 1
    return q * i2f((np.int32(k) + np.int32(127)) << 23)


@nb.njit(inline="always", **_LEAF)
def pow32(x, y):
    """x**y for float32 x in [0, ~1] and y > 0 (see the module docstring); SIMD-friendly."""
    t = y * log2_32(x)
    return exp2_32(t if x > np.float32(0.0) else np.float32(-200.0))


# --------------------------------------------------------------------------------------------
# float64

_SPLIT64 = 0x3FE6A09E667F3BCD  # the bits of float64 sqrt(1/2)
_TINY64 = 2.0**-1022  # below: subnormal, scaled by 2**54 before the split
_LOG2E = 1.4426950408889634


@intrinsic
def split64(typingctx, x):
    """x = 2**k · m for a positive, normal float64 x, m in [sqrt(1/2), sqrt(2)): (k, m) as
    float64 (as :func:`split32`, in 64-bit integers; k goes through int32, whose conversion to
    float64 vectorises on every x86-64 vector unit)."""
    if x != types.float64:
        return None

    def codegen(context, builder, sig, args):
        i64 = ir.IntType(64)
        ix = builder.bitcast(args[0], i64)
        tmp = builder.sub(ix, ir.Constant(i64, _SPLIT64))
        k = builder.ashr(tmp, ir.Constant(i64, 52))
        im = builder.sub(ix, builder.and_(tmp, ir.Constant(i64, -(1 << 52))))
        kf = builder.sitofp(builder.trunc(k, ir.IntType(32)), ir.DoubleType())
        m = builder.bitcast(im, ir.DoubleType())
        return context.make_tuple(builder, sig.return_type, (kf, m))

    return types.UniTuple(types.float64, 2)(types.float64), codegen


@intrinsic
def exp2i64(typingctx, j):
    """2**j for an integral float64 j in [-1022, 1023], from its exponent bits."""
    if j != types.float64:
        return None

    def codegen(context, builder, sig, args):
        i64 = ir.IntType(64)
        k = builder.sext(builder.fptosi(args[0], ir.IntType(32)), i64)
        bits = builder.shl(builder.add(k, ir.Constant(i64, 1023)), ir.Constant(i64, 52))
        return builder.bitcast(bits, ir.DoubleType())

    return types.float64(j), codegen


@nb.njit(inline="always", **_LEAF)
def log2_64(x):
    """log2 x for a positive, finite float64 x (subnormals included)."""
    sub = x < _TINY64
    e, m = split64(x * 18014398509481984.0 if sub else x)  # (2**54)
    e = e - 54.0 if sub else e
    s = (m - 1.0) / (m + 1.0)
    w = s * s
    p = 0.07308224842521703  # (atanh(s)/s - 1)/w, fitted at Chebyshev nodes on [0, 0.0295]
    p = p * w + 0.07665860800278021
    p = p * w + 0.09091444562630861
    p = p * w + 0.1111110556739754
    p = p * w + 0.14285714312987743
    p = p * w + 0.19999999999949752
    p = p * w + 0.3333333333333335
    ln = 2.0 * s + (2.0 * s) * (w * p)  # ln m = 2·atanh(s)
    return e + ln * _LOG2E


@nb.njit(inline="always", **_LEAF)
def exp2_64(t):
    """2**t for float64 t <= 1023; 0 for t < -1022."""
    j = np.rint(max(t, -1022.0))
    f = t - j  # in [-1/2, 1/2]
    q = 7.070977866508138e-09  # (2**f - 1)/f, fitted at Chebyshev nodes on [-1/2, 1/2]
    q = q * f + 1.0205905413765595e-07
    q = q * f + 1.3215451633221434e-06
    q = q * f + 1.5252672924850737e-05
    q = q * f + 0.00015403530424776529
    q = q * f + 0.0013333558200794592
    q = q * f + 0.009618129107618665
    q = q * f + 0.05550410866465167
    q = q * f + 0.24022650695910075
    q = q * f + 0.6931471805599462
    q = q * f + 1.0  # exact at f = 0: 1**y == 1
    r = q * exp2i64(j)
    return r if t >= -1022.0 else 0.0


@nb.njit(inline="always", **_LEAF)
def pow64(x, y):
    """x**y for float64 x in [0, ~1] and y >= 0, relative error below (|t| + 4)·2**-51 with
    t = y·log2 x (see the module docstring); SIMD-friendly. 0**0 = 1."""
    pos = x > 0.0
    t = y * log2_64(x if pos else 1.0)
    t = t if pos else (-2000.0 if y > 0.0 else 0.0)
    return exp2_64(min(t, 1023.0))


def fpow(x, y):
    """x**y in the working precision: :func:`pow32` for float32, :func:`pow64` for float64."""
    return x**y


@overload(fpow, inline="always", jit_options=_LEAF)
def _fpow_overload(x, y):
    if x == types.float32:
        return lambda x, y: pow32(x, y)
    return lambda x, y: pow64(x, y)


# --------------------------------------------------------------------------------------------
# lane compaction (float64, 8 lanes)

_V8 = ir.VectorType(ir.DoubleType(), 8)
_M8 = ir.VectorType(ir.IntType(1), 8)


#: whether the compiled code may use AVX-512F's register-form compress (see the module docstring)
NATIVE_COMPRESS = register_bits() >= 512
#: whether it packs by AVX2's cross-lane permute and a table instead (see the module docstring)
PERMUTE_PACK = register_bits() == 256
#: how :func:`compress8` and :func:`expand8` pack: "compress" (AVX-512F), "permute" (AVX2) or
#: "" (lane by lane: too slow to pay, the kernels do not pack)
PACK = "compress" if NATIVE_COMPRESS else "permute" if PERMUTE_PACK else ""

_V4 = ir.VectorType(ir.DoubleType(), 4)
_I32x8 = ir.VectorType(ir.IntType(32), 8)
_F32x8 = ir.VectorType(ir.FloatType(), 8)


def _pairs(lanes) -> list[int]:
    """``vpermps`` indices (float32 lanes) that move float64 lanes ``lanes`` (4 of them)."""
    return [x for j in lanes for x in (2 * j, 2 * j + 1)]


#: per 4 mask bits m: the permute that moves the lanes m keeps to the front, in order (the
#: others after them: zeroed)
_COMPRESS = [_pairs([j for j in range(4) if m >> j & 1] + [0] * 4)[:8] for m in range(16)]
#: per 4 mask bits m: the permute that puts the packed lanes 0, 1, ... back in the lanes m keeps
#: (lane j takes the packed lane of its rank among them; the others: zeroed)
_EXPAND = [_pairs([bin(m & ((1 << j) - 1)).count("1") for j in range(4)]) for m in range(16)]


def _table_row(context, builder, name, table, nibble):
    """Row ``nibble`` (i64) of a permute table (16 x 8 int32), a constant of the module."""
    aty = ir.ArrayType(_I32x8, 16)
    init = ir.Constant(aty, [ir.Constant(_I32x8, row) for row in table])
    gv = context.insert_unique_const(builder.module, name, init)
    gv.align = 32
    zero = ir.Constant(ir.IntType(32), 0)
    return builder.load(builder.gep(gv, [zero, nibble], inbounds=True), align=32)


def _permute4(context, builder, name, table, half, nibble, keep):
    """The 4 float64 lanes ``half`` permuted by row ``nibble`` of ``table``, 0 where ``keep``
    (<4 x i1>) is false."""
    fnty = ir.FunctionType(_F32x8, [_F32x8, _I32x8])
    fn = cgutils.get_or_insert_function(builder.module, fnty, "llvm.x86.avx2.permps")
    idx = _table_row(context, builder, name, table, nibble)
    moved = builder.bitcast(builder.call(fn, [builder.bitcast(half, _F32x8), idx]), _V4)
    return builder.select(keep, moved, ir.Constant(_V4, [0.0] * 4))


def _nibbles(builder, mask):
    """The low and high 4 bits of an 8-lane mask (i64 each) and the low half's count (i64)."""
    bits = builder.zext(builder.bitcast(mask, ir.IntType(8)), ir.IntType(64))
    lo = builder.and_(bits, ir.Constant(ir.IntType(64), 15))
    hi = builder.lshr(bits, ir.Constant(ir.IntType(64), 4))
    fnty = ir.FunctionType(ir.IntType(64), [ir.IntType(64)])
    ctpop = cgutils.get_or_insert_function(builder.module, fnty, "llvm.ctpop.i64")
    return lo, hi, builder.call(ctpop, [lo])


def _first(builder, count):
    """The mask of lanes j < ``count`` (i64) of 4."""
    splat = builder.insert_element(
        ir.Constant(ir.VectorType(ir.IntType(64), 4), None), count, ir.Constant(ir.IntType(32), 0)
    )
    splat = builder.shuffle_vector(
        splat, splat, ir.Constant(ir.VectorType(ir.IntType(32), 4), [0] * 4)
    )
    lane = ir.Constant(ir.VectorType(ir.IntType(64), 4), [0, 1, 2, 3])
    return builder.icmp_unsigned("<", lane, splat)


def _half(builder, v, high):
    """Lanes 0-3 (or 4-7) of 8."""
    first = 4 if high else 0
    idx = ir.Constant(ir.VectorType(ir.IntType(32), 4), list(range(first, first + 4)))
    return builder.shuffle_vector(v, v, idx)


def _lanes(context, builder, aryty, ary, i):
    """A pointer to element ``i`` of a 1-D array, as a pointer to 8 float64 lanes."""
    a = context.make_array(aryty)(context, builder, value=ary)
    return builder.bitcast(builder.gep(a.data, [i]), _V8.as_pointer())


def _positive(builder, w):
    """The mask w > 0 of 8 lanes, and how many lanes it keeps (int64)."""
    mask = builder.fcmp_ordered(">", w, ir.Constant(_V8, [0.0] * 8))
    bits = builder.bitcast(mask, ir.IntType(8))
    fnty = ir.FunctionType(ir.IntType(8), [ir.IntType(8)])
    count = builder.call(
        cgutils.get_or_insert_function(builder.module, fnty, "llvm.ctpop.i8"), [bits]
    )
    return mask, builder.zext(count, ir.IntType(64))


def _is_row64(a):
    return isinstance(a, types.Array) and a.ndim == 1 and a.dtype == types.float64


@intrinsic
def compress8(typingctx, src, w, i, dst, k):
    """dst[k : k + 8] <- the lanes j of src[i : i + 8] with w[j] > 0, in order, then zeros;
    returns how many (int64). 1-D float64 arrays, i + 8 <= len(src), len(w); k + 8 <= len(dst)
    (no bounds checks: with k <= i, compacting a row into another as long never leaves it)."""
    if not (_is_row64(src) and _is_row64(w) and _is_row64(dst)):
        return None
    sig = types.int64(src, w, types.intp, dst, types.intp)

    def codegen(context, builder, sig, args):
        tsrc, tw, _, tdst, _ = sig.args
        s = builder.load(_lanes(context, builder, tsrc, args[0], args[2]), align=8)
        mask, count = _positive(
            builder, builder.load(_lanes(context, builder, tw, args[1], args[2]), align=8)
        )
        to = _lanes(context, builder, tdst, args[3], args[4])
        zeros = ir.Constant(_V8, [0.0] * 8)
        if NATIVE_COMPRESS:
            fnty = ir.FunctionType(_V8, [_V8, _M8, _V8])
            fn = cgutils.get_or_insert_function(
                builder.module, fnty, "llvm.experimental.vector.compress.v8f64"
            )
            builder.store(builder.call(fn, [s, mask, zeros]), to, align=8)
        elif PERMUTE_PACK:  # zeros in lanes 4-7, the low half's kept lanes, then the high's
            lo, hi, c0 = _nibbles(builder, mask)
            whole = _lanes(context, builder, tdst, args[3], args[4])
            at = builder.bitcast(whole, ir.DoubleType().as_pointer())
            four = builder.bitcast(
                builder.gep(at, [ir.Constant(ir.IntType(64), 4)]), _V4.as_pointer()
            )
            builder.store(ir.Constant(_V4, [0.0] * 4), four, align=8)
            low = _permute4(
                context,
                builder,
                "vmath_compress4",
                _COMPRESS,
                _half(builder, s, False),
                lo,
                _first(builder, c0),
            )
            builder.store(low, builder.bitcast(at, _V4.as_pointer()), align=8)
            high = _permute4(
                context,
                builder,
                "vmath_compress4",
                _COMPRESS,
                _half(builder, s, True),
                hi,
                _first(builder, builder.sub(count, c0)),
            )
            builder.store(high, builder.bitcast(builder.gep(at, [c0]), _V4.as_pointer()), align=8)
        else:  # zeros, then the kept lanes over them
            builder.store(zeros, to, align=8)
            fnty = ir.FunctionType(ir.VoidType(), [_V8, ir.DoubleType().as_pointer(), _M8])
            fn = cgutils.get_or_insert_function(
                builder.module, fnty, "llvm.masked.compressstore.v8f64"
            )
            builder.call(fn, [s, builder.bitcast(to, ir.DoubleType().as_pointer()), mask])
        return count

    return sig, codegen


@intrinsic
def expand8(typingctx, src, k, w, i, dst):
    """dst[i : i + 8] <- src[k], src[k + 1] ... in the lanes j with w[j] > 0 (w[i : i + 8]), in
    order, 0 in the others (the inverse of :func:`compress8`); returns how many it took (int64).
    Reads within src[k : k + 8] (with :data:`PERMUTE_PACK`, whole halves of 4 from there: k + 8
    <= len(src), as when k <= i); 1-D float64 arrays, i + 8 <= len(w), len(dst), no bounds
    checks."""
    if not (_is_row64(src) and _is_row64(w) and _is_row64(dst)):
        return None
    sig = types.int64(src, types.intp, w, types.intp, dst)

    def codegen(context, builder, sig, args):
        tsrc, _, tw, _, tdst = sig.args
        mask, count = _positive(
            builder, builder.load(_lanes(context, builder, tw, args[2], args[3]), align=8)
        )
        a = context.make_array(tsrc)(context, builder, value=args[0])
        first = builder.gep(a.data, [args[1]])
        if PERMUTE_PACK:  # the low half's lanes from src[k:], the high half's after them
            lo, hi, c0 = _nibbles(builder, mask)
            parts = []
            for nib, at, keep in (
                (lo, first, _half(builder, mask, False)),
                (hi, builder.gep(first, [c0]), _half(builder, mask, True)),
            ):
                packed = builder.load(builder.bitcast(at, _V4.as_pointer()), align=8)
                parts.append(
                    _permute4(context, builder, "vmath_expand4", _EXPAND, packed, nib, keep)
                )
            idx = ir.Constant(ir.VectorType(ir.IntType(32), 8), list(range(8)))
            lanes = builder.shuffle_vector(parts[0], parts[1], idx)
        else:
            fnty = ir.FunctionType(_V8, [ir.DoubleType().as_pointer(), _M8, _V8])
            fn = cgutils.get_or_insert_function(
                builder.module, fnty, "llvm.masked.expandload.v8f64"
            )
            lanes = builder.call(fn, [first, mask, ir.Constant(_V8, [0.0] * 8)])
        builder.store(lanes, _lanes(context, builder, tdst, args[4], args[3]), align=8)
        return count

    return sig, codegen


# --------------------------------------------------------------------------------------------
# ordered integer keys


def _key_types(t):
    if t == types.float32:
        return types.int32, 32
    if t == types.float64:
        return types.int64, 64
    return None, 0


def _flip(builder, i, width):
    """i ^ ((i >> (width - 1)) >>> 1): the bits of a negative float reversed but for its sign,
    so that integer order is float order (its own inverse)."""
    sign = builder.ashr(i, ir.Constant(ir.IntType(width), width - 1))
    return builder.xor(i, builder.lshr(sign, ir.Constant(ir.IntType(width), 1)))


@intrinsic
def order_key(typingctx, x):
    """An integer (int32 for float32 x, int64 for float64) whose order is the order of x, for
    x not NaN (-0.0 just below +0.0); :func:`from_key` gives x back."""
    it, width = _key_types(x)
    if it is None:
        return None

    def codegen(context, builder, sig, args):
        return _flip(builder, builder.bitcast(args[0], ir.IntType(width)), width)

    return it(x), codegen


@intrinsic
def from_key(typingctx, k):
    """The float whose :func:`order_key` is ``k`` (int32: float32, int64: float64)."""
    if k == types.int32:
        ft, width, lt = types.float32, 32, ir.FloatType()
    elif k == types.int64:
        ft, width, lt = types.float64, 64, ir.DoubleType()
    else:
        return None

    def codegen(context, builder, sig, args):
        return builder.bitcast(_flip(builder, args[0], width), lt)

    return ft(k), codegen
