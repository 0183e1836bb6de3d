"""The explorer in the browser and in Jupyter: a trame server that is the second front end of
:class:`~explorer.app.controller.Controller` (the Qt window is the first), so both share every
flow (open, save, export, difference, undo) and differ only in their widgets.

The 3D view is rendered on the server (an off-screen PyVista plotter shown by trame's
``VtkRemoteView``, drawn by :class:`~explorer.app.view.SceneView`): the page receives pictures,
so the engine's colours, the lobe inset, the light handles and the difference heat map are the
desktop's pixels. Dragging in the view turns the server's camera, and the camera is the viewer:
before each frame it goes into the state (:meth:`Controller.camera_moved`). The panel is
vuetify widgets (:mod:`explorer.app.webpanel`), each named (``aria-label``) like the scene
file's key it sets.

One explorer per server process: every tab shows and edits the same state. Nothing from the
page names a server path (:mod:`explorer.app.webfiles`): uploads are written under fixed names
into a private temporary folder and read by the same readers (and their size caps) as files on
disk; downloads are written there first; presets go to the user's preset folder.

trame, VTK and PyVista are imported inside the functions that need them (``import explorer``
stays free of them).
"""

from __future__ import annotations

import dataclasses
import logging
import os
import tempfile
import threading
import time
from collections.abc import Sequence

import numpy as np

from explorer.app import intents, webpage, webpanel
from explorer.app import model as M
from explorer.app.controller import Controller, Ports
from explorer.app.difference import PENDING, DifferenceWorker, HeatMap
from explorer.app.handledrag import HandleDragger
from explorer.app.session import session_mapping
from explorer.app.start import (
    DEFAULT_MESH,
    DEFAULT_PRESET,
    default_viewer,
    first_state,
    load_mesh_choice,
)
from explorer.app.view import SceneView, view_camera
from explorer.app.webcompare import WebCompare
from explorer.app.webfiles import WebFiles
from explorer.core.errors import ExplorerError, ExplorerTypeError
from explorer.core.lights import PointLight
from explorer.core.presets import find_preset
from explorer.core.scene import Scene, load_scene
from explorer.geometry.meshes import Mesh
from explorer.render.images import encode_png
from explorer.render.offscreen import BACKGROUND
from explorer.shading import tiers

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
#: VTK encodes each picture in a thread of its own, and trame sends a picture still being
#: encoded half a second later: instead, every FOLLOW_S seconds the server asks for it again
#: and sends it once it is done (FOLLOW_TRIES times at most; trame's own retry stays behind)
FOLLOW_S = 0.004
FOLLOW_TRIES = 1000
#: how many messages the page's message log keeps
MESSAGE_LOG = 50
#: the environment variable that sends :func:`show`'s page through jupyter-server-proxy: the
#: Jupyter server's base URL (``/`` for a Jupyter server at the root of its host,
#: ``/user/NAME/`` under JupyterHub)
JUPYTER_PROXY_ENV = "PHONG_EXPLORER_JUPYTER_PROXY"
#: the variable JupyterHub sets in a user's server (its base URL): the page goes through the proxy
JUPYTERHUB_PREFIX_ENV = "JUPYTERHUB_SERVICE_PREFIX"
#: the values of :data:`JUPYTER_PROXY_ENV` that keep the direct address (even under JupyterHub)
PROXY_OFF = ("0", "off", "false", "no")


