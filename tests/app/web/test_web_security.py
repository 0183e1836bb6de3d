"""Who may use a ``phong-explorer web`` server, and what a page may set (issue 37 §1 and its
XSS item), on a real server process: a raw wslink client (``webserver.ws_connect``) with
wslink's public default secret, a wrong token, no Origin or another one; a Host naming another
site (HTTP and websocket); the page without its token, and with its cookie; a ``mesh`` that is
a path; a client setting the page's Vue template, an unknown key or a wrong type; and, in
headless Chromium, a page served from another port of 127.0.0.1 that tries the hijack, and the
real page that still works (and keeps working when reloaded, its token gone from the
address bar)."""

from __future__ import annotations

import threading
import time
import urllib.error
import urllib.request
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import pytest
import websocket
from test_web import by_name, open_page, picture_src, report, wait
from webserver import page_origin, ws_connect

from explorer.app.web import guard as webguard
from explorer.app.web.panel import MESH_REFUSED
from explorer.core.controls import CONTROLS, from_step

pytestmark = pytest.mark.web

#: the page's Vue template, as an attacker would set it: an image whose error handler runs
XSS = "<div><img src='/nothing.png' onerror='window.__xss = 1'></div>"


def get(url: str, headers=None) -> tuple[int, str, dict]:
    """``(status, body, headers)`` of a GET that follows no redirect."""

    class NoRedirect(urllib.request.HTTPRedirectHandler):
        def redirect_request(self, *args, **kw):
            return None

    opener = urllib.request.build_opener(NoRedirect)
    try:
        with opener.open(urllib.request.Request(url, headers=headers or {}), timeout=30) as r:
            return r.status, r.read().decode(errors="replace"), dict(r.headers)
    except urllib.error.HTTPError as e:
        return e.code, e.read().decode(errors="replace"), dict(e.headers)


def refused_upgrade(server, **kw) -> int | None:
    """The status of a refused websocket upgrade (None: it opened)."""
    try:
        ws_connect(server, **kw).close()
    except websocket.WebSocketBadStatusException as e:
        return e.status_code
    return None


def state_of(client) -> dict:
    reply = client.call("trame.state.get")
    assert "result" in reply, reply
    return reply["result"]["state"]


def server_report(client) -> dict:
    reply = client.call("trame.trigger", ["report", [], {}])
    assert "result" in reply, reply
    return reply["result"]


# -- the websocket ----------------------------------------------------------------------------
@pytest.mark.parametrize("secret", ["wslink-secret", "wrong", None, ""])
def test_a_websocket_without_the_token_gets_no_session(server, secret):
    """The hijack's first step: wslink's public default secret (what trame's page says when
    its URL has no token), a wrong token or none: the hello fails, and so does every call."""
    client = ws_connect(server, token=secret)
    try:
        assert client.hello.get("error", {}).get("message") == "Authentication failed"
        reply = client.call("trame.state.get")
        assert "result" not in reply and "Unauthorized" in reply["error"]["message"]
        reply = client.call("trame.state.update", [[{"key": "kd_step", "value": 1}]])
        assert "result" not in reply
    finally:
        client.close()
    assert server.token not in server.output().replace(server.url, "")


@pytest.mark.parametrize(
    "origin", [None, "http://127.0.0.1:1", "http://evil.example", "http://localhost:{port}", "null"]
)
def test_a_websocket_from_another_origin_is_refused_even_with_the_token(server, origin):
    """A page of another site, or of another port of this machine (another name for this
    server is another origin too), cannot open the page's websocket: refused at the upgrade,
    before any message, and said in the server's log."""
    origin = origin and origin.format(port=server.port)
    assert refused_upgrade(server, origin=origin) == 403
    assert f"Origin {origin!r} is not the page's" in server.output()


def test_the_pages_own_origin_with_the_token_gets_the_session(server):
    client = ws_connect(server)
    try:
        assert "clientID" in client.hello["result"]
        assert state_of(client)["mesh"] == "sphere"
    finally:
        client.close()


