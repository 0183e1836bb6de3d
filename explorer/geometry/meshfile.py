"""A mesh file's bytes and the parts trimesh reads from them.

:func:`read_mesh_file` reads the file once through the checked open, with its caps: the file's
size and, for an archive (zip, bz2, gzip), what it unpacks to (:mod:`explorer.core.tolerances`);
every refusal is one :class:`~explorer.core.errors.ExplorerError` naming the file and the cap.
The other functions take trimesh's result apart for :func:`explorer.geometry.meshes.load_mesh`:
its triangle parts, their material names, texture coordinates and unread colours.
"""

from __future__ import annotations

import bz2
import gzip
import io
import os
import warnings
import zipfile

import numpy as np

from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError, Notice
from explorer.core.files import UnreadableFile, read_checked


def read_mesh_file(path) -> bytes:
    """The bytes of a mesh file, read once through the checked open
    (:func:`explorer.core.files.read_checked`): a file that does not exist, is a directory, a
    FIFO, socket or device (never opened in a way that blocks), is empty, is larger than
    ``MAX_MESH_FILE_BYTES``, or is an archive unpacking to more than
    ``MAX_MESH_UNPACKED_BYTES`` (see :mod:`explorer.core.tolerances`) raises an
    :class:`ExplorerError` naming the file and the cap."""
    shown = os.fspath(path)
    try:
        data = read_checked(shown, cap=tol.MAX_MESH_FILE_BYTES, what="mesh file")
    except UnreadableFile as exc:
        raise ExplorerError(f"mesh file '{shown}' {_unreadable(exc)}") from None
    if not data:
        raise ExplorerError(f"mesh file '{shown}' is empty")
    unpacked = _unpacked_size(data, tol.MAX_MESH_UNPACKED_BYTES)
    if unpacked is not None and unpacked > tol.MAX_MESH_UNPACKED_BYTES:
        raise ExplorerError(
            f"mesh file '{shown}' is an archive that unpacks to more than "
            f"{tol.MAX_MESH_UNPACKED_BYTES} bytes ({tol.MAX_MESH_UNPACKED_BYTES >> 20} MiB), "
            "the limit for a mesh; unpack it yourself if it is really meant"
        )
    return data


def _unreadable(exc: UnreadableFile) -> str:
    """The end of a mesh-file message for what :func:`read_checked` refused."""
    reason = exc.reason
    if reason == "no such file":
        return "does not exist"
    if reason.startswith("it is a directory"):
        return "is a directory, not a mesh file"
    if reason == "permission denied":
        return "cannot be read (permission denied)"
    if reason.startswith("too large"):
        size = f"{exc.size} bytes" if exc.size is not None else "more bytes than that"
        return (
            f"is too large: {size}, the limit is {tol.MAX_MESH_FILE_BYTES} bytes "
            f"({tol.MAX_MESH_FILE_BYTES >> 20} MiB)"
        )
    if reason.startswith("it is a"):
        return f"is not a regular file ({reason[6:].split(', not')[0]})"
    return f"cannot be read: {reason}"


def _unpacked_size(data: bytes, cap: int) -> int | None:
    """The size an archive's bytes unpack to (zip: the declared sizes; bz2 / gzip: counted
    while unpacking, stopping once past ``cap``); None for a file that is no archive."""
    stream = io.BytesIO(data)
    try:
        if zipfile.is_zipfile(stream):
            with zipfile.ZipFile(stream) as archive:
                return sum(info.file_size for info in archive.infolist())
        unpack = {b"BZh": bz2.BZ2File, b"\x1f\x8b\x08": lambda f: gzip.GzipFile(fileobj=f)}
        opener = unpack.get(data[:3])
        if opener is None:
            return None
        total = 0
        with opener(io.BytesIO(data)) as unpacking:
            while total <= cap:
                chunk = unpacking.read(1 << 20)
                if not chunk:
                    break
                total += len(chunk)
        return total
    except (OSError, EOFError, zipfile.BadZipFile, ValueError):
        return None  # a damaged archive: the loader reports it


def part_uv(part) -> np.ndarray | None:
    """(n, 2) texture coordinates trimesh read for a part (an OBJ's ``vt``), or None."""
    uv = getattr(getattr(part, "visual", None), "uv", None)
    if uv is None:
        return None
    uv = np.asarray(uv, np.float64)
    return uv if uv.shape == (len(part.vertices), 2) else None


def used_vertices(pos, faces) -> np.ndarray:
    used = np.zeros(len(pos), bool)
    used[faces.ravel()] = True
    return used


def say_unread_materials(shown: str, parts, obj: bool) -> None:
    """A :class:`~explorer.core.errors.Notice` when the file carries colours or materials the
    engine does not read (anything but an OBJ's .mtl materials)."""
    kinds = {getattr(getattr(m, "visual", None), "kind", None) for m, _ in parts}
    if obj:  # an OBJ's texture visuals are its vt (read) and its .mtl materials (read there)
        kinds.discard("texture")
    kinds.discard(None)
    if kinds:
        what = "texture materials" if kinds == {"texture"} else "colours or materials"
        warnings.warn(
            f"mesh file '{shown}': its {what} are not read (only an OBJ's .mtl materials "
            "are); the scene's material is used",
            Notice,
            stacklevel=3,
        )


def material_name(part) -> str | None:
    """The name of the material trimesh's OBJ reader gave a part (one per ``usemtl``)."""
    material = getattr(getattr(part, "visual", None), "material", None)
    name = getattr(material, "name", None)
    return name if isinstance(name, str) and name else None


def triangle_parts(loaded) -> list:
    """``[(Trimesh, 4x4 transform or None), ...]`` of the triangle meshes in what trimesh
    loaded; scene nodes keep their own geometry (and its normals) with the node's transform."""
    import trimesh

    if isinstance(loaded, trimesh.Trimesh):
        items = [(loaded, None)]
    elif isinstance(loaded, trimesh.Scene):
        items = []
        for node in loaded.graph.nodes_geometry:
            matrix, name = loaded.graph[node]
            geometry = loaded.geometry.get(name)
            matrix = np.asarray(matrix, np.float64)
            items.append((geometry, None if np.allclose(matrix, np.eye(4)) else matrix))
    else:
        items = []
    return [(m, t) for m, t in items if isinstance(m, trimesh.Trimesh) and len(m.faces)]


def drop_unused(pos, nrm, faces):
    used = np.zeros(len(pos), bool)
    used[faces.ravel()] = True
    if used.all():
        return pos, nrm, faces
    new_index = np.cumsum(used) - 1
    return pos[used], nrm[used], new_index[faces]


def file_uv(uvs: list, shown: str) -> np.ndarray | None:
    """The texture coordinates of all parts stacked (None unless every part has them)."""
    if not uvs or any(t is None for t in uvs):
        return None
    tex = np.vstack(uvs)
    if not np.isfinite(tex).all():
        raise ExplorerError(
            f"mesh file '{shown}' has texture coordinates (vt) that are not finite numbers"
        )
    return tex
