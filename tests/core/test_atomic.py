"""The one writer of user files (explorer.core.atomic): leftovers swept, several files
all-or-nothing."""

from __future__ import annotations

import os
import time

import pytest

from explorer.core import atomic
from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError


def _age(path, seconds):
    t = time.time() - seconds
    os.utime(path, (t, t))


def test_a_stale_temporary_is_swept_by_the_next_write_there(tmp_path):
    stale = tmp_path / ".render.png.a1b2c3d4.tmp"  # a kill -9 during an earlier write
    stale.write_bytes(b"x" * 1000)
    _age(stale, 120)
    fresh = tmp_path / ".other.png.zz99yy88.tmp"  # another write, in progress right now
    fresh.write_bytes(b"y")
    mine = tmp_path / ".notes.tmp"  # not our naming
    mine.write_bytes(b"z")
    _age(mine, 3600)
    link = tmp_path / ".link.png.abcdefgh.tmp"  # a symlink is never followed nor removed
    link.symlink_to(mine)
    os.utime(link, (time.time() - 3600,) * 2, follow_symlinks=False)
    write_atomic(tmp_path / "new.png", b"data")
    assert not stale.exists()
    assert fresh.exists() and mine.exists() and link.is_symlink()
    assert (tmp_path / "new.png").read_bytes() == b"data"


def test_a_failed_write_leaves_no_temporary(tmp_path, monkeypatch):
    def fail(*args):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(atomic.os, "fsync", fail)
    with pytest.raises(ExplorerError, match="No space left"):
        write_atomic(tmp_path / "a.png", b"data")
    assert list(tmp_path.iterdir()) == []


def test_write_all_atomic_writes_every_file(tmp_path):
    files = {tmp_path / "a.json": b"1", tmp_path / "a.md": b"2"}
    assert atomic.write_all_atomic(files) == list(files)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json", "a.md"]
    assert (tmp_path / "a.md").read_bytes() == b"2"
    with pytest.raises(ExplorerError, match="already exists"):
        atomic.write_all_atomic({tmp_path / "b.json": b"3", tmp_path / "a.md": b"4"})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json", "a.md"]


@pytest.mark.parametrize("overwrite", [False, True])
def test_write_all_atomic_is_all_or_nothing(tmp_path, monkeypatch, overwrite):
    """The last rename fails (a full disk, an interrupt): the files renamed before it are taken
    back, the old files are as they were, no temporary is left."""
    if overwrite:
        (tmp_path / "a.json").write_bytes(b"old json")
        (tmp_path / "a.png").write_bytes(b"old png")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    real_replace, real_link = os.replace, os.link

    def failing(real):
        def move(src, dst, *args, **kwargs):
            if str(dst).endswith("a.png"):
                raise OSError(28, "No space left on device")
            return real(src, dst, *args, **kwargs)

        return move

    monkeypatch.setattr(atomic.os, "replace", failing(real_replace))
    monkeypatch.setattr(atomic.os, "link", failing(real_link))
    files = {tmp_path / "a.json": b"new json", tmp_path / "a.png": b"new png"}
    with pytest.raises(ExplorerError, match="a.png: cannot write: No space left"):
        atomic.write_all_atomic(files, overwrite=overwrite)
    monkeypatch.setattr(atomic.os, "replace", real_replace)
    after = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    assert after == before


def test_write_all_atomic_refuses_before_writing_anything(tmp_path):
    with pytest.raises(ExplorerError, match="does not exist"):
        atomic.write_all_atomic({tmp_path / "a": b"1", tmp_path / "no" / "b": b"2"})
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("kind", ["fifo", "device", "dangling link"])
def test_overwrite_replaces_a_regular_file_only(tmp_path, kind):
    """``overwrite`` (``--force``) put a regular file in the place of a FIFO a reader waits on,
    or of the link to a device; a dangling link is replaced as a file would be."""
    target = tmp_path / "out.yaml"
    if kind == "fifo":
        os.mkfifo(target)
    elif kind == "device":
        target.symlink_to(os.devnull)
    else:
        target.symlink_to(tmp_path / "gone")
    if kind == "dangling link":
        write_atomic(target, b"new", overwrite=True)
        assert not target.is_symlink() and target.read_bytes() == b"new"
        return
    with pytest.raises(atomic.UnwritableFile, match="not a regular file") as info:
        write_atomic(target, b"new", overwrite=True)
    assert info.value.path == str(target)
    with pytest.raises(ExplorerError, match="not a regular file"):
        atomic.write_all_atomic({tmp_path / "other": b"1", target: b"2"}, overwrite=True)
    assert os.path.lexists(target) and not os.path.isfile(target)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.yaml"]


def test_a_name_the_file_system_refuses_is_an_explorer_error(tmp_path):
    """A name over 255 bytes raised ``OSError`` 36 out of the checks before writing; one of
    255 is written (its temporary, 14 characters longer, is named from a shorter part)."""
    with pytest.raises(ExplorerError, match="File name too long"):
        write_atomic(tmp_path / ("x" * 300), b"data")
    with pytest.raises(ExplorerError, match="File name too long"):
        atomic.write_all_atomic({tmp_path / ("x" * 300): b"data"}, overwrite=True)
    assert list(tmp_path.iterdir()) == []
    name = "y" * 255
    assert write_atomic(tmp_path / name, b"data").read_bytes() == b"data"
    assert [p.name for p in tmp_path.iterdir()] == [name]
