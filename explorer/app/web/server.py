"""The explorer in the browser and in Jupyter: a trame server that is the second front end of
:class:`~explorer.app.controller.Controller` (the Qt window is the first), so both share every
flow (open, save, export, difference, undo) and differ only in their widgets.

The 3D view is rendered on the server (an off-screen PyVista plotter shown by trame's
``VtkRemoteView``, drawn by the desktop's view port, :class:`~explorer.app.viewport.PlotterView`,
whose pictures :class:`WebExplorer` pushes to the page): the page receives pictures,
so the engine's colours, the lobe inset, the light handles and the difference heat map are the
desktop's pixels. Dragging in the view turns the server's camera, and the camera is the viewer:
before each frame it goes into the state (:meth:`Controller.camera_moved`). The panel is
vuetify widgets (:mod:`explorer.app.web.panel`), each named (``aria-label``) like the scene
file's key it sets.

Only the address the server prints (with its token) opens the page, a websocket only from the
page's own origin, and a page sets only its controls' keys: :mod:`explorer.app.web.guard`.
One explorer per server process: every tab shows and edits the same state. Nothing from the
page names a server path (:mod:`explorer.app.web.files`): uploads are written under fixed names
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
from collections.abc import Sequence

from explorer.app import intents, panelmodel
from explorer.app import model as M
from explorer.app.controller import Controller, Ports
from explorer.app.difference import DifferenceWorker
from explorer.app.messagelog import MessageLog
from explorer.app.session import session_mapping
from explorer.app.sides import SideB
from explorer.app.start import (
    MESH_CHOICES,
)
from explorer.app.steps import Steps
from explorer.app.viewport import PlotterView
from explorer.app.web import direct, guard, page, panel, wire
from explorer.app.web.compare import WebCompare
from explorer.app.web.direct import Direct
from explorer.app.web.files import WebFiles
from explorer.app.web.pictures import Pictures
from explorer.core.errors import ExplorerError
from explorer.geometry.meshes import Mesh
from explorer.render.offscreen import BACKGROUND
from explorer.render.vtk import DRAW_LOCK
from explorer.shading import tiers

log = logging.getLogger(__name__)

#: the view's size (pixels) before the page tells its own
VIEW_SIZE = (800, 600)
#: where the server listens unless told otherwise (this machine only)
DEFAULT_HOST = "127.0.0.1"
#: the warning printed when the server listens beyond this machine
OPEN_HOST_WARNING = (
    "warning: listening on {host}: anyone who can reach port {port} can use this explorer "
    "(and save presets into your preset folder) once they have the address printed below: "
    "its token is the only key, share it with care"
)
#: trame-vtk's call by which a page's remote view asks for a view's pictures
OBSERVE = "viewport.image.push.observer.add"
#: how many messages the page's message log keeps
MESSAGE_LOG = 50


class WebExplorer:
    """One explorer served by trame: the controller's ports (dialogs, messages, choices,
    progress; the view is :attr:`viewport`, whose pictures this sends) for a page.

    state, mesh : the start (``mesh`` is the mesh ``state.mesh`` names)
    materials_dirs : extra preset directories; preset_dir : where presets are saved (default:
        the user's); size : the view's first size (pixels); name : the trame server's name
        (one server per name in a process); background : RGB in [0, 1]; last_session : where
        :func:`serve` keeps the session when the server stops (True: the desktop's file,
        ``--last`` reopens it; None: nowhere); start_warnings : the warnings of the start
        mesh's materials (printed at the start; the page's message log lists them too)
    direct : whether a page of this machine may take its pictures raw through its direct
        socket (:mod:`explorer.app.web.direct`); False: every picture goes as JPEG (then PNG)
        through trame's socket (``phong-explorer web --no-direct``)
    """

    def __init__(self, state: M.State, mesh: Mesh, *, materials_dirs=(), preset_dir=None,
                 size=VIEW_SIZE, name: str = "phong-explorer", background=None,
                 last_session=None, start_warnings=(), direct: bool = True):  # fmt: skip
        from trame.app import get_server

        from explorer.render.vtk import plotter  # VTK only once a server is made

        self.pushing = False  # the server is setting the page's values (no user change)
        # the start framed for the page's view, at each of its sizes until the camera is moved
        # (as the window frames it when shown): the view's size the start was framed for, and
        # the camera it was given (None: not framed yet); a session's camera is kept as it is
        self._framing = state.camera is None
        self._framed_for = tuple(int(v) for v in size)
        self._start_camera = None
        self.said = MessageLog(keep=MESSAGE_LOG)  # the page's message log
        self.message_seq = 0  # messages said so far (a page shows those after it opened)
        self.answers: dict = {}  # the page's answers to the controller's next questions
        self._uploads = tempfile.TemporaryDirectory(prefix="phong-explorer-web-")
        self.files = WebFiles(self, self._uploads.name)  # the uploads and downloads
        self.loop = None  # the server's event loop (the difference worker delivers into it)
        self.pictures = None  # the pages' picture path (web.pictures.Pictures), once it runs
        self.direct = None  # the direct sockets (web.direct.Direct): None with direct False
        if direct:
            self.direct = Direct(
                self._direct_refusal,
                self._tabs,
                self._last_frame,
                self._resend,
                stall=wire.SEND_STALL_S,
            )
        self._wire = None  # wslink's connection handler (web.wire.WireHandler), once bound
        self._job: Steps | None = None  # the long job running (run_steps)
        self.server = get_server(name, client_type="vue3")
        self.token = guard.new_token()  # the page's key: in the URL the user is given only
        self.hosts = guard.listening_names(DEFAULT_HOST)  # what a Host may name (None: any)
        guard.install(self.server, self.token, lambda: self.hosts)
        self.mesh_values = guard.MeshValues(MESH_CHOICES)  # the chooser names no path
        self.plotter = plotter(size, BACKGROUND if background is None else background)
        self.viewport = PlotterView(self.plotter, self)  # the page's pictures: see send()
        self.heat = self.viewport.heat
        self.worker = DifferenceWorker(self._deliver)
        self.controller = Controller(
            state, mesh, Ports.of(self, worker=self.worker, view=self.viewport),
            materials_dirs=materials_dirs, preset_dir=preset_dir, output_dir=self._uploads.name,
            last_session=last_session,
        )  # fmt: skip
        self.store = self.controller.store
        state = self.store.state
        self.compare = WebCompare(self, size)
        self.view = self.viewport.attach(
            self.controller, mesh, side_b=SideB(self.viewport, self.compare)
        )
        self.viewport.watch_drags(self.plotter)  # (the remote view passes the page's pointer)
        self.viewport.observe(self.plotter.render_window, "StartEvent", self._frame, "view", 1.0)
        panel.connect(self)
        page.build(self)
        tiers.preload()  # the compiled kernels in a thread once numba's cache holds them
        self.server.state.engine = tiers.status() or ""
        self.server.state.direct = False  # (offered once the server runs: _ready)
        self.server.controller.on_server_ready.add(self._ready)
        self.server.controller.on_server_bind.add(wire.bind)  # the wire's limits (issue 37)
        self.server.controller.on_server_bind.add(self._bind_direct)
        self.controller.start()
        self.controller.files.say_mesh_warnings(mesh.name, start_warnings, logged=True)
        self.viewport.show_start(state)

    def guard(self, fn, where: str):
        """``fn`` made safe for VTK's and trame's callbacks: an error is said on the page and
        logged, never lost (:meth:`PlotterView.guard`)."""
        return self.viewport.guard(fn, where)

    def _frame(self, *_) -> None:
        """Before a frame: while the camera is still the start's (not dragged, not set by a
        session), a view drawn at another size than the start was framed for gets the start's
        mesh framed for its shape (``Controller.frame_start``). The page's view takes its size
        in steps as the page lays itself out (30x30, then the drawer's width taken, then its
        opening's steps: 260x384 ... 370x396 in a 640x480 page), and the browser's window may
        be resized before the camera is touched: framed once, at the first of those sizes, the
        start showed the light's handle out of a view taller than wide. The view halved for the
        compare view is not framed for (the window does not frame anew either)."""
        w, h = (int(v) for v in self.plotter.window_size)
        if not self._framing or (w, h) == self._framed_for or min(w, h) < 2:
            return
        if self.store.state.compare is not None:
            return  # the view halved for pane B: the start stays framed for the whole view
        if self._start_camera is not None and not _same_pose(
            self.store.state.camera, self._start_camera
        ):
            self._framing = False  # the camera is the user's now: it stays as they left it
            return
        self._framed_for = (w, h)
        self.controller.frame_start()
        self._start_camera = self.store.state.camera
        self.view.apply_camera(self._start_camera)

    def _ready(self, **_) -> None:
        """The server runs: its loop is kept (the difference worker delivers into it), and
        trame's image publisher sends the pictures as :class:`~explorer.app.web.pictures.Pictures`
        makes them (baseline JPEG 4:4:4 at once, PNG once the view is still)."""
        import asyncio

        self.loop = asyncio.get_event_loop()
        with self.server.state as s:  # (the pages try the direct socket only where offered)
            s.direct = self.direct is not None and self.hosts is not None
        for p in self.server.protocol.getLinkProtocols():
            if hasattr(p, "push_render") and hasattr(p, "tracking_views"):
                self.pictures = Pictures(p, self.loop, self.guard, self.direct)

    # -- the direct sockets (explorer.app.web.direct) ---------------------------------------------
    def _bind_direct(self, web_server) -> None:
        """trame's ``on_server_bind``: the direct socket's route, beside wslink's; and each
        page's subscription to a view's pictures (trame-vtk's ``viewport.image.push.observer
        .add``, a page's remote view shown: the start, pane B shown again) tells the sockets
        that a page began to show the view (:meth:`Direct.expect`: its next picture goes as
        JPEG too, for the canvas the page makes at its first picture). Without that call's
        name (trame-vtk changed) no direct socket is offered."""
        handlers = getattr(web_server, "_ws_handlers", [])
        self._wire = handlers[0] if handlers else None
        functions = getattr(self._wire, "functionMap", {})
        if self.direct is None or OBSERVE not in functions:
            self.direct = None
            return
        obj, add = functions[OBSERVE]
        direct_ = self.direct

        def added(publisher, view_id, *rest):
            try:
                direct_.expect(str(publisher.get_global_id(publisher.get_view(view_id))))
            except Exception:  # noqa: BLE001 - a bad id is the call's own error to say
                pass
            return add(publisher, view_id, *rest)

        functions[OBSERVE] = (obj, added)
        web_server.app.router.add_get(direct.PATH, self.direct.handle)

    def _direct_refusal(self, request) -> str | None:
        cookie = request.cookies.get(guard.cookie_name(guard.served_port(request)))
        return guard.direct_refusal(request.remote, self.hosts, cookie, self.token)

    def _tabs(self) -> int:
        """The pages connected (wslink's authenticated connections)."""
        return len(self._wire._targets()) if self._wire is not None else 1

    def _last_frame(self, view: str):
        return self.pictures.last.get(view) if self.pictures is not None else None

    def _resend(self, view: str) -> None:
        if self.pictures is not None:
            self.pictures.resend(view)

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
        page_text = self.files.page_text
        text, details = page_text(text), [page_text(d) for d in details]
        if text:  # (empty: the message shown taken away, nothing logged)
            self.said.add(level, text, details)
        self.message_seq += 1
        with self.server.state as s:
            s.message = text
            s.message_level = level
            s.message_seq = self.message_seq
            s.message_log = [m.as_dict() for m in self.said.messages]

    # -- Progress --------------------------------------------------------------------------------
    def run_steps(self, title: str, text: str, total: int, step, cancel) -> object:
        """A long job stepped from the server's loop (pictures keep coming), its progress in the
        page (state ``progress``: title, text, done, total, running; the page's Cancel calls
        ``cancel``). Returns the job's :class:`~explorer.app.steps.Steps`."""
        job = self._job = Steps(title, text, total, step, cancel)
        self._show_progress(job)

        def go():
            if not job.running:
                return  # cancelled (cancel_job showed it)
            if job.next():
                self.loop.call_soon(self.guard(go, title))
            elif self._job is job:
                self._job = None
            self._show_progress(job)

        self.loop.call_soon(self.guard(go, title))
        return job

    def cancel_job(self) -> None:
        """The page's Cancel: the running job stops, and its flow says what was left."""
        if self._job is not None:
            job, self._job = self._job, None
            job.cancel()
            self._show_progress(job)

    def _show_progress(self, job: Steps) -> None:
        path = self.files.turntable_path
        with self.server.state as s:
            s.progress = job.as_dict()
            s.turntable_ready = not job.running and path is not None and path.is_file()
            s.turntable_made = self.files.turntable_made if s.turntable_ready else ""

    # -- Choices ---------------------------------------------------------------------------------
    # (a value set on trame's state waits for the next flush: ``with state`` flushes it, so a
    # change from a worker's callback reaches the pages now, not at the user's next action)
    def show_presets(self, presets: list) -> None:
        with self.server.state as s:
            s.presets = [panel.item(i) for i in panelmodel.preset_items(presets)]

    def show_meshes(self, labels: dict[str, str]) -> None:
        with self.server.state as s:
            s.meshes = [{"title": t, "value": self.mesh_values.page(n)}
                        for n, t in labels.items()]  # fmt: skip

    def show_recent(self, paths: list[str]) -> None:
        """The page keeps no recent files (it opens uploads only)."""

    def show_history(self, undo: str | None, redo: str | None) -> None:
        with self.server.state as s:
            s.can_undo, s.can_redo = undo is not None, redo is not None
            s.undo_label, s.redo_label = undo or "", redo or ""
            s.intents_enabled = intents.enabled(self.controller)

    # -- the view port's pictures (explorer.app.viewport.Pictures) --------------------------------
    def send(self) -> None:
        """Send a new picture to every page (side B's follows side A's frame). The compiled
        kernels are looked for too (:func:`explorer.shading.tiers.preload`: the numpy tier
        serves until they are loaded), and the page says which engine serves."""
        tiers.preload()
        engine = tiers.status() or ""
        if engine != self.server.state.engine:
            with self.server.state as s:
                s.engine = engine
        self._send(self.server.controller.view_update, self.plotter.render_window)

    def show_controls(self, state: M.State) -> None:
        self._push(state)

    def show_legend(self, legend: str, advice: str) -> None:
        """The difference's legend and advice (the accuracy table's word on this material, as
        the window shows it under the legend), on every page now (they come from the
        difference worker's callback, between two of the user's actions: set without a flush,
        they waited for the next one, and the page said "computing the map" over the finished
        heat map)."""
        with self.server.state as s:
            s.legend = legend
            s.advice = advice

    def after_frame(self) -> None:
        """Nothing of the page's own after a frame (side B's picture follows: WebCompare)."""

    def _send(self, update, window) -> None:
        """``update()``: the remote view of ``window`` asks for a picture, which
        :class:`~explorer.app.web.pictures.Pictures` makes and sends at once."""
        update()

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
                s.update({**panel.values(state), "mesh": self.mesh_values.page(state.mesh)})
        finally:
            self.pushing = False

    def report_state(self) -> dict:
        """What a test may read (plain JSON values): the view port's report
        (:meth:`PlotterView.report`, the probe and the handles in the view's pixels, origin
        top-left), the view's size, the selected light's placement, side B's probe, the term
        strip, the lobe inset and its lit sphere, the session, the last picture's steps."""
        state, view, shared = self.store.state, self.view, self.viewport.report()
        probe = view.mesh.positions[view.probe_vertex()]
        return {
            **shared,
            "size": list(self.viewport.size()),
            "placement": list(state.placement()) if state.selected_light is not None else None,
            "compare": self.viewport.side_b.probe() if self.viewport.side_b.shown else None,
            "strip": view.strip.report(view.to_view(probe)),
            "lobes": view.lobe.report(),
            "sphere": view.lobe.sphere_report(),
            "session": session_mapping(state),
            # the last picture's steps (ms; explorer.app.web.pictures) and the last change's
            # time to its frame's end (the benchmark's breakdown)
            "picture": {
                **(self.pictures.times if self.pictures else {}),
                "frame_ms": shared["frame_ms"],
                **({"sent_bytes": self.direct.last_bytes()} if self.direct is not None else {}),
            },
        }

    def close(self) -> None:
        self.worker.close()
        if self.pictures is not None:
            self.pictures.close()
        self._uploads.cleanup()
        self.viewport.close()  # (VTK's observers removed; the windows closed under DRAW_LOCK)
        if self.viewport.side_b.plotter is None:  # side B's, made with the page, never shown
            with DRAW_LOCK:
                self.compare.plotter.close()


def own_arguments() -> None:
    """trame reads its own options from the command line (``--host``, ``--port``,
    ``--timeout``...) unless ``TRAME_ARGS`` is set: it is set empty, so that only the
    explorer's arguments, given to ``server.start``, count."""
    os.environ["TRAME_ARGS"] = ""


def _stop(signum, frame):
    """SIGTERM ends the server as Ctrl-C does (the session is kept on the way out)."""
    raise KeyboardInterrupt


def check_listen(host: str, port: int) -> None:
    """Refuse at once, in one :class:`ExplorerError`, an address the server could not listen
    on: a port taken by another server, an address not of this machine (``EADDRNOTAVAIL``), a
    host name that does not resolve. Port 0 (any free one) is never taken. The server's own
    bind can still fail (a port taken in between): :func:`serve` and :func:`show` say that
    as this does (:func:`cannot_listen`)."""
    import socket

    try:
        found = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
        for family, kind, proto, _, address in found:
            with socket.socket(family, kind, proto) as s:
                s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as aiohttp binds
                s.bind(address)
    except OSError as exc:
        raise cannot_listen(host, port, exc) from None


def cannot_listen(host: str, port: int, exc: OSError) -> ExplorerError:
    """The one line for an address the server cannot listen on."""
    import errno

    reason = exc.strerror or str(exc)
    if exc.errno == errno.EADDRINUSE:
        reason += " (another server has it: choose another port, or 0 for any free one)"
    elif exc.errno == errno.EADDRNOTAVAIL:
        reason += " (not an address of this machine)"
    return ExplorerError(f"cannot listen on {host} port {port}: {reason}")


def serve(app: WebExplorer, *, port: int = 0, host: str = DEFAULT_HOST, open_browser=False):
    """Serve ``app`` until the process ends (prints ``App running at:`` and the URL with the
    page's token, the only place the token is written; ``open_browser``: opens it). A request
    whose Host is not one of ``host``'s names (:func:`~explorer.app.guard.listening_names`)
    is refused. When the server stops (Ctrl-C, SIGTERM) the session is kept as the desktop
    keeps it when its window closes (:meth:`FileFlows.keep_last_session`; ``--last`` reopens
    it), but only if it served: an address it cannot listen on (:func:`check_listen`) is one
    :class:`ExplorerError`, and the session kept before stays."""
    import signal

    check_listen(host, port)
    own_arguments()
    signal.signal(signal.SIGTERM, _stop)
    app.hosts = guard.listening_names(host)

    def ready(**_):
        url = guard.page_url(served_url(host, app.server.port), app.token)
        print(f"\nApp running at:\n - Local:   {url}\n", flush=True)
        if open_browser:
            import webbrowser

            webbrowser.open(url)

    app.server.controller.on_server_ready.add(ready)
    try:
        app.server.start(port=port, host=host, open_browser=False, timeout=0,
                         show_connection_info=False)  # fmt: skip
    except KeyboardInterrupt:
        pass
    except OSError as exc:
        if app.loop is None:  # never served: the bind failed after the check
            raise cannot_listen(host, port, exc) from None
        raise
    finally:
        if app.loop is not None:  # set once the server listens (WebExplorer._ready)
            app.controller.files.keep_last_session()


def served_url(host: str, port: int) -> str:
    """The page's address on a server listening on ``host`` (an IPv6 address in brackets)."""
    return f"http://[{host}]:{port}/" if ":" in host else f"http://{host}:{port}/"


def _same_pose(a, b) -> bool:
    """Whether cameras ``a`` and ``b`` (:class:`explorer.render.camera.Camera`) look from the
    same place the same way with the same view: their clipping ranges aside, which the view
    sets anew for what it shows each frame (the start's framed camera comes back from the
    view with its own)."""
    if a is None or b is None:
        return a is b
    return dataclasses.replace(a, clipping_range=b.clipping_range) == b
