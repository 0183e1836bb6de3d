"""The yardstick for the engine's throughput: a lean fused float32 kernel, and what each of the
engine's guarantees costs on top of it.

    python benchmarks/bench_lean_kernel.py              # 1M vertices, 8 white point lights
    python benchmarks/bench_lean_kernel.py --rounds 10

The lean kernel is the hot loop alone: blocks of 512 vertices, view vector, then per point light
L, attenuation, N·L, Blinn's N·H and pow (the engine's own :func:`explorer.shading.vmath.pow32`),
grey sums, and the compose into (n, 3) colours. It has none of the engine's guarantees, so it is
not a usable shader; it shows how far the engine's full pass (``bench_engine.py``, "full shading,
float32") is from the bare arithmetic, and which guarantee costs what:

- ``floors``: the clamps that keep a light at the vertex and L = -V finite;
- ``tracking``: marking lanes whose result hangs on a nearly-zero sign (the engine redoes those
  in float64; see explorer.core.tolerances.AMBIGUOUS_DOT);
- ``store (n,3)`` / ``store grey (n,1)``: writing the diffuse and specular sums a material
  change recomposes from, per channel or once (the engine stores grey sums when every light is
  grey, as here).

Every variant is compiled once, then timed in interleaved rounds in one process (this VM's speed
drifts between processes by 30-40%); the table gives the best round and the ratio to ``lean``.
"""

from __future__ import annotations

import argparse
import sys
import time

import numba as nb
import numpy as np
from bench_engine import machine, scene_with, sphere_points  # its machine line, scene, mesh

import explorer
from explorer.core import tolerances as tol
from explorer.shading import codegen
from explorer.shading.kernels import _LEAF, _OPTS
from explorer.shading.vmath import pow32

BLOCK = 512
F = np.float32
# compiled as the engine's kernels are: the light loop without reference counting, both with
# 16-lane vectors where the engine gets them (explorer.shading.codegen.wide_vectors)
_JIT = {k: v for k, v in _OPTS.items() if k != "cache"}
_JIT_LEAF = {k: v for k, v in _LEAF.items() if k != "cache"}
# the engine's tolerances, in float32 (frozen into the kernels as constants)
AMB_DOT, AMB_LEN2 = F(tol.AMBIGUOUS_DOT), F(tol.AMBIGUOUS_LEN2)
AMB_DIST2, P_EPS2 = F(tol.AMBIGUOUS_DIST**2), F(tol.POINT_EPS**2)
H_EPS2, ATT_FLOOR = F(tol.HALFWAY_EPS2), F(tol.ATTENUATION_FLOOR)


