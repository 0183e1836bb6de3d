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
