"""The explorer in the browser and in Jupyter: a trame server over the same
:class:`~explorer.app.model.Store` and :class:`~explorer.app.view.SceneView` as the Qt window.

The 3D view is rendered on the server (an off-screen PyVista plotter, trame's
``VtkRemoteView``): the page receives pictures, so the engine's colours, the lobe inset, the
light handles and the difference heat map are the desktop's pixels. Dragging in the view turns
the server's camera, and the camera is the viewer (before each frame it goes into the state,
as in the window). The panel is vuetify widgets, each named (``aria-label``) like the scene
file's key it sets; every change is an action on the store, so undo / redo are the window's.

One explorer per server: every tab shows and edits the same state. Nothing from the page names
a server path: uploads are read from a private temporary folder under fixed names, through the
same readers (and their size caps) as files on disk; a session from the page may name only a
built-in mesh.

trame, VTK and PyVista are imported inside the functions that need them (``import explorer``
stays free of them).
"""

from __future__ import annotations

import dataclasses
import logging
import tempfile
import threading
from pathlib import Path

from explorer.app import model as M
from explorer.app import webpanel as P
from explorer.app.session import load_session, session_mapping, session_text
from explorer.app.start import (
    DEFAULT_MESH,
    DEFAULT_PRESET,
    MESH_CHOICES,
    default_viewer,
    first_state,
    load_mesh_choice,
)
from explorer.app.view import SceneView, framed_camera, view_camera
from explorer.core.errors import ExplorerError
from explorer.core.lights import PointLight
from explorer.core.presets import find_preset, list_presets
from explorer.core.scene import Scene, load_scene
from explorer.core.yamlio import MAX_BYTES, load_yaml
from explorer.geometry.meshes import Mesh
from explorer.render.offscreen import BACKGROUND

log = logging.getLogger(__name__)

#: the view's size (pixels) before the page tells its own
VIEW_SIZE = (800, 600)
#: where the server listens unless told otherwise (this machine only)
DEFAULT_HOST = "127.0.0.1"
#: the warning printed when the server listens beyond this machine
OPEN_HOST_WARNING = (
    "warning: listening on {host}: anyone who can reach port {port} can use this explorer "
    "(and save presets into your preset folder)"
)


