"""The web explorer's files (a mix-in of :class:`explorer.app.web.WebExplorer`): uploads and
downloads, through the controller's flows.

Nothing from the page names a server path. An upload is written into the explorer's private
temporary folder under a name of its own (the page's file name reduced to its last part, with
only letters, digits, ``.``, ``-`` and ``_``), after the same size cap as a file on disk
(:data:`explorer.core.yamlio.MAX_BYTES` for sessions,
:data:`~explorer.core.tolerances.MAX_MESH_FILE_BYTES` for meshes,
:data:`~explorer.core.tolerances.MAX_MTL_FILE_BYTES` for material libraries), and then read by
the same readers, with their checks. A session from the page may name only a built-in mesh,
and an OBJ's ``mtllib`` only a library uploaded with it. A download is written there by the
controller's flow (save session, export) and its bytes are sent to the page. Presets are saved
into the user's preset folder only.
"""

from __future__ import annotations

import itertools
import os
import re
from pathlib import Path

from explorer.app.start import MESH_CHOICES
from explorer.app.turntablejob import DEFAULT_FRAMES, format_name, read_frames, turntable_formats
from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError
from explorer.core.files import read_checked
from explorer.core.presets import user_dir
from explorer.core.tolerances import MAX_DOWNLOAD_BYTES
from explorer.core.yamlio import MAX_BYTES, load_yaml
from explorer.geometry.meshes import MESH_SUFFIXES, obj_material_names

#: what the page may download: kind -> (file suffix, MIME type)
DOWNLOADS = {
    "session": (".yaml", "text/yaml"),
    "png": (".png", "image/png"),
    "mtl": (".mtl", "text/plain"),
    "json": (".json", "application/json"),
    "x3d": (".x3d", "model/x3d+xml"),
    "preset": (".yaml", "text/yaml"),
}
#: the characters an uploaded file's own name keeps (others become ``_``)
UNSAFE = re.compile(r"[^A-Za-z0-9._-]")
#: the longest uploaded file name kept (characters)
MAX_UPLOAD_NAME = 100


def upload_name(name: str) -> str:
    """The name an uploaded file is kept under: the page's name's last part, made safe (never
    empty, never ``.`` or ``..``)."""
    base = UNSAFE.sub("_", re.split(r"[\\/]", str(name))[-1])[:MAX_UPLOAD_NAME].lstrip(".")
    return base or "upload"


#: what an upload's content may be: bytes (the page's file), or a list of them (its chunks)
BYTES = (bytes, bytearray, memoryview)


def upload_name_of(upload) -> str:
    """The page's own name of a trame file upload (a dict with ``name`` and ``content``)."""
    if not isinstance(upload, dict):
        raise ExplorerError("upload: not a file")
    name = upload.get("name") or "upload"
    if not isinstance(name, str):
        raise ExplorerError(f"upload: its name must be text, got {type(name).__name__}")
    return name


def upload_bytes(upload, limit: int, what: str) -> tuple[str, bytes]:
    """``(name, content)`` of a trame file upload (a dict with ``name`` and ``content``, the
    content bytes, whole or a list of chunks), its size checked against ``limit`` (bytes;
    ``what`` names the file in the message) before anything is joined or copied. Content
    that is not bytes is refused (``bytes(n)`` of a number would make n zero bytes)."""
    name = upload_name_of(upload)
    data = upload.get("content") or b""
    parts = data if isinstance(data, list) else [data]
    bad = next((p for p in parts if not isinstance(p, BYTES)), None)
    if bad is not None:
        raise ExplorerError(f"{what} '{upload_name(name)}': the content must be bytes, got "
                            f"{type(bad).__name__}")  # fmt: skip
    check_size(name, sum(memoryview(p).nbytes for p in parts), limit, what)
    return name, b"".join(parts)


def check_size(name: str, size: int, limit: int, what: str) -> None:
    """``size`` (bytes) within ``limit``, else one line naming the file and the limit."""
    if size > limit:
        raise ExplorerError(f"{what} '{upload_name(name)}' is too large: {size} bytes, the "
                            f"limit is {limit} bytes ({limit >> 20} MiB)")  # fmt: skip


