"""What the page may send the server (explorer.app.web.files): a file name never becomes a
server path, an upload meets the same size caps as a file on disk, a session from the page
names only a built-in mesh, and an OBJ's ``mtllib`` only a library uploaded with it."""

from __future__ import annotations

import tempfile
import tracemalloc
from types import SimpleNamespace

import pytest

from explorer.app.colours import parse_hex, rgb_hex
from explorer.app.turntablejob import turntable_formats
from explorer.app.web.files import WebFiles, upload_name
from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError
from explorer.core.yamlio import MAX_BYTES


class Flows:
    """Records the flows the uploads end in (the controller's ``files``)."""

    def __init__(self):
        self.calls = []

    def open_session(self, path):
        self.calls.append(("open_session", str(path)))

    def choose_mesh(self, path):
        self.calls.append(("choose_mesh", str(path)))

    def import_materials(self, path):
        self.calls.append(("import_materials", str(path), self.answers()))

    def export_turntable(self, path, frames):
        self.calls.append(("export_turntable", str(path), frames))

    def picture_stem(self):
        return "stem"


@pytest.fixture
def files():
    app = SimpleNamespace(
        controller=SimpleNamespace(files=Flows()),
        answers={},
        server=SimpleNamespace(state=SimpleNamespace(preset_replace=False)),
    )
    app.controller.files.answers = lambda: dict(app.answers)
    folder = tempfile.TemporaryDirectory(prefix="phong-explorer-web-test-")
    f = WebFiles(app, folder.name)
    f.controller = app.controller  # what the tests read back
    yield f
    folder.cleanup()


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
    assert files.controller.files.calls == []
    files.open_uploaded_session(
        {"name": "../s.yaml", "content": [session("cube")[:9], session("cube")[9:]]}
    )
    ((call, path),) = files.controller.files.calls
    assert call == "open_session" and path.startswith(files.folder)


def test_uploads_meet_the_caps_of_files_on_disk(files):
    with pytest.raises(ExplorerError, match=f"limit is {MAX_BYTES} bytes"):
        files.open_uploaded_session({"name": "s.yaml", "content": b" " * (MAX_BYTES + 1)})
    big = b"#" * (tol.MAX_MTL_FILE_BYTES + 1)
    with pytest.raises(ExplorerError, match="material library 'm.mtl' is too large"):
        files.open_uploaded_mesh([{"name": "m.obj", "content": b"v 0 0 0\n"},
                                  {"name": "m.mtl", "content": big}])  # fmt: skip
    assert files.controller.files.calls == []


@pytest.mark.parametrize("content", [[900_000_000], 900_000_000, [b"v 0 0 0\n", 10**9], "v 0 0 0",
                                     {"a": 1}])  # fmt: skip
def test_an_uploads_content_must_be_bytes(files, content):
    """Numbers as content are refused before anything is allocated (``bytes(n)`` of a number
    made n zero bytes: a 30-byte message took 0.9 GB), and so is text or a mapping."""
    tracemalloc.start()
    try:
        for opener in (files.open_uploaded_mesh, files.open_uploaded_session):
            with pytest.raises(ExplorerError, match="the content must be bytes, got"):
                opener({"name": "m.obj", "content": content})
        with pytest.raises(ExplorerError, match="the content must be bytes, got"):
            files.import_uploaded_materials({"name": "m.mtl", "content": content})
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 1 << 20
    assert files.controller.files.calls == []


