"""The web explorer's admission rules (:mod:`explorer.app.web.guard`), without a server: the
token, the Host and Origin checks, the page's verdict, and the table of what a client may set.
The server's hooks are tested on a real ``phong-explorer web`` in
tests/app/web/test_web_security.py."""

from __future__ import annotations

import pytest

from explorer.app.web import guard as G
from explorer.app.web.panel import NUMBERS

TOKEN = G.new_token()


def test_a_token_is_random_long_and_url_safe():
    tokens = {G.new_token() for _ in range(20)}
    assert len(tokens) == 20
    for t in tokens:
        assert len(t) >= 43  # 32 bytes in base64
        assert all(c.isalnum() or c in "-_" for c in t)
    assert G.page_url("http://127.0.0.1:8080/", "abc") == "http://127.0.0.1:8080/?secret=abc"


@pytest.mark.parametrize(
    "given",
    [None, "", "wslink-secret", TOKEN[:-1], TOKEN + "x", 12, [TOKEN], TOKEN.swapcase()],
    # named, not shown: the token is new in each process, and the suite's workers must collect
    # the same test ids (tests/helpers/workers.py)
    ids=["none", "empty", "wslink-default", "cut", "longer", "number", "in-a-list", "swapcase"],
)
def test_only_the_token_itself_is_the_token(given):
    assert G.token_ok(TOKEN, TOKEN)
    assert not G.token_ok(given, TOKEN)


@pytest.mark.parametrize(
    "host",
    [
        "127.0.0.1:8080",
        "localhost:8080",
        "LOCALHOST:8080",
        "[::1]:8080",
        "127.0.0.1",
        "10.1.2.3:8080",
    ],
)
def test_a_host_naming_this_server_is_allowed(host):
    assert G.host_ok(host, G.listening_names("127.0.0.1"), 8080)


@pytest.mark.parametrize(
    "host",
    [
        "evil.example:8080",
        "evil.example",
        "127.0.0.1:8081",
        "localhost.evil.example:8080",
        "",
        None,
        "a b:8080",
        "user@127.0.0.1:8080",
        "127.0.0.1:8080/x",
        "[::1:8080",
        "127.0.0.1:99999",
    ],
)
def test_a_host_naming_another_site_or_port_is_refused(host):
    """DNS rebinding: a name that resolves to this machine is still another site's name."""
    assert not G.host_ok(host, G.listening_names("127.0.0.1"), 8080)


def test_the_listening_names_are_the_loopback_names_and_a_named_host():
    assert G.listening_names("127.0.0.1") == {"localhost"}
    assert G.listening_names("::1") == {"localhost"}
    assert G.listening_names("0.0.0.0", machine="Box") == {"localhost", "box"}
    assert G.listening_names("::", machine="box") == {"localhost", "box"}
    assert G.host_ok("box:9000", G.listening_names("0.0.0.0", machine="box"), 9000)
    assert G.listening_names("Explorer.Lan") == {"localhost", "explorer.lan"}
    assert G.host_ok("explorer.lan:9000", G.listening_names("explorer.lan"), 9000)
    assert not G.host_ok("explorer.lan:9000", G.listening_names("127.0.0.1"), 9000)
    assert G.host_ok("anything.example", None, 9000)  # behind a proxy that checks it


@pytest.mark.parametrize(
    ("origin", "host"),
    [
        ("http://127.0.0.1:8080", "127.0.0.1:8080"),
        ("http://localhost:8080", "localhost:8080"),
        ("https://hub.example.org", "hub.example.org"),
        ("https://hub.example.org:443", "hub.example.org"),
        ("http://hub.example.org", "hub.example.org:80"),
        ("http://[::1]:8080", "[::1]:8080"),
    ],
)
def test_the_pages_own_origin_is_allowed(origin, host):
    assert G.origin_ok(origin, host)


@pytest.mark.parametrize(
    ("origin", "host"),
    [
        (None, "127.0.0.1:8080"),  # no Origin: not a browser's page
        ("", "127.0.0.1:8080"),
        ("null", "127.0.0.1:8080"),  # a sandboxed frame or a file: page
        ("http://127.0.0.1:9999", "127.0.0.1:8080"),  # another port of this machine
        ("http://evil.example", "127.0.0.1:8080"),
        ("http://localhost:8080", "127.0.0.1:8080"),  # another name is another origin
        ("https://127.0.0.1:8080/x", "127.0.0.1:8080"),
        ("file://", "127.0.0.1:8080"),
        ("http://127.0.0.1:8080", None),
        ("https://hub.example.org", "hub.example.org:80"),
    ],
)
def test_another_origin_is_refused(origin, host):
    assert not G.origin_ok(origin, host)


