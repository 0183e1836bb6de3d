"""Files the system refuses are one ``error:`` line, exit status 2, and nothing lost (issue 37
§3): an output name too long for the file system (``OSError`` 36), a folder that cannot be
searched (``PermissionError``), a FIFO or a device where ``--force`` would have put a regular
file, an MP4 cut short by a file size limit. Each printed a traceback, or reported a file as
written that was not whole."""

from __future__ import annotations

import os
import resource
import stat
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.files import permissions_hold

from explorer.cli import main

LONG = "x" * 300  # over the 255 bytes a name may have on every usual file system


def _one_error_line(err: str, *needles: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    for needle in needles:
        assert needle in lines[0], err
    return lines[0]


def _mtl(tmp_path) -> Path:
    path = tmp_path / "a.mtl"
    path.write_text("newmtl a\nKd 0.5 0.5 0.5\n")
    return path


def _writers(tmp_path, out: str) -> dict[str, list[str]]:
    """Every command that writes a file the user names, writing ``out`` (+ its suffix)."""
    small = ["--mesh", "sphere", "--size", "32x32"]
    return {
        "render png": ["render", *small, "--out", f"{out}.png"],
        "render obj": ["render", *small, "--out", f"{out}.obj"],
        "render turntable": ["render", *small, "--turntable", "2", "--out", f"{out}.gif"],
        "sheet": ["sheet", "--tile", "32x32", "--out", f"{out}.png"],
        "presets export": ["presets", "export", "gold", "--out", f"{out}.mtl"],
        "presets import": ["presets", "import", str(_mtl(tmp_path)), "--into", out],
    }


WRITERS = [
    "render png",
    "render obj",
    "render turntable",
    "sheet",
    "presets export",
    "presets import",
]


@pytest.mark.parametrize("command", WRITERS)
def test_an_output_name_too_long_is_one_line(tmp_path, command, capsys):
    writers = _writers(tmp_path, str(tmp_path / LONG))
    assert list(writers) == WRITERS
    argv = writers[command]
    assert main(argv) == 2
    _one_error_line(capsys.readouterr().err, "File name too long")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.mtl"]  # nothing written


def test_a_name_of_255_characters_is_written(tmp_path):
    """The temporary beside it (14 characters longer) must not be what refuses it."""
    out = tmp_path / ("y" * 251 + ".mtl")
    assert main(["presets", "export", "gold", "--out", str(out)]) == 0
    assert "newmtl" in out.read_text()
    assert [p.name for p in tmp_path.iterdir()] == [out.name]


@pytest.mark.parametrize("kind", ["fifo", "device"])
@pytest.mark.parametrize("command", ["render", "gui --state-file", "presets export"])
def test_force_replaces_a_file_never_a_fifo_or_a_device(tmp_path, kind, command, capsys):
    target = tmp_path / "out.png"
    if kind == "fifo":
        os.mkfifo(target)
    else:
        target.symlink_to(os.devnull)  # a character device behind the name
    argv = {
        "render": ["render", "--mesh", "sphere", "--size", "32x32", "--out", str(target)],
        "gui --state-file": ["gui", "--state-file", str(target), "--exit-after", "1"],
        "presets export": ["presets", "export", "gold", "--out", str(target)],
    }[command]
    if command == "presets export":
        target.rename(tmp_path / "out.mtl")
        target = tmp_path / "out.mtl"
        argv[-1] = str(target)
    assert main([*argv, "--force"]) == 2
    what = "FIFO" if kind == "fifo" else "character device"
    _one_error_line(capsys.readouterr().err, what, "not a regular file")
    mode = os.stat(target).st_mode
    assert stat.S_ISFIFO(mode) if kind == "fifo" else stat.S_ISCHR(mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == [target.name]


def _run(argv, *, prefix=(), env=None, limit=None, cwd=None):
    """``phong-explorer argv`` in a subprocess (after ``prefix``; with a file size ``limit``)."""
    full_env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path), **(env or {})}

    def limited():
        if limit is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return subprocess.run(
        [*prefix, sys.executable, "-m", "explorer.cli", *argv],
        capture_output=True,
        text=True,
        env=full_env,
        timeout=240,
        preexec_fn=limited,
        cwd=cwd,
    )