class WebExplorer(WebFiles):
    """One explorer served by trame: the controller's ports (dialogs, messages, view,
    choices, progress) for a page.

    state, mesh : the start (``mesh`` is the mesh ``state.mesh`` names)
    materials_dirs : extra preset directories; preset_dir : where presets are saved (default:
        the user's); size : the view's first size (pixels); name : the trame server's name
        (one server per name in a process); background : RGB in [0, 1]; last_session : where
        :func:`serve` keeps the session when the server stops (True: the desktop's file,
        ``--last`` reopens it; None: nowhere); start_warnings : the warnings of the start
        mesh's materials (printed at the start; the page's message log lists them too)
    """

    def __init__(self, state: M.State, mesh: Mesh, *, materials_dirs=(), preset_dir=None,
                 size=VIEW_SIZE, name: str = "phong-explorer", background=None,
                 last_session=None, start_warnings=()):  # fmt: skip
        from trame.app import get_server

        from explorer.render.vtk import plotter  # VTK only once a server is made

        self.frames = 0
        self.pushing = False  # the server is setting the page's values (no user change)
        self.messages: list[dict] = []
        self.answers: dict = {}  # the page's answers to the controller's next questions
        self._uploads = tempfile.TemporaryDirectory(prefix="phong-explorer-web-")
        self.loop = None  # the server's event loop (the difference worker delivers into it)
        self._publisher = None  # trame's image publisher (its vtkWebPublishImageDelivery)
        self._job = None  # the long job running (run_steps) and its cancel
        self.server = get_server(name, client_type="vue3")
        self.plotter = plotter(size, BACKGROUND if background is None else background)
        self.view = None
        self.heat = HeatMap(self.plotter.renderer)
        self.worker = DifferenceWorker(self._deliver)
        self.controller = Controller(
            state, mesh, Ports.of(self, worker=self.worker), materials_dirs=materials_dirs,
            preset_dir=preset_dir, output_dir=self._uploads.name, last_session=last_session,
        )  # fmt: skip
        self.store = self.controller.store
        state = self.store.state
        self.view = SceneView(self.plotter, mesh, state)
        self.compare = WebCompare(self, size)
        self._mesh_name = state.mesh
        self.view.apply_camera(state.camera)
        self.handles = HandleDragger(self)
        self.plotter.renderer.AddObserver("StartEvent", self.guard(self._before_frame, "frame"))
        self.plotter.render_window.AddObserver("EndEvent", self._after_frame)
        webpanel.connect(self)
        webpage.build(self)
        tiers.preload()  # the compiled kernels in a thread once numba's cache holds them
        self.server.state.engine = tiers.status() or ""
        self.server.controller.on_server_ready.add(self._ready)
        self.controller.start()
        self.controller.files.say_mesh_warnings(mesh.name, start_warnings, logged=True)
        self._push(state)

    # -- drags and errors (the handles' dragger calls these too) ----------------------------------
    def begin_drag(self, *_) -> None:
        self.view.begin_drag()
        self.controller.begin_drag()

    def end_drag(self, *_) -> None:
        self.view.end_drag()
        self.controller.end_drag()

    def guard(self, fn, where: str):
        """``fn`` made safe for VTK's and trame's callbacks: an error is said on the page and
        logged, never lost."""

        def call(*args, **kw):
            try:
                return fn(*args, **kw)
            except Exception as exc:  # noqa: BLE001 - every error is shown, none is lost
                self.controller.report(exc, where)
                return None

        return call

    _guard = guard  # the name the handles' dragger calls

    def _ready(self, **_) -> None:
        """The server runs: its loop is kept (the difference worker delivers into it), and
        trame's image publisher (see :meth:`_follow_picture`)."""
        import asyncio

        self.loop = asyncio.get_event_loop()
        for p in self.server.protocol.getLinkProtocols():
            if hasattr(p, "push_render") and hasattr(p, "tracking_views"):
                self._publisher = p

    # -- Dialogs ---------------------------------------------------------------------------------
    def ask_text(self, title: str, label: str, default: str = "") -> str | None:
        return self.answers.pop("text", None)

    def ask_yes(self, question: str) -> bool:
        """Yes only when the page said so beforehand (the "replace" switch); else the question
        is said, and the answer is no."""
        yes = bool(self.answers.get("yes", False))
        if not yes:
            self.show_message(f"{question} (no: turn on 'replace' to do so)", "warning")
        return yes

    def ask_path(self, title: str, *, save: bool = False, default: str = "",
                 filter: str = "") -> str | None:  # fmt: skip
        return None  # the page names no server path: every flow is given its file

    def ask_number(self, title: str, label: str, default: int, lo: int, hi: int) -> int | None:
        return default

    def tell(self, title: str, text: str, *, details: str = "", error: bool = False) -> None:
        self.show_message(f"{title}: {text}", "error" if error else "info",
                          details.splitlines())  # fmt: skip

    # -- Messages --------------------------------------------------------------------------------
    def show_message(self, text: str, level: str = "info", details: Sequence[str] = (),
                     msecs: int | None = None, open_log: bool = True) -> None:  # fmt: skip
        text, details = self.page_text(text), [self.page_text(d) for d in details]
        entry = {"text": text, "level": level, "details": details, "at": time.strftime("%H:%M:%S")}
        self.messages = [*self.messages, entry][-MESSAGE_LOG:]
        with self.server.state as s:
            s.message = text
            s.message_level = level
            s.message_log = self.messages

    # -- Progress --------------------------------------------------------------------------------
    def run_steps(self, title: str, text: str, total: int, step, cancel) -> object:
        """A long job stepped from the server's loop (pictures keep coming), its progress in the
        page (state ``progress``: title, text, done, total; the page's Cancel calls
        ``cancel``). Returns the job's progress record."""
        job = {"title": title, "text": text, "done": 0, "total": int(total), "running": True}
        self._job = (job, cancel)
        self._show_progress(job)

        def go():
            if not job["running"]:
                return
            out = step()
            if out is None:
                job["running"] = False
                self._job = None
            else:
                job["done"], job["text"] = out[0], out[1] or job["text"]
                self.loop.call_soon(self.guard(go, title))
            self._show_progress(job)

        self.loop.call_soon(self.guard(go, title))
        return job

    def cancel_job(self) -> None:
        """The page's Cancel: the running job stops, and its flow says what was left."""
        if self._job is not None:
            job, cancel = self._job
            job["running"] = False
            self._job = None
            cancel()
            self._show_progress(job)

    def _show_progress(self, job: dict) -> None:
        path = getattr(self, "turntable_path", None)
        with self.server.state as s:
            s.progress = dict(job)
            s.turntable_ready = not job["running"] and path is not None and path.is_file()
            s.turntable_made = getattr(self, "turntable_made", "") if s.turntable_ready else ""

    # -- Choices ---------------------------------------------------------------------------------
    def show_presets(self, presets: list) -> None:
        self.server.state.presets = [webpanel.preset_item(p) for p in presets]

    def show_meshes(self, labels: dict[str, str]) -> None:
        self.server.state.meshes = [{"title": t, "value": n} for n, t in labels.items()]

    def show_recent(self, paths: list[str]) -> None:
        """The page keeps no recent files (it opens uploads only)."""

    def show_history(self, undo: str | None, redo: str | None) -> None:
        with self.server.state as s:
            s.can_undo, s.can_redo = undo is not None, redo is not None
            s.undo_label, s.redo_label = undo or "", redo or ""
            s.intents_enabled = intents.enabled(self.controller)

    # -- View ------------------------------------------------------------------------------------
    def show(self, old: M.State | None, new: M.State) -> None:
        """The view and the panel show ``new`` (``old`` None: everything afresh)."""
        if self.view is None:
            return
        if new.mesh != self._mesh_name:
            self.view.set_mesh(self.controller.meshes[new.mesh], new)
            self._mesh_name = new.mesh
        else:
            self.view.show_state(new)
        if new.camera is not None and not self.controller.in_frame:
            live = view_camera(self.plotter.camera, new.centre, new.radius)
            if live != new.camera:
                self.view.apply_camera(new.camera)
        self.compare.show(old, new)
        if old is None or not self.controller.in_frame:
            self._push(new)

    def redraw(self) -> None:
        """Send a new picture to every page (side B's follows side A's frame). The compiled
        kernels are looked for too (:func:`explorer.shading.tiers.preload`: the numpy tier
        serves until they are loaded), and the page says which engine serves."""
        tiers.preload()
        engine = tiers.status() or ""
        if engine != self.server.state.engine:
            self.server.state.engine = engine
        self._send(self.server.controller.view_update, self.plotter.render_window)

    def _send(self, update, window) -> None:
        """``update()`` (a remote view's push) and then :meth:`_follow_picture` for
        ``window``'s picture."""
        pub = self._publisher
        vid = None if pub is None else str(pub.get_global_id(window))
        sent = None if vid is None else pub.tracking_views.get(vid, {}).get("mtime")
        update()
        if vid is not None and self.loop is not None:
            self.loop.call_later(FOLLOW_S, self.guard(self._follow_picture, "view"), vid, sent,
                                 FOLLOW_TRIES)  # fmt: skip

    def _follow_picture(self, vid: str, sent, tries: int) -> None:
        """Send the view's picture as soon as VTK has encoded it: until a picture newer than
        ``sent`` (the publisher's time of the last one sent) has gone, look every
        :data:`FOLLOW_S` seconds (``tries`` times at most)."""
        pub = self._publisher
        if pub.tracking_views.get(vid, {}).get("mtime") != sent or tries <= 0:
            return  # sent (by trame itself, or below)
        pub.push_render(vid)  # sends the picture if it is encoded by now
        self.loop.call_later(FOLLOW_S, self.guard(self._follow_picture, "view"), vid, sent,
                             tries - 1)  # fmt: skip

    def size(self) -> tuple[int, int]:
        w, h = self.plotter.window_size
        return int(w), int(h)

    def aspect(self) -> float:
        w, h = self.size()
        return w / max(h, 1)

    def background(self) -> tuple[float, float, float]:
        return tuple(self.plotter.renderer.GetBackground())

    def colors(self) -> np.ndarray:
        return self.view.drawings[0].colors()

    def dragging(self) -> bool:
        return self.view is not None and self.view.dragging > 0

    def show_difference(self, result, *, on: bool) -> None:
        if result is not None and result is not self.heat.result:
            self.heat.set(result)
        current = on and result is not None
        self.heat.show(current)
        if self.view is not None:
            self.view.show_mesh(not current)
        legend = "" if not on else (self.heat.legend() if current else PENDING)
        self.server.state.legend = legend

    def png(self) -> bytes:
        return encode_png(self.plotter.screenshot(return_img=True)[:, :, :3])

    # -- the worker's results ------------------------------------------------------------------
    def _deliver(self, result) -> None:
        """From the difference worker's thread: handed to the server's loop."""
        if self.loop is not None:
            self.loop.call_soon_threadsafe(self.guard(self._on_difference, "difference"), result)

    def _on_difference(self, result) -> None:
        self.controller.on_difference(result)

    # -- the store to the page -------------------------------------------------------------------
    def _push(self, state: M.State) -> None:
        """Every control's value from ``state`` (the change handlers ignore these)."""
        self.pushing = True
        try:
            with self.server.state as s:
                s.update(webpanel.values(state))
        finally:
            self.pushing = False

    # -- frames ----------------------------------------------------------------------------------
    def _before_frame(self, *_) -> None:
        """The camera is the viewer: it goes into the state (no undo step) before each frame;
        translucent triangles are sorted, the inset and the handle ring laid out."""
        self.view.frame_camera(self.store.state, self.controller.camera_moved)

    def _after_frame(self, *_) -> None:
        """A frame of side A: counted; side B (the same camera) is sent after it."""
        self.frames += 1
        if self.compare.shown and self.loop is not None:
            b = self.compare.plotter.render_window
            self.loop.call_soon(self.guard(self._send, "B"), self.server.controller.view_b_update,
                                b)  # fmt: skip

    def report_state(self) -> dict:
        """What a test may read (plain JSON values): the frame count, the view's size, the
        probe vertex and its pixel in the view (origin top-left), the session."""
        probe = self.view.probe_vertex()
        return {
            "frame": self.frames,
            "size": list(self.size()),
            "probe": {"vertex": probe,
                      "px": self.view.world_to_window(self.view.mesh.positions[probe])},
            "handles_px": [self.view.world_to_window(M.handle_point(self.store.state, i))
                           for i in range(len(self.store.state.scene.lights))],
            "placement": (list(self.store.state.placement())
                          if self.store.state.selected_light is not None else None),
            "can_undo": self.store.can_undo,
            "can_redo": self.store.can_redo,
            "errors": list(self.controller.errors),
            "n_vertices": self.view.mesh.n_vertices,
            "difference": self.heat.state(),
            "compare": self.compare.probe() if self.compare.shown else None,
            "session": session_mapping(self.store.state),
        }  # fmt: skip

    def close(self) -> None:
        self.worker.close()
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


