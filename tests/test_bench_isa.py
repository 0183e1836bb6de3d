"""The benchmarks' ``--isa native|avx2|both`` (benchmarks/isa.py; issue 44): each ISA measured in
a child process with its numba target and cache, the children taking turns, their figures side by
side, and the machine line saying what numba compiled for (the registers of the code it made).
No timing is asserted: the children here are small scripts, or a probe compile of one loop."""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))

import isa  # noqa: E402 - benchmarks/isa.py, after its folder is on the path

#: a benchmark in miniature: records what its environment says, as bench_engine records rows
FAKE = """
import argparse, os, sys
sys.path.insert(0, {bench!r})
import isa
ap = argparse.ArgumentParser()
isa.add_arguments(ap)
args = ap.parse_args()
if args.isa and not isa.in_child():
    sys.exit(isa.run(__file__, sys.argv[1:], args))
print("child", os.environ[isa.CHILD], os.environ.get("NUMBA_CPU_NAME"),
      os.environ.get("NUMBA_CPU_FEATURES"), os.environ.get("NUMBA_CACHE_DIR"), flush=True)
avx2 = os.environ.get("NUMBA_CPU_NAME") == "znver3"
isa.record("a pass", 30.0 if avx2 else 10.0)
isa.record("rays", 2.0 if avx2 else 8.0, "M rays/s")
isa.record("recolour / floor", 3.0 if avx2 else 1.5, "x")
isa.write_results()
"""


def _script(tmp_path) -> Path:
    path = tmp_path / "fake_bench.py"
    path.write_text(FAKE.format(bench=str(ROOT / "benchmarks")))
    return path


def test_the_avx2_child_compiles_for_zen3_into_its_own_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "host"))
    env = isa.child_env("avx2", tmp_path / "avx2", "out.json")
    assert env["NUMBA_CPU_NAME"] == "znver3" and env["NUMBA_CPU_FEATURES"] == "-avx512f"
    assert env["NUMBA_CACHE_DIR"] == str(tmp_path / "avx2")
    assert env[isa.CHILD] == "avx2" and env[isa.RESULTS] == "out.json"
    assert env["PYTHONPATH"].split(os.pathsep)[0] == str(ROOT)
    # without --cache-dir: the persistent folder (a second run loads what the first compiled)
    assert isa.child_env("avx2", None, "x")["NUMBA_CACHE_DIR"] == str(isa.default_cache())


def test_the_native_child_drops_a_target_the_caller_set(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CPU_NAME", "haswell")
    monkeypatch.setenv("NUMBA_CPU_FEATURES", "+avx2")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "host"))
    env = isa.child_env("native", tmp_path / "avx2", "out.json")
    assert "NUMBA_CPU_NAME" not in env and "NUMBA_CPU_FEATURES" not in env
    assert env["NUMBA_CACHE_DIR"] == str(tmp_path / "host")  # the host's cache, as it was


