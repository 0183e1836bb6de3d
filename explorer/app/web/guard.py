"""Who may use the web explorer, and what a page may set: the admission rules of
:mod:`explorer.app.web` as plain functions and one table, and the thin hooks that put them
into trame, wslink and aiohttp (:func:`install`; aiohttp is imported inside them only).

As Jupyter does it:

- **A token per server.** :func:`new_token` makes a random one when the server is made; the
  URL the user is given carries it (``?secret=TOKEN``: trame's page reads its websocket secret
  from that query parameter, sends it in wslink's ``wslink.hello`` and takes it out of the
  address bar). A websocket that does not say it gets no session; the page itself without it
  (or the cookie below) is refused (:data:`NO_TOKEN`). A page opened with the token sets a
  cookie (:func:`cookie_name`: HttpOnly, SameSite=Strict, this server's port in its name) so
  that reloading the tab, whose address bar no longer shows the token, gets the token back
  through a redirect (:func:`page_verdict`).
- **The Origin of a websocket** must be the page's own: its host and port are the request's
  ``Host`` (:func:`origin_ok`). A page of another site, or of another port of 127.0.0.1, is
  refused before any message (the cross-site websocket hijack).
- **The Host of every request** must name this server (:func:`host_ok`): one of the names of
  the addresses it listens on, or an IP address (a DNS rebinding attack needs a name). Behind
  jupyter-server-proxy the Host is the Jupyter server's (the proxy passes the browser's): the
  check is the proxy's then (``hosts=None``); the token and the Origin still hold.
- **A client sets only the keys the page's controls own**, each with its type
  (:data:`CLIENT_KEYS`, made by :func:`key_table` from a list of ``(key, kind)`` rows;
  :func:`admit` sorts a client's changes): a server-owned key (``trame__template_main``, the
  page's Vue template; the message log; the preset list) or a value of the wrong type is
  dropped before it reaches the state or any other tab, and logged.
- **The page names no server path**: the mesh chooser's values are :class:`MeshValues`, and
  the page's ``mesh`` is taken back only as one of them.
- **The direct picture socket** (raw frames to the page's worker, :mod:`explorer.app.web.direct`)
  is for a page of this machine only: a loopback connection with the page's cookie, not behind
  a proxy (:func:`direct_refusal`), besides the Host and Origin every websocket is checked for.
"""

from __future__ import annotations

import hmac
import ipaddress
import logging
import math
import secrets
import socket
from collections.abc import Iterable, Mapping
from pathlib import PurePath
from urllib.parse import urlsplit

from explorer.app import panelmodel

log = logging.getLogger(__name__)

#: the query parameter of the page's URL that carries the token (trame-client reads the
#: websocket's secret from it and removes it from the address bar)
TOKEN_PARAM = "secret"
#: the token's random bytes (256 bits, as Jupyter's 24 bytes rounded up)
TOKEN_BYTES = 32
#: the paths that serve the page (trame redirects ``/`` to ``index.html``)
PAGE_PATHS = ("/", "/index.html")
#: the websocket's path (wslink's ``--ws`` default, trame's page opens ``<page folder>/ws``)
WS_PATH = "/ws"
#: the names of this machine's loopback addresses a Host may give
LOOPBACK_NAMES = ("localhost",)
#: the addresses that listen on every address of the machine (``--host 0.0.0.0``)
WILDCARDS = ("0.0.0.0", "::", "")
#: the longest text a client may set in a state key (characters): a preset name, a choice
MAX_CLIENT_TEXT = 4096
#: the refusal of a page asked for without the token (one line, no path, no token)
NO_TOKEN = (
    "phong-explorer: this page needs its token: open the address the server printed "
    "(http://HOST:PORT/?secret=...)"
)
#: the refusal of a request whose Host names another site
BAD_HOST = "phong-explorer: this server does not answer to that host name"
#: the refusal of a websocket opened by a page of another origin
BAD_ORIGIN = "phong-explorer: a websocket from another origin is refused"


def new_token() -> str:
    """A fresh random token (URL-safe text)."""
    return secrets.token_urlsafe(TOKEN_BYTES)


def token_ok(given, token: str) -> bool:
    """Whether ``given`` is ``token`` (compared in constant time; anything not text is not)."""
    return isinstance(given, str) and hmac.compare_digest(given.encode(), token.encode())


