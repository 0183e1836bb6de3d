"""The processes the tests start: ending one (:func:`end_process`), and the ones this process
started that still run (:func:`running_children`: tests/conftest.py's ``no_child_left`` checks
that the session's fixtures ended theirs)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path


def end_process(proc: subprocess.Popen, wait: float = 30) -> None:
    """Ask ``proc`` to end (SIGTERM), and kill it if it still runs ``wait`` seconds later. A
    server keeps its session as it stops: on a machine loaded 15 to 30 deep that took more
    than 10 s (the suite's run in two workers killed test_web_parity's first server)."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(wait)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def running_children(pid: int | None = None) -> list[tuple[int, str]]:
    """The processes whose parent is ``pid`` (default: this one) and that still run (not
    zombies: a child that ended and was not waited for yet is no running process), each
    ``(pid, command line)``; none where there is no ``/proc`` (Linux's)."""
    pid = os.getpid() if pid is None else pid
    found = []
    proc = Path("/proc")
    if not proc.is_dir():
        return found
    for d in proc.iterdir():
        if not d.name.isdigit():
            continue
        try:
            stat = (d / "stat").read_text()
            cmdline = (d / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:  # (it ended meanwhile)
            continue
        # pid (comm) state ppid ...: comm may hold spaces and parentheses, so after the last ')'
        state, ppid = stat[stat.rindex(")") + 2 :].split()[:2]
        if int(ppid) == pid and state != "Z":
            found.append((int(d.name), cmdline.strip()))
    return found
