"""Starting and stopping the web explorer (issue 37 §3): ``web`` on a taken port or on an
address not of this machine printed a traceback, and its unserved start state replaced the
session the user kept (``--last`` then reopened the wrong one); ``show()`` on a taken port
waited 120 s and raised something else; the object ``show()`` returned could not be stopped
(its port stayed open, its thread ran on)."""

from __future__ import annotations

import os
import re
import socket
import subprocess
import sys
import threading
import time
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
    env = dict(
        os.environ, PYTHONPATH=os.pathsep.join(sys.path), PHONG_EXPLORER_LAST_SESSION=str(last)
    )
    with _taken() as other:
        port = other.getsockname()[1]
        host = ["--host", "192.0.2.1"] if where != "taken port" else []  # TEST-NET-1
        res = subprocess.run(
            [
                sys.executable,
                "-m",
                "explorer.cli",
                "web",
                "--mesh",
                "sphere",
                *host,
                "--port",
                str(port),
            ],
            env=env,
            capture_output=True,
            text=True,
            timeout=240,
        )
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
    before = _servers()
    with _taken() as other:
        port = other.getsockname()[1]
        with pytest.raises(ExplorerError, match=f"cannot listen on 127.0.0.1 port {port}: "):
            web.show(mesh="sphere", port=port)
    assert _servers() == before  # no server thread left behind


def _servers() -> set:
    """The threads :func:`show` started that still run (other tests' included)."""
    return {t for t in threading.enumerate() if t.name == "phong-explorer-web" and t.is_alive()}


def test_shown_stop_closes_the_port_and_ends_the_thread():
    pytest.importorskip("trame")
    from explorer.app import web

    before = _servers()
    shown = web.show(mesh="sphere")
    port = urlsplit(shown.url).port
    with urllib.request.urlopen(shown.url, timeout=60) as page:
        assert page.status == 200
    assert _servers() == before | {shown.thread}
    shown.stop()
    assert not shown.thread.is_alive() and _servers() == before
    with pytest.raises(ConnectionRefusedError):
        socket.create_connection(("127.0.0.1", port), timeout=10).close()
    shown.stop()  # a stopped one: nothing happens
    again = web.show(mesh="sphere", port=port)  # the port is free for the next one
    try:
        assert urlsplit(again.url).port == port
    finally:
        again.stop()


def test_web_with_its_config_folder_locked_starts_serves_and_stops(tmp_path):
    """The user's config folder (the last session, the recent files, the presets) that cannot
    be searched: the recent files' ``PermissionError`` ended the start in a traceback, and so
    did keeping the session at the stop. Now the server serves, and its stop says in one
    warning that the session could not be kept."""
    pytest.importorskip("trame")
    from helpers.files import permissions_hold
    from webserver import end_process, free_port

    prefix = permissions_hold()
    if prefix is None:
        pytest.skip("no way to run a command that folder permissions hold for")
    config = tmp_path / "config"
    (config / "phong-explorer").mkdir(parents=True)
    config.chmod(0)
    port = free_port()
    env = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join(sys.path),
        XDG_CONFIG_HOME=str(config),
        MPLCONFIGDIR=str(tmp_path),
        PHONG_EXPLORER_KERNELS="numpy",
    )
    env.pop("PHONG_EXPLORER_LAST_SESSION", None)
    env.pop("PHONG_EXPLORER_MATERIALS", None)
    log = tmp_path / "web.log"
    with open(log, "w") as out:
        proc = subprocess.Popen(
            [
                *prefix,
                sys.executable,
                "-m",
                "explorer.cli",
                "web",
                "--mesh",
                "sphere",
                "--port",
                str(port),
            ],
            stdout=out,
            stderr=subprocess.STDOUT,
            env=env,
        )
        try:
            printed = re.compile(re.escape(f"http://127.0.0.1:{port}/") + r"\?secret=\S+")
            for _ in range(1200):  # at most two minutes
                if printed.search(log.read_text()) or proc.poll() is not None:
                    break
                time.sleep(0.1)
            assert proc.poll() is None, log.read_text()
            url = printed.search(log.read_text()).group(0)  # the page's address with its token
            with urllib.request.urlopen(url, timeout=60) as page:
                assert page.status == 200
        finally:
            end_process(proc, wait=60)
            config.chmod(0o755)
    said = log.read_text()
    assert proc.returncode == 0, said
    assert "Traceback" not in said and "error:" not in said, said
    assert said.count("could not keep the last session") == 1, said