def cookie_name(port: int) -> str:
    """The name of the cookie that keeps the token of the server on ``port`` (a browser
    sends 127.0.0.1's cookies to every port: the name keeps two servers apart)."""
    return f"phong-explorer-{int(port)}"


def page_url(base: str, token: str) -> str:
    """``base`` (the page's address, ending with ``/``) with the token."""
    return f"{base}?{TOKEN_PARAM}={token}"


def split_host(host: str | None) -> tuple[str, int | None] | None:
    """``(name, port)`` of a Host header or an origin's netloc (the name lower-case, without
    an IPv6 address's brackets; port None when absent), or None when it is not one."""
    if not host or any(c.isspace() or c in "/@?#\\" for c in host):
        return None
    try:
        parts = urlsplit(f"//{host}")
        port = parts.port
    except ValueError:
        return None
    name = parts.hostname
    return (name, port) if name else None


def _is_ip(name: str) -> bool:
    try:
        ipaddress.ip_address(name)
    except ValueError:
        return False
    return True


def listening_names(host: str, machine: str | None = None) -> frozenset[str]:
    """The host names a request to a server listening on ``host`` may give: the loopback
    names, ``host`` itself when it is a name (an IP address is allowed anyway), and for a
    wildcard address (:data:`WILDCARDS`: every address of the machine) the machine's name
    (``machine``; default :func:`socket.gethostname`)."""
    name = host.strip("[]").lower()
    names = {*LOOPBACK_NAMES, *(() if _is_ip(name) or not name else (name,))}
    if name in WILDCARDS:
        names.add((machine if machine is not None else socket.gethostname()).lower())
    return frozenset(n for n in names if n)


def host_ok(host: str | None, names: Iterable[str] | None, port: int) -> bool:
    """Whether Host header ``host`` names this server (on ``port``): an IP address or one of
    ``names`` (:func:`listening_names`), with this port (or none: a browser leaves out 80).
    ``names`` None: any host (behind a proxy that checks it)."""
    if names is None:
        return True
    parsed = split_host(host)
    if parsed is None:
        return False
    name, given = parsed
    if given is not None and given != port:
        return False
    return _is_ip(name) or name in {n.lower() for n in names}


def origin_ok(origin: str | None, host: str | None) -> bool:
    """Whether websocket ``origin`` (the ``Origin`` header a browser sends) is the page's
    own, the one the request's ``host`` names (http or https, the same host and port). No
    Origin is refused too: a browser always sends one, and the page is a browser's."""
    if not origin or not host:
        return False
    try:
        parts = urlsplit(origin)
    except ValueError:
        return False
    if parts.scheme not in ("http", "https") or parts.path or parts.query:
        return False
    mine, theirs = split_host(host), split_host(parts.netloc)
    if mine is None or theirs is None:
        return False
    default = 443 if parts.scheme == "https" else 80
    return mine[0] == theirs[0] and (mine[1] or default) == (theirs[1] or default)


def page_verdict(path: str, query_token, cookie_token, token: str) -> str:
    """What a GET of ``path`` gets: ``"serve"`` (an asset, or the page with the token in its
    query), ``"redirect"`` (the page without it but with the cookie: sent again to its
    address with the token), or ``"refuse"`` (:data:`NO_TOKEN`)."""
    if path not in PAGE_PATHS or token_ok(query_token, token):
        return "serve"
    return "redirect" if token_ok(cookie_token, token) else "refuse"


def loopback(peer: str | None) -> bool:
    """Whether address ``peer`` (a connection's remote address) is this machine's loopback
    (127.0.0.0/8, ::1, or an IPv4 loopback written as IPv6)."""
    try:
        ip = ipaddress.ip_address((peer or "").split("%")[0])
    except ValueError:
        return False
    mapped = getattr(ip, "ipv4_mapped", None)
    return ip.is_loopback or (mapped is not None and mapped.is_loopback)


