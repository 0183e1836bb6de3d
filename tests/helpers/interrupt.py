"""Ctrl-C in the middle of a command: the command runs in a child process whose work is slowed
down (its ray kernel: each chunk announces itself on stderr and sleeps 0.1 s; or its start: the
first subcommand module announces its import and sleeps before it), and SIGINT is sent once that
work has started. Counted in chunks, never timed."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

#: the child: ``kernel`` is the name of the chunk function of explorer.geometry.bvh to slow down
_CHILD = """
import sys, time
import explorer.geometry.bvh as B
kernel = getattr(B, {kernel!r})
def slow(*args):
    sys.stderr.write("chunk\\n")  # one write: the two threads' lines never interleave
    sys.stderr.flush()
    time.sleep(0.1)
    return kernel(*args)
setattr(B, {kernel!r}, slow)
from explorer.cli import main
sys.exit(main(sys.argv[1:]))
"""


#: the child for :func:`interrupt_start`: the import of the first subcommand module is slowed
_START = """
import importlib, sys, time
import explorer.cli as cli
assert "numpy" not in sys.modules  # main() starts before the engine loads
load = importlib.import_module
def slow(name, package=None):
    if name.startswith("explorer.cli."):
        sys.stderr.write("chunk\\n")
        sys.stderr.flush()
        time.sleep(0.1)
    return load(name, package)
importlib.import_module = slow
sys.exit(cli.main(sys.argv[1:]))
"""


def interrupt_ray_work(kernel: str, argv: list[str]) -> tuple[list[str], int, int]:
    """Run ``phong-explorer argv`` with ``kernel`` slowed down and send SIGINT once its first
    chunk has started. Returns (stderr's lines other than the chunks', the chunks started after
    the first, the exit status)."""
    return _interrupt(_CHILD.format(kernel=kernel), argv)


def interrupt_start(argv: list[str]) -> tuple[list[str], int, int]:
    """Run ``phong-explorer argv`` and send SIGINT while it imports its subcommands (the engine,
    numpy, numba: about half a second of a real start); returns as :func:`interrupt_ray_work`."""
    return _interrupt(_START, argv)


def _interrupt(child: str, argv: list[str]) -> tuple[list[str], int, int]:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    proc = subprocess.Popen(
        [sys.executable, "-c", child, *argv],
        stderr=subprocess.PIPE, text=True, env=env,
        # a shell starts background jobs with SIGINT ignored, and Python then leaves it so
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )  # fmt: skip
    try:
        assert proc.stderr.readline() == "chunk\n"  # the rays have started
        proc.send_signal(signal.SIGINT)
        err = proc.communicate(timeout=60)[1]
    finally:
        proc.kill()
    lines = err.splitlines()
    return [ln for ln in lines if ln != "chunk"], lines.count("chunk"), proc.returncode