# -- the Host ---------------------------------------------------------------------------------
def test_a_host_naming_another_site_is_refused(server):
    """DNS rebinding: a name of another site that resolves to 127.0.0.1 makes that site
    same-origin with the explorer; the server answers only to its own names."""
    evil = f"rebind.evil.example:{server.port}"
    status, body, _ = get(server.url, {"Host": evil})
    assert (status, body.strip()) == (403, webguard.BAD_HOST)
    assert "<html" not in body
    assert refused_upgrade(server, host=evil, origin=f"http://{evil}") == 403
    assert f"Host {evil!r} is not this server's" in server.output()
    # the refusal's log line quotes the path: a newline in it forges no line of its own
    assert get(server.base + "x%0Aforged%20line", {"Host": evil})[0] == 403
    assert "\nforged line" not in server.output() and "'/x\\nforged line'" in server.output()
    for own in (f"localhost:{server.port}", f"127.0.0.1:{server.port}"):
        assert get(server.url, {"Host": own})[0] in (200, 302)


# -- the page and its token -------------------------------------------------------------------
def test_the_page_without_its_token_is_refused_in_one_line(server):
    for url in (server.base, server.base + "index.html", server.base + "?secret=wslink-secret"):
        status, body, _ = get(url)
        assert status == 403, url
        assert body.strip() == webguard.NO_TOKEN
    status, body, headers = get(server.base + f"index.html?secret={server.token}")
    assert status == 200 and "<html" in body
    cookie = headers["Set-Cookie"]
    assert cookie.startswith(f"{webguard.cookie_name(server.port)}={server.token};")
    assert "HttpOnly" in cookie and "SameSite=Strict" in cookie
    # a reload (the address bar no longer shows the token): the cookie brings it back
    name = webguard.cookie_name(server.port)
    status, _, headers = get(server.base + "index.html", {"Cookie": f"{name}={server.token}"})
    assert status == 302 and headers["Location"] == f"index.html?secret={server.token}"
    status, _, _ = get(server.base + "index.html", {"Cookie": f"{name}=wrong"})
    assert status == 403


def test_the_token_is_written_only_in_the_printed_address(server):
    get(server.url)
    get(server.base)
    ws_connect(server).close()
    out = server.output()
    assert out.count(server.token) == 1, out
    assert f"App running at:\n - Local:   {server.url}\n" in out


# -- the mesh ---------------------------------------------------------------------------------
def test_a_mesh_that_is_a_path_is_refused_alike_and_nothing_is_loaded(server, tmp_path):
    """``mesh`` set over the socket to a path (a system file, one under ``~``, an existing
    mesh file, a missing one): the same refusal each time, naming no path, telling nothing of
    which files exist, and the mesh shown stays."""
    real = tmp_path / "tetra.obj"
    real.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n")
    client = ws_connect(server)
    try:
        before = server_report(client)
        said = set()
        for value in (
            "/etc/passwd",
            "~/.bashrc",
            str(real),
            str(tmp_path / "missing.obj"),
            "../../etc/hosts",
        ):
            reply = client.call("trame.state.update", [[{"key": "mesh", "value": value}]])
            assert "error" not in reply, reply
            state = state_of(client)
            said.add(state["message"])
            assert state["mesh"] == "sphere"
            rep = server_report(client)
            assert rep["n_vertices"] == before["n_vertices"]
            assert rep["session"]["mesh"] == "sphere"
        assert said == {f"error: {MESH_REFUSED}"}
        assert "/" not in MESH_REFUSED and "~" not in MESH_REFUSED
        # a built-in name of the chooser is still a choice (and back)
        client.call("trame.state.update", [[{"key": "mesh", "value": "cube"}]])
        assert server_report(client)["session"]["mesh"] == "cube"
        client.call("trame.state.update", [[{"key": "mesh", "value": "sphere"}]])
        assert server_report(client)["session"]["mesh"] == "sphere"
    finally:
        client.close()
    assert str(real) not in server.output() and "passwd" not in server.output()


