"""The kernels' hand-written LLVM code (explorer.shading.vmath's and traverse.enter4) on CPUs
without AVX-512.

The float64 lobe's lane packing (vmath.compress8 / expand8) emits LLVM's vector compress and
masked expand intrinsics, which AVX-512 does in one instruction each and LLVM writes out
otherwise (its generic expansion of the register-form compress aborted the process on such CPUs,
hence vmath.NATIVE_COMPRESS; on AVX2 a permute by table, vmath.PERMUTE_PACK). This machine may
have AVX-512, so the intrinsics are compiled here
for portable x86-64 targets (numba's ``NUMBA_CPU_NAME`` / ``NUMBA_CPU_FEATURES``, in a
subprocess with a cache directory of its own) and must give what they give on this host: the
packing's lanes, the powers (pow32 / pow64: their bit tricks), the ordered keys, and the shadow
rays' four-box test (explorer.geometry.traverse.enter4).
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

TESTS = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# the round trip of tests/shading/test_vmath.py, with weights of every kind (0, -0, NaN,
# subnormal, infinite), checked against numpy inside the subprocess
ROUND_TRIP = """
import sys
import numba as nb, numpy as np
from explorer.shading import vmath
sys.path.insert(0, sys.argv[1])  # tests/: the round trip of test_vmath.py
from helpers.lanes import round_trip

rng = np.random.default_rng(7)
kinds = [0.0, -0.0, np.nan, 5e-324, -5e-324, np.inf, -np.inf, 1.0]
for n in (8, 16, 64):
    for w in (rng.normal(size=n), np.zeros(n), rng.random(n) + 1e-300, rng.choice(kinds, n)):
        src = rng.normal(size=n)
        packed, back, nc, k = round_trip(src, w)
        keep = w > 0
        assert nc == k == np.count_nonzero(keep), (n, w)
        assert np.array_equal(packed[:nc], src[keep]), (n, w)
        assert np.array_equal(back, np.where(keep, src, 0.0)), (n, w)

@nb.njit(error_model="numpy")
def powers_and_keys(x, y, x32, y32):
    p64, p32, back = np.empty_like(x), np.empty_like(x32), np.empty_like(x)
    for i in range(x.shape[0]):
        p64[i] = vmath.pow64(x[i], y[i])
        p32[i] = vmath.pow32(x32[i], y32[i])
        back[i] = vmath.from_key(vmath.order_key(x[i]))
    return p64, p32, back

x, y = rng.random(4096), rng.random(4096) * 128
p64, p32, back = powers_and_keys(x, y, x.astype(np.float32), y.astype(np.float32))
assert np.allclose(p64, x**y, rtol=1e-12, atol=1e-300)
assert np.allclose(p32, x.astype(np.float32) ** y.astype(np.float32), rtol=1e-4, atol=1e-30)
assert np.array_equal(back, x)

# the shadow rays' four-box test (explorer.geometry.traverse.enter4): its bits, as a digest
import hashlib
from explorer.geometry import bvh as B, traverse as T

@nb.njit
def entered(wide, O, D, t1):
    out = np.empty((wide.shape[0], O.shape[0]), np.int64)
    for w in range(wide.shape[0]):
        for r in range(O.shape[0]):
            ox, oy, oz, _, _, _, ix, iy, iz = T.ray_of(O, D, r)
            out[w, r] = T.enter4(wide, w, ox, oy, oz, ix, iy, iz, t1[r])
    return out

wide = B.aligned_rows(16, T.WIDE)
lo = rng.uniform(-1, 1, (16, 24)).astype(np.float32)
wide[:, :24] = np.where(np.arange(24) // 4 % 2 == 0, lo, lo + 0.5)  # x0 of 4, x1 of 4, ...
O, D = rng.uniform(-1.5, 1.5, (2000, 3)), rng.normal(size=(2000, 3))
D[::7, 0] = 0.0
bits = entered(wide, O, D, rng.uniform(0.1, 3.0, 2000))
assert 0 < bits.mean() < 15
asm = next(iter(round_trip.inspect_asm().values()))
from explorer.shading import codegen
print("ok", vmath.NATIVE_COMPRESS, "zmm" in asm, hashlib.sha256(bits.tobytes()).hexdigest()[:16],
      vmath.PACK or "-", codegen.VECTOR_BITS, "vpermd" in asm or "vpermps" in asm)
"""


def _run(tmp_path, **target) -> list[str]:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), **target)
    if not target:
        for name in ("NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES"):
            env.pop(name, None)
    out = subprocess.run(
        [sys.executable, "-c", ROUND_TRIP, TESTS],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr
    return out.stdout.split()


# (numba takes the host's features for a named CPU unless NUMBA_CPU_FEATURES says otherwise)
@pytest.mark.parametrize(
    "cpu, pack, bits, permute",
    [
        ("x86-64", "-", "0", "False"),  # SSE2 only: lane by lane, LLVM's own vector width
        ("znver3", "permute", "256", "True"),  # AVX2 (Zen 3): the table's permute, 256 bits
    ],
)
def test_intrinsics_on_cpus_without_avx512(cpu, pack, bits, permute, tmp_path):
    if os.uname().machine not in ("x86_64", "AMD64"):
        pytest.skip("x86-64 targets")
    got = _run(tmp_path / cpu, NUMBA_CPU_NAME=cpu, NUMBA_CPU_FEATURES="-avx512f")
    # compiled for the target asked for: no AVX-512 compress, no 512-bit registers; the
    # packing and the kernels' vector width (vmath.PACK, codegen.VECTOR_BITS) the target's
    assert got[:3] == ["ok", "False", "False"], got
    assert got[4:] == [pack, bits, permute], got
    # the four-box test enters the same boxes as on this host
    assert got[3] == _run(tmp_path / "host")[3]
