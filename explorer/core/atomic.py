"""Writing user files safely: atomically, and never over an existing file unless asked.

One mechanism for every file the project writes (presets, renders, meshes, reports): a temporary
file in the target directory, flushed to disk and renamed into place, so a reader sees the old
file or the complete new one, never a torn one; without ``overwrite`` the rename is a hard link,
which fails if the target appeared in the meantime.

Leftovers: an interrupted write removes its temporary file (the CLI turns SIGTERM into an exception
so that this cleanup runs); a temporary file that survived anyway (``kill -9``, power loss) is swept
by a later write into the same directory once it is older than :data:`STALE_TEMP_AGE` (a process
lists a directory for this at most once per that age). :func:`write_all_atomic` writes several files
all-or-nothing.

What is refused before anything is written (:func:`check_target`, also called by the commands'
early checks): a name the file system cannot take (too long), a folder that cannot be searched
or does not exist, a directory at the path, an existing file without ``overwrite`` and, even
with it, anything but a regular file (a FIFO, a device, a socket: ``--force`` replaces a file,
never a pipe a reader waits on). Every refusal and every failure is one
:class:`~explorer.core.errors.ExplorerError` naming the path; no ``OSError`` leaves this module.
"""

from __future__ import annotations

import os
import re
import stat
import tempfile
import time
from collections.abc import Mapping
from pathlib import Path

from explorer.core.errors import ExplorerError
from explorer.core.files import file_kind

#: A temporary file of this module's naming older than this (seconds) is a leftover of a killed
#: run: the next write into its directory removes it. A live write keeps touching its file and
#: takes well under a second per file, so a minute never catches one in progress.
STALE_TEMP_AGE = 60.0
#: The temporaries' names: ``.<target name>.<8 random characters of mkstemp>.tmp``.
TEMP_NAME = re.compile(r"\..+\.[a-z0-9_]{8}\.tmp")
#: directory -> when this process last swept it: a directory is listed at most once per
#: STALE_TEMP_AGE (the window rewrites its state file after every frame; a leftover younger
#: than that would not be removed anyway)
_swept: dict[str, float] = {}


def sweep_stale_temps(directory, *, now: float | None = None) -> list[Path]:
    """Remove leftover temporaries of :func:`write_atomic` in ``directory``: regular files (not
    symlinks) named like :data:`TEMP_NAME`, owned by this user, last modified more than
    :data:`STALE_TEMP_AGE` seconds ago. Returns the files removed; never raises for a file
    it cannot remove or a directory it cannot list."""
    now = time.time() if now is None else now
    uid = os.getuid() if hasattr(os, "getuid") else None
    removed: list[Path] = []
    try:
        entries = list(os.scandir(directory))
    except OSError:
        return removed
    for entry in entries:
        if not TEMP_NAME.fullmatch(entry.name):
            continue
        try:
            st = entry.stat(follow_symlinks=False)
            if not stat.S_ISREG(st.st_mode) or (uid is not None and st.st_uid != uid):
                continue
            if now - st.st_mtime <= STALE_TEMP_AGE:
                continue
            os.unlink(entry.path)
        except OSError:
            continue
        removed.append(Path(entry.path))
    return removed


def _sweep_now_and_then(directory) -> None:
    """:func:`sweep_stale_temps` unless this process swept ``directory`` within the last
    STALE_TEMP_AGE seconds."""
    key, now = os.fspath(directory), time.monotonic()
    if now - _swept.get(key, -STALE_TEMP_AGE) >= STALE_TEMP_AGE:
        _swept[key] = now
        sweep_stale_temps(directory)


def write_atomic(path, data: bytes, *, overwrite: bool = False, make_dirs: bool = False) -> Path:
    """Write ``data`` to ``path`` atomically; returns the path written.

    overwrite : replace an existing file (otherwise :class:`ExplorerError`)
    make_dirs : create missing parent directories (otherwise a missing directory is an error)
    Every failure is an :class:`ExplorerError` naming the path; the temporary file is removed.
    """
    target = Path(os.fspath(path))
    parent = target.parent
    if make_dirs:
        _make_dirs(parent)
    check_target(target, overwrite=overwrite)
    _sweep_now_and_then(parent)
    tmp = None
    try:
        tmp = _new_temp(target)
        _fill(tmp, data)
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


class UnwritableFile(ExplorerError):
    """A path :func:`check_target` refuses: ``path`` as given, ``reason`` the phrase after it
    (``"is a FIFO (named pipe), not a regular file; ..."``); the message is
    ``"<path>: <reason>"``."""

    def __init__(self, path, reason: str):
        self.path, self.reason = os.fspath(path), reason
        super().__init__(f"{self.path}: {reason}")


