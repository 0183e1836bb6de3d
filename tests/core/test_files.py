"""The one checked open (explorer.core.files) and every reader of the product on files that are
not plain files: a FIFO (opening it for reading waits for a writer forever), /dev/zero behind a
symbolic link (it never ends), a sparse file of gigabytes, a directory. Every reader must refuse
each with a clean ValueError naming the file, at once. A hang would stop the suite: each test
runs under an alarm that turns a hang into a failure."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from helpers.files import KINDS, special_file

from explorer.core import files as F
from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError

ROOT = Path(__file__).resolve().parents[2]


pytestmark = pytest.mark.usefixtures("no_hang")


#: what each kind is called in the messages
SAID = {
    "fifo": "FIFO",
    "zero": "character device",
    "sparse": "too large",
    "dir": "directory",
}


# -- the helper --------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", KINDS)
def test_read_checked_refuses_what_is_not_a_small_regular_file(tmp_path, kind):
    path = special_file(tmp_path, kind, "x")
    with pytest.raises(F.UnreadableFile) as info:
        F.read_checked(path, cap=1 << 20, what="scene")
    msg = str(info.value)
    assert msg.startswith(f"{path}: cannot read scene: ") and SAID[kind] in msg
    assert isinstance(info.value, ValueError)


def test_read_checked_never_trusts_the_size(tmp_path):
    """/proc files say 0 bytes and hold more: at most cap + 1 bytes are read, then refused."""
    with pytest.raises(F.UnreadableFile, match=r"too large \(more than 8 bytes"):
        F.read_checked("/proc/self/maps", cap=8)
    text = F.read_text_checked("/proc/self/status", cap=tol.MAX_DATA_FILE_BYTES)
    assert "Pid:" in text


def test_read_checked_reads_a_file_and_names_a_missing_one(tmp_path):
    path = tmp_path / "a b\x1b[2J..c"
    path.write_bytes(b"x" * 10)
    assert F.read_checked(path, cap=10) == b"x" * 10
    with pytest.raises(F.UnreadableFile, match="too large"):
        F.read_checked(path, cap=9)
    with pytest.raises(F.UnreadableFile, match="no such file"):
        F.read_checked(tmp_path / "nope", cap=9)


def test_inside_keeps_side_files_in_the_folder(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "link.mtl").symlink_to("/etc/passwd")
    assert F.inside(str(tmp_path), "a.mtl") == str(tmp_path / "a.mtl")
    assert F.inside(str(tmp_path), "sub/../a b.mtl") == str(tmp_path / "sub/../a b.mtl")
    for name in ["../red.mtl", "/etc/passwd", "sub/../../x.mtl", "link.mtl", ".", "a\0.mtl"]:
        assert F.inside(str(tmp_path), name) is None, name


# -- no reader can forget the checked open ------------------------------------------------------
#: calls that read a file without the checked open: the builtin ``open``, these methods
#: (``Path.read_text``...) and these module functions; ``x.open(arguments)`` too (``Path.open``,
#: ``Image.open``), but not ``dialog.open()`` without arguments (a Qt dialog)
READ_CALLS = {
    "open", "read_text", "read_bytes", "fromfile", "loadtxt", "genfromtxt", "fdopen",
    "imread", "ZipFile", "load_path", "safe_load", "json.load", "np.load", "trimesh.load",
    "trimesh.load_mesh", "x.open", "os.open", "io.open", "gzip.open", "bz2.open", "lzma.open",
}  # fmt: skip
#: (file, call) -> why it may read without explorer.core.files.read_checked
ALLOWED = {
    ("explorer/core/files.py", "os.open"): "the checked open itself",
    ("explorer/core/atomic.py", "open"): "_fill writes the temporary file mkstemp just made",
    ("explorer/core/atomic.py", "read_bytes"): (
        "_backup copies a file being replaced, only where hard links are missing"
    ),
    ("explorer/core/atomic.py", "os.open"): "_fsync_dir opens a directory to fsync it",
    ("explorer/cli/__init__.py", "os.open"): "opens /dev/null for writing after a broken pipe",
    ("explorer/app/start.py", "fdopen"): "reads the pipe of the Xvfb it started (-displayfd)",
    ("explorer/analysis/report.py", "read_text"): "the package's own report template",
    ("explorer/geometry/meshes.py", "trimesh.load"): (
        "parses bytes read by read_mesh_file, with sidefiles.CheckedResolver for side files"
    ),
    ("explorer/shading/tiers.py", "open"): "appends to the compile log (a write)",
    ("explorer/render/images.py", "x.open"): "Pillow decodes PNG bytes already read (BytesIO)",
    ("explorer/render/textures.py", "x.open"): (
        "Pillow decodes a texture's bytes already read by read_checked (BytesIO)"
    ),
    ("explorer/shading/tiers.py", "os.open"): (
        "the compile lock, opened (O_NONBLOCK, O_NOFOLLOW) to flock it, after lstat set aside "
        "anything that is not a regular file"
    ),
    ("explorer/shading/tiers.py", "fdopen"): "wraps the lock's descriptor opened just before",
    ("explorer/render/turntable.py", "open"): (
        "reads back the MP4 its encoder just wrote into a private temporary directory"
    ),
    ("explorer/geometry/meshfile.py", "ZipFile"): "an archive's bytes read by read_mesh_file",
    ("explorer/app/web/server.py", "x.open"): "webbrowser.open hands the browser the page's URL",
    ("explorer/geometry/kernelcache.py", "open"): (
        "hashes and parses the package's own kernel sources (numba's cache stamp)"
    ),
}


def _call_name(node: ast.Call) -> str:
    f = node.func
    if isinstance(f, ast.Name):
        return f.id
    if isinstance(f, ast.Attribute):
        base = f.value.id if isinstance(f.value, ast.Name) else None
        dotted = f"{base}.{f.attr}" if base else f.attr
        if dotted in READ_CALLS:
            return dotted
        if f.attr == "open":
            return "x.open" if node.args or node.keywords else ""
        return f.attr
    return ""


def test_every_reader_goes_through_read_checked():
    """An AST scan of explorer/: a call that reads a file (``open``, ``Path.read_text``,
    ``np.load``, ``trimesh.load`` ...) outside explorer/core/files.py must be in ALLOWED with
    its reason; an ALLOWED entry no code needs any more must go."""
    found = set()
    for path in sorted((ROOT / "explorer").rglob("*.py")):
        rel = path.relative_to(ROOT).as_posix()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call):
                name = _call_name(node)
                if name in READ_CALLS:
                    found.add((rel, name, node.lineno))
    unlisted = sorted(f"{rel}:{line}: {name}" for rel, name, line in found
                      if (rel, name) not in ALLOWED)  # fmt: skip
    assert not unlisted, "read through explorer.core.files.read_checked:\n" + "\n".join(unlisted)
    stale = set(ALLOWED) - {(rel, name) for rel, name, _ in found}
    assert not stale, f"allowed reads that are gone: {sorted(stale)}"


# -- every reader on every kind of bad file -----------------------------------------------------
def _scene(path):
    from explorer.core.scene import load_scene

    load_scene(path)


def _session(path):
    from explorer.app.session import load_session

    load_session(path)


def _preset(path):
    from explorer.core.presets import load_material_file

    load_material_file(path)


def _mtl(path):
    from explorer.core.mtl import read_mtl

    read_mtl(path)


def _mesh(path):
    from explorer.geometry.meshes import load_mesh

    load_mesh(path)


def _table(path):
    from explorer.analysis.advice import load_table

    load_table(path)


READERS = {
    "scene.yaml": _scene,
    "session.yaml": _session,
    "preset.yaml": _preset,
    "lib.mtl": _mtl,
    "mesh.obj": _mesh,
    "mesh.stl": _mesh,
    "accuracy.json": _table,
}


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("name", sorted(READERS))
def test_every_reader_refuses_special_and_huge_files_at_once(tmp_path, name, kind):
    path = special_file(tmp_path, kind, f"x \x1b]0;t\x07 {name}")
    with pytest.raises(ValueError) as info:
        READERS[name](path)
    msg = str(info.value)
    assert path.name in msg or repr(str(path))[1:-1] in msg or "accuracy" in msg
    said = SAID[kind] if name != "accuracy.json" else "accuracy table"
    assert said in msg or "not a regular file" in msg, msg


@pytest.mark.parametrize("kind", KINDS)
def test_cli_readers_refuse_special_files(tmp_path, kind, capsys, monkeypatch):
    """presets import / validate, render --mesh, plan, gui --last: rc 2 (1 for validate) and
    one line naming the file, never a hang or a traceback."""
    from explorer.app import session as S
    from explorer.cli import build_parser, main
    from explorer.cli.gui import start_state

    mtl = special_file(tmp_path, kind, "f.mtl")
    monkeypatch.setenv("PHONG_EXPLORER_MATERIALS", str(tmp_path / "presets"))
    assert main(["presets", "import", str(mtl), "--into", str(tmp_path / "p")]) == 2
    assert main(["presets", "validate", str(mtl)]) == 1
    mesh = special_file(tmp_path, kind, "m.obj")
    assert main(["render", "--mesh", str(mesh), "--out", str(tmp_path / "o.png")]) == 2
    scene = special_file(tmp_path, kind, "s.yaml")
    assert main(["plan", str(scene)]) == 2
    out = capsys.readouterr()
    assert "Traceback" not in out.err and out.err.count("error:") == 3
    last = special_file(tmp_path, kind, "last.yaml")
    monkeypatch.setenv(S.LAST_SESSION_ENV, str(last))
    with pytest.raises(ExplorerError) as info:
        start_state(build_parser().parse_args(["gui", "--last"]))
    assert "does not exist" not in str(info.value) and SAID[kind] in str(info.value)


def test_a_huge_recent_files_list_is_not_read(tmp_path):
    """The window's recent-files list through the checked open: a sparse 3 GiB file reads as
    no list (before, all of it was read)."""
    from explorer.app.controller.files import RECENT_NAME, read_recent, recent_path

    special_file(tmp_path, "sparse", RECENT_NAME)
    assert read_recent(recent_path(str(tmp_path / "last.yaml"))) == []


def test_a_socket_is_named_as_a_socket(tmp_path):
    import socket

    path = tmp_path / "s.yaml"
    with socket.socket(socket.AF_UNIX) as sock:
        sock.bind(str(path))
        with pytest.raises(F.UnreadableFile, match="it is a socket, not a file"):
            F.read_checked(path, cap=10)
