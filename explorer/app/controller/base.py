"""The controller: intents in, model actions, the view port told once per change (see
:mod:`explorer.app.controller`)."""

from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

from explorer.app import model as M
from explorer.app import panelmodel
from explorer.app.controller.files import FileFlows
from explorer.app.controller.ports import Ports
from explorer.app.difference import Job
from explorer.app.start import MESH_CHOICES
from explorer.app.view import framed_camera
from explorer.core.errors import ExplorerError
from explorer.core.lights import LIGHT_TYPES
from explorer.core.presets import list_presets
from explorer.geometry.meshes import Mesh
from explorer.render.camera import Camera

#: the file dialog's filter for a texture map's image
IMAGE_FILTER = "images (*.png *.jpg *.jpeg);;all files (*)"

log = logging.getLogger(__name__)

#: a view smaller than this (either side, pixels) is not laid out yet: no difference asked
MIN_DIFFERENCE_SIZE = 16


class Controller:
    """Every flow of the explorer, for any front end.

    state, mesh : the start (``mesh`` is the mesh ``state.mesh`` names; a state without a
        camera gets this mesh framed for the view's aspect)
    ports : the front end (:class:`~explorer.app.controller.ports.Ports`)
    materials_dirs : extra preset directories; preset_dir : where presets are saved (default:
        the user's); output_dir : where screenshots go (default: the current directory);
    last_session : the file the session is kept in on quit (True: the default one; None: none)
    """

    def __init__(self, state: M.State, mesh: Mesh, ports: Ports, *, materials_dirs=(),
                 preset_dir=None, output_dir=None, last_session=None):  # fmt: skip
        self.ports = ports
        self.materials_dirs = tuple(materials_dirs)
        self.preset_dir = preset_dir
        self.output_dir = Path(output_dir) if output_dir else Path.cwd()
        self.last_session = last_session
        self.session_path: Path | None = None
        self.errors: list[str] = []
        self._error_shown = False  # the last message said is an error (the next edit clears it)
        self.presets: list = []
        self.turntable = None
        self.meshes: dict[str, Mesh] = {state.mesh: mesh}
        self.mesh_choices = dict(MESH_CHOICES)
        if state.mesh not in self.mesh_choices:
            self.mesh_choices = {state.mesh: None, **self.mesh_choices}
        if state.camera is None:
            state = M.set_camera(state, self.framed(state, mesh))
        self.start_state = state
        self.store = M.Store(state)
        self.difference = None  # the difference result shown (its key says for what)
        self._requested = None  # the key of the difference job asked for last
        self._size = None  # the view's size at the last difference check
        self._in_frame = False
        #: the file flows (open, save, import, export, screenshots, meshes), a collaborator
        self.files = FileFlows(self)

    def start(self) -> None:
        """Observe the store, show the lists, schedule the difference (call once, after the
        front end's view exists)."""
        self.store.subscribe(self._on_change)
        self.reload_presets()
        self.files.show_meshes()
        self.ports.choices.show_recent(self.files.recent_files())
        self._show_history()
        self.update_difference()

    @property
    def state(self) -> M.State:
        return self.store.state

    @property
    def in_frame(self) -> bool:
        """Whether the change being shown came from the view's own camera (before a frame)."""
        return self._in_frame

    # -- messages ---------------------------------------------------------------------------
    def say(self, text: str, level: str = "info", details=(), msecs=None, open_log=True):
        """Say ``text`` (see :class:`~explorer.app.controller.ports.Messages`; ``""`` takes
        the message shown away and logs nothing)."""
        self._error_shown = False
        self.ports.messages.show_message(text, level, tuple(details), msecs, open_log)

    def report(self, exc: BaseException, where: str) -> None:
        """An error, said whole (an :class:`ExplorerError` is the user's; anything else is a
        bug, logged with its traceback) and kept in :attr:`errors`."""
        if isinstance(exc, ExplorerError):
            text = str(exc)
            log.error("%s: %s", where, text)
        else:
            text = f"{type(exc).__name__}: {exc}"
            log.error("%s failed", where, exc_info=exc)
        lines = text.splitlines() or [type(exc).__name__]
        self.errors.append(f"{where}: {text}")
        self.say(f"error ({where}): {lines[0]}", "error", lines[1:])
        self._error_shown = True

    def reject_input(self, text: str) -> None:
        """A typed value was refused (``text`` names the key and the range)."""
        self.errors.append(f"typed value: {text}")
        self.say(f"error: {text}", "error")
        self._error_shown = True
        self.ports.view.show(None, self.store.state)

    # -- changes ----------------------------------------------------------------------------
    def act(self, action, *args, label: str | None = None, merge=None) -> bool:
        """Apply ``action(state, *args)`` as one undo step (steps with the same ``merge`` key
        join until the next seal); ``act(None)`` seals (a slider's release). Errors are said,
        and the controls show the state again."""
        if action is None:
            self.store.seal()
            return False
        try:
            changed = self.store.apply(action, *args, label=label, merge=merge)
        except ExplorerError as exc:
            self.report(exc, label or action.__name__)
            self.ports.view.show(None, self.store.state)  # the sending control shows the state
            return False
        if changed and self._error_shown:  # an edit that worked takes the last error away
            self._error_shown = False
            self.say("", "info", open_log=False)
        return changed

    def set_value(self, key: str, value, *, merge: bool = True) -> bool:
        """Set control ``key`` (a row of :mod:`explorer.app.panelmodel`: a number, a colour's
        (r, g, b), a choice, a toggle, the attenuation's triple; ``distance`` in mesh radii; a
        list's item: a preset's name, a light's index); a run of steps of one control is one
        undo step until :meth:`release`. A key the state does not show (a spot's cutoff on a
        point light) is refused by its action and said; an unknown key or preset raises
        :class:`ExplorerError`. An image row's :data:`~explorer.app.panelmodel.ASK_FILE` asks
        the front end's file dialog for the image first (nothing when none is given)."""
        if value is panelmodel.ASK_FILE:
            value = self.ports.dialogs.ask_path(f"Choose the {key} image", filter=IMAGE_FILTER)
            if not value:
                return False
        action, args, label = panelmodel.edit(self.store.state, key, value, self.presets)
        return self.act(action, *args, label=label, merge=key if merge else None)

    def release(self) -> None:
        """A control was let go: the steps so far are one undo step."""
        self.store.seal()

    def _on_change(self, old: M.State, new: M.State) -> None:
        """One change: the view shows it (one engine update, one upload), the difference is
        scheduled once, and one frame is asked for (none when the change came from a frame)."""
        self.ports.view.show(old, new)
        self._show_history()
        self.update_difference()
        if not self._in_frame:
            self.ports.view.redraw()

    def _show_history(self) -> None:
        s = self.store
        self.ports.choices.show_history(s.undo_label() if s.can_undo else None,
                                        s.redo_label() if s.can_redo else None)  # fmt: skip

    # -- camera -----------------------------------------------------------------------------
    def framed(self, state: M.State, mesh: Mesh) -> Camera:
        """``mesh`` framed from ``state``'s viewer for the view's aspect."""
        view = self.ports.view
        cam = framed_camera(state, mesh, view.aspect(), view.size()[1])
        return dataclasses.replace(cam, window_center=(0.0, 0.0))

    def camera_moved(self, camera: Camera) -> None:
        """The view's camera before a frame (the camera is the viewer): no undo step, no frame
        asked for; the difference is checked again when the view's size changed."""
        self._in_frame = True
        try:
            self.store.set_camera(camera)
        finally:
            self._in_frame = False
        if self.ports.view.size() != self._size:
            self.update_difference()

    def move_camera(self, camera: Camera) -> None:
        """Put the camera somewhere (no undo step)."""
        self.store.set_camera(camera)

    def frame_start(self) -> None:
        """Frame the start's mesh anew for the view's present aspect (its first showing)."""
        cam = self.framed(self.store.state, self.meshes[self.store.state.mesh])
        self.start_state = M.set_camera(self.start_state, cam)
        self.store.set_camera(cam)

    def reset_camera(self) -> None:
        """The start camera (this mesh framed from the start's viewer); no undo step."""
        s = self.store.state
        if s.mesh == self.start_state.mesh:
            cam = self.start_state.camera
        else:
            start = s.replace(scene=s.scene.replace(viewer=self.start_state.scene.viewer))
            cam = self.framed(start, self.meshes[s.mesh])
        self.store.set_camera(cam)
        self.say("camera reset")

    # -- edit -------------------------------------------------------------------------------
    def undo(self) -> None:
        if not self.store.undo():
            self.say("nothing to undo")

    def redo(self) -> None:
        if not self.store.redo():
            self.say("nothing to redo")

    def reset_all(self) -> None:
        """Back to the start (material, lights, mesh, terms, camera): one undo step."""
        self.store.commit(self.start_state, "reset all")
        self.say("reset to the start (Ctrl+Z brings your changes back)")

    # -- toggles ----------------------------------------------------------------------------
    def toggle_difference(self) -> None:
        self.act(M.set_difference, not self.store.state.difference, label="difference")

    def toggle_compare(self) -> None:
        self.act(M.set_compare, self.store.state.compare is None, label="compare")

    def swap_sides(self) -> None:
        self.act(M.swap_compare, label="swap A and B")

    def toggle_model(self) -> None:
        """The next specular model of :data:`explorer.core.material.MODELS`."""
        self.act(M.set_model, M.next_model(self.store.state.scene.model), label="model")

    def toggle_term(self, term: str) -> None:
        shown = term not in self.store.state.hidden
        self.act(M.set_term, term, not shown, label=f"{term} term")

    def toggle_ambient(self) -> None:
        self.toggle_term("ambient")

    def toggle_diffuse(self) -> None:
        self.toggle_term("diffuse")

    def toggle_specular(self) -> None:
        self.toggle_term("specular")

    # -- presets and lights -----------------------------------------------------------------
    def reload_presets(self) -> None:
        notices: list[str] = []
        self.presets = list_presets(self.materials_dirs, notices=notices)
        for text in notices:
            log.warning("%s", text)
        self.ports.choices.show_presets(self.presets)

    def pick_preset(self, name: str) -> bool:
        """Show preset ``name`` (one undo step; the preset row's edit)."""
        return self.set_value("preset", name, merge=False)

    def _step_preset(self, step: int) -> None:
        if not self.presets:
            raise ExplorerError("no presets found")
        names = [p.name for p in self.presets]
        s = self.store.state
        i = names.index(s.preset) if s.preset in names else (-1 if step > 0 else 0)
        self.pick_preset(names[(i + step) % len(names)])

    def next_preset(self) -> None:
        self._step_preset(1)

    def previous_preset(self) -> None:
        self._step_preset(-1)

    def next_light_type(self) -> None:
        light = self.store.state.selected_light
        if light is None:
            raise ExplorerError("the scene has no lights: add one in the lights tab")
        nxt = LIGHT_TYPES[(LIGHT_TYPES.index(light.type) + 1) % len(LIGHT_TYPES)]
        self.act(M.set_light_type, nxt, label="light type")

    def next_light(self) -> None:
        s = self.store.state
        n = len(s.scene.lights)
        if n < 2:
            self.say(f"the scene has {n} light{'s' if n != 1 else ''}: nothing to switch"
                     " to (add one in the lights tab)")  # fmt: skip
            return
        self.act(M.select_light, (s.light + 1) % n, label="select light")
        self.say(f"controlling light {self.store.state.light + 1} of {n}")

    # -- the difference view ----------------------------------------------------------------
    def difference_key(self) -> tuple:
        """What a difference map is for: the shown scene and groups, mesh, camera, view size."""
        s = self.store.state
        return (repr(s.shown_scene()), repr(s.shown_groups()), s.mesh, s.camera,
                tuple(self.ports.view.size()))  # fmt: skip

    def update_difference(self) -> None:
        """The heat map when it matches the view; else the live view, and one request for the
        map unless something is being dragged (then it waits for the release)."""
        s, view = self.store.state, self.ports.view
        size = tuple(int(v) for v in view.size())
        self._size = size
        if not s.difference:
            self.ports.worker.cancel()
            self._requested = None
            view.show_difference(None, on=False)
            return
        key = self.difference_key()
        current = self.difference is not None and self.difference.job.key == key
        view.show_difference(self.difference if current else None, on=True)
        if current or view.dragging() or key == self._requested or min(size) < MIN_DIFFERENCE_SIZE:
            return  # (a view not laid out yet asks at its first frame)
        self._requested = key
        self.ports.worker.submit(Job(
            key, s.shown_scene(), self.meshes[s.mesh], view.colors().copy(), s.camera, size,
            tuple(view.background()), s.shown_groups(),
        ))  # fmt: skip

    def on_difference(self, result) -> None:
        """A comparison is done (delivered on the main thread): shown if it is still the
        view's, dropped if stale; an error turns the difference off and is said."""
        if result.error is not None:
            self._requested = None
            self.act(M.set_difference, False, label="difference")
            self.report(result.error, "difference view")
            return
        if result.job.key != self.difference_key():
            return  # stale: a newer request is on its way
        self.difference = result
        self.update_difference()
        self.ports.view.redraw()

    def begin_drag(self) -> None:
        """A drag starts (a slider, the camera, a handle): the difference waits for its end."""
        self.update_difference()

    def end_drag(self) -> None:
        """A drag ended: its steps are one undo step; the difference is asked for."""
        self.store.seal()
        self.update_difference()
        self.ports.view.redraw()
