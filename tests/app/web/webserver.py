"""The web tests' server and browser (a module of its own name: ``from conftest import``
would find whichever conftest came first on the path when tests/app/web runs with other test
folders): a ``phong-explorer web`` process, as a user starts it, and a headless Chromium
(Debian's ``chromium`` and ``chromium-driver``, driven by Selenium)."""

from __future__ import annotations

import os
import re
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers.processes import end_process

from explorer.app import browser

#: how long the server may take to print its URL (the first start compiles nothing: the numpy
#: tier serves while numba's cache is cold)
START_TIMEOUT = 120
CHROMIUM, CHROMEDRIVER = browser.CHROMIUM, browser.CHROMEDRIVER


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


#: the engine's tier in the servers these tests start. The suite runs in mode ``compiled``
#: (tests/conftest.py), which compiles a missing kernel in the calling process: in a server that
#: holds the interpreter for tens of seconds on a cold cache and freezes the page (CI's cold run
#: timed out on the difference view). A user's server never compiles in-process (mode ``auto``:
#: the numpy tier serves while the background compile runs, tests/app/web/test_web_cold.py), so the
#: page tests' servers run the numpy tier: the same colours (the tiers' contract), no compile.
SERVER_KERNELS = "numpy"


class Server:
    """A ``phong-explorer web`` process: its URL (the address it printed, with its token:
    ``url``; without it: ``base``, and ``token``), its output, whether it still runs."""

    def __init__(self, args, log: Path, env=None, host: str = "127.0.0.1"):
        self.port = free_port()
        self.log = log
        self._out = open(log, "w")  # noqa: SIM115 - closed in stop()
        env = dict(os.environ if env is None else env, PHONG_EXPLORER_KERNELS=SERVER_KERNELS)
        # the server keeps its session when it stops (web --last): never in the user's folder
        env.setdefault("PHONG_EXPLORER_LAST_SESSION", str(log.with_suffix(".last.yaml")))
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "explorer.cli", "web", "--port", str(self.port), *args],
            stdout=self._out, stderr=subprocess.STDOUT, env=env,
        )  # fmt: skip
        self.base = f"http://{host}:{self.port}/"
        printed = re.compile(re.escape(self.base) + r"\?secret=([A-Za-z0-9_-]+)")
        end = time.monotonic() + START_TIMEOUT
        while not (found := printed.search(log.read_text(errors="replace"))):
            if self.proc.poll() is not None or time.monotonic() > end:
                self.stop()
                pytest.fail(f"the server did not start:\n{log.read_text(errors='replace')}")
            time.sleep(0.1)
        self.token = found.group(1)
        self.url = found.group(0)

    def output(self) -> str:
        return self.log.read_text(errors="replace")

    def stop(self) -> None:
        end_process(self.proc)
        self._out.close()


def need_browser() -> None:
    for f in (CHROMIUM, CHROMEDRIVER):
        if not os.path.exists(f):
            pytest.skip(f"{f} is not installed (apt-get install chromium chromium-driver)")
    pytest.importorskip("selenium")
    pytest.importorskip("trame")


def new_browser(downloads: Path, prefs: dict | None = None):
    """A headless Chromium at 1280x900 that saves downloads into ``downloads`` and keeps the
    page's console log (:func:`explorer.app.browser.new_browser`; ``prefs``: more of Chromium's
    preferences)."""
    return browser.new_browser(downloads=downloads, console_log=True, prefs=prefs)


def page_origin(server: Server) -> str:
    """The origin of the page ``server`` serves (what a browser sends with its websocket)."""
    return server.base.rstrip("/")


class WsClient:
    """A raw wslink client (what trame's page does, in Python): ``call`` sends one RPC and
    returns its reply (``{"result": ...}`` or ``{"error": ...}``); ``seen`` keeps every other
    message received meanwhile (the server's publications: the state other tabs changed)."""

    def __init__(self, ws, unchunk, secret: str | None):
        self.ws, self._unchunk, self._n = ws, unchunk, 0
        self.seen: list[dict] = []
        self.hello = _rpc(self, "system:c0:0", "wslink.hello", [{"secret": secret}], 30)

    def call(self, method: str, args=(), timeout: float = 30) -> dict:
        self._n += 1
        rid = f"rpc:{self.hello.get('result', {}).get('clientID', 'c0')}:{self._n}"
        return _rpc(self, rid, method, list(args), timeout)

    def close(self) -> None:
        self.ws.close()


def _frames(message: dict) -> list[bytes]:
    import msgpack
    from wslink.chunking import generate_chunks

    return list(generate_chunks(msgpack.packb(message), 0))


def _rpc(client: WsClient, rid: str, method: str, args: list, timeout: float) -> dict:
    """Send RPC ``method`` (id ``rid``) and return the reply with that id (other messages,
    the state's publications, go to ``client.seen``)."""
    import msgpack

    for frame in _frames({"wslink": "1.0", "id": rid, "method": method, "args": args,
                          "kwargs": {}}):  # fmt: skip
        client.ws.send_binary(frame)
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        client.ws.settimeout(max(end - time.monotonic(), 0.1))
        msg = client._unchunk.process_chunk(client.ws.recv())
        if msg is not None:
            msg = msg if isinstance(msg, dict) else msgpack.unpackb(msg)
            if msg.get("id") == rid:
                return msg
            client.seen.append(msg)
    raise TimeoutError(f"no reply to {method} within {timeout} s")


def ws_connect(
    server: Server,
    *,
    origin: str | None = "page",
    token: str | None = "server",
    host: str | None = None,
) -> WsClient:
    """A raw websocket to ``server``'s ``/ws`` that says hello as trame's page does, and its
    client (``.hello``: the server's answer). ``origin``: the Origin header (``"page"``: the
    page's own, None: none); ``token``: the secret said in the hello (``"server"``: the
    server's own; trame's page without one says wslink's default ``"wslink-secret"``);
    ``host``: the Host header (None: the server's address). A refused upgrade raises
    ``websocket.WebSocketBadStatusException`` (its ``status_code``)."""
    import websocket
    from wslink.chunking import UnChunker

    origin = page_origin(server) if origin == "page" else origin
    kw = {"suppress_origin": origin is None}
    if origin is not None:
        kw["origin"] = origin
    if host is not None:
        kw["host"] = host
    url = server.base.replace("http://", "ws://", 1) + "ws"
    ws = websocket.create_connection(url, timeout=30, **kw)
    unchunk = UnChunker()
    unchunk.set_max_message_size(1 << 30)
    return WsClient(ws, unchunk, server.token if token == "server" else token)