def make(track: bool, floors: bool, store: int):
    """A shading kernel with these guarantees compiled in (store: 0 no, 1 (n,3), 2 grey (n,1))."""

    @nb.njit(**_JIT_LEAF)
    def light(px, py, pz, nx, ny, nz, vx, vy, vz, GD, GS, TRK, q, y, m):
        one, zero = F(1), F(0)
        qx, qy, qz, kc, kl, kq = q[0], q[1], q[2], q[3], q[4], q[5]
        for i in range(m):
            x = qx - px[i]
            yy = qy - py[i]
            z = qz - pz[i]
            d2 = x * x + yy * yy + z * z
            inv = one / np.sqrt(max(d2, P_EPS2) if floors else d2)
            lx, ly, lz = x * inv, yy * inv, z * inv
            d = d2 * inv
            att = kc + (kl + kq * d) * d
            w = one / (max(att, ATT_FLOOR) if floors else att)  # attenuation
            a, b, c = nx[i], ny[i], nz[i]
            ndl = a * lx + b * ly + c * lz
            GD[i] += w * max(ndl, zero)  # diffuse
            ux = lx + vx[i]
            uy = ly + vy[i]
            uz = lz + vz[i]
            h2 = ux * ux + uy * uy + uz * uz
            base = (a * ux + b * uy + c * uz) * (one / np.sqrt(max(h2, H_EPS2) if floors else h2))
            GS[i] += (w if ndl > zero else zero) * pow32(max(base, zero), y)  # specular
            if track:
                amb = (d2 < AMB_DIST2) | (abs(ndl) < AMB_DOT) | (h2 < AMB_LEN2)
                amb = amb | (abs(base) < AMB_DOT)
                TRK[i] = max(TRK[i], one if amb else zero)

    @nb.njit(parallel=True, **_JIT)
    def shade(G, lights, eye, y, mat, out, D, S):
        n = G.shape[1]
        nblocks = (n + BLOCK - 1) // BLOCK
        for blk in nb.prange(nblocks):
            s = blk * BLOCK
            e = min(n, s + BLOCK)
            m = e - s
            scr = np.empty((6, BLOCK), F)
            px, py, pz = G[0, s:e], G[1, s:e], G[2, s:e]
            nx, ny, nz = G[3, s:e], G[4, s:e], G[5, s:e]
            vx, vy, vz, GD, GS, TRK = (
                scr[0, :m],
                scr[1, :m],
                scr[2, :m],
                scr[3, :m],
                scr[4, :m],
                scr[5, :m],
            )
            for i in range(m):  # V toward a local viewer; sums start at 0
                x = eye[0] - px[i]
                yy = eye[1] - py[i]
                z = eye[2] - pz[i]
                inv = F(1) / np.sqrt(x * x + yy * yy + z * z)
                vx[i] = x * inv
                vy[i] = yy * inv
                vz[i] = z * inv
                GD[i] = 0
                GS[i] = 0
                TRK[i] = 0
            for li in range(lights.shape[0]):
                light(px, py, pz, nx, ny, nz, vx, vy, vz, GD, GS, TRK, lights[li], y, m)
            if store == 1:  # flat views of the (n, 3) sums, as the engine writes them
                Db, Sb = D[3 * s : 3 * e], S[3 * s : 3 * e]
                for i in range(m):
                    Db[3 * i] = GD[i]
                    Db[3 * i + 1] = GD[i]
                    Db[3 * i + 2] = GD[i]
                    Sb[3 * i] = GS[i]
                    Sb[3 * i + 1] = GS[i]
                    Sb[3 * i + 2] = GS[i]
            elif store == 2:  # grey (n, 1) sums, as the engine writes them for grey lights
                D[s:e] = GD
                S[s:e] = GS
            o = out[3 * s : 3 * e]  # a flat view of the (n, 3) colours, as the engine's
            for i in range(m):  # compose: a + d·D + s·S, clamped
                o[3 * i] = min(mat[0] + mat[3] * GD[i] + mat[6] * GS[i], F(1))
                o[3 * i + 1] = min(mat[1] + mat[4] * GD[i] + mat[7] * GS[i], F(1))
                o[3 * i + 2] = min(mat[2] + mat[5] * GD[i] + mat[8] * GS[i], F(1))

    return shade


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--vertices", type=int, default=1_000_000)
    ap.add_argument("--lights", type=int, default=8)
    ap.add_argument("--rounds", type=int, default=6)
    args = ap.parse_args(argv)
    n, L = args.vertices, args.lights
    rng = np.random.default_rng(0)
    P, _ = sphere_points(n, rng)  # the engine benchmark's mesh: unit sphere, P = N
    G = np.ascontiguousarray(np.vstack([P.T, P.T]))
    # the engine benchmark's scene: its lights, Blinn, eye at (0, 0, 5)
    lights = np.array(
        [[*pl.position, *pl.attenuation] for pl in scene_with(L, np.random.default_rng(0)).lights],
        F,
    )
    eye = np.array([0, 0, 5], F)
    mat = np.array([0.1, 0.1, 0.1, 0.5, 0.4, 0.3, 0.8, 0.8, 0.8], F)
    out = np.empty(3 * n, F)  # (n, 3) arrays as flat views (see explorer.shading.kernels)
    sums = {1: (np.empty(3 * n, F), np.empty(3 * n, F)), 2: (np.empty(n, F), np.empty(n, F))}
    variants = {
        "lean": (False, False, 0),
        "floors": (False, True, 0),
        "tracking": (True, False, 0),
        "store (n,3)": (False, False, 1),
        "store grey (n,1)": (False, False, 2),
        "all of the above, grey (n,1)": (True, True, 2),
    }
    fns = {}
    for name, (track, floors, store) in variants.items():
        fn = make(track, floors, store)
        D, S = sums.get(store, sums[1])
        fns[name] = lambda fn=fn, D=D, S=S: fn(G, lights, eye, F(25.6), mat, out, D, S)
        with codegen.wide_vectors():
            fns[name]()  # compile
    # the engine itself, in the same rounds: a light change on a float32 Shader, as bench_engine
    scene = scene_with(L, np.random.default_rng(0))
    flip = [scene.lights, scene_with(L, np.random.default_rng(1)).lights]
    sh = explorer.Shader(scene, P, P, precision="float32")

    def relight():
        flip.reverse()
        sh.set_lights(flip[0])
        return sh.colors

    relight()
    fns["engine: Shader light change (all guarantees, caches, fix-ups)"] = relight
    best = {name: [] for name in fns}
    for _ in range(args.rounds):
        for name, fn in fns.items():
            ts = []
            for _ in range(8):
                t = time.perf_counter()
                fn()
                ts.append(time.perf_counter() - t)
            best[name].append(min(ts))
    print(f"machine: {machine()}")
    print(f"mesh: {n} vertices, {L} point lights; best of {args.rounds} interleaved rounds\n")
    print("| lean kernel + | ms | G vertex-lights/s | vs lean |")
    print("|---|---:|---:|---:|")
    lean = min(best["lean"])
    for name, ts in best.items():
        t = min(ts)
        print(f"| {name} | {t * 1e3:.2f} | {n * L / t / 1e9:.2f} | {t / lean:.2f}x |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