def test_an_uploaded_mesh_is_chosen_by_a_value_that_names_no_path(server):
    """The chooser's values never name a server path: an upload (sent as the page's file
    field sends it) is listed as ``file N: NAME``, chosen again by that value, and its path
    refused."""
    obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"
    client = ws_connect(server)
    try:
        upload = [{"name": "tetra.obj", "size": len(obj), "type": "", "content": obj}]
        client.call("trame.state.update", [[{"key": "mesh_upload", "value": upload}]])
        path = server_report(client)["session"]["mesh"]
        assert path.endswith("/tetra.obj")  # the server's own name for it
        state = state_of(client)
        value = state["mesh"]
        assert value.startswith("file ") and value.endswith(": tetra.obj"), value
        assert all("/" not in m["value"] for m in state["meshes"]), state["meshes"]
        client.call("trame.state.update", [[{"key": "mesh", "value": "sphere"}]])
        assert server_report(client)["session"]["mesh"] == "sphere"
        client.call("trame.state.update", [[{"key": "mesh", "value": path}]])
        assert state_of(client)["message"] == f"error: {MESH_REFUSED}"
        assert server_report(client)["session"]["mesh"] == "sphere"
        client.call("trame.state.update", [[{"key": "mesh", "value": value}]])
        assert server_report(client)["session"]["mesh"] == path
        client.call("trame.state.update", [[{"key": "mesh", "value": "sphere"}]])
    finally:
        client.close()


# -- what a client may set --------------------------------------------------------------------
def test_a_client_sets_only_the_controls_keys_with_their_types(server):
    """A server-owned key (the page's Vue template, the message log), an unknown key and a
    control's key with a value of the wrong type are dropped: the state keeps its values,
    another tab is sent none of them, and the server's log says what was dropped (not the
    value)."""
    attacker, other = ws_connect(server), ws_connect(server)
    try:
        template = state_of(other)["trame__template_main"]
        log = [{"text": "forged", "level": "info", "details": [], "at": "00:00:00"}]
        reply = attacker.call(
            "trame.state.update",
            [
                [
                    {"key": "trame__template_main", "value": XSS},
                    {"key": "message_log", "value": log},
                    {"key": "no_such_key", "value": 1},
                    {"key": "show_ambient", "value": "yes"},
                    {"key": "light", "value": -3},
                ]
            ],
        )
        assert "error" not in reply, reply
        state = state_of(other)  # the publications to this tab came before this reply
        assert state["trame__template_main"] == template
        assert all(m.get("text") != "forged" for m in state["message_log"])
        assert "no_such_key" not in state
        assert state["show_ambient"] is True and state["light"] == 0
        sent = [
            k
            for m in other.seen
            if str(m.get("id", "")).startswith("publish:")
            for k in (m.get("result") or {})
        ]
        assert not {"trame__template_main", "message_log", "no_such_key"} & set(sent), sent
    finally:
        attacker.close()
        other.close()
    out = server.output()
    for line in (
        "'trame__template_main': not a key the page's controls set",
        "'message_log': not a key the page's controls set",
        "'no_such_key': not a key the page's controls set",
        "'show_ambient': must be bool, got str",
        "'light': must be index, got int",
    ):
        assert f"a page's change was dropped: {line}" in out
    assert "onerror" not in out


def test_the_pages_foot_is_the_explorers_not_an_advert(server):
    """The template the page is served: its foot names the explorer and its version, not
    trame's "Powered by trame" and Kitware links, nor the server's package versions."""
    from explorer.core.version import __version__

    client = ws_connect(server)
    try:
        template = state_of(client)["trame__template_main"]
    finally:
        client.close()
    assert f"phong-explorer {__version__}" in template
    for advert in ("Powered by trame", "kitware", "trame_vuetify", "mdi-help-circle"):
        assert advert.lower() not in template.lower(), advert