def test_the_page_needs_the_token_or_its_cookie():
    assert G.page_verdict("/", TOKEN, None, TOKEN) == "serve"
    assert G.page_verdict("/index.html", TOKEN, "stale", TOKEN) == "serve"
    assert G.page_verdict("/index.html", None, TOKEN, TOKEN) == "redirect"
    assert G.page_verdict("/", "wrong", TOKEN, TOKEN) == "redirect"
    for query, cookie in ((None, None), ("wrong", None), (None, "wrong"), ("", "")):
        assert G.page_verdict("/index.html", query, cookie, TOKEN) == "refuse"
        assert G.page_verdict("/", query, cookie, TOKEN) == "refuse"
    # trame's assets hold nothing of the user's: served as they are
    assert G.page_verdict("/assets/index.js", None, None, TOKEN) == "serve"
    assert TOKEN not in G.NO_TOKEN and "\n" not in G.NO_TOKEN
    assert G.cookie_name(8080) != G.cookie_name(8081)


def test_the_client_keys_are_the_page_controls_keys():
    for k in (r.key for r in NUMBERS):
        assert G.CLIENT_KEYS[f"{k}_step"] == "number"
        assert k not in G.CLIENT_KEYS  # the fields call the server's parser, never set state
    for server_owned in (
        "trame__template_main",
        "message_log",
        "presets",
        "meshes",
        "engine",
        "can_undo",
        "legend",
        "progress",
        "message",
    ):
        assert server_owned not in G.CLIENT_KEYS
    assert G.CLIENT_KEYS["mesh_upload"] == "upload"


def test_a_table_is_made_from_key_kind_rows_once():
    assert G.key_table([("a", "bool"), ("b", "text")]) == {"a": "bool", "b": "text"}
    with pytest.raises(ValueError, match="'a' is given twice"):
        G.key_table([("a", "bool"), ("a", "text")])
    with pytest.raises(ValueError, match="kind 'colour'"):
        G.key_table([("a", "colour")])


def test_admit_keeps_the_controls_changes_and_drops_the_rest_with_a_line_each():
    xss = "<img src=x onerror='window.__xss=1'>"
    changes = [
        {"key": "kd_step", "value": 40},
        {"key": "trame__template_main", "value": xss},
        {"key": "kd_step", "value": "40"},
        {"key": "show_ambient", "value": 1},
        {"key": "light", "value": -1},
        {"key": "light", "value": True},
        {"key": "kd_step", "value": float("nan")},
        {"key": "preset_name", "value": "x" * (G.MAX_CLIENT_TEXT + 1)},
        {"key": "mesh_upload", "value": "/etc/passwd"},
        {"value": 1},
        "kd_step",
        {"key": "difference", "value": None},
        {"key": "mesh_upload", "value": [{"name": "a.obj", "content": b"v 0 0 0"}]},
        {"key": "turntable_frames", "value": "12"},
        {"key": "turntable_frames", "value": 12},
    ]
    kept, dropped = G.admit(changes)
    assert kept == [changes[0], changes[11], changes[12], changes[13], changes[14]]
    assert len(dropped) == len(changes) - len(kept)
    assert dropped[0] == "'trame__template_main': not a key the page's controls set"
    assert dropped[1] == "'kd_step': must be number, got str"
    assert all(xss not in d and "passwd" not in d for d in dropped)  # the key, never the value


def test_a_long_unknown_key_is_cut_in_the_log_line():
    _, dropped = G.admit([{"key": "k" * 10_000, "value": 1}])
    assert len(dropped[0]) < 200


def test_the_mesh_chooser_names_no_path_and_takes_back_only_its_own_values():
    names = G.MeshValues(("sphere", "teapot"))
    assert names.page("sphere") == "sphere" and names.name("sphere") == "sphere"
    first = names.page("/tmp/phong-explorer-web-x/mesh-1/parts.obj")
    second = names.page("/home/ana/models/parts.obj")
    assert (first, second) == ("file 1: parts.obj", "file 2: parts.obj")
    assert names.page("/tmp/phong-explorer-web-x/mesh-1/parts.obj") == first  # stable
    assert names.name(first) == "/tmp/phong-explorer-web-x/mesh-1/parts.obj"
    assert names.name(second) == "/home/ana/models/parts.obj"
    for other in ("/etc/passwd", "~/.bashrc", "file 3: parts.obj", "parts.obj", None, 1, ["x"]):
        assert names.name(other) is None


def test_the_access_log_never_writes_the_token():
    import logging

    line = '127.0.0.1 "GET /?secret=%s HTTP/1.1" 302'
    record = logging.LogRecord("aiohttp.access", logging.INFO, __file__, 1, line, (TOKEN,), None)
    assert G.Redact(TOKEN).filter(record)
    assert TOKEN not in record.getMessage()
    assert record.getMessage() == '127.0.0.1 "GET /?secret=<token> HTTP/1.1" 302'
    other = logging.LogRecord("aiohttp.access", logging.INFO, __file__, 1, "GET /%s", ("a",), None)
    assert G.Redact(TOKEN).filter(other) and other.getMessage() == "GET /a"
