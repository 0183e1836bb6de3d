"""The explorer in a notebook: :func:`show` serves a :class:`~explorer.app.web.server.WebExplorer`
on 127.0.0.1 from a thread of its own (the kernel stays free) and returns a :class:`Shown`, which
a cell displays as an ``<iframe>`` of the page (with its token), reads back (``.state``), sets
(``.set``) and stops (``.stop()``). Under JupyterHub, or a Jupyter server on another machine,
the page goes through jupyter-server-proxy (:func:`proxy_prefix`, :func:`page_url`).

trame, VTK and PyVista are imported inside the functions that need them.
"""

from __future__ import annotations

import dataclasses
import os
import threading

from explorer.app import model as M
from explorer.app.controller import Controller
from explorer.app.session import session_mapping
from explorer.app.start import DEFAULT_MESH, DEFAULT_PRESET, notebook_state
from explorer.app.web import guard
from explorer.app.web.server import (
    DEFAULT_HOST,
    WebExplorer,
    cannot_listen,
    check_listen,
    own_arguments,
)
from explorer.core.errors import ExplorerError, ExplorerTypeError

#: the environment variable that sends :func:`show`'s page through jupyter-server-proxy: the
#: Jupyter server's base URL (``/`` for a Jupyter server at the root of its host,
#: ``/user/NAME/`` under JupyterHub)
JUPYTER_PROXY_ENV = "PHONG_EXPLORER_JUPYTER_PROXY"
#: the variable JupyterHub sets in a user's server (its base URL): the page goes through the proxy
JUPYTERHUB_PREFIX_ENV = "JUPYTERHUB_SERVICE_PREFIX"
#: the values of :data:`JUPYTER_PROXY_ENV` that keep the direct address (even under JupyterHub)
PROXY_OFF = ("0", "off", "false", "no")


@dataclasses.dataclass
class Shown:
    """An explorer served from a thread for a notebook: displayed inline as an ``<iframe>``;
    :attr:`state` reads the explorer's present state back in Python.

    app : the :class:`WebExplorer`; url : its page; height : the cell's height (pixels)

    :meth:`stop` ends it: the port closes and the server's thread ends (a new :func:`show`
    may then take the same port).
    """

    app: WebExplorer
    url: str
    height: int = 720
    thread: threading.Thread | None = dataclasses.field(default=None, repr=False)

    def stop(self, timeout: float = 30.0) -> None:
        """Stop the server: it stops listening (the port is free again), its open pages lose
        it, its thread ends and the explorer's resources (the view, the temporary folder of
        uploads) are released. Stopping a stopped one does nothing."""
        import asyncio

        if self.thread is None or not self.thread.is_alive():
            return
        loop = self.app.loop
        try:
            asyncio.run_coroutine_threadsafe(self.app.server.stop(), loop).result(timeout)
        finally:
            loop.call_soon_threadsafe(loop.stop)
            self.thread.join(timeout)

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

    def __repr__(self) -> str:
        """What a console prints for it (outside a notebook): where its page is."""
        return f"<phong-explorer page at {self.url} (.stop() ends it)>"

    def _repr_html_(self) -> str:
        """The page in an ``<iframe>``, and below it its address as a link that opens it in a
        browser tab of its own (the frame may be too small, or blocked)."""
        import html

        url = html.escape(self.url)
        return (f'<iframe src="{url}" style="width:100%;height:{self.height}px;'
                f'border:none" title="phong-explorer"></iframe>'
                f'<div style="font-size:small">phong-explorer: <a href="{url}" target="_blank" '
                f'rel="noopener">{url}</a> (a tab of its own)</div>')  # fmt: skip


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
    """``base`` (a path or an http(s) URL) checked, ending with ``/``: no space, quote, ``<``,
    ``>``, ``?``, ``#``, backslash, nor any character that is not printable (a control
    character such as ``\\r``, ``\\0`` or ``\\v`` would go into the cell's ``<iframe src>``)."""
    from urllib.parse import urlsplit

    parts = urlsplit(base)
    url = parts.scheme in ("http", "https") and parts.netloc
    path = base.startswith("/") and not base.startswith("//")  # "//host" names another host
    bad = any(c in " \"'<>?#\\" or not c.isprintable() for c in base)  # \r, \0, \v, \u2028
    if not (path or url) or bad:
        raise ExplorerError(f"{where}: a Jupyter base URL is a path from / (such as "
                            f"/user/NAME/) or an http(s) URL, got {base!r}")  # fmt: skip
    return base if base.endswith("/") else base + "/"


def page_url(port: int, prefix: str | None, token: str = "") -> str:
    """The address of the page served on ``port``: direct (``http://127.0.0.1:PORT/``) or,
    under Jupyter base URL ``prefix``, jupyter-server-proxy's ``<prefix>proxy/<port>/`` (the
    page's assets are relative and its websocket is ``<page's folder>/ws``: both go through
    the proxy); with the page's ``token`` when given (``?secret=TOKEN``)."""
    base = f"http://{DEFAULT_HOST}:{port}/" if prefix is None else f"{prefix}proxy/{int(port)}/"
    return guard.page_url(base, token) if token else base


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
    check_listen(DEFAULT_HOST, port)
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
            # behind jupyter-server-proxy the Host is the Jupyter server's (checked there)
            app.hosts = None if prefix is not None else app.hosts
            own_arguments()
            app.server.start(port=port, host=DEFAULT_HOST, exec_mode="task", thread=True,
                             open_browser=False, timeout=0, show_connection_info=False,
                             disable_logging=True)  # fmt: skip

            async def wait():
                try:
                    await app.server.ready
                    box["port"] = app.server.port
                except OSError as exc:  # the bind failed after check_listen
                    box["error"] = cannot_listen(DEFAULT_HOST, port, exc)
                    loop.stop()
                ready.set()

            loop.create_task(wait())
        except Exception as exc:  # noqa: BLE001 - handed to the caller's thread
            box["error"] = exc
            ready.set()
            return
        try:
            loop.run_forever()
        finally:  # Shown.stop(), or a failed start: the explorer's resources go with it
            if "app" in box:
                box["app"].close()
            loop.close()

    thread = threading.Thread(target=run, daemon=True, name="phong-explorer-web")
    thread.start()
    if not ready.wait(120):
        raise ExplorerError("the explorer's web server did not start within 120 s")
    if "error" in box:
        thread.join(30)  # its loop stopped: the explorer closes with it
        raise box["error"]
    return Shown(box["app"], page_url(box["port"], prefix, box["app"].token), height, thread)