def test_an_injected_template_never_reaches_an_open_page(server, browser):
    """The XSS: another client sets the page's Vue template to an image whose error handler
    runs; the open page keeps its panel, and the handler never runs (a change the other client
    is allowed to make arrives after it, so the page has had both)."""

    def xss():
        return browser.execute_script("return window.__xss")

    def shows_kd(value):
        found = browser.execute_script(
            "return [...document.querySelectorAll('[aria-label=\"kd\"]')].map(e => e.value)"
        )
        return bool(found) and float(found[0]) == value

    open_page(browser, server.url)
    client = ws_connect(server)
    try:
        step = 200 if state_of(client)["kd_step"] != 200 else 300
        c = CONTROLS["kd"]
        want = round(from_step(c, step, c.lo, c.hi), c.decimals)
        client.call(
            "trame.state.update",
            [
                [
                    {"key": "trame__template_main", "value": XSS},
                    {"key": "kd_step", "value": step},
                ]
            ],
        )
        wait("the other client's changes", lambda: xss() or shows_kd(want))
    finally:
        client.close()
    assert xss() is None
    assert shows_kd(want)
    assert by_name(browser, "kd").is_displayed() and picture_src(browser)


# -- in a real browser ------------------------------------------------------------------------
#: the attacking page: it opens the explorer's websocket, says wslink's default secret, asks
#: for the state and writes what it got into its title
ATTACK_JS = """
const hello = new Uint8Array(%s), ask = new Uint8Array(%s);
let opened = false, replies = 0;
document.title = 'trying';
const ws = new WebSocket('ws://127.0.0.1:%d/ws');
ws.binaryType = 'arraybuffer';
ws.onopen = () => { opened = true; ws.send(hello); };
ws.onmessage = (e) => {
  replies += 1;
  if (replies === 1) { ws.send(ask); return; }
  document.title = 'read ' + e.data.byteLength + ' bytes of the session';
};
ws.onclose = (e) => {
  if (!document.title.startsWith('read'))
    document.title = (opened ? 'opened, ' : '') + 'closed ' + e.code;
};
"""


def frames(message: dict) -> list[int]:
    import msgpack
    from wslink.chunking import generate_chunks

    (frame,) = generate_chunks(msgpack.packb(message), 0)
    return list(frame)


def test_a_page_of_another_port_cannot_hijack_the_session(server, browser):
    """Cross-site websocket hijack, in Chromium: a page served from another port of
    127.0.0.1 opens the explorer's websocket with wslink's default secret and asks for the
    state. The socket never opens (the title says so); the real page, with its token, still
    gets its session."""
    hello = frames(
        {
            "wslink": "1.0",
            "id": "system:c0:0",
            "method": "wslink.hello",
            "args": [{"secret": "wslink-secret"}],
            "kwargs": {},
        }
    )
    ask = frames(
        {"wslink": "1.0", "id": "rpc:c0:1", "method": "trame.state.get", "args": [], "kwargs": {}}
    )
    page = (
        f"<!doctype html><html><head><title>-</title></head><body><script>"
        f"{ATTACK_JS % (hello, ask, server.port)}</script></body></html>"
    ).encode()

    class Attacker(BaseHTTPRequestHandler):
        def do_GET(self):
            self.send_response(200)
            self.send_header("Content-Type", "text/html")
            self.send_header("Content-Length", str(len(page)))
            self.end_headers()
            self.wfile.write(page)

        def log_message(self, *args):
            pass

    site = ThreadingHTTPServer(("127.0.0.1", 0), Attacker)
    threading.Thread(target=site.serve_forever, daemon=True).start()
    try:
        browser.get(f"http://127.0.0.1:{site.server_port}/")
        title = wait(
            "the attack to end", lambda: browser.title not in ("-", "trying") and browser.title
        )
        time.sleep(0.5)  # a late reply would turn the title into "read ..."
        assert browser.title == title == "closed 1006", title
        said = [e["message"] for e in browser.get_log("browser")]  # read: the log is emptied
        assert any("Unexpected response code: 403" in m for m in said), said
    finally:
        site.shutdown()
        site.server_close()
    origin = f"http://127.0.0.1:{site.server_port}"
    assert f"Origin {origin!r} is not the page's" in server.output()
    rep = open_page(browser, server.url)
    assert rep["session"]["mesh"] == "sphere"


