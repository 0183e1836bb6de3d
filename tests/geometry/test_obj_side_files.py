"""The files an OBJ names (``mtllib`` libraries, ``map_Kd`` textures inside them): resolved and
checked by the product before any library opens one, inside the OBJ's folder, never shown. And
what the product writes as OBJ + MTL reads back, in the product and in trimesh. A seeded fuzz
of .mtl and .obj bytes closes the file."""

from __future__ import annotations

import os
import re
import warnings
from pathlib import Path

import pytest
from helpers.files import KINDS, special_file
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from explorer.core.errors import ExplorerError, Notice
from explorer.core.material import Material
from explorer.core.mtl import MtlError, parse_mtl, read_mtl
from explorer.geometry import meshes as M
from explorer.geometry.filematerials import group_materials
from explorer.geometry.sidefiles import mtllib_names

TRIANGLE = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n"
RED = "newmtl red\nKd 1 0 0\n"


pytestmark = pytest.mark.usefixtures("no_hang")


@pytest.fixture
def no_trimesh_files(monkeypatch):
    """trimesh's own file resolver must never be used: the product serves every side file."""
    import trimesh.resolvers as R

    def refuse(self, name):
        raise AssertionError(f"trimesh opened the side file {name!r} itself")

    monkeypatch.setattr(R.FilePathResolver, "get", refuse)


def obj(tmp_path: Path, header: str, name: str = "m.obj") -> Path:
    path = tmp_path / name
    path.write_text(header + TRIANGLE)
    return path


def load(path):
    """``(mesh, notices, materials warnings, materials)`` of an OBJ."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesh = M.load_mesh(path)
    notices = [str(w.message) for w in caught if issubclass(w.category, Notice)]
    found, said = group_materials(mesh, Material())
    return mesh, notices, said, found


@pytest.mark.parametrize("kind", KINDS)
def test_an_mtllib_that_is_no_small_file_is_named_and_never_opened_blocking(
    tmp_path, kind, no_trimesh_files
):
    """Before: a FIFO hung ``render --mesh``; a sparse 3 GiB library cost 25 s and 6.1 GiB."""
    special_file(tmp_path, kind, "red.mtl")
    mesh, notices, said, found = load(obj(tmp_path, "mtllib red.mtl\n"))
    assert mesh.n_faces == 1
    text = " ".join(notices + said)
    assert "red.mtl" in text
    assert {"fifo": "FIFO", "zero": "outside", "sparse": "too large", "dir": "directory"}[
        kind
    ] in text, text


def test_a_map_kd_naming_a_fifo_is_never_opened(tmp_path, no_trimesh_files):
    os.mkfifo(tmp_path / "tex.png")
    (tmp_path / "red.mtl").write_text(RED + "map_Kd tex.png\n")
    mesh, notices, said, found = load(obj(tmp_path, "mtllib red.mtl\n"))
    assert found[0].diffuse == (1.0, 0.0, 0.0)
    # the map is named (the material's diffuse_map), not opened: the image is read when drawn,
    # through the checked open (tests/render/test_textures.py refuses the FIFO there)
    assert found[0].diffuse_map.file == str(tmp_path / "tex.png")
    assert not any("map_Kd" in w for w in said)


def test_a_library_outside_the_folder_is_refused_before_opening_with_the_right_notice(
    tmp_path, no_trimesh_files
):
    """``mtllib ../red.mtl`` was read by the product and refused by trimesh (the default
    material, with the wrong warning); ``mtllib /etc/passwd`` was opened and its first line
    shown. One policy now: inside the OBJ's folder, an .mtl name, checked before opening."""
    sub = tmp_path / "sub"
    sub.mkdir()
    (tmp_path / "red.mtl").write_text(RED)
    (sub / "secret.mtl").symlink_to("/etc/passwd")
    header = "mtllib ../red.mtl\nmtllib /etc/passwd\nmtllib secret.mtl\n"
    mesh, notices, said, found = load(obj(sub, header))
    assert mesh.groups is None and found == ()  # no library read: the scene's material
    text = "\n".join(notices)
    assert "mtllib ../red.mtl: outside the OBJ's folder" in text
    assert "mtllib /etc/passwd: not an .mtl file name" in text
    assert "mtllib secret.mtl: outside the OBJ's folder" in text
    assert "root:" not in text + " ".join(said)