def own_arguments() -> None:
    """trame reads its own options from the command line (``--host``, ``--port``,
    ``--timeout``...) unless ``TRAME_ARGS`` is set: it is set empty, so that only the
    explorer's arguments, given to ``server.start``, count."""
    os.environ["TRAME_ARGS"] = ""


def _stop(signum, frame):
    """SIGTERM ends the server as Ctrl-C does (the session is kept on the way out)."""
    raise KeyboardInterrupt


def serve(app: WebExplorer, *, port: int = 0, host: str = DEFAULT_HOST, open_browser=False):
    """Serve ``app`` until the process ends (prints ``App running at:`` and the URL). When the
    server stops (Ctrl-C, SIGTERM) the session is kept as the desktop keeps it when its window
    closes (:meth:`FileFlows.keep_last_session`; ``--last`` reopens it)."""
    import signal

    own_arguments()
    signal.signal(signal.SIGTERM, _stop)
    try:
        app.server.start(port=port, host=host, open_browser=open_browser, timeout=0,
                         show_connection_info=True)  # fmt: skip
    except KeyboardInterrupt:
        pass
    finally:
        app.controller.files.keep_last_session()


@dataclasses.dataclass
class Shown:
    """An explorer served from a thread for a notebook: displayed inline as an ``<iframe>``;
    :attr:`state` reads the explorer's present state back in Python.

    app : the :class:`WebExplorer`; url : its page; height : the cell's height (pixels)
    """

    app: WebExplorer
    url: str
    height: int = 720

    @property
    def state(self) -> M.State:
        return self.app.store.state

    @property
    def controller(self) -> Controller:
        return self.app.controller

    def session(self) -> dict:
        """The present state as a session mapping (what Save session writes)."""
        return session_mapping(self.app.store.state)

    def run(self, fn, *args, timeout: float = 60.0):
        """``fn(*args)`` run in the server's thread (VTK draws there), and its result."""
        import asyncio

        async def call():
            return fn(*args)

        return asyncio.run_coroutine_threadsafe(call(), self.app.loop).result(timeout)

    def set(self, key: str, value) -> None:
        """Set control ``key`` (a scene-file key: ``kd``, ``shininess``, ``azimuth``...) as
        the page's control does: one undo step; every open page shows it."""

        def go():
            self.app.controller.set_value(key, value, merge=False)

        self.run(go)

    def _repr_html_(self) -> str:
        import html

        return (f'<iframe src="{html.escape(self.url)}" style="width:100%;height:{self.height}px;'
                f'border:none" title="phong-explorer"></iframe>')  # fmt: skip