def test_both_runs_the_isas_in_turns_and_sets_their_figures_side_by_side(tmp_path):
    script = _script(tmp_path)
    cache = str(tmp_path / "avx2-cache")
    out = subprocess.run(
        [sys.executable, str(script), "--isa", "both", "--alternate", "2", "--cache-dir", cache],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    children = [ln.split() for ln in out.stdout.splitlines() if ln.startswith("child ")]
    assert [c[1] for c in children] == ["native", "avx2", "native", "avx2"]  # in turns
    for c in children:
        if c[1] == "avx2":
            assert c[2:] == ["znver3", "-avx512f", cache]
        else:
            assert c[2:4] == ["None", "None"]
    table = out.stdout[out.stdout.index("| case |") :].splitlines()
    head = "| case | unit | native (2 processes) | avx2 (2 processes) | avx2 / native (time) |"
    assert table[0] == head
    assert "| a pass | ms | 10 | 30 | 3.00x |" in table  # times: avx2's over native's
    assert "| rays | M rays/s | 8 | 2 | 4.00x |" in table  # rates: native's over avx2's
    assert "| recolour / floor | x | 1.5 | 3 | 2.00x |" in table


def test_one_isa_prints_its_child_and_no_table(tmp_path):
    out = subprocess.run(
        [sys.executable, str(_script(tmp_path)), "--isa", "native"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    assert "child native" in out.stdout and "| case |" not in out.stdout


def test_a_failing_child_fails_the_run(tmp_path):
    script = tmp_path / "broken.py"
    script.write_text(
        _script(tmp_path).read_text().replace('print("child"', 'sys.exit(3); print("child"')
    )
    out = subprocess.run(
        [sys.executable, str(script), "--isa", "both"], capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 3
    assert "error: the native child exited with status 3" in out.stderr


def test_the_registers_name_the_widest_vectors():
    zmm = "vmovups (%rdi), %zmm0\n\tvaddps %ymm1, %ymm2, %ymm3\n"
    assert isa.registers(zmm) == {"zmm": 1, "ymm": 3, "xmm": 0}
    assert isa.widest(zmm) == "zmm (512-bit)"
    assert isa.widest("vaddps %ymm1, %ymm2, %ymm3") == "ymm (256-bit)"
    assert isa.widest("addss %xmm0, %xmm1") == "xmm (128-bit)"
    assert isa.widest("ret") == "no vector registers"


LINE = "import sys; sys.path.insert(0, {bench!r}); import isa; print(isa.isa_line())"


def _line(env) -> str:
    code = LINE.format(bench=str(ROOT / "benchmarks"))
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300
    )
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


@pytest.mark.skipif(not isa.host_has("avx2"), reason="this CPU cannot run AVX2 code")
def test_the_avx2_childs_machine_line_says_what_numba_compiled(tmp_path):
    """The line reads the code numba made for the kernels' loops in the child: 256-bit ymm
    registers for Zen 3, and the float64 lobe packed by AVX2's permute."""
    line = _line(isa.child_env("avx2", tmp_path, str(tmp_path / "r.json")))
    assert line.startswith("ISA avx2: numba targets znver3 (features -avx512f); ")
    assert "kernel code in ymm (256-bit) registers" in line
    assert "float64 lobe: AVX2 permute (PACK_SHARE 0.75)" in line


@pytest.mark.skipif(not isa.host_has("avx512f"), reason="this CPU has no AVX-512")
def test_the_native_childs_machine_line_on_an_avx512_host_says_zmm(tmp_path):
    env = isa.child_env("native", None, str(tmp_path / "r.json"))
    env.pop("PHONG_EXPLORER_WIDE_VECTORS", None)
    line = _line(env)
    assert line.startswith("ISA native: numba targets ")
    assert "(host features)" in line and "kernel code in zmm (512-bit) registers" in line
    assert "float64 lobe: AVX-512 compress" in line


@pytest.mark.parametrize("bench", ["bench_engine", "bench_rays"])
def test_the_benchmarks_hand_isa_to_the_children(bench, monkeypatch):
    """``--isa`` in bench_engine.py and bench_rays.py starts the children (isa.run) with the
    script and its arguments, before measuring anything."""
    module = __import__(bench)
    calls = []

    def run(script, argv, args):
        calls.append((Path(script).name, argv, args.isa, args.alternate))
        return 0

    monkeypatch.setattr(isa, "run", run)
    monkeypatch.delenv(isa.CHILD, raising=False)
    argv = ["--isa", "both", "--alternate", "3", "--repeat", "2"]
    assert module.main(argv) == 0
    assert calls == [(f"{bench}.py", argv, "both", 3)]


def test_the_arguments():
    ap = argparse.ArgumentParser()
    isa.add_arguments(ap)
    args = ap.parse_args(["--isa", "avx2", "--cache-dir", "/tmp/x"])
    assert (args.isa, args.cache_dir, args.alternate) == ("avx2", Path("/tmp/x"), 1)
    assert isa.isas("both") == ("native", "avx2") and isa.isas("avx2") == ("avx2",)
    with pytest.raises(SystemExit):
        ap.parse_args(["--isa", "avx512"])
    assert textwrap.dedent(isa.__doc__).startswith("``--isa native|avx2|both``")


ASM = """_ZN8__main__1fB2v1:
\tvaddps\t%ymm1, %ymm2, %ymm3
\tvfmadd213ss\t%xmm1, %xmm2, %xmm3
\tvsqrtpd\t%ymm0, %ymm0
\tjne\t.LBB0_1
_ZN7cpython8__main__1fB2v1:
\tvaddps\t%zmm1, %zmm2, %zmm3
\tcallq\t*%rax
"""
IR = """define i32 @_ZN8__main__1fB2v1(ptr %a) {
  %x = fmul fast <8 x float> %a, %b
  %y = fadd fast <8 x float> %x, %b
  %z = fadd fast <4 x double> %c, %d
  %p = call double @pow(double %u, double %v)
  %e = call i32 @numba_gil_ensure()
}
define i32 @_ZN7cpython8__main__1fB2v1(ptr %a) {
  %w = fmul fast <16 x float> %a, %b
}
"""


def test_the_loop_counts_read_the_compiled_functions_only():
    """bench_isa_code.py counts the instructions of the compiled functions, not of numba's
    Python wrappers (``cpython.*``), and names the IR's main vector type and its libm calls."""
    import bench_isa_code as C

    s = C.stats(ASM, IR)
    assert (s["zmm"], s["ymm"]) == (0, 5)  # the wrapper's zmm is not counted
    assert (s["packed fp"], s["scalar fp"], s["sqrt"], s["branches"]) == (1, 1, 1, 1)
    assert s["IR vectors"] == "<8 x float>"  # the most frequent, not the wrapper's widest
    assert s["IR calls"] == "pow"  # libm, not numba's own helpers
