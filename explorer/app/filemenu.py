"""The explorer window's File menu (a mix-in of :class:`explorer.app.window.ExplorerWindow`):
open a mesh, scene or session (and the recent ones), import materials from an .mtl file,
export the material, the view as a PNG and a turntable, save the session and presets.

Every question goes through a replaceable method (:meth:`Commands.ask_path`,
:meth:`Commands.ask_yes`, :meth:`FileCommands.ask_number`, :meth:`FileCommands.tell`), so that
scripts and tests answer them. No file is replaced without a yes from :meth:`ask_yes`; every
file is written atomically.
"""

from __future__ import annotations

import json
import logging
import os
from pathlib import Path

import numpy as np
from PySide6 import QtCore, QtWidgets

from explorer.app import model as M
from explorer.app.session import last_session_path
from explorer.app.start import add_mesh_materials, load_mesh_choice
from explorer.app.turntablejob import DEFAULT_FRAMES, TurntableJob, turntable_size
from explorer.core import tolerances as tol
from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError
from explorer.core.files import read_text_checked
from explorer.core.formats import EXPORT_SUFFIXES, convert
from explorer.core.mtl import MtlError, format_mtl, mtl_import, preset_name
from explorer.core.presets import user_dir
from explorer.core.yamlio import dump_yaml
from explorer.geometry.meshes import Mesh
from explorer.render.images import encode_png, side_by_side
from explorer.render.turntable import TURNTABLE_SUFFIXES

log = logging.getLogger(__name__)

#: how many files File > Open recent keeps
RECENT_MAX = 8
#: the recent-files list is kept beside the last session, under this name
RECENT_NAME = "recent-files.json"
#: export suffixes of the material: the formats of ``presets export``, and preset YAML
MATERIAL_SUFFIXES = {**EXPORT_SUFFIXES, ".yaml": "preset YAML", ".yml": "preset YAML"}
MATERIAL_FILTER = (
    "Wavefront MTL (*.mtl);;three.js MeshPhongMaterial JSON (*.json);;X3D Material (*.x3d);;"
    "phong-explorer preset (*.yaml *.yml)"
)
#: how long the status bar shows what a mesh's materials were read with (ms)
STATUS_MS = 18_000
#: how often the turntable's timer takes a step (ms; 0: whenever the event loop is idle)
TURNTABLE_STEP_MS = 0


def plural(n: int, noun: str) -> str:
    """``"1 preset"``, ``"2 presets"``."""
    return f"{n} {noun}{'s' * (n != 1)}"