def proxy_prefix(proxy: bool | str | None, environ=None) -> str | None:
    """The Jupyter base URL through which :func:`show`'s page goes (jupyter-server-proxy's
    ``<base>proxy/<port>/``), or None for the direct address.

    ``proxy``: a base URL (``"/user/ana/"``, ``"https://hub.example.org/user/ana/"``), True
    (the environment's base URL, else ``/``), False (direct), None (the environment decides:
    :data:`JUPYTER_PROXY_ENV` when set (:data:`PROXY_OFF`: direct), else JupyterHub's
    :data:`JUPYTERHUB_PREFIX_ENV`, else direct). The result ends with ``/``; a base URL that
    is neither a path from ``/`` nor an http(s) URL is an :class:`ExplorerError` naming where
    it came from."""
    env = os.environ if environ is None else environ
    if proxy is False:
        return None
    if isinstance(proxy, str):
        return _base_url(proxy.strip(), "proxy")
    if proxy is not None and proxy is not True:
        raise ExplorerTypeError(f"proxy must be a Jupyter base URL, True, False or None, "
                                f"got {type(proxy).__name__}")  # fmt: skip
    own = env.get(JUPYTER_PROXY_ENV, "").strip()
    hub = env.get(JUPYTERHUB_PREFIX_ENV, "").strip()
    if own.lower() in PROXY_OFF:
        if proxy is None:
            return None
        own = ""  # proxy=True asks for it all the same
    if own:
        return _base_url(own, JUPYTER_PROXY_ENV)
    if hub:
        return _base_url(hub, JUPYTERHUB_PREFIX_ENV)
    return "/" if proxy else None