@pytest.fixture
def locked(tmp_path):
    """A folder that cannot be searched (``chmod 000``; its files are there, out of reach),
    and the command prefix under which that holds (root: without its overriding
    capabilities)."""
    prefix = permissions_hold()
    if prefix is None:
        pytest.skip("no way to run a command that folder permissions hold for")
    folder = tmp_path / "locked"
    (folder / "sub").mkdir(parents=True)
    (folder / "sub" / "keep.png").write_bytes(b"the user's file")
    (folder / "last.yaml").write_text("kept\n")
    folder.chmod(0)
    yield folder, prefix
    folder.chmod(0o755)
    assert (folder / "sub" / "keep.png").read_bytes() == b"the user's file"


def test_a_locked_folder_is_one_line_per_command(tmp_path, locked):
    """One subprocess per kind of path: the output of render (--force over a file there), an
    import into it, the last session in it (``--last`` reads it), a ``--materials-dir`` in it,
    the user's preset folder in it (left out with a notice: the rest works)."""
    folder, prefix = locked
    res = _run(
        [
            "render",
            "--mesh",
            "sphere",
            "--size",
            "32x32",
            "--force",
            "--out",
            str(folder / "sub" / "keep.png"),
        ],
        prefix=prefix,
    )
    assert res.returncode == 2
    _one_error_line(res.stderr, "keep.png", "Permission denied")
    res = _run(
        ["presets", "import", str(_mtl(tmp_path)), "--into", str(folder / "sub")], prefix=prefix
    )
    assert res.returncode == 2
    _one_error_line(res.stderr, "a.yaml", "Permission denied")
    res = _run(
        ["web", "--last", "--port", "1"],
        prefix=prefix,
        env={"PHONG_EXPLORER_LAST_SESSION": str(folder / "last.yaml")},
    )
    assert res.returncode == 2
    _one_error_line(res.stderr, "--last", "last.yaml", "Permission denied")
    res = _run(
        [
            "render",
            "--mesh",
            "sphere",
            "--size",
            "32x32",
            "--materials-dir",
            str(folder / "sub"),
            "--out",
            str(tmp_path / "x.png"),
        ],
        prefix=prefix,
    )
    assert res.returncode == 2  # (it said the folder "is not a directory")
    _one_error_line(res.stderr, "--materials-dir", "cannot read it: Permission denied")
    res = _run(["presets", "list"], prefix=prefix, env={"XDG_CONFIG_HOME": str(folder)})
    assert res.returncode == 0 and "gold" in res.stdout
    assert res.stderr.startswith("notice: cannot read the user's preset directory"), res.stderr
    assert "Traceback" not in res.stderr


def test_an_mp4_cut_short_by_a_file_size_limit_is_an_error_and_no_file(tmp_path):
    """ffmpeg stops writing at the limit (``RLIMIT_FSIZE``, as a full disk would); imageio
    does not look at its exit status, and the half-written MP4 was written as the result."""
    out = tmp_path / "spin.mp4"
    argv = ["render", "--mesh", "teapot", "--size", "96x96", "--turntable", "4", "--out", str(out)]
    # the numpy tier: the limit is for the MP4, not for numba's cache (a kernel compiled here
    # would be saved under the same limit: numba's own OSError, not the writer's)
    numpy = {"PHONG_EXPLORER_KERNELS": "numpy"}
    res = _run(argv, limit=1024, cwd=tmp_path, env=numpy)  # the whole file is about 2.5 kB
    assert res.returncode == 2, res.stderr
    _one_error_line(res.stderr, "MP4", "did not finish")
    assert list(tmp_path.iterdir()) == []
    res = _run(argv, cwd=tmp_path)  # without the limit: the same command writes it
    assert res.returncode == 0, res.stderr
    assert out.stat().st_size > 1024