class FileCommands:
    """The File menu and its commands (needs the window's ``store``, ``view``, ``plotter``,
    ``add_action``, ``render``, ``report``, ``show_status``, ``reload_presets`` and the
    questions of :class:`~explorer.app.commands.Commands`)."""

    # -- questions (replaceable by scripts and tests) -----------------------------------------
    def ask_number(self, title: str, label: str, default: int, lo: int, hi: int) -> int | None:
        value, ok = QtWidgets.QInputDialog.getInt(self, title, label, default, lo, hi)
        return int(value) if ok else None

    def tell(self, title: str, text: str, *, details: str = "", error: bool = False) -> None:
        """A message box (``details`` behind its Show Details button)."""
        box = QtWidgets.QMessageBox(self)
        box.setIcon(QtWidgets.QMessageBox.Icon.Warning if error
                    else QtWidgets.QMessageBox.Icon.Information)  # fmt: skip
        box.setWindowTitle(f"phong-explorer: {title}")
        box.setText(text)
        if details:
            box.setDetailedText(details)
        box.exec()

    def _output_path(self, path, title: str, default: str, filter: str, suffixes) -> Path | None:
        """``path``, or the one the user gives (None: given up), checked to end in one of
        ``suffixes``; ``default`` is a name in the output directory."""
        if path is None:
            path = self.ask_path(title, save=True, default=str(self.output_dir / default),
                                 filter=filter)  # fmt: skip
            if not path:
                return None
        path = Path(path)
        if path.suffix.lower() not in suffixes:
            raise ExplorerError(f"{path}: the file name must end in {', '.join(suffixes)}")
        return path

    def _say_done(self, title: str, text: str, notes, noun: str) -> None:
        """``text`` on the status bar; with ``notes`` (each logged) their count, and a dialog
        that lists them."""
        for note in notes:
            log.warning("%s", note)
        if notes:
            text += f" ({plural(len(notes), noun)})"
            self.tell(title, text, details="\n".join(notes))
        self.show_status(text, warning=bool(notes), details=notes, open_log_=False)

    def _ask_replace(self, path: Path) -> bool:
        """True when ``path`` may be written: it does not exist, or the user said yes."""
        return not os.path.lexists(path) or self.ask_yes(f"Replace the file {path}?")

    # -- the menu -----------------------------------------------------------------------------
    def build_file_menu(self, f: QtWidgets.QMenu) -> None:
        add = self.add_action
        add(f, "open", "&Open mesh, scene or session…", self.open_file, "Ctrl+O")
        self.recent_menu = f.addMenu("Open &recent")
        self.recent_menu.setObjectName("recent")
        f.addSeparator()
        add(f, "import_materials", "&Import materials (.mtl)…", self.import_materials, "Ctrl+I")
        add(f, "export_material", "&Export material…", self.export_material, "Ctrl+E")
        add(f, "export_render", "Export &view as PNG…", self.export_render, "Ctrl+Shift+E")
        add(f, "export_turntable", "Export &turntable (GIF, MP4)…", self.export_turntable,
            "Ctrl+T")  # fmt: skip
        f.addSeparator()
        add(f, "save_session", "&Save session…", self.save_session_as, "Ctrl+S")
        add(f, "save_preset", "Save &preset as…", self.save_preset_as, "Ctrl+Shift+S")
        add(f, "screenshot", "Save screens&hot", self.screenshot)
        f.addSeparator()
        add(f, "quit", "&Quit", self.close, "Ctrl+Q")
        self.turntable = None
        self._show_recent()

    # -- meshes -------------------------------------------------------------------------------
    def choose_mesh(self, name: str) -> bool:
        """Show mesh ``name`` (a chooser name): loaded once, the camera framed anew, with the
        materials its file brings. Returns False (the error shown) when it cannot."""
        try:
            mesh = self.meshes.get(name)
            if mesh is None:
                mesh = load_mesh_choice(name, self.mesh_choices.get(name))
                self.meshes[name] = mesh
            if name not in self.mesh_choices:
                self.mesh_choices[name] = None
                self._set_mesh_choices()
            state = M.set_mesh(self.store.state, name, mesh.centre, mesh.radius)
            state = M.set_camera(state, self._framed(state, mesh))
            state, warnings = self._with_mesh_materials(state, mesh)
            self.store.commit(state, f"mesh {Path(name).name}")
        except ExplorerError as exc:
            self.report(exc, "mesh")
            return False
        if warnings:
            for w in warnings:
                log.warning("%s", w)
            self.show_status(f"{mesh.name}: its materials read with "
                             f"{plural(len(warnings), 'warning')} (View ▸ Messages)",
                             msecs=STATUS_MS, warning=True, details=warnings)  # fmt: skip
        return True

    def _with_mesh_materials(self, state: M.State, mesh: Mesh) -> tuple[M.State, list[str]]:
        """``state`` showing the materials the mesh file brings; a library the reader cannot
        take is reported (file and line) and the mesh is drawn in the present material."""
        try:
            return add_mesh_materials(state, mesh)
        except MtlError as exc:
            self.report(exc, "mesh materials")
            return state, []

    # -- recent files -------------------------------------------------------------------------
    def recent_file(self) -> Path | None:
        """Where the recent-files list is kept: beside the last session (none when the window
        keeps no session)."""
        if self.last_session is None:
            return None
        last = last_session_path() if self.last_session is True else Path(self.last_session)
        return last.with_name(RECENT_NAME)

    def recent_files(self) -> list[str]:
        """The files opened last, newest first (a list that cannot be read is empty)."""
        path = self.recent_file()
        if path is None or not path.is_file():
            return []
        try:
            text = read_text_checked(path, cap=tol.MAX_DATA_FILE_BYTES, what="recent files")
            items = json.loads(text)
        except ValueError as exc:  # UnreadableFile and JSON errors are ValueErrors
            log.warning("%s: cannot be read (%s); the recent files start afresh", path, exc)
            return []
        return [str(p) for p in items if isinstance(p, str)][:RECENT_MAX] if isinstance(
            items, list) else []  # fmt: skip

    def remember_recent(self, path) -> None:
        """Put ``path`` first in the recent files."""
        path = os.path.abspath(os.fspath(path))
        items = [path] + [p for p in self.recent_files() if p != path]
        self._keep_recent(items[:RECENT_MAX])

    def _keep_recent(self, items: list[str]) -> None:
        where = self.recent_file()
        if where is not None:
            try:
                text = json.dumps(items, indent=1).encode("utf-8")
                write_atomic(where, text, overwrite=True, make_dirs=True)
            except (OSError, ExplorerError) as exc:
                log.warning("could not keep the recent files: %s", exc)
        self._show_recent(items)

    def _show_recent(self, items: list[str] | None = None) -> None:
        menu = self.recent_menu
        menu.clear()
        items = self.recent_files() if items is None else items
        for i, path in enumerate(items):
            a = menu.addAction(f"&{i + 1} {Path(path).name}   ({Path(path).parent})")
            a.setObjectName(f"recent_{i + 1}")
            a.triggered.connect(self._guard(lambda _=False, p=path: self._open_recent(p),
                                            "open recent"))  # fmt: skip
        if items:
            menu.addSeparator()
            clear = menu.addAction("&Clear the list")
            clear.triggered.connect(self._guard(lambda _=False: self._keep_recent([]), "recent"))
        menu.setEnabled(bool(items))

    def _open_recent(self, path: str) -> None:
        if not os.path.isfile(path):
            self._keep_recent([p for p in self.recent_files() if p != path])
            raise ExplorerError(f"{path}: no such file (taken off the recent files)")
        self.open_file(path)

    # -- materials ----------------------------------------------------------------------------
    def import_materials(self, path=None) -> list[Path]:
        """Every material of an .mtl file as a preset in the user's preset directory (as
        ``presets import``): asks before replacing preset files (all or nothing); a file the
        reader cannot take is named with its line in a dialog, and nothing is written; the
        reader's warnings are shown. Returns the preset files written."""
        if path is None:
            path = self.ask_path("Import materials", filter="material libraries (*.mtl);;"
                                 "all files (*)")  # fmt: skip
            if not path:
                return []
        directory = Path(self.preset_dir) if self.preset_dir else user_dir()
        try:
            job = mtl_import(path, directory)
        except MtlError as exc:
            self.show_status(f"error (import materials): {exc}", error=True)
            self.tell("Import materials", f"{exc}\n\nNothing was imported.", error=True)
            return []
        existing = job.existing
        if existing and not self.ask_yes(
            f"{plural(len(existing), 'preset file')} of {Path(path).name} "
            f"exist already:\n" + "\n".join(str(t) for t in existing) + "\n\nReplace them?"
        ):
            self.show_status(f"nothing imported from {path}: the preset files exist")
            return []
        written = job.write(overwrite=bool(existing))
        warnings = [w for m in job.found for w in m.warnings]
        names = job.names
        self.reload_presets()
        text = (f"imported {plural(len(written), 'preset')} from {Path(path).name} into "
                f"{directory}: " + ", ".join(names))  # fmt: skip
        self._say_done("Import materials", text, warnings, "warning")
        return written

    def material_name(self) -> str:
        """A file or preset name for the material shown: the preset's, or the edited group's."""
        s = self.store.state
        if s.groups is not None:
            return preset_name(s.mesh_materials.names[s.group] or "material")
        return preset_name(s.preset or s.material.name or "material")

    def export_material(self, path=None) -> Path | None:
        """The material (with the specular model) as a file chosen by its suffix: ``.mtl``,
        ``.json`` (three.js), ``.x3d``, ``.yaml`` (a preset file). While the mesh shows its own
        materials, an ``.mtl`` holds every group's (a library for the OBJ); the other formats
        hold the edited group's. The approximations a format makes are shown."""
        s = self.store.state
        name = self.material_name()
        path = self._output_path(path, "Export material", f"{name}.mtl", MATERIAL_FILTER,
                                 tuple(MATERIAL_SUFFIXES))  # fmt: skip
        if path is None or not self._ask_replace(path):
            return None
        suffix = path.suffix.lower()
        material = s.material.replace(model=s.scene.model)
        if suffix == ".mtl" and s.groups is not None:
            # the usemtl names as they are, so the file serves as the OBJ's library
            names = [n if n and not any(c.isspace() for c in n) else preset_name(n or "material")
                     for n in s.mesh_materials.names]  # fmt: skip
            models = [m.replace(model=s.scene.model) for m in s.groups]
            pairs = list(zip(names, models, strict=True))
            text, notes, what = format_mtl(pairs), [], f"{len(pairs)} materials of the mesh"
        elif suffix in EXPORT_SUFFIXES:
            converted = convert(material, name, EXPORT_SUFFIXES[suffix])
            text, notes, what = converted.text, list(converted.notes), f"'{name}'"
        else:
            header = f"phong-explorer material preset '{name}'"
            text, notes, what = dump_yaml(material.to_mapping(), header=header), [], f"'{name}'"
        written = write_atomic(path, text.encode("utf-8"), overwrite=os.path.lexists(path))
        message = f"exported {what} to {written} as {MATERIAL_SUFFIXES[suffix]}"
        self._say_done("Export material", message, notes, "approximation")
        return written

    # -- pictures -----------------------------------------------------------------------------
    def view_png(self) -> bytes:
        """The 3D view as it is drawn now, PNG-encoded: in the compare view both panes, side
        by side as in the window (A left, B right, the gap between them in the splitter's
        place)."""
        self.render()
        img = self.plotter.screenshot(return_img=True)[:, :, :3]
        pl_b = self.plotter_b
        if pl_b is not None and pl_b.isVisible():
            pl_b.render_window.Render()  # drawn at its present size before it is read
            b = pl_b.screenshot(return_img=True)[:, :, :3]
            a_x = self.plotter.mapTo(self, QtCore.QPoint(0, 0)).x()
            gap = max(pl_b.mapTo(self, QtCore.QPoint(0, 0)).x() - a_x - img.shape[1], 0)
            fill = self.views.palette().window().color().getRgb()[:3]  # the splitter's
            img = side_by_side(img, b, gap, fill)
        return encode_png(np.ascontiguousarray(img))

    def picture_stem(self) -> str:
        """``phong-explorer-<preset or mesh file>-<mesh>``, safe as a file name."""
        s = self.store.state
        what = s.preset or (s.mesh_materials.source if s.groups is not None else "material")
        stem = f"phong-explorer-{Path(what).stem}-{Path(s.mesh).stem}"
        return "".join(ch if ch.isalnum() or ch in "-_" else "_" for ch in stem)

    def export_render(self, path=None) -> Path | None:
        """The 3D view as a PNG file of the user's choice (asks before replacing one)."""
        path = self._output_path(path, "Export view as PNG", f"{self.picture_stem()}.png",
                                 "PNG pictures (*.png)", (".png",))  # fmt: skip
        if path is None or not self._ask_replace(path):
            return None
        written = write_atomic(path, self.view_png(), overwrite=os.path.lexists(path))
        self.show_status(f"exported the view to {written}")
        return written

    def export_turntable(self, path=None, frames: int | None = None, size=None):
        """A turntable of the present state (the camera and lights orbit the mesh) as a GIF or
        MP4, made a frame at a time under a progress dialog whose Cancel leaves no file.
        ``size``: (width, height), default the view's. Returns the job (its ``stage`` says
        how far it got), or None when the user gave up at a question."""
        if self.turntable is not None and self.turntable.stage in ("render", "encode"):
            raise ExplorerError("a turntable is being made: wait for it, or cancel it")
        s = self.store.state
        path = self._output_path(path, "Export turntable",
                                 f"{self.picture_stem()}-turntable.gif",
                                 "GIF (*.gif);;MP4 (*.mp4)", TURNTABLE_SUFFIXES)  # fmt: skip
        if path is None:
            return None
        if frames is None:
            frames = self.ask_number("Export turntable", "frames in a full turn:",
                                     DEFAULT_FRAMES, 2, tol.MAX_TURNTABLE_FRAMES)  # fmt: skip
            if frames is None:
                return None
        if not self._ask_replace(path):
            return None
        size = turntable_size(*(size or self.plotter.window_size))
        job = TurntableJob(
            s.shown_scene(), self.view.mesh, frames, size, path, groups=s.shown_groups(),
            camera=s.camera,
            background=tuple(self.plotter.renderer.GetBackground()),
            overwrite=os.path.lexists(path),
        )  # fmt: skip
        self.turntable = job
        dialog = QtWidgets.QProgressDialog(f"Drawing {frames} frames of {path.name}…",
                                           "Cancel", 0, frames + 1, self)  # fmt: skip
        dialog.setObjectName("turntable_progress")
        dialog.setWindowTitle("phong-explorer: turntable")
        dialog.setWindowModality(QtCore.Qt.WindowModality.WindowModal)
        dialog.setMinimumDuration(0)
        dialog.setAutoClose(False)
        dialog.setAutoReset(False)
        timer = QtCore.QTimer(dialog)
        job.dialog = dialog

        def finish(text: str, error: bool = False) -> None:
            timer.stop()
            dialog.close()
            self.show_status(text, error=error)

        def step() -> None:
            if dialog.wasCanceled():
                job.cancel()
                finish(f"turntable cancelled: {path} was not written")
                return
            try:
                stage = job.step()
            except Exception as exc:  # noqa: BLE001 - shown, and the job ends
                job.cancel()
                timer.stop()
                dialog.close()
                self.report(exc, "turntable")
                return
            dialog.setValue(job.done)
            if stage == "encode":
                dialog.setLabelText(f"Encoding {path.name}…")
            elif stage == "written":
                dialog.setValue(frames + 1)
                finish(f"wrote {path}: {frames} frames of {size[0]}x{size[1]}")

        timer.timeout.connect(step)
        timer.start(TURNTABLE_STEP_MS)
        dialog.show()
        return job