def test_a_library_beside_the_obj_is_read_once_by_the_product(tmp_path, no_trimesh_files):
    (tmp_path / "my lib#1.mtl").write_text(RED + "newmtl blue\nKd 0 0 1\n")
    path = tmp_path / "m.obj"
    path.write_text(
        "mtllib my lib#1.mtl # a comment\n" + TRIANGLE + "v 0 0 1\nusemtl blue\nf 1 2 4\n"
    )
    mesh, notices, said, found = load(path)
    assert not notices and mesh.groups.names == ("red", "blue")
    assert [m.diffuse for m in found] == [(1.0, 0.0, 0.0), (0.0, 0.0, 1.0)]


def test_mtllib_names_group_words_into_mtl_names():
    assert mtllib_names("my model.mtl") == ["my model.mtl"]
    assert mtllib_names("a.mtl  b.MTL") == ["a.mtl", "b.MTL"]
    assert mtllib_names("a.mtl notes") == ["a.mtl", "notes"]


@pytest.mark.parametrize("name", ["my model.obj", "a#b.obj", "tab\there.obj"])
def test_what_the_product_writes_as_obj_reads_back(tmp_path, name, capsys):
    """``render --out "my model.obj"`` wrote ``mtllib my model.mtl``, read back as "mtllib my:
    no such file" (``a#b.obj`` too): the .mtl gets a name every reader takes."""
    import trimesh

    from explorer.cli import main

    out = tmp_path / name
    assert main(["render", "--mesh", "cube", "--preset", "ruby", "--out", str(out)]) == 0
    mtl = tmp_path / (out.stem.replace(" ", "_").replace("#", "_").replace("\t", "_") + ".mtl")
    assert f"mtllib {mtl.name}\n" in out.read_text()
    capsys.readouterr()
    mesh, notices, said, found = load(out)
    assert not notices and not [w for w in said if "no such file" in w]
    assert found and found[0].name == "ruby"
    loaded = trimesh.load(out, process=False)  # and trimesh reads the same library
    assert loaded.visual.material.name == "ruby"


def test_a_newmtl_name_import_accepts_validate_accepts(tmp_path, monkeypatch):
    """A 1.2 MB ``newmtl`` name imported (rc 0) a preset that validate and render refused:
    one rule, checked when the .mtl is read."""
    from explorer.cli import main
    from explorer.core import tolerances as tol

    monkeypatch.setenv("PHONG_EXPLORER_MATERIALS", str(tmp_path / "presets"))
    with pytest.raises(MtlError, match=r"x:1: newmtl name is 1200000 characters long; the lim"):
        parse_mtl("newmtl " + "a" * 1_200_000 + "\nKd 1 0 0\n", "x")
    longest = tmp_path / "long.mtl"
    longest.write_text("newmtl " + "é" * tol.MAX_MTL_NAME_LENGTH + "\nKd 1 0 0\n")
    into = tmp_path / "p"
    assert main(["presets", "import", str(longest), "--into", str(into)]) == 0
    assert main(["presets", "validate", str(into)]) == 0


@pytest.mark.parametrize("word", ["1_0", "٣", "0x1", "1e", ".", "+", "१.५", "1__0"])
def test_mtl_numbers_are_ascii_decimals(word):
    """float() took ``Ns 1_0`` and Arabic-Indic digits: MTL numbers are ASCII decimals."""
    with pytest.raises(MtlError, match=re.escape(f"x:2: Ns: {word!r} is not a number")):
        parse_mtl(f"newmtl a\nNs {word}\n", "x")
    for good in ["10", "+1.5", "-0", ".5", "5.", "1e1", "1E+1", "2.5e-1"]:
        assert parse_mtl(f"newmtl a\nNs {good}\n", "x")[0].material.shininess == float(good)


# -- fuzz ----------------------------------------------------------------------------------------
#: the side-file names the fuzz puts into mtllib / map_Kd lines
SIDE_NAMES = ["fifo.mtl", "dir.mtl", "missing.mtl", "../up.mtl", "/etc/passwd", "good.mtl",
              "zero.mtl", "a b.mtl", "x\x1b[2J.mtl", "n\0ul.mtl", "L" * 300 + ".mtl",
              "fifo.png", "good.mtl good.mtl"]  # fmt: skip