def test_an_uploads_size_is_checked_before_its_chunks_are_joined(files):
    chunks = [b"#" * (1 << 20)] * (tol.MAX_MTL_FILE_BYTES // (1 << 20) + 1)
    tracemalloc.start()
    try:
        with pytest.raises(ExplorerError, match="material library 'm.mtl' is too large"):
            files.import_uploaded_materials({"name": "m.mtl", "content": chunks})
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 1 << 20


OBJ = b"mtllib %s\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n"


def test_an_objs_mtllib_must_be_uploaded_with_it(files):
    for lib in (b"../outside.mtl", b"/etc/passwd"):
        with pytest.raises(ExplorerError, match="outside the upload"):
            files.open_uploaded_mesh({"name": "m.obj", "content": OBJ % lib})
    assert files.controller.files.calls == []
    mtl = {"name": "../m.mtl", "content": b"newmtl red\nKd 1 0 0\n"}
    files.open_uploaded_mesh([{"name": "m.obj", "content": OBJ % b"m.mtl"}, mtl])
    ((call, path),) = files.controller.files.calls
    assert call == "choose_mesh" and path.endswith("/m.obj")
    assert path.startswith(files.folder)


def test_one_mesh_file_per_upload(files):
    with pytest.raises(ExplorerError, match="upload one mesh file"):
        files.open_uploaded_mesh([{"name": "m.mtl", "content": b"newmtl red\n"}])


def test_an_uploaded_mtl_is_capped_kept_under_its_own_name_and_imported(files):
    with pytest.raises(ExplorerError, match="'x.obj' is not an .mtl file"):
        files.import_uploaded_materials({"name": "x.obj", "content": b"v 0 0 0\n"})
    big = b"#" * (tol.MAX_MTL_FILE_BYTES + 1)
    with pytest.raises(ExplorerError, match="material library 'm.mtl' is too large"):
        files.import_uploaded_materials({"name": "m.mtl", "content": big})
    assert files.controller.files.calls == []
    files.app.server.state.preset_replace = True  # the page's "replace": the answer to "replace?"
    files.import_uploaded_materials({"name": "../../evil.mtl", "content": b"newmtl a\n"})
    ((call, path, answers),) = files.controller.files.calls
    assert call == "import_materials" and path.endswith("/evil.mtl") and answers == {"yes": True}
    assert path.startswith(files.folder) and files.app.answers == {}
    assert files.page_text(f"{path}:2: Kd: bad") == "evil.mtl:2: Kd: bad"


def test_a_saved_presets_message_names_no_server_folder(files, tmp_path, monkeypatch):
    """The controller says where a preset was saved (the window shows the path); the page
    says ``presets/NAME.yaml``, not the server's folder."""
    monkeypatch.setenv("PHONG_EXPLORER_MATERIALS", str(tmp_path / "mine"))
    said = f"saved preset 'jade 2' to {tmp_path / 'mine' / 'jade_2.yaml'}"
    assert files.page_text(said) == "saved preset 'jade 2' to presets/jade_2.yaml"
    assert str(tmp_path) not in files.page_text(said)


def test_the_turntable_takes_the_frames_and_a_format_the_server_can_write(files):
    files.start_turntable(".gif", "12")
    ((call, path, frames),) = files.controller.files.calls
    assert path.endswith("stem-turntable.gif") and frames == 12
    for bad in ("1", "361", "2.5", "many"):
        with pytest.raises(ExplorerError, match="frames"):
            files.start_turntable(".gif", bad)
    with pytest.raises(ExplorerError, match="the format must be one of"):
        files.start_turntable(".avi", 12)
    assert ".gif" in turntable_formats() and len(files.controller.files.calls) == 1


def test_a_picked_colour_is_8_bit_both_ways():
    assert parse_hex("diffuse", "#336699") == (0.2, 0.4, 0.6)
    assert parse_hex("diffuse", "#FF8000FF") == (1.0, 128 / 255, 0.0)  # the alpha dropped
    assert parse_hex("diffuse", "#fff") == (1.0, 1.0, 1.0)
    assert rgb_hex((0.2, 0.4, 0.6)) == "#336699" and rgb_hex((0.5, 2.0, -1.0)) == "#80ff00"
    for bad in ("", "#12345", "#gg0000", "red"):
        with pytest.raises(ExplorerError, match="diffuse: a picked colour is #rrggbb"):
            parse_hex("diffuse", bad)
