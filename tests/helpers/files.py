"""Files that are not small regular files, for the tests of every reader."""

from __future__ import annotations

import os
from pathlib import Path

#: a FIFO (opening it for reading waits for a writer), /dev/zero behind a symbolic link (never
#: ends), a sparse 3 GiB file (takes no disk), a directory
KINDS = ["fifo", "zero", "sparse", "dir"]


def special_file(tmp_path: Path, kind: str, name: str) -> Path:
    """A file of ``kind`` (one of :data:`KINDS`) named ``name`` in ``tmp_path``."""
    path = tmp_path / name
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "zero":
        path.symlink_to("/dev/zero")
    elif kind == "sparse":
        with open(path, "wb") as fh:
            fh.truncate(3 << 30)
    elif kind == "dir":
        path.mkdir()
    return path


#: root's capabilities that let it past a folder's permissions (``chmod 000`` means nothing to it)
_OVERRIDES = "-dac_override,-dac_read_search"


def permissions_hold() -> list[str] | None:
    """A command prefix under which a folder's permissions hold for the command run after it:
    none for a user, and for root ``setpriv`` without the capabilities that override them
    (the files stay root's, so the test still owns them); None where neither works (a test
    then skips)."""
    if not hasattr(os, "geteuid"):
        return None
    if os.geteuid() != 0:
        return []
    import shutil
    import subprocess

    setpriv = shutil.which("setpriv")
    if setpriv is None:
        return None
    prefix = [setpriv, f"--bounding-set={_OVERRIDES}", "--"]
    probe = subprocess.run([*prefix, "true"], capture_output=True, timeout=30)
    return prefix if probe.returncode == 0 else None


#: an OBJ of two usemtl groups with its .mtl (tests/data/obj)
TWO_GROUPS = Path(__file__).resolve().parents[1] / "data" / "obj" / "two_groups.obj"


def write_two_groups(directory: Path) -> Path:
    """A copy of :data:`TWO_GROUPS` and its .mtl in ``directory``, as ``two.obj``."""
    mtl = TWO_GROUPS.with_suffix(".mtl")
    (directory / mtl.name).write_bytes(mtl.read_bytes())
    path = directory / "two.obj"
    path.write_bytes(TWO_GROUPS.read_bytes())
    return path