MTL_LINES = ["newmtl a", "newmtl b c", "Kd 1 0 0", "Kd 0.5", "Ns 10", "Ns 1_0", "d 0.5",
             "Tr 0.2", "illum 2", "illum 11", "Ka 1 1 1", "map_Kd fifo.png", "Ke 2 0 0",
             "# c", "", "\\", "newmtl " + "n" * 300, "Kd nan 0 0", "Ks 1e400 0 0"]  # fmt: skip
OBJ_LINES = ["v 0 0 0", "v 1 0 0", "v 0 1 0", "v 0 0 1", "vn 0 0 1", "f 1 2 3", "f 1 2 4",
             "f 1//1 2//1 3//1", "usemtl a", "usemtl b c", "o x", "g y", "f 1 2 9",
             "v nan 0 0", "vt 0 0", "# c"]  # fmt: skip


@pytest.fixture(scope="module")
def side_folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fuzz")
    os.mkfifo(folder / "fifo.mtl")
    os.mkfifo(folder / "fifo.png")
    (folder / "dir.mtl").mkdir()
    (folder / "zero.mtl").symlink_to("/dev/zero")
    (folder / "good.mtl").write_text("newmtl a\nKd 1 0 0\nnewmtl b c\nKd 0 1 0\n")
    (folder / "a b.mtl").write_text("newmtl a\nKd 0 0 1\n")
    return folder


def _text(lines) -> st.SearchStrategy:
    line = st.one_of(st.sampled_from(lines), st.text(max_size=20))
    return st.lists(line, max_size=12).map("\n".join)


def _bytes(lines) -> st.SearchStrategy:
    return st.one_of(
        _text(lines).map(lambda t: t.encode("utf-8", "surrogatepass")),
        st.binary(max_size=200),
    )


FUZZ = settings(max_examples=150, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])  # fmt: skip


@FUZZ
@given(data=_bytes(MTL_LINES))
def test_fuzzed_mtl_reads_or_names_the_file(side_folder, data):
    path = side_folder / "fuzz.mtl"
    path.write_bytes(data)
    try:
        found = read_mtl(path)
    except MtlError as exc:
        assert str(path) in str(exc)
        return
    assert found and all(isinstance(m.material, Material) for m in found)


@FUZZ
@given(
    libs=st.lists(st.sampled_from(SIDE_NAMES), max_size=3),
    body=_bytes(OBJ_LINES),
)
def test_fuzzed_obj_with_side_files_loads_or_names_the_file(side_folder, libs, body):
    """Random OBJ bytes with mtllib lines naming FIFOs, directories, missing files, ``..``,
    absolute paths, long names, escapes and NUL: a mesh, or a clean ValueError / TypeError
    naming the file; never a hang (the alarm), never another exception."""
    path = side_folder / "fuzz.obj"
    head = "".join(f"mtllib {name}\n" for name in libs).encode("utf-8")
    path.write_bytes(head + TRIANGLE.encode() + body)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Notice)
            mesh = M.load_mesh(path)
            group_materials(mesh, Material())
    except (ValueError, TypeError) as exc:
        assert isinstance(exc, ExplorerError)
        assert "fuzz.obj" in str(exc) or "good.mtl" in str(exc) or "a b.mtl" in str(exc)


@pytest.mark.parametrize("kind", ["fifo", "zero", "outside"])
def test_a_gltf_buffer_is_served_through_the_checked_open(tmp_path, kind, no_trimesh_files):
    """A .gltf names its buffers: trimesh gets them only through the checked open, inside the
    file's folder; a FIFO, a device or a buffer outside is a clean error naming the file."""
    import trimesh

    # the files of a .gltf export as bytes, written here (trimesh's own file export leaves a
    # file open: a ResourceWarning)
    for name, data in trimesh.creation.box().export(file_type="gltf").items():
        (tmp_path / ("b.gltf" if name == "model.gltf" else name)).write_bytes(data)
    assert M.load_mesh(tmp_path / "b.gltf").n_faces == 12
    buffer = tmp_path / "gltf_buffer_0.bin"
    buffer.unlink()
    if kind == "outside":
        text = (tmp_path / "b.gltf").read_text()
        (tmp_path / "b.gltf").write_text(text.replace('"gltf_buffer_0.bin"', '"../x.bin"'))
    else:
        special_file(tmp_path, kind, buffer.name)
    with pytest.raises(ExplorerError, match="b.gltf"):
        M.load_mesh(tmp_path / "b.gltf")
