"""Writing user files safely: atomically, and never over an existing file unless asked.

One mechanism for every file the project writes (presets, renders, meshes, reports): a temporary
file in the target directory, flushed to disk and renamed into place, so a reader sees the old
file or the complete new one, never a torn one; without ``overwrite`` the rename is a hard link,
which fails if the target appeared in the meantime.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from explorer.core.errors import ExplorerError


def write_atomic(path, data: bytes, *, overwrite: bool = False, make_dirs: bool = False) -> Path:
    """Write ``data`` to ``path`` atomically; returns the path written.

    overwrite : replace an existing file (otherwise :class:`ExplorerError`)
    make_dirs : create missing parent directories (otherwise a missing directory is an error)
    Every failure is an :class:`ExplorerError` naming the path; the temporary file is removed.
    """
    target = Path(os.fspath(path))
    if target.is_dir():
        raise ExplorerError(f"{target}: is a directory; give a file name to write")
    if target.exists() and not overwrite:
        raise exists_error(target)
    parent = target.parent
    if make_dirs:
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ExplorerError(
                f"{parent}: cannot create directory: {exc.strerror or exc}"
            ) from None
    elif not parent.is_dir():
        raise ExplorerError(f"{target}: directory {str(parent)!r} does not exist")
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=parent)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        if overwrite:
            os.replace(tmp, target)
        else:
            _link_no_clobber(tmp, target)
        tmp = None
        _fsync_dir(parent)
    except ExplorerError:
        raise
    except OSError as exc:
        raise ExplorerError(f"{target}: cannot write: {exc.strerror or exc}") from None
    finally:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass
    return target


def exists_error(target: Path) -> ExplorerError:
    return ExplorerError(
        f"{target}: already exists; not overwriting it. Choose another name, or overwrite "
        "explicitly (overwrite=True / the --force option)"
    )


def _link_no_clobber(tmp: str, target: Path) -> None:
    """Move ``tmp`` to ``target`` only if ``target`` does not exist (atomic where possible)."""
    try:
        os.link(tmp, target)
    except FileExistsError:
        raise exists_error(target) from None
    except OSError:  # no hard links here (some network / FAT file systems)
        if target.exists():
            raise exists_error(target) from None
        os.replace(tmp, target)
        return
    os.unlink(tmp)


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _fsync_dir(directory: Path) -> None:
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