class WebExplorer:
    """One explorer served by trame.

    state, mesh : the start (``mesh`` is the mesh ``state.mesh`` names)
    materials_dirs : extra preset directories; size : the view's first size (pixels)
    name : the trame server's name (one server per name in a process)
    """

    def __init__(self, state: M.State, mesh: Mesh, *, materials_dirs=(), size=VIEW_SIZE,
                 name: str = "phong-explorer", background=None):  # fmt: skip
        from trame.app import get_server

        from explorer.render.vtk import plotter  # VTK only once a server is made

        self.materials_dirs = tuple(materials_dirs)
        self.meshes: dict[str, Mesh] = {state.mesh: mesh}
        self.errors: list[str] = []
        self.frames = 0
        self._uploads = tempfile.TemporaryDirectory(prefix="phong-explorer-web-")
        self.server = get_server(name, client_type="vue3")
        self.plotter = plotter(size, BACKGROUND if background is None else background)
        self.plotter.iren.initialize() if self.plotter.iren is not None else None
        aspect = size[0] / size[1]
        if state.camera is None:
            cam = dataclasses.replace(framed_camera(state, mesh, aspect), window_center=(0, 0))
            state = M.set_camera(state, cam)
        self.store = M.Store(state)
        self.view = SceneView(self.plotter, mesh, state)
        self.view.apply_camera(state.camera)
        self.presets = list_presets(self.materials_dirs)
        self._pushing = False
        self._in_frame = False
        self.plotter.renderer.AddObserver("StartEvent", self._before_frame)
        self.plotter.render_window.AddObserver("EndEvent", self._after_frame)
        self.store.subscribe(self._on_change)
        P.build(self)
        self._push(state)

    # -- actions -----------------------------------------------------------------------------
    def act(self, action, *args, label: str | None = None, merge=None) -> bool:
        """Apply ``action(state, *args)`` as one undo step (``merge``: see
        :meth:`~explorer.app.model.Store.commit`); an error is shown on the page."""
        try:
            return self.store.apply(action, *args, label=label, merge=merge)
        except ExplorerError as exc:
            self.report(exc, label or action.__name__)
            self._push(self.store.state)  # the control that sent it shows the state again
            return False

    def report(self, exc: BaseException, where: str) -> None:
        text = str(exc) if isinstance(exc, ExplorerError) else f"{type(exc).__name__}: {exc}"
        self.errors.append(f"{where}: {text}")
        log.error("%s: %s", where, text)
        with self.server.state as s:
            s.message = f"error ({where}): {text.splitlines()[0] if text else ''}"

    def undo(self) -> None:
        self.store.undo()

    def redo(self) -> None:
        self.store.redo()

    def seal(self) -> None:
        self.store.seal()

    # -- the store to the page ---------------------------------------------------------------
    def _on_change(self, old: M.State, new: M.State) -> None:
        if new.mesh != old.mesh:
            self.view.set_mesh(self.meshes[new.mesh], new)
        else:
            self.view.show_state(new)
        if new.camera is not None and not self._in_frame:
            live = view_camera(self.plotter.camera, new.centre, new.radius)
            if live != new.camera:
                self.view.apply_camera(new.camera)
        if not self._in_frame:
            self._push(new)
            self.update_view()

    def _push(self, state: M.State) -> None:
        """Every control's value from ``state`` (the change handlers ignore these)."""
        self._pushing = True
        try:
            with self.server.state as s:
                s.update(P.values(self, state))
        finally:
            self._pushing = False

    def update_view(self) -> None:
        """Send a new picture to every page."""
        self.server.controller.view_update()

    # -- frames ------------------------------------------------------------------------------
    def _before_frame(self, *_) -> None:
        """The camera is the viewer: it goes into the state (no undo step) before each frame;
        translucent triangles are sorted, the inset and the handle ring laid out."""
        s = self.store.state
        cam = view_camera(self.plotter.camera, s.centre, s.radius)
        self._in_frame = True
        try:
            self.store.set_camera(cam)
        finally:
            self._in_frame = False
        self.view.before_frame(cam)
        self.plotter.renderer.ResetCameraClippingRange()

    def _after_frame(self, *_) -> None:
        self.frames += 1

    def report_state(self) -> dict:
        """What a test may read (plain JSON values): the frame count, the view's size, the
        probe vertex and its pixel in the view (origin top-left), undo / redo."""
        probe = self.view.probe_vertex()
        return {
            "frame": self.frames,
            "size": list(self.plotter.window_size),
            "probe": {"vertex": probe,
                      "px": self.view.world_to_window(self.view.mesh.positions[probe])},
            "can_undo": self.store.can_undo,
            "can_redo": self.store.can_redo,
            "errors": list(self.errors),
            "n_vertices": self.view.mesh.n_vertices,
            "session": session_mapping(self.store.state),
        }  # fmt: skip

    # -- files -------------------------------------------------------------------------------
    def session_text(self) -> str:
        """The present session as YAML (what the desktop's File > Save session writes)."""
        return session_text(self.store.state)

    def open_session_bytes(self, data: bytes) -> None:
        """Open a session uploaded from the page: written under a fixed name in the private
        upload folder and read by :func:`~explorer.app.session.load_session` (its caps and
        checks); its mesh must be a built-in one (a page names no server path)."""
        path = Path(self._uploads.name) / "session.yaml"
        path.write_bytes(data)
        doc = load_yaml(path, what="session")
        name = doc.data.get("mesh") if isinstance(doc.data, dict) else None
        if name not in MESH_CHOICES:
            raise ExplorerError(
                f"session: mesh {name!r}: a session opened from the page may name only a "
                f"built-in mesh ({', '.join(MESH_CHOICES)})"
            )
        state, mesh = load_session(path, materials_dirs=self.materials_dirs)
        self.meshes[state.mesh] = mesh
        if state.camera is None:
            w, h = self.plotter.window_size
            state = M.set_camera(state, framed_camera(state, mesh, w / max(h, 1)))
        self.store.commit(state, "open session")

    def open_uploaded_session(self, upload: dict) -> None:
        """A session file chosen in the page (trame's file dict: ``content`` bytes, ``size``);
        refused above the YAML reader's cap before anything is written."""
        data = upload.get("content") or b""
        if isinstance(data, list):  # a large file arrives in chunks
            data = b"".join(data)
        if len(data) > MAX_BYTES:
            raise ExplorerError(f"session: {upload.get('name', 'upload')!r} is too large: "
                                f"{len(data)} bytes, the limit is {MAX_BYTES} bytes")  # fmt: skip
        self.open_session_bytes(bytes(data))

    def choose_mesh(self, name: str) -> None:
        """Show built-in mesh ``name`` (the chooser offers only the built-in meshes and the
        start's)."""
        if name not in self.meshes:
            if name not in MESH_CHOICES:
                raise ExplorerError(f"mesh must be one of {', '.join(MESH_CHOICES)}, got {name!r}")
            self.meshes[name] = load_mesh_choice(name)
        mesh = self.meshes[name]
        self.act(M.set_mesh, name, tuple(mesh.centre), float(mesh.radius or 1.0), label="mesh")

    def close(self) -> None:
        self._uploads.cleanup()
        self.plotter.close()


