"""The controller's file flows (a collaborator :class:`explorer.app.controller.Controller` holds as
``files``): open a
mesh, scene or session (and the recent ones), import materials from an .mtl file, export the
material and the view, save the session and presets, screenshots.

Every question goes through the dialogs port, so that scripts and tests answer them. No file is
replaced without a yes from ``ask_yes``; every file is written atomically.
"""

from __future__ import annotations

import json
import logging
import os
import stat
from pathlib import Path

from explorer.app import model as M
from explorer.app.session import last_session_path, load_session, save_session
from explorer.app.start import MESH_CHOICES, add_mesh_materials, free_name, load_mesh_choice
from explorer.app.turntablejob import DEFAULT_FRAMES, FRAMES_LABEL, TurntableJob, turntable_size
from explorer.core import tolerances as tol
from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError
from explorer.core.files import read_text_checked
from explorer.core.formats import EXPORT_SUFFIXES, convert
from explorer.core.mtl import MtlError, format_mtl, mtl_import, preset_name
from explorer.core.presets import MAX_NAME_LENGTH, check_name, save_preset, user_dir
from explorer.core.scene import load_scene
from explorer.core.yamlio import dump_yaml, load_yaml
from explorer.geometry.meshes import MESH_SUFFIXES, Mesh
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
#: file types File > Open takes
OPEN_FILTER = "meshes, scenes and sessions (*{} *.yaml *.yml *.json);;all files (*)".format(
    " *".join(MESH_SUFFIXES)
)
#: how long the status line shows what a mesh's materials were read with (ms)
STATUS_MS = 18_000


def plural(n: int, noun: str) -> str:
    """``"1 preset"``, ``"2 presets"``."""
    return f"{n} {noun}{'s' * (n != 1)}"


def recent_path(last_session) -> Path | None:
    """Where the recent-files list is kept: beside the last session (``last_session``: the
    controller's; none when no session is kept)."""
    if last_session is None:
        return None
    last = last_session_path() if last_session is True else Path(last_session)
    return last.with_name(RECENT_NAME)


def read_recent(path: Path | None) -> list[str]:
    """The files opened last, newest first, from the list at ``path`` (a list that cannot be
    read is empty)."""
    if path is None or not os.path.isfile(path):  # (False for a folder not searchable)
        return []
    try:
        text = read_text_checked(path, cap=tol.MAX_DATA_FILE_BYTES, what="recent files")
        items = json.loads(text)
    except ValueError as exc:  # UnreadableFile and JSON errors are ValueErrors
        log.warning("%s: cannot be read (%s); the recent files start afresh", path, exc)
        return []
    return [str(p) for p in items if isinstance(p, str)][:RECENT_MAX] if isinstance(
        items, list) else []  # fmt: skip