def direct_refusal(peer: str | None, names, cookie_token, token: str) -> str | None:
    """Why a request for the direct picture socket (:mod:`explorer.app.web.direct`: raw
    frames, about 1.4 MiB each) is refused, or None when it is not: the server behind a proxy
    (``names`` None: :func:`host_ok`; the browser may be anywhere), a connection that does not
    come from this machine (``peer``: :func:`loopback`), no token in the page's cookie. The
    Host and the Origin were checked by the middleware, as for every websocket."""
    if names is None:
        return "the server is behind a proxy"
    if not loopback(peer):
        return f"{peer or 'an unknown address'} is not this machine"
    if not token_ok(cookie_token, token):
        return "no token"
    return None


# -- what a client may set --------------------------------------------------------------------
def _number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _text(v) -> bool:
    return isinstance(v, str) and len(v) <= MAX_CLIENT_TEXT


def _upload(v) -> bool:
    """A trame file upload: a mapping (name, size, type, content...) or a list of them."""
    items = v if isinstance(v, list) else [v]
    return all(isinstance(i, dict) and all(isinstance(k, str) for k in i) for i in items)


#: the kinds of value a client may give: kind -> its test (every kind takes None too: a
#: control the state does not show has no value)
KINDS = {
    "number": _number,
    "index": lambda v: isinstance(v, int) and not isinstance(v, bool) and v >= 0,
    "bool": lambda v: isinstance(v, bool),
    "text": _text,
    "text or number": lambda v: _text(v) or _number(v),
    "upload": _upload,
}


def key_table(rows: Iterable[tuple[str, str]]) -> dict[str, str]:
    """The client keys' table from ``(key, kind)`` rows (a kind of :data:`KINDS`); a key
    given twice or an unknown kind is a programming error (``ValueError``)."""
    table: dict[str, str] = {}
    for key, kind in rows:
        if kind not in KINDS:
            raise ValueError(f"client key {key!r}: kind {kind!r} is not one of {list(KINDS)}")
        if key in table:
            raise ValueError(f"client key {key!r} is given twice")
        table[key] = kind
    return table


#: every state key the page's controls set (their ``v_model``), with its kind: the panel
#: model's rows (:func:`explorer.app.panelmodel.client_keys`: the sliders' steps, the choices,
#: toggles and lists), then the page's own selects, switches and text fields that are state, the
#: uploads, the tab and the drawer. The number fields, colour fields and pickers, buttons and
#: downloads are not state: they call the server's handlers, which parse what they are given.
#: tests/app/web/test_web_security.py checks it against the page's template (every ``v-model``).
CLIENT_KEYS: Mapping[str, str] = key_table(
    [
        *panelmodel.client_keys().items(),
        ("mesh", "text"),
        ("turntable_frames", "text or number"),
        ("turntable_format", "text"),
        ("preset_name", "text"),
        ("preset_replace", "bool"),
        ("session_upload", "upload"),
        ("mesh_upload", "upload"),
        ("mtl_upload", "upload"),
        ("tab", "text"),
        ("main_drawer", "bool"),  # the layout's drawer (its toolbar button)
    ]
)


def admit(changes, table: Mapping[str, str] = CLIENT_KEYS) -> tuple[list, list[str]]:
    """A client's state changes (trame's ``[{"key": k, "value": v}, ...]``) sorted:
    ``(kept, dropped)``, the changes of ``table``'s keys whose values have their kind, and a
    line for each one dropped (naming the key and what is allowed, never the value)."""
    kept, dropped = [], []
    for change in changes if isinstance(changes, list) else [changes]:
        key = change.get("key") if isinstance(change, dict) else None
        if not isinstance(key, str):
            dropped.append("a change without a key")
            continue
        kind = table.get(key)
        if kind is None:
            dropped.append(f"{key[:80]!r}: not a key the page's controls set")
            continue
        value = change.get("value")
        if value is not None and not KINDS[kind](value):
            dropped.append(f"{key!r}: must be {kind}, got {type(value).__name__}")
            continue
        kept.append(change)
    return kept, dropped


class MeshValues:
    """The mesh chooser's values on the page, which never name a server path: a built-in
    mesh's own name, a file's ``file N: NAME`` (its order of arrival and its file name); and
    back: :meth:`name` gives the chooser name only for a value the page was given."""

    def __init__(self, builtins: Iterable[str]):
        self._builtins = frozenset(builtins)
        self._page: dict[str, str] = {}  # chooser name -> page value
        self._names: dict[str, str] = {}  # page value -> chooser name

    def page(self, name: str) -> str:
        """The page's value of chooser name ``name`` (a built-in name, or a file's path)."""
        if name in self._builtins:
            return name
        if name not in self._page:
            value = f"file {len(self._page) + 1}: {PurePath(name).name}"
            self._page[name], self._names[value] = value, name
        return self._page[name]

    def name(self, value) -> str | None:
        """The chooser name of page value ``value``; None when the page was never given it
        (a path sent over the socket, anything else)."""
        if isinstance(value, str) and value in self._builtins:
            return value
        return self._names.get(value) if isinstance(value, str) else None