class WebFiles:
    """The page's uploads and downloads: a collaborator the web explorer holds (``app.files``),
    as the controller holds its file flows.

    app : the explorer (its ``controller``, its trame ``server`` and its ``answers`` to the
        controller's next questions); folder : the server's private temporary folder (uploads
        and downloads are written there first, under names of their own)
    """

    _count = itertools.count(1)

    def __init__(self, app, folder: str) -> None:
        self.app = app
        self.folder = folder
        self.turntable_path: Path | None = None  # the turntable written last
        self.turntable_made = ""  # what it is ("36 frames, GIF")

    def _fresh_folder(self, kind: str) -> Path:
        folder = Path(self.folder) / f"{kind}-{next(self._count)}"
        folder.mkdir()
        return folder

    def page_text(self, text: str) -> str:
        """``text`` with the server's folders taken out of its paths: the page names an
        upload or a download by its own name (``bad.mtl:3: ...``) and a saved preset by
        ``presets/NAME.yaml`` (the user's preset folder, :func:`~explorer.core.presets.user_dir`),
        never a server path."""
        text = re.sub(re.escape(self.folder) + r"/[^/\s]+/", "", str(text))
        return text.replace(f"{user_dir()}{os.sep}", "presets/")

    # -- downloads -------------------------------------------------------------------------------
    def download(self, kind: str) -> dict:
        """``{"name", "type", "content"}``: the session, the view (PNG) or the material
        (.mtl, three.js JSON, X3D, preset YAML) as a file for the page to save."""
        if kind == "turntable":
            return self.turntable_download()
        if kind not in DOWNLOADS:
            raise ExplorerError(f"download must be one of {', '.join(DOWNLOADS)}, got {kind!r}")
        suffix, mime = DOWNLOADS[kind]
        c = self.app.controller
        folder = self._fresh_folder("download")
        if kind == "session":
            path = c.files.save_session_as(folder / "session.yaml")
        elif kind == "png":
            path = c.files.export_render(folder / f"{c.files.picture_stem()}.png")
        else:
            path = c.files.export_material(folder / f"{c.files.material_name()}{suffix}")
        if path is None:
            raise ExplorerError(f"download {kind}: nothing was written")
        data = read_checked(path, cap=MAX_DOWNLOAD_BYTES, what=f"{kind} download")
        return {"name": Path(path).name, "type": mime,
                "content": data if kind == "png" else data.decode("utf-8")}  # fmt: skip

    def start_turntable(self, suffix: str = ".gif", frames=DEFAULT_FRAMES) -> None:
        """A turntable of the present state, ``frames`` pictures in a full turn (a whole
        number, or its text, from 2 to :data:`~explorer.core.tolerances.MAX_TURNTABLE_FRAMES`),
        written as ``suffix`` (one of :func:`turntable_formats`), made in the background (the
        page shows its progress and offers it as a download when it is written)."""
        if suffix not in turntable_formats():
            raise ExplorerError(f"turntable: the format must be one of "
                                f"{', '.join(turntable_formats())}, got {suffix!r}")  # fmt: skip
        n = read_frames(frames)
        c = self.app.controller
        path = self._fresh_folder("turntable") / f"{c.files.picture_stem()}-turntable{suffix}"
        before = self.turntable_path, self.turntable_made
        self.turntable_path = path
        self.turntable_made = f"{n} frames, {format_name(suffix)}"
        try:
            c.files.export_turntable(path, frames=n)
        except BaseException:
            self.turntable_path, self.turntable_made = before  # the one made before stays
            raise

    def turntable_download(self) -> dict:
        """The turntable written last, as a file for the page to save."""
        path = self.turntable_path
        if path is None or not path.is_file():
            raise ExplorerError("no turntable has been written yet")
        mime = "image/gif" if path.suffix == ".gif" else "video/mp4"
        data = read_checked(path, cap=MAX_DOWNLOAD_BYTES, what="turntable download")
        return {"name": path.name, "type": mime, "content": data}

    # -- uploads ---------------------------------------------------------------------------------
    def open_uploaded_session(self, upload) -> None:
        """A session file chosen in the page: capped, kept under a fixed name, its mesh checked
        to be a built-in one, then opened by the controller."""
        name, data = upload_bytes(upload, MAX_BYTES, "session")
        path = self._fresh_folder("session") / "session.yaml"
        path.write_bytes(data)
        doc = load_yaml(path, what="session")
        mesh = doc.data.get("mesh") if isinstance(doc.data, dict) else None
        if mesh not in MESH_CHOICES:
            raise ExplorerError(
                f"session '{upload_name(name)}': mesh {mesh!r}: a session opened from the page "
                f"may name only a built-in mesh ({', '.join(MESH_CHOICES)})"
            )
        self.app.controller.files.open_session(path)

    def open_uploaded_map(self, key: str, upload) -> None:
        """An image chosen in the page for texture map ``key``: capped at
        :data:`~explorer.core.tolerances.MAX_TEXTURE_FILE_BYTES`, kept under its own safe name
        where the page's other uploads go, then set by the controller (one undo step; a file
        that is not a PNG or JPEG image is one line and nothing changes)."""
        uploads = upload if isinstance(upload, list) else [upload]
        if len(uploads) != 1:
            raise ExplorerError(f"{key}: upload one image (PNG or JPEG), got {len(uploads)}")
        name, data = upload_bytes(uploads[0], tol.MAX_TEXTURE_FILE_BYTES, f"{key} image")
        path = self._fresh_folder("map") / upload_name(name)
        path.write_bytes(data)
        self.app.controller.set_value(key, os.fspath(path), merge=False)

    @staticmethod
    def _upload_limit(name: str) -> tuple[int, str]:
        """The cap of an upload named ``name`` in a mesh's upload, and what it is called."""
        if name.lower().endswith(MESH_SUFFIXES):
            return tol.MAX_MESH_FILE_BYTES, "mesh file"
        return tol.MAX_MTL_FILE_BYTES, "material library"

    def open_uploaded_mesh(self, uploads) -> None:
        """A mesh file (and, for an OBJ, the .mtl libraries it names) chosen in the page."""
        files = [upload_bytes(u, *self._upload_limit(upload_name_of(u)))
                 for u in (uploads if isinstance(uploads, list) else [uploads])]  # fmt: skip
        meshes = [(n, d) for n, d in files if n.lower().endswith(MESH_SUFFIXES)]
        if len(meshes) != 1:
            raise ExplorerError(f"upload one mesh file ({', '.join(MESH_SUFFIXES)}) with its "
                                f".mtl files, got {len(meshes)} mesh files")  # fmt: skip
        folder = self._fresh_folder("mesh")
        for name, data in files:
            (folder / upload_name(name)).write_bytes(data)
        path = folder / upload_name(meshes[0][0])
        if path.suffix.lower() == ".obj":
            # the readers' one policy (geometry.sidefiles) refuses a library outside the OBJ's
            # folder, here the upload's: the page says so before anything is opened
            _, _, refused = obj_material_names(os.fspath(path), meshes[0][1])
            if refused:
                raise ExplorerError(
                    f"mesh file '{path.name}': {refused[0]}; a library outside the upload is "
                    "never read: upload the .mtl files beside the OBJ"
                )  # fmt: skip
        self.app.controller.files.choose_mesh(os.fspath(path))

    def import_uploaded_materials(self, upload) -> None:
        """An .mtl file chosen in the page: capped as a file on disk
        (:data:`~explorer.core.tolerances.MAX_MTL_FILE_BYTES`), kept under its own safe name,
        then imported by the controller (:meth:`FileFlows.import_materials`: its materials
        as presets in the user's preset folder, read by the same reader and checks). Preset
        files that exist are replaced only when the page's "replace" switch is on."""
        uploads = upload if isinstance(upload, list) else [upload]
        if len(uploads) != 1:
            raise ExplorerError(f"import materials: upload one .mtl file, got {len(uploads)}")
        name = upload_name_of(uploads[0])
        if not name.lower().endswith(".mtl"):
            raise ExplorerError(f"import materials: '{upload_name(name)}' is not an .mtl file")
        name, data = upload_bytes(uploads[0], tol.MAX_MTL_FILE_BYTES, "material library")
        path = self._fresh_folder("mtl") / upload_name(name)
        path.write_bytes(data)
        self.app.answers = {"yes": bool(self.app.server.state.preset_replace)}
        try:
            self.app.controller.files.import_materials(path)
        finally:
            self.app.answers = {}

    def save_preset(self, name: str, replace: bool = False) -> None:
        """Save the material as preset ``name`` in the user's preset folder (``replace``: the
        page's answer to "replace the file?" and "hide the preset of that name?")."""
        self.app.answers = {"yes": bool(replace)}
        try:
            self.app.controller.files.save_preset_as(str(name))
        finally:
            self.app.answers = {}
