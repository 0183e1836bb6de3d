"""The files a mesh file names, served to trimesh only after the product has checked them.

An OBJ's ``mtllib`` lines name material libraries, and those name textures (``map_Kd``); a glTF
names its buffers and images. trimesh would open each itself, before any check: a FIFO hung the
command, a sparse 3 GiB library cost 25 s and 6.1 GiB, ``mtllib /etc/passwd`` was opened. Here
:func:`obj_material_names` resolves an OBJ's libraries by one policy (``.mtl`` names inside the
OBJ's folder, checked by :func:`explorer.core.files.read_checked` when read) and
:class:`CheckedResolver` is what trimesh gets instead of its file resolver: for an OBJ only the
material names, for other formats files inside the mesh's folder through the checked open.
"""

from __future__ import annotations

import os
import re

from explorer.core import tolerances as tol
from explorer.core.files import UnreadableFile, inside, read_checked
from explorer.core.mtl import MtlError, read_mtl
from explorer.core.text import printable

#: an OBJ line naming material libraries or a material (at the start of a line)
_MATERIAL_LINE = re.compile(rb"^[ \t]*(mtllib|usemtl)[ \t]+([^\r\n]*)", re.MULTILINE)
#: a comment: ``#`` at the start of the text or after a blank (``a#b.mtl`` is a name)
_COMMENT = re.compile(r"(?:^|\s)#.*$")


def obj_material_names(path: str, data: bytes) -> tuple[tuple, tuple, tuple]:
    """``(libraries, used, refused)`` of an OBJ's bytes ``data`` (read from ``path``).

    libraries : the ``mtllib`` files the OBJ names that may be read, as paths in its folder
        (at most ``MAX_MTL_LIBRARIES``); not yet opened
    used : the names its ``usemtl`` lines give, in the order first met
    refused : one sentence per library not read, each naming the library and why: outside the
        OBJ's folder (``..``, an absolute path, a link out of it), not an ``.mtl`` name; these
        are never opened, so nothing of their content is ever shown

    An ``mtllib`` line holds one or more names; a name may hold blanks: the words are grouped
    into names each ending in ``.mtl`` (as Blender reads them), so ``mtllib my model.mtl`` is
    one file and ``mtllib a.mtl b.mtl`` two. ``#`` starts a comment at a line's start or after
    a blank (``a#b.mtl`` is a name).
    """
    folder = os.path.dirname(path)
    libraries: list[str] = []
    used: list[str] = []
    refused: list[str] = []
    for match in _MATERIAL_LINE.finditer(data):
        rest = _COMMENT.sub("", match.group(2).decode("utf-8", "replace")).strip()
        if match.group(1) == b"usemtl":
            if rest and rest not in used:
                used.append(rest)
            continue
        for name in mtllib_names(rest):
            where = f"mesh file '{path}': mtllib {printable(name)}"
            lib = inside(folder, name) if name.lower().endswith(".mtl") else None
            if not name.lower().endswith(".mtl"):
                refused.append(f"{where}: not an .mtl file name; it is not read")
            elif lib is None:
                refused.append(
                    f"{where}: outside the OBJ's folder; it is not read (put the library "
                    "beside the OBJ)"
                )
            elif lib not in libraries:
                if len(libraries) >= tol.MAX_MTL_LIBRARIES:
                    refused.append(
                        f"{where}: more than {tol.MAX_MTL_LIBRARIES} libraries; it is not read"
                    )
                    continue
                libraries.append(lib)
    return tuple(libraries), tuple(used), tuple(refused)


def mtllib_names(rest: str) -> list[str]:
    """The library names of an ``mtllib`` line's text after the keyword: words grouped into
    names each ending in ``.mtl`` (case aside); words after the last such name form one more
    name. ``"my model.mtl"`` -> ``["my model.mtl"]``; ``"a.mtl b.mtl"`` -> two names."""
    names: list[str] = []
    pending: list[str] = []
    for word in rest.split():
        pending.append(word)
        if word.lower().endswith(".mtl"):
            names.append(" ".join(pending))
            pending = []
    if pending:
        names.append(" ".join(pending))
    return names


def library_names(libraries) -> tuple[str, ...]:
    """Every material name the readable ``libraries`` define (read with the strict reader,
    :func:`explorer.core.mtl.read_mtl`; a library it refuses adds none here, and
    :func:`explorer.geometry.filematerials.group_materials` reports it)."""
    names: list[str] = []
    for lib in libraries:
        try:
            found = read_mtl(lib)
        except MtlError:
            continue
        names.extend(m.name for m in found if m.name not in names)
    return tuple(names)


class CheckedResolver:
    """What trimesh gets to fetch the files a mesh file names, instead of opening them itself.

    An OBJ (``materials`` given) is served a material library holding only ``newmtl`` lines of
    ``materials``: trimesh needs the names to split faces by ``usemtl``; the colours are read
    by :mod:`explorer.core.mtl`, and no texture is ever opened. Any other format (a glTF's
    buffers and images) is served files inside the mesh file's folder, through
    :func:`explorer.core.files.read_checked` with the mesh-file cap; anything else is
    "not found" to trimesh.
    """

    def __init__(self, path: str, materials: tuple[str, ...] | None):
        self.folder = os.path.dirname(path)
        self.file_name = os.path.basename(path)
        self.materials = materials

    def get(self, name: str) -> bytes:
        if self.materials is not None:
            if not self.materials:
                raise FileNotFoundError(name)
            return "".join(f"newmtl {m}\n" for m in self.materials).encode("utf-8")
        lib = inside(self.folder, str(name).strip())
        if lib is None:
            raise FileNotFoundError(name)
        try:
            return read_checked(lib, cap=tol.MAX_MESH_FILE_BYTES, what="file a mesh names")
        except UnreadableFile as exc:
            raise FileNotFoundError(str(exc)) from None

    __getitem__ = get

    def get_base(self) -> bytes:  # pragma: no cover - trimesh asks this of web resolvers only
        raise FileNotFoundError(self.file_name)

    def keys(self):
        return iter(())

    def __contains__(self, name) -> bool:
        return False

    def namespaced(self, namespace):
        return CheckedResolver(os.path.join(self.folder, namespace, "x"), self.materials)

    def write(self, name, data):  # pragma: no cover - loading never writes
        raise OSError("the mesh reader writes no files")