def notebook_state(scene=None, *, preset: str | None = DEFAULT_PRESET, mesh: str = DEFAULT_MESH,
                   materials_dirs=()) -> tuple[M.State, Mesh]:  # fmt: skip
    """``(state, mesh)`` for :func:`show`: ``scene`` (a Scene, a scene file or a mapping; None:
    one point light at :data:`~explorer.app.model.DEFAULT_PLACEMENT` seen from the explorer's
    start camera) on built-in mesh ``mesh``, in preset ``preset`` (None: the scene's
    material)."""
    m = load_mesh_choice(mesh)
    if scene is None:
        az, el, d = M.DEFAULT_PLACEMENT
        light = PointLight().placed(az, el, d * (m.radius or 1.0), m.centre)
        scene = Scene(lights=(light,), viewer=default_viewer(m))
    else:
        scene = load_scene(scene, materials_dirs=materials_dirs)
    if preset is not None:
        scene = scene.replace(material=find_preset(preset, materials_dirs))
    scene = scene.replace(mesh=mesh)
    state = first_state(scene, m, name=mesh, preset=preset, materials_dirs=materials_dirs)
    return state, m


def serve(app: WebExplorer, *, port: int = 0, host: str = DEFAULT_HOST, open_browser=False):
    """Serve ``app`` until the process ends (prints ``App running at:`` and the URL)."""
    app.server.start(port=port, host=host, open_browser=open_browser, timeout=0,
                     show_connection_info=True)  # fmt: skip


class Shown:
    """An explorer served from a thread for a notebook: displayed inline as an ``<iframe>``;
    :attr:`state` reads the explorer's present state back in Python."""

    def __init__(self, app: WebExplorer, url: str, height: int):
        self.app, self.url, self.height = app, url, int(height)

    @property
    def state(self) -> M.State:
        return self.app.store.state

    def session(self) -> dict:
        """The present state as a session mapping (what Save session writes)."""
        return session_mapping(self.app.store.state)

    def _repr_html_(self) -> str:
        return (f'<iframe src="{self.url}" style="width:100%;height:{self.height}px;'
                f'border:none" title="phong-explorer"></iframe>')  # fmt: skip


def show(scene=None, *, preset: str | None = DEFAULT_PRESET, mesh: str = DEFAULT_MESH,
         port: int = 0, height: int = 720, materials_dirs=()) -> Shown:  # fmt: skip
    """Serve an explorer on 127.0.0.1 from a background thread and return it for display in a
    notebook cell. ``scene``: a :class:`~explorer.core.scene.Scene`, a scene file or None (the
    explorer's start); ``preset`` overrides its material."""
    state, m = notebook_state(scene, preset=preset, mesh=mesh, materials_dirs=materials_dirs)
    ready = threading.Event()
    box: dict = {}

    def run():
        import asyncio

        loop = asyncio.new_event_loop()
        asyncio.set_event_loop(loop)
        app = WebExplorer(state, m, materials_dirs=materials_dirs,
                          name=f"phong-explorer-{id(box)}")  # fmt: skip
        box["app"] = app
        app.server.start(port=port, host=DEFAULT_HOST, exec_mode="task", open_browser=False,
                         timeout=0, show_connection_info=False, disable_logging=True)  # fmt: skip

        async def wait():
            await app.server.ready
            box["port"] = app.server.port
            ready.set()

        loop.create_task(wait())
        loop.run_forever()

    threading.Thread(target=run, daemon=True, name="phong-explorer-web").start()
    if not ready.wait(60):
        raise ExplorerError("the explorer's web server did not start within 60 s")
    return Shown(box["app"], f"http://{DEFAULT_HOST}:{box['port']}/", height)
