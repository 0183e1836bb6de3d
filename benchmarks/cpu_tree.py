"""The CPU time of a command and of every process under it, the browser's included.

    python benchmarks/cpu_tree.py python -m pytest -n 0 tests/app/web -q -p no:randomly
    python benchmarks/cpu_tree.py /usr/bin/time -v python -m pytest ...   # both figures

``/usr/bin/time`` (and ``resource.getrusage(RUSAGE_CHILDREN)``) counts a process's children
only once their parents wait for them: Chromium's processes, started by chromedriver, are
never waited for by it, so their CPU is missing from ``time``'s figure of a web test run (a
page that spun 2 s in the browser added 0.5 s to it). This script makes itself a child
subreaper (Linux's ``PR_SET_CHILD_SUBREAPER``): every orphan under the command comes to it, it
waits for each, and their CPU is in its total. It prints one line on stderr, ``cpu_tree: exit
N; wall W s; user U s; sys S s; cpu C s``, and exits with the command's status.

Linux only. The machine's other load changes the figures a little (polling waits run
longer on a loaded machine): say the load (``uptime``) with each, and alternate the variants
compared.
"""

from __future__ import annotations

import ctypes
import os
import resource
import subprocess
import sys
import time

#: prctl's option that makes the caller the reaper of its descendants' orphans
PR_SET_CHILD_SUBREAPER = 36


def main(argv: list[str]) -> int:
    if not argv:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    if ctypes.CDLL("libc.so.6", use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) != 0:
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_CHILD_SUBREAPER) failed")
    t0 = time.monotonic()
    proc = subprocess.Popen(argv)
    status = 1
    while True:  # the command, and every orphan handed to this process, until none is left
        try:
            pid, how = os.wait()
        except ChildProcessError:
            break
        if pid == proc.pid:
            status = os.waitstatus_to_exitcode(how)
            proc.returncode = status  # (waited for here: its Popen must not wait again)
    wall = time.monotonic() - t0
    c = resource.getrusage(resource.RUSAGE_CHILDREN)
    print(
        f"cpu_tree: exit {status}; wall {wall:.1f} s; user {c.ru_utime:.1f} s; "
        f"sys {c.ru_stime:.1f} s; cpu {c.ru_utime + c.ru_stime:.1f} s",
        file=sys.stderr,
    )
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
