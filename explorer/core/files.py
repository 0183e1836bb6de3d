"""Reading user files safely: the one checked open every file read goes through.

A name given by a user (a preset, a scene, a session, an .mtl, a mesh and the files a mesh
names) can be a FIFO (opening it waits for a writer forever), a device (``/dev/zero`` never
ends), a directory, or a sparse file of gigabytes whose size the directory listing gives as
anything. :func:`read_checked` opens the name without blocking (``O_NONBLOCK``), refuses
anything but a regular file by ``fstat`` of what it opened (no race between a check and the
open), and reads at most ``cap + 1`` bytes whatever the file claims, so a reader can neither
hang nor read without bound. :func:`inside` is the policy for a file that another file names
(an OBJ's ``mtllib``): it must lie in that file's folder.

``tests/core/test_files.py::test_every_reader_goes_through_read_checked`` scans the package for
any other way of reading a file, so the next reader cannot forget this one.
"""

from __future__ import annotations

import os
import stat

from explorer.core.errors import ExplorerError

#: one read() asks for at most this many bytes (a large file is read in these steps)
_CHUNK = 1 << 20


#: the reason of an :class:`UnreadableFile` that does not exist (callers for whom absence is
#: normal tell it apart by this)
NO_SUCH_FILE = "no such file"


class UnreadableFile(ExplorerError):
    """A file :func:`read_checked` would not or could not read. ``path`` is the name as given,
    ``reason`` the phrase after it (``"it is a FIFO (named pipe), not a file"``); the message
    is ``"<path>: cannot read <what>: <reason>"``; ``size`` is the size of a file refused as
    too large (None when it is not known: it grew while read)."""

    def __init__(self, path: str, what: str, reason: str, size: int | None = None):
        self.path, self.what, self.reason, self.size = path, what, reason, size
        super().__init__(f"{path}: cannot read {what}: {reason}")


def file_kind(mode: int) -> str:
    """What a file that is not a regular file is, for messages ("a FIFO (named pipe)")."""
    kinds = (
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISSOCK, "a socket"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISDIR, "a directory"),
    )
    return next((text for test, text in kinds if test(mode)), "not a regular file")


def too_large(size: int | None, cap: int) -> str:
    """The reason for a file over ``cap`` bytes (``size`` None: it was still growing)."""
    got = f"{size} bytes" if size is not None else f"more than {cap} bytes"
    return f"too large ({got}; the limit is {cap} bytes, {_mib(cap)})"


def _mib(n: int) -> str:
    return f"{n / (1 << 20):g} MiB"


def read_checked(path, *, cap: int, what: str = "file") -> bytes:
    """The bytes of the regular file ``path``, at most ``cap`` of them.

    It is opened with ``O_NONBLOCK`` (a FIFO does not wait for a writer) and refused unless
    ``fstat`` of the open file says it is a regular file; its size is never taken on trust: at
    most ``cap + 1`` bytes are read, and one more than ``cap`` refuses it. ``what`` names the
    file in messages ("scene", "material library"). Every refusal is an :class:`UnreadableFile`
    (an :class:`~explorer.core.errors.ExplorerError`, a ``ValueError``) naming the file.
    """
    name = os.fspath(path)
    if not isinstance(name, str):
        name = os.fsdecode(name)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
    flags |= getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(name, flags)
    except FileNotFoundError:
        raise UnreadableFile(name, what, NO_SUCH_FILE) from None
    except IsADirectoryError:
        raise UnreadableFile(name, what, "it is a directory, not a file") from None
    except PermissionError:
        raise UnreadableFile(name, what, "permission denied") from None
    except (OSError, ValueError) as exc:  # ValueError: a NUL in the name
        mode = _mode(name)
        if mode is not None and not stat.S_ISREG(mode):  # a socket cannot be opened at all
            raise UnreadableFile(name, what, f"it is {file_kind(mode)}, not a file") from None
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise UnreadableFile(name, what, reason) from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise UnreadableFile(name, what, f"it is {file_kind(st.st_mode)}, not a file")
        if st.st_size > cap:
            raise UnreadableFile(name, what, too_large(st.st_size, cap), st.st_size)
        chunks, total = [], 0
        while total <= cap:
            chunk = os.read(fd, min(_CHUNK, cap + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
    except OSError as exc:
        raise UnreadableFile(name, what, exc.strerror or str(exc)) from None
    finally:
        os.close(fd)
    if total > cap:  # it grew since fstat, or it is a file whose size says nothing (/proc)
        raise UnreadableFile(name, what, too_large(None, cap))
    return b"".join(chunks)


def _mode(name: str) -> int | None:
    """``st_mode`` of ``name`` (links followed), None if it cannot be had."""
    try:
        return os.stat(name).st_mode
    except (OSError, ValueError):
        return None


def read_text_checked(path, *, cap: int, what: str = "file") -> str:
    """:func:`read_checked`, decoded as UTF-8 (an undecodable file is an
    :class:`UnreadableFile` naming the first bad byte's line)."""
    raw = read_checked(path, cap=cap, what=what)
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise UnreadableFile(os.fspath(path), what, f"line {line} is not UTF-8 text") from None


def inside(folder, name: str) -> str | None:
    """The path ``name`` (as another file in ``folder`` names it: relative to that folder) if it
    lies inside ``folder`` after resolving ``..`` and symbolic links, else None. An absolute
    ``name`` is outside unless it resolves into the folder."""
    base = os.path.realpath(folder or ".")
    if "\0" in name:
        return None
    full = os.path.realpath(os.path.join(base, name))
    if full == base or os.path.commonpath([base, full]) != base:
        return None
    return os.path.join(folder, name) if folder else name