def check_target(path, *, overwrite: bool, make_dirs: bool = False) -> Path:
    """Refuse ``path`` as a file to write, before anything is written (see the module's
    docstring for what is refused); returns it as a :class:`~pathlib.Path`. Each refusal but an
    existing file's (:func:`exists_error`) is one :class:`UnwritableFile` naming the path; the
    ``OSError`` of a name too long or of a folder that cannot be searched is said in its words
    (``File name too long``). ``make_dirs``: a folder that does not exist yet is no refusal
    (the writer makes it). The path is checked, not held: a FIFO made between this check
    and the rename would still be replaced."""
    target = Path(os.fspath(path))
    parent = target.parent
    try:
        st = os.lstat(target)
    except FileNotFoundError:
        st = None
    except OSError as exc:  # ENAMETOOLONG, EACCES (a folder on the way cannot be searched)
        raise _cannot_write(target, exc) from None
    except ValueError:  # a NUL in the name
        raise UnwritableFile(target, "cannot write: the name holds a NUL character") from None
    if st is None:
        try:
            if not stat.S_ISDIR(os.stat(parent).st_mode):
                raise UnwritableFile(target, f"{str(parent)!r} is not a directory")
        except FileNotFoundError:
            if make_dirs:  # the writer makes it
                return target
            raise UnwritableFile(target, f"directory {str(parent)!r} does not exist") from None
        except OSError as exc:
            raise _cannot_write(target, exc) from None
        return target
    try:
        mode = os.stat(target).st_mode if stat.S_ISLNK(st.st_mode) else st.st_mode
    except OSError:  # a dangling link: replaced as a file would be
        mode = stat.S_IFREG
    if stat.S_ISDIR(mode):
        raise UnwritableFile(target, "is a directory; give a file name to write")
    if not overwrite:
        raise exists_error(target)
    if not stat.S_ISREG(mode):
        raise UnwritableFile(
            target,
            f"is {file_kind(mode)}, not a regular file; not replacing "
            "it (overwrite / --force replace only a file)",
        )
    return target


def _cannot_write(target: Path, exc: OSError) -> UnwritableFile:
    return UnwritableFile(target, f"cannot write: {exc.strerror or exc}")


def _make_dirs(directory: Path) -> None:
    """Create ``directory`` and its missing parents (an :class:`ExplorerError` naming it)."""
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ExplorerError(
            f"{directory}: cannot create directory: {exc.strerror or exc}"
        ) from None


def write_all_atomic(
    files: Mapping, *, overwrite: bool = False, make_dirs: bool = False
) -> list[Path]:
    """Write several files all-or-nothing: ``files`` maps each path to its bytes.

    Every file is first written to a temporary beside its target; only when all of them are
    on disk are they renamed into place. If anything fails (a full disk, a target that
    appeared, an interrupt) no new file is left and the files that were there before are
    back as they were. Returns the paths written, in the order given. ``overwrite`` and
    ``make_dirs`` as for :func:`write_atomic` (without it each target's directory must exist).
    """
    targets = [(Path(os.fspath(p)), data) for p, data in files.items()]
    if make_dirs:
        for parent in dict.fromkeys(t.parent for t, _ in targets):
            _make_dirs(parent)
    for target, _ in targets:
        check_target(target, overwrite=overwrite)
    for parent in {t.parent for t, _ in targets}:
        _sweep_now_and_then(parent)
    temps: dict[Path, str] = {}  # target -> its new contents, not yet in place
    backups: dict[Path, str] = {}  # target -> a hard link to the file it replaces
    placed: list[Path] = []
    current = None
    try:
        for current, data in targets:
            temps[current] = _new_temp(current)
            _fill(temps[current], data)
        for current, _ in targets:
            if overwrite and current.exists():
                backups[current] = _backup(current)
            if overwrite:
                os.replace(temps[current], current)
            else:
                _link_no_clobber(temps[current], current)
            del temps[current]
            placed.append(current)
        for parent in {t.parent for t, _ in targets}:
            _fsync_dir(parent)
    except BaseException as exc:
        _roll_back(placed, backups)
        if isinstance(exc, OSError):
            raise ExplorerError(f"{current}: cannot write: {exc.strerror or exc}") from None
        raise
    finally:
        for tmp in list(temps.values()) + list(backups.values()):
            _unlink_quietly(tmp)
    return [t for t, _ in targets]


def _roll_back(placed: list[Path], backups: dict[Path, str]) -> None:
    """Undo the renames of :func:`write_all_atomic`: old files back, new ones removed."""
    for target in reversed(placed):
        try:
            if target in backups:
                os.replace(backups.pop(target), target)
            else:
                os.unlink(target)
        except OSError:
            pass


def _backup(target: Path) -> str:
    """A hard link (or, where there are none, a copy) of ``target`` under a temporary name."""
    tmp = _new_temp(target)
    try:
        os.unlink(tmp)
        os.link(target, tmp)
    except OSError:
        _fill(tmp, target.read_bytes())
    return tmp


def _new_temp(target: Path) -> str:
    """A new empty temporary file beside ``target`` (named like :data:`TEMP_NAME`)."""
    # the name's first 200 characters: a temporary name is 14 longer, and a target of up to
    # 255 (most file systems' limit) must still be writable
    prefix = f".{target.name[:200]}."
    fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=".tmp", dir=target.parent)
    os.close(fd)
    return tmp


def _fill(tmp: str, data: bytes) -> None:
    """Write ``data`` to the file ``tmp``, flush it to disk, give it the usual permissions."""
    with open(tmp, "wb") as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())
    os.chmod(tmp, 0o666 & ~_umask())


def _unlink_quietly(path) -> None:
    try:
        os.unlink(path)
    except OSError:
        pass


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
