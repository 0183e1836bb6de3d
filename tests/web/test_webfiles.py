"""What the page may send the server (explorer.app.webfiles): a file name never becomes a
server path, an upload meets the same size caps as a file on disk, a session from the page
names only a built-in mesh, and an OBJ's ``mtllib`` only a library uploaded with it."""

from __future__ import annotations

import tempfile

import pytest

from explorer.app.webfiles import WebFiles, upload_name
from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError
from explorer.core.yamlio import MAX_BYTES


class Controller:
    """Records the flows the uploads end in."""

    def __init__(self):
        self.calls = []

    def open_session(self, path):
        self.calls.append(("open_session", str(path)))

    def choose_mesh(self, path):
        self.calls.append(("choose_mesh", str(path)))


@pytest.fixture
def files():
    f = WebFiles()
    f.controller = Controller()
    f._uploads = tempfile.TemporaryDirectory(prefix="phong-explorer-web-test-")
    yield f
    f._uploads.cleanup()


@pytest.mark.parametrize(
    ("name", "kept"),
    [("../../etc/passwd", "passwd"), ("..\\..\\boot.ini", "boot.ini"), ("/abs/x.obj", "x.obj"),
     ("..", "upload"), (".bashrc", "bashrc"), ("a b;$(rm).obj", "a_b___rm_.obj"), ("", "upload")],
)  # fmt: skip
def test_an_uploaded_file_keeps_only_a_safe_last_name(name, kept):
    assert upload_name(name) == kept


def session(mesh: str) -> bytes:
    return (f"session: 1\nmesh: {mesh}\nscene:\n  material: gold\n").encode()


def test_a_session_from_the_page_may_name_only_a_built_in_mesh(files, tmp_path):
    secret = tmp_path / "secret.obj"
    secret.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(ExplorerError, match="only a built-in mesh"):
        files.open_uploaded_session({"name": "s.yaml", "content": session(str(secret))})
    assert files.controller.calls == []
    files.open_uploaded_session(
        {"name": "../s.yaml", "content": [session("cube")[:9], session("cube")[9:]]}
    )
    ((call, path),) = files.controller.calls
    assert call == "open_session" and path.startswith(files._uploads.name)


def test_uploads_meet_the_caps_of_files_on_disk(files):
    with pytest.raises(ExplorerError, match=f"limit is {MAX_BYTES} bytes"):
        files.open_uploaded_session({"name": "s.yaml", "content": b" " * (MAX_BYTES + 1)})
    big = b"#" * (tol.MAX_MTL_FILE_BYTES + 1)
    with pytest.raises(ExplorerError, match="material library 'm.mtl' is too large"):
        files.open_uploaded_mesh([{"name": "m.obj", "content": b"v 0 0 0\n"},
                                  {"name": "m.mtl", "content": big}])  # fmt: skip
    assert files.controller.calls == []


OBJ = b"mtllib %s\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n"


def test_an_objs_mtllib_must_be_uploaded_with_it(files):
    for lib in (b"../outside.mtl", b"/etc/passwd"):
        with pytest.raises(ExplorerError, match="outside the upload"):
            files.open_uploaded_mesh({"name": "m.obj", "content": OBJ % lib})
    assert files.controller.calls == []
    mtl = {"name": "../m.mtl", "content": b"newmtl red\nKd 1 0 0\n"}
    files.open_uploaded_mesh([{"name": "m.obj", "content": OBJ % b"m.mtl"}, mtl])
    ((call, path),) = files.controller.calls
    assert call == "choose_mesh" and path.endswith("/m.obj")
    assert path.startswith(files._uploads.name)


def test_one_mesh_file_per_upload(files):
    with pytest.raises(ExplorerError, match="upload one mesh file"):
        files.open_uploaded_mesh([{"name": "m.mtl", "content": b"newmtl red\n"}])
