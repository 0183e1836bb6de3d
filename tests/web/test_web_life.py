"""Starting and stopping the web explorer (issue 37 §3): ``web`` on a taken port or on an
address not of this machine printed a traceback, and its unserved start state replaced the
session the user kept (``--last`` then reopened the wrong one); ``show()`` on a taken port
waited 120 s and raised something else; the object ``show()`` returned could not be stopped
(its port stayed open, its thread ran on)."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import threading
import urllib.request
from urllib.parse import urlsplit

import pytest

from explorer.core.errors import ExplorerError

pytestmark = pytest.mark.web
KEPT = "the session the user kept\n"


def _taken() -> socket.socket:
    """A socket listening on a free port of 127.0.0.1: another server's port."""
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    s.listen()
    return s


@pytest.mark.parametrize("where", ["taken port", "address not of this machine"])
def test_web_that_cannot_listen_is_one_line_and_keeps_the_last_session(tmp_path, where):
    pytest.importorskip("trame")
    last = tmp_path / "last.yaml"
    last.write_text(KEPT)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path),
               PHONG_EXPLORER_LAST_SESSION=str(last))  # fmt: skip
    with _taken() as other:
        port = other.getsockname()[1]
        host = ["--host", "192.0.2.1"] if where != "taken port" else []  # TEST-NET-1
        res = subprocess.run(
            [sys.executable, "-m", "explorer.cli", "web", "--mesh", "sphere", *host, "--port",
             str(port)], env=env, capture_output=True, text=True, timeout=240,
        )  # fmt: skip
    assert res.returncode == 2, res.stderr
    lines = [ln for ln in res.stderr.splitlines() if not ln.startswith("warning: listening on")]
    assert len(lines) == 1 and lines[0].startswith("error: cannot listen on"), res.stderr
    assert ("already in use" if where == "taken port" else "not an address of this") in lines[0]
    assert last.read_text() == KEPT


def test_a_bind_that_fails_after_the_check_keeps_the_last_session(tmp_path, monkeypatch):
    """The port taken between :func:`check_listen` and the server's own bind: the same one
    error, and the start state never replaces the session kept before."""
    pytest.importorskip("trame")
    from explorer.app import web

    last = tmp_path / "last.yaml"
    last.write_text(KEPT)
    monkeypatch.setenv("PHONG_EXPLORER_LAST_SESSION", str(last))
    monkeypatch.setattr(web, "check_listen", lambda host, port: None)
    import signal

    previous = signal.getsignal(signal.SIGTERM)
    state, mesh = web.notebook_state(mesh="sphere")
    app = web.WebExplorer(state, mesh, last_session=True, name="phong-explorer-bind-test")
    try:
        with _taken() as other, pytest.raises(ExplorerError, match="cannot listen on"):
            web.serve(app, port=other.getsockname()[1])
    finally:
        signal.signal(signal.SIGTERM, previous)
        app.close()
    assert last.read_text() == KEPT


@pytest.mark.parametrize("when", ["before the start", "in the server's bind"])
def test_show_on_a_taken_port_is_one_error(monkeypatch, when):
    pytest.importorskip("trame")
    from explorer.app import web

    if when != "before the start":
        monkeypatch.setattr(web, "check_listen", lambda host, port: None)
    with _taken() as other:
        port = other.getsockname()[1]
        with pytest.raises(ExplorerError, match=f"cannot listen on 127.0.0.1 port {port}: "):
            web.show(mesh="sphere", port=port)
    assert not [t for t in threading.enumerate() if t.name == "phong-explorer-web"]


def test_shown_stop_closes_the_port_and_ends_the_thread():
    pytest.importorskip("trame")
    from explorer.app import web

    shown = web.show(mesh="sphere")
    port = urlsplit(shown.url).port
    with urllib.request.urlopen(shown.url, timeout=60) as page:
        assert page.status == 200
    shown.stop()
    assert not shown.thread.is_alive()
    assert not [t for t in threading.enumerate() if t.name == "phong-explorer-web"]
    with pytest.raises(ConnectionRefusedError):
        socket.create_connection(("127.0.0.1", port), timeout=10).close()
    shown.stop()  # a stopped one: nothing happens
    again = web.show(mesh="sphere", port=port)  # the port is free for the next one
    try:
        assert urlsplit(again.url).port == port
    finally:
        again.stop()