class Redact(logging.Filter):
    """Takes ``token`` out of every record of the logger it filters (aiohttp's access log
    writes each request line, the page's address with its token among them, when a program
    turns its INFO level on)."""

    def __init__(self, token: str):
        super().__init__()
        self.token = token

    def filter(self, record: logging.LogRecord) -> bool:
        text = record.getMessage()
        if self.token in text:
            record.msg, record.args = text.replace(self.token, "<token>"), ()
        return True


# -- the hooks into trame, wslink and aiohttp -------------------------------------------------
def install(server, token: str, hosts) -> None:
    """The rules above on trame ``server`` (before it starts): wslink's secret is ``token``;
    an aiohttp middleware checks each request's Host (``hosts()``: the names it may give,
    None for any, :func:`host_ok`), a websocket's Origin and the page's token
    (:func:`page_verdict`); a client's ``trame.state.update`` goes through :func:`admit`."""
    server.cli.set_defaults(authKey=token)  # wslink's secret (trame's --authKey)
    logging.getLogger("aiohttp.access").addFilter(Redact(token))

    def bind(web_server) -> None:
        web_server.app.middlewares.append(_middleware(token, hosts))
        handlers = getattr(web_server, "_ws_handlers", [])
        for handler in handlers:
            _filter_updates(handler)
        if not handlers:  # never serve a page unguarded: trame or wslink changed
            raise RuntimeError("phong-explorer: wslink's websocket handler was not found")

    server.controller.on_server_bind.add(bind)


def _refuse(text: str, request, why: str):
    from aiohttp import web

    log.warning("refused %s %r: %s", request.method, request.path, why)  # %r: a path's \n too
    return web.Response(status=403, text=text + "\n")


def served_port(request) -> int:
    """The port aiohttp ``request`` came in on (0 when its transport is gone)."""
    sock = request.transport.get_extra_info("sockname") if request.transport else None
    return int(sock[1]) if sock else 0


def _middleware(token: str, hosts):
    from aiohttp import web

    @web.middleware
    async def admission(request, handler):
        port = served_port(request)
        host = request.headers.get("Host")
        if not host_ok(host, hosts(), port):
            return _refuse(BAD_HOST, request, f"Host {host!r} is not this server's")
        ws = request.headers.get("Upgrade", "").lower() == "websocket"
        if ws or request.path == WS_PATH:
            origin = request.headers.get("Origin")
            if not origin_ok(origin, host):
                return _refuse(BAD_ORIGIN, request, f"Origin {origin!r} is not the page's")
            return await handler(request)
        verdict = page_verdict(
            request.path,
            request.query.get(TOKEN_PARAM),
            request.cookies.get(cookie_name(port)),
            token,
        )
        if verdict == "refuse":
            return _refuse(NO_TOKEN, request, "no token")
        if verdict == "redirect":
            raise web.HTTPFound(f"index.html?{TOKEN_PARAM}={token}")
        response = await handler(request)
        if request.path in PAGE_PATHS:  # the page with its token: reloading it keeps it
            response.set_cookie(cookie_name(port), token, httponly=True, samesite="Strict")
        return response

    return admission


def _filter_updates(handler) -> None:
    """wslink ``handler``'s ``trame.state.update`` (a client's state changes) through
    :func:`admit`: what it drops is logged and reaches neither the state nor another tab."""
    name = "trame.state.update"
    if name not in handler.functionMap:
        raise RuntimeError(f"phong-explorer: trame's {name} was not found")
    obj, update = handler.functionMap[name]

    def admitted(protocol, changes):
        kept, dropped = admit(changes)
        for why in dropped:
            log.warning("a page's change was dropped: %s", why)
        return update(protocol, kept) if kept else None

    handler.functionMap[name] = (obj, admitted)