class FileFlows:
    """The controller's file flows, a collaborator it holds (``controller.files``): they use
    the controller's ``store``, ``ports``, ``say``, ``report``, ``act``, ``framed``,
    ``reload_presets``, ``presets``, ``meshes``, ``mesh_choices``, its directories, its session
    and last-session files and the turntable running."""

    def __init__(self, controller):
        self.c = controller

    # -- questions --------------------------------------------------------------------------
    def _output_path(self, path, title: str, default: str, filter: str, suffixes) -> Path | None:
        """``path``, or the one the user gives (None: given up), checked to end in one of
        ``suffixes``; ``default`` is a name in the output directory."""
        if path is None:
            path = self.c.ports.dialogs.ask_path(title, save=True, default=str(
                self.c.output_dir / default), filter=filter)  # fmt: skip
            if not path:
                return None
        path = Path(path)
        if path.suffix.lower() not in suffixes:
            raise ExplorerError(f"{path}: the file name must end in {', '.join(suffixes)}")
        return path

    def _ask_replace(self, path: Path) -> bool:
        """True when ``path`` may be written: it does not exist, or the user said yes."""
        return not os.path.lexists(path) or self.c.ports.dialogs.ask_yes(
            f"Replace the file {path}?")  # fmt: skip

    def _say_done(self, title: str, text: str, notes, noun: str) -> None:
        """``text`` said; with ``notes`` (each logged) their count, and a dialog that lists
        them."""
        for note in notes:
            log.warning("%s", note)
        if notes:
            text += f" ({plural(len(notes), noun)})"
            self.c.ports.dialogs.tell(title, text, details="\n".join(notes))
        self.c.say(text, "warning" if notes else "info", notes, open_log=False)

    # -- meshes -----------------------------------------------------------------------------
    def show_meshes(self) -> None:
        labels = {n: (Path(n).name if n not in MESH_CHOICES else n) for n in self.c.mesh_choices}
        self.c.ports.choices.show_meshes(labels)

    def _known_mesh(self, name: str, mesh: Mesh) -> None:
        self.c.meshes[name] = mesh
        if name not in self.c.mesh_choices:
            self.c.mesh_choices[name] = None
            self.show_meshes()

    def choose_mesh(self, name: str) -> bool:
        """Show mesh ``name`` (a chooser name): loaded once, the camera framed anew, with the
        materials its file brings. Returns False (the error said) when it cannot."""
        try:
            mesh = self.c.meshes.get(name) or load_mesh_choice(name, self.c.mesh_choices.get(name))
            self._known_mesh(name, mesh)
            state = M.set_mesh(
                self.c.store.state, name, mesh.centre, mesh.radius, uv=mesh.uv is not None
            )
            state = M.set_camera(state, self.c.framed(state, mesh))
            try:
                state, warnings = add_mesh_materials(state, mesh)
            except MtlError as exc:  # the mesh is drawn in the present material
                self.c.report(exc, "mesh materials")
                warnings = []
            self.c.store.commit(state, f"mesh {Path(name).name}")
        except ExplorerError as exc:
            self.c.report(exc, "mesh")
            return False
        self.say_mesh_warnings(mesh.name, warnings)
        return True

    def say_mesh_warnings(self, mesh_name: str, warnings, *, logged: bool = False) -> None:
        """The warnings of a mesh file's materials (its .mtl read), one message whose log lines
        are the warnings, whole: when the mesh is chosen, and for the mesh the explorer
        started with (``logged``: already printed where the explorer was started)."""
        if not warnings:
            return
        if not logged:
            for w in warnings:
                log.warning("%s", w)
        text = f"{mesh_name}: its materials read with {plural(len(warnings), 'warning')}"
        # the start's mesh: the log keeps them but does not open over the window at start
        # (they were printed where the explorer was started; the status bar says where they are)
        self.c.say(
            text + " (details in the message log)",
            "warning",
            list(warnings),
            STATUS_MS,
            open_log=not logged,
        )

    # -- open -------------------------------------------------------------------------------
    def open_file(self, path=None) -> None:
        """Open a mesh file, a scene file or a session (File > Open)."""
        if path is None:
            path = self.c.ports.dialogs.ask_path("Open mesh, scene or session", filter=OPEN_FILTER)
            if not path:
                return
        path = os.fspath(path)
        if not os.path.lexists(path):  # anything else is read, or refused, by the checked open
            raise ExplorerError(f"{path}: no such file")
        if path.lower().endswith(MESH_SUFFIXES):
            if self.choose_mesh(os.path.abspath(path)):
                self.remember_recent(path)
            return
        doc = load_yaml(path, what="scene or session")
        if isinstance(doc.data, dict) and "session" in doc.data:
            self.open_session(path)
        else:
            self._open_scene(load_scene(path, materials_dirs=self.c.materials_dirs), path)
        self.remember_recent(path)

    def _open_scene(self, scene, path: str) -> None:
        M.check_window_lights(len(scene.lights), path)
        s = self.c.store.state  # the scene's material covers the mesh (groups=None)
        new = s.replace(scene=scene.replace(mesh=s.mesh), preset=scene.material.name,
                        preset_material=None, light=0, held_azimuth=None,
                        groups=None)  # fmt: skip
        if scene.mesh is not None and scene.mesh != s.mesh:
            mesh = load_mesh_choice(scene.mesh)
            self._known_mesh(scene.mesh, mesh)
            new = M.set_mesh(new, scene.mesh, mesh.centre, mesh.radius, uv=mesh.uv is not None)
            new = new.replace(scene=new.scene.replace(lights=scene.lights))
            try:
                new, _ = add_mesh_materials(new, mesh, use=False)
            except MtlError as exc:
                self.c.report(exc, "mesh materials")
        new = M.set_camera(new, self.c.framed(new, self.c.meshes[new.mesh]))
        self.c.store.commit(new, f"open {Path(path).name}")
        self.c.say(f"opened scene {path}")

    def open_session(self, path) -> None:
        state, mesh = load_session(path, materials_dirs=self.c.materials_dirs)
        self._known_mesh(state.mesh, mesh)
        if state.camera is None:
            state = M.set_camera(state, self.c.framed(state, mesh))
        self.c.store.commit(state, f"open {Path(path).name}")
        self.c.session_path = Path(path)
        self.c.say(f"opened session {path}")

    # -- sessions and presets ---------------------------------------------------------------
    def save_session_as(self, path=None) -> Path | None:
        if path is None:
            default = str(self.c.session_path or Path.cwd() / "session.yaml")
            path = self.c.ports.dialogs.ask_path(
                "Save session", save=True, default=default, filter="sessions (*.yaml *.yml *.json)"
            )
            if not path:
                return None
        path = Path(path)
        overwrite = path.exists()
        if overwrite and not self.c.ports.dialogs.ask_yes(f"Replace the session file {path}?"):
            return None
        written = save_session(path, self.c.store.state, overwrite=overwrite)
        self.c.session_path = written
        self.remember_recent(written)
        self.c.say(f"saved session {written}")
        return written

    def keep_last_session(self) -> None:
        """Write the session to the last-session file (``gui --last`` reopens it). The file
        kept before is replaced; anything else at that path (a FIFO, a device, a link, a
        folder: not a session this explorer kept) is left as it is, and the warning says so."""
        if self.c.last_session is None:
            return
        try:
            path = Path(self.c.last_session) if self.c.last_session is not True else None
            path = path or last_session_path()
            if os.path.lexists(path) and not stat.S_ISREG(os.lstat(path).st_mode):
                raise ExplorerError(f"{path}: is not a regular file; left as it is")
            save_session(path, self.c.store.state, overwrite=True)
        except ExplorerError as exc:
            log.warning("could not keep the last session: %s", exc)

    def _preset_name(self, name, stem: str, taken: set) -> str | None:
        """The name to save a preset under: ``name``, or the one the user gives (checked)."""
        s = self.c.store.state
        if name is None:
            name = self.c.ports.dialogs.ask_text(
                "Save preset as", "preset name (lowercase letters, digits, _):",
                free_name(stem, taken) if s.edited else (s.preset or stem),
            )  # fmt: skip
            if not name:
                return None
        check_name(name)
        return name

    def save_preset_as(self, name: str | None = None) -> Path | None:
        """Save the material (with the current specular model) as a preset: asks for a name,
        checks it, asks before replacing a file or hiding another preset. The preset is then
        shown clean; while the mesh shows its own materials the edited group's is saved, and
        the groups stay."""
        s = self.c.store.state
        stem = (s.preset or self.material_name())[: MAX_NAME_LENGTH - 8]
        taken = {p.name for p in self.c.presets}
        name = self._preset_name(name, stem, taken)
        if name is None:
            return None
        directory = Path(self.c.preset_dir) if self.c.preset_dir else user_dir()
        path = directory / f"{name}.yaml"
        overwrite = path.exists()
        ask = self.c.ports.dialogs.ask_yes
        if overwrite and not ask(f"Replace the preset file {path}?"):
            return None
        if (
            not overwrite
            and name in taken
            and not ask(f"A preset named '{name}' exists; yours will hide it. Save anyway?")
        ):
            return None
        material = s.material.replace(model=s.scene.model, description=s.material.description
                                      or f"{stem} as edited in phong-explorer")  # fmt: skip
        written = save_preset(material, name, directory, overwrite=overwrite)
        self.c.reload_presets()
        info = next((p for p in self.c.presets if p.name == name), None)
        if info is not None and s.groups is None:
            self.c.act(M.apply_preset, name, info.material, label=f"save preset {name}")
        self.c.say(f"saved preset '{name}' to {written}")
        return written

    # -- recent files -----------------------------------------------------------------------
    def recent_files(self) -> list[str]:
        """The files opened last, newest first (:func:`read_recent`)."""
        return read_recent(recent_path(self.c.last_session))

    def remember_recent(self, path) -> None:
        """Put ``path`` first in the recent files."""
        path = os.path.abspath(os.fspath(path))
        items = [path] + [p for p in self.recent_files() if p != path]
        self.keep_recent(items[:RECENT_MAX])

    def keep_recent(self, items: list[str]) -> None:
        where = recent_path(self.c.last_session)
        if where is not None:
            try:
                text = json.dumps(items, indent=1).encode("utf-8")
                write_atomic(where, text, overwrite=True, make_dirs=True)
            except (OSError, ExplorerError) as exc:
                log.warning("could not keep the recent files: %s", exc)
        self.c.ports.choices.show_recent(items)

    def open_recent(self, path: str) -> None:
        if not os.path.isfile(path):
            self.keep_recent([p for p in self.recent_files() if p != path])
            raise ExplorerError(f"{path}: no such file (taken off the recent files)")
        self.open_file(path)

    # -- materials --------------------------------------------------------------------------
    def import_materials(self, path=None) -> list[Path]:
        """Every material of an .mtl file as a preset in the user's preset directory (as
        ``presets import``): asks before replacing preset files (all or nothing); a file the
        reader cannot take is named with its line in a dialog, and nothing is written; the
        reader's warnings are shown. Returns the preset files written."""
        dialogs = self.c.ports.dialogs
        if path is None:
            path = dialogs.ask_path("Import materials", filter="material libraries (*.mtl);;"
                                    "all files (*)")  # fmt: skip
            if not path:
                return []
        directory = Path(self.c.preset_dir) if self.c.preset_dir else user_dir()
        try:
            job = mtl_import(path, directory)
        except MtlError as exc:
            self.c.say(f"error (import materials): {exc}", "error")
            dialogs.tell("Import materials", f"{exc}\n\nNothing was imported.", error=True)
            return []
        existing = job.existing
        if existing and not dialogs.ask_yes(
            f"{plural(len(existing), 'preset file')} of {Path(path).name} "
            f"exist already:\n" + "\n".join(str(t) for t in existing) + "\n\nReplace them?"
        ):
            self.c.say(f"nothing imported from {path}: the preset files exist")
            return []
        written = job.write(overwrite=bool(existing))
        warnings = [w for m in job.found for w in m.warnings]
        self.c.reload_presets()
        text = (f"imported {plural(len(written), 'preset')} from {Path(path).name} into "
                f"{directory}: " + ", ".join(job.names))  # fmt: skip
        self._say_done("Import materials", text, warnings, "warning")
        return written

    def material_name(self) -> str:
        """A file or preset name for the material shown: the preset's, or the edited group's."""
        s = self.c.store.state
        if s.groups is not None:
            return preset_name(s.mesh_materials.names[s.group] or "material")
        return preset_name(s.preset or s.material.name or "material")

    def export_material(self, path=None) -> Path | None:
        """The material (with the specular model) as a file chosen by its suffix: ``.mtl``,
        ``.json`` (three.js), ``.x3d``, ``.yaml`` (a preset file). While the mesh shows its own
        materials, an ``.mtl`` holds every group's (a library for the OBJ); the other formats
        hold the edited group's. The approximations a format makes are shown."""
        s = self.c.store.state
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

    # -- pictures ---------------------------------------------------------------------------
    def picture_stem(self) -> str:
        """``phong-explorer-<preset or mesh file>-<mesh>``, safe as a file name."""
        s = self.c.store.state
        what = s.preset or (s.mesh_materials.source if s.groups is not None else "material")
        stem = f"phong-explorer-{Path(what).stem}-{Path(s.mesh).stem}"
        return "".join(ch if ch.isalnum() or ch in "-_" else "_" for ch in stem)

    def export_render(self, path=None) -> Path | None:
        """The view as a PNG file of the user's choice (asks before replacing one)."""
        path = self._output_path(path, "Export view as PNG", f"{self.picture_stem()}.png",
                                 "PNG pictures (*.png)", (".png",))  # fmt: skip
        if path is None or not self._ask_replace(path):
            return None
        written = write_atomic(path, self.c.ports.view.png(), overwrite=os.path.lexists(path))
        self.c.say(f"exported the view to {written}")
        return written

    def screenshot(self) -> Path:
        """Save the view as a PNG in the output directory (a new file every time)."""
        stem = self.picture_stem()
        taken = {p.stem for p in self.c.output_dir.glob(f"{stem}_*.png")}
        path = self.c.output_dir / f"{free_name(stem, taken)}.png"
        write_atomic(path, self.c.ports.view.png())
        self.c.say(f"saved screenshot {path}")
        return path

    def export_turntable(self, path=None, frames: int | None = None, size=None):
        """A turntable of the present state (the camera and lights orbit the mesh) as a GIF or
        MP4, made a frame at a time under the progress port, whose Cancel leaves no file.
        ``size``: (width, height), default the view's. Returns the job (its ``stage`` says how
        far it got; ``job.dialog`` the front end's progress handle), or None when the user gave
        up at a question."""
        if self.c.turntable is not None and self.c.turntable.stage in ("render", "encode"):
            raise ExplorerError("a turntable is being made: wait for it, or cancel it")
        s = self.c.store.state
        path = self._output_path(path, "Export turntable",
                                 f"{self.picture_stem()}-turntable.gif",
                                 "GIF (*.gif);;MP4 (*.mp4)", TURNTABLE_SUFFIXES)  # fmt: skip
        if path is None:
            return None
        if frames is None:
            frames = self.c.ports.dialogs.ask_number(
                "Export turntable",
                f"{FRAMES_LABEL}:",
                DEFAULT_FRAMES,
                2,
                tol.MAX_TURNTABLE_FRAMES,
            )
            if frames is None:
                return None
        if not self._ask_replace(path):
            return None
        size = turntable_size(*(size or self.c.ports.view.size()))
        job = TurntableJob(s.shown_scene(), self.c.meshes[s.mesh], frames, size, path,
                           groups=s.shown_groups(), camera=s.camera,
                           background=tuple(self.c.ports.view.background()),
                           overwrite=os.path.lexists(path))  # fmt: skip
        self.c.turntable = job

        def step():
            try:
                stage = job.step()
            except Exception as exc:  # noqa: BLE001 - said, and the job ends
                job.cancel()
                self.c.report(exc, "turntable")
                return None
            if stage == "written":
                self.c.say(f"wrote {path}: {frames} frames of {size[0]}x{size[1]}")
                return None
            return job.done, (f"Encoding {path.name}…" if stage == "encode" else None)

        def cancel():
            job.cancel()
            self.c.say(f"turntable cancelled: {path} was not written")

        job.dialog = self.c.ports.progress.run_steps(
            "turntable", f"Drawing {frames} frames of {path.name}…", frames + 1, step, cancel
        )
        return job