def test_the_real_page_hides_its_token_and_survives_a_reload(server, browser):
    """The page takes its token out of the address bar (trame's client does); reloading it
    brings the token back through the cookie, and the page works again."""
    open_page(browser, server.url)
    assert server.token not in browser.current_url
    assert browser.current_url.startswith(page_origin(server))
    browser.refresh()
    wait("the picture after a reload", lambda: picture_src(browser))
    assert report(browser)["session"]["mesh"] == "sphere"
    assert server.token not in browser.current_url


def test_open_opens_the_address_with_its_token(tmp_path):
    """``--open`` hands the browser the printed address, token included (trame's own opener
    gave the address without it: a page that could not connect). ``$BROWSER`` is the
    browser Python's ``webbrowser`` runs: here a script that writes down what it was given."""
    import os
    import sys

    from webserver import Server, need_browser

    need_browser()
    got = tmp_path / "opened.txt"
    script = f"import sys; open({str(got)!r}, 'w').write(sys.argv[1])"
    env = dict(os.environ, BROWSER=f'{sys.executable} -c "{script}" %s')
    srv = Server(["--mesh", "cube", "--open"], tmp_path / "server.log", env=env)
    try:
        wait("the browser to be opened", lambda: got.is_file() and got.read_text())
        assert got.read_text() == srv.url
        assert got.read_text().endswith(f"/?secret={srv.token}")
    finally:
        srv.stop()


def test_the_access_log_at_info_level_never_writes_the_token(tmp_path):
    """A program that turns logging's INFO level on gets aiohttp's access log, a line per
    request with its address: the token is taken out of it (here the server's Python is
    started with a ``sitecustomize`` that does ``logging.basicConfig(level=INFO)``)."""
    import os

    from webserver import Server, need_browser

    need_browser()
    site = tmp_path / "site"
    site.mkdir()
    (site / "sitecustomize.py").write_text("import logging\nlogging.basicConfig(level=20)\n")
    path = os.pathsep.join(p for p in (str(site), os.environ.get("PYTHONPATH")) if p)
    srv = Server(["--mesh", "cube"], tmp_path / "server.log", env=dict(os.environ, PYTHONPATH=path))
    try:
        assert get(srv.url)[0] == 302  # to index.html, with the token
        assert get(f"{srv.base}index.html?secret={srv.token}")[0] == 200
        wait("the access log's line", lambda: "GET /index.html?secret=<token>" in srv.output())
        assert srv.output().count(srv.token) == 1  # the printed address only
    finally:
        srv.stop()


def test_every_key_a_control_of_the_page_sets_is_in_the_client_table(server):
    """The page's template (what trame's client renders) names each key a control sets
    (``v-model``): every one is in the client-key table (a control added without its row
    would be dropped by the server), and the table holds no key the page does not set but
    the uploads and the fields' keys that are in it by design (none)."""
    import re

    client = ws_connect(server)
    try:
        template = state_of(client)["trame__template_main"]
    finally:
        client.close()
    models = set(re.findall(r'v-model(?::\w+)?="([^"]+)"', template))
    assert {"kd_step", "preset", "mesh", "tab", "mesh_upload"} <= models, models
    # the message log's and the help's dialogs: kept in each tab, never sent
    client_only = {"show_messages", "show_help"}
    assert models - client_only <= set(webguard.CLIENT_KEYS), models - set(webguard.CLIENT_KEYS)
    assert set(webguard.CLIENT_KEYS) <= models, set(webguard.CLIENT_KEYS) - models