def _base_url(base: str, where: str) -> str:
    """``base`` (a path or an http(s) URL) checked, ending with ``/``."""
    from urllib.parse import urlsplit

    parts = urlsplit(base)
    url = parts.scheme in ("http", "https") and parts.netloc
    path = base.startswith("/") and not base.startswith("//")  # "//host" names another host
    if not (path or url) or any(c in base for c in " \t\n\"'<>?#\\"):
        raise ExplorerError(f"{where}: a Jupyter base URL is a path from / (such as "
                            f"/user/NAME/) or an http(s) URL, got {base!r}")  # fmt: skip
    return base if base.endswith("/") else base + "/"


def page_url(port: int, prefix: str | None) -> str:
    """The address of the page served on ``port``: direct (``http://127.0.0.1:PORT/``) or,
    under Jupyter base URL ``prefix``, jupyter-server-proxy's ``<prefix>proxy/<port>/`` (the
    page's assets are relative and its websocket is ``<page's folder>/ws``: both go through
    the proxy)."""
    if prefix is None:
        return f"http://{DEFAULT_HOST}:{port}/"
    return f"{prefix}proxy/{int(port)}/"


def show(scene=None, *, preset: str | None = DEFAULT_PRESET, mesh: str = DEFAULT_MESH,
         port: int = 0, height: int = 720, materials_dirs=(),
         proxy: bool | str | None = None) -> Shown:  # fmt: skip
    """Serve an explorer on 127.0.0.1 from a background thread (its own event loop, so the
    notebook's kernel stays free) and return it for display in a notebook cell. ``scene``: a
    :class:`~explorer.core.scene.Scene`, a scene file or None (the explorer's start);
    ``preset`` overrides its material; ``mesh`` a built-in mesh. ``proxy``: whether the cell's
    page goes through jupyter-server-proxy (a remote Jupyter, JupyterHub), and under which
    Jupyter base URL (:func:`proxy_prefix`; by default, under JupyterHub or when
    ``$PHONG_EXPLORER_JUPYTER_PROXY`` is set)."""
    prefix = proxy_prefix(proxy)
    state, m = notebook_state(scene, preset=preset, mesh=mesh, materials_dirs=materials_dirs)
    ready = threading.Event()
    box: dict = {}

    def run():
        import asyncio

        loop = asyncio.new_event_loop()
        asyncio.set_event_loop(loop)
        try:
            app = WebExplorer(state, m, materials_dirs=materials_dirs,
                              name=f"phong-explorer-{id(box)}")  # fmt: skip
            box["app"] = app
            own_arguments()
            app.server.start(port=port, host=DEFAULT_HOST, exec_mode="task", thread=True,
                             open_browser=False, timeout=0, show_connection_info=False,
                             disable_logging=True)  # fmt: skip

            async def wait():
                await app.server.ready
                box["port"] = app.server.port
                ready.set()

            loop.create_task(wait())
        except Exception as exc:  # noqa: BLE001 - handed to the caller's thread
            box["error"] = exc
            ready.set()
            return
        loop.run_forever()

    threading.Thread(target=run, daemon=True, name="phong-explorer-web").start()
    if not ready.wait(120):
        raise ExplorerError("the explorer's web server did not start within 120 s")
    if "error" in box:
        raise box["error"]
    return Shown(box["app"], page_url(box["port"], prefix), height)
