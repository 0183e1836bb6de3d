"""``explorer.app.web.show`` behind a remote Jupyter: the address its cell's ``<iframe>`` names
(direct, or jupyter-server-proxy's ``<base>proxy/<port>/``), and the page working in a real
browser through a real reverse proxy that serves it under a path prefix.

The proxy (:class:`PrefixProxy`, aiohttp, in a thread) does what jupyter-server-proxy does for
a JupyterHub user's server: ``/user/ana/proxy/<port>/<rest>`` (HTTP and websocket) goes to
``127.0.0.1:<port>/<rest>``; it also serves ``/user/ana/notebook``, a page holding the cell's
displayed HTML as Jupyter would, so the iframe's address is resolved as in a notebook. The
"kernel" is a Python process that calls ``show()`` with ``JUPYTERHUB_SERVICE_PREFIX`` set, as
JupyterHub sets it."""

from __future__ import annotations

import asyncio
import importlib.util
import os
import re
import subprocess
import sys
import threading
import time

import pytest
from webserver import (
    SERVER_KERNELS,
    START_TIMEOUT,
    end_process,
    free_port,
    need_browser,
    new_browser,
)

from explorer.app import web
from explorer.core.errors import ExplorerError, ExplorerTypeError

HUB = "/user/ana/"
OWN, JHUB = "PHONG_EXPLORER_JUPYTER_PROXY", "JUPYTERHUB_SERVICE_PREFIX"
KERNEL = """
import sys
from explorer.app import web
app = web.show(mesh="sphere", preset="gold", height=600)
print("HTML " + app._repr_html_(), flush=True)
sys.stdin.read()  # served until the test closes stdin
"""


# -- the address -------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("proxy", "environ", "prefix"),
    [
        (None, {}, None),  # a local Jupyter: direct
        (None, {JHUB: "/user/ana/"}, "/user/ana/"),
        (None, {OWN: "/lab"}, "/lab/"),
        (None, {OWN: "/a/", JHUB: "/b/"}, "/a/"),  # the explorer's variable first
        (None, {OWN: "off", JHUB: "/b/"}, None),
        (False, {JHUB: "/user/ana/"}, None),
        (True, {}, "/"),
        (True, {OWN: "0"}, "/"),
        (True, {JHUB: "/user/ana/"}, "/user/ana/"),
        ("/jupyter", {JHUB: "/user/ana/"}, "/jupyter/"),
        ("https://hub.example.org/user/ana/", {}, "https://hub.example.org/user/ana/"),
    ],
)
def test_the_proxy_prefix_is_chosen_from_the_argument_then_the_environment(proxy, environ,
                                                                          prefix):  # fmt: skip
    assert web.proxy_prefix(proxy, environ) == prefix


@pytest.mark.parametrize("bad", ["user/ana", "//evil.example/", "/a b/", '/a"b/', "ftp://x/",
                                 "/a?b", ""])  # fmt: skip
def test_a_bad_base_url_is_refused_naming_where_it_came_from(bad):
    with pytest.raises(ExplorerError, match=r"^proxy: a Jupyter base URL"):
        web.proxy_prefix(bad, {})
    if bad.strip():
        with pytest.raises(ExplorerError, match=r"^PHONG_EXPLORER_JUPYTER_PROXY: "):
            web.proxy_prefix(None, {OWN: bad})
    with pytest.raises(ExplorerTypeError, match="proxy must be"):
        web.proxy_prefix(8888, {})


@pytest.mark.parametrize("control", ["\r", "\0", "\v", "\x1b", "\x85", "\u2028"])
@pytest.mark.parametrize("form", ["/user/a{}b/", "https://hub.example.org/a{}b/"])
def test_a_base_url_with_a_control_character_is_refused(control, form):
    """A control character inside the base URL went into the cell's ``<iframe src>`` (issue 37
    §3); it is refused from either source, and the message shows it escaped."""
    bad = form.format(control)
    for proxy, environ, where in ((bad, {}, "proxy"), (None, {OWN: bad}, OWN)):
        with pytest.raises(ExplorerError, match=f"^{where}: a Jupyter base URL") as info:
            web.proxy_prefix(proxy, environ)
        assert control not in str(info.value)


def test_the_page_url_is_direct_or_under_the_proxy():
    assert web.page_url(8123, None) == "http://127.0.0.1:8123/"
    assert web.page_url(8123, "/user/ana/") == "/user/ana/proxy/8123/"
    assert web.page_url(8123, None, "T0k-_") == "http://127.0.0.1:8123/?secret=T0k-_"
    assert web.page_url(8123, "/user/ana/", "T0k") == "/user/ana/proxy/8123/?secret=T0k"
    shown = web.Shown(app=None, url=web.page_url(8123, "/user/a&b/", "T0k"), height=500)
    assert 'src="/user/a&amp;b/proxy/8123/?secret=T0k"' in shown._repr_html_()
    # the address is said too: a link under the frame, and what a console prints
    assert 'href="/user/a&amp;b/proxy/8123/?secret=T0k" target="_blank"' in shown._repr_html_()
    assert (
        repr(shown) == "<phong-explorer page at /user/a&b/proxy/8123/?secret=T0k (.stop() ends it)>"
    )


# -- through a real proxy, in a real browser --------------------------------------------------
class PrefixProxy:
    """An aiohttp reverse proxy in a thread: ``<hub>proxy/<port>/<rest>`` (HTTP and
    websocket) to ``127.0.0.1:<port>/<rest>``, as jupyter-server-proxy (which passes the
    browser's headers on, Host and Origin too); :attr:`blank`, a page of the proxy's origin
    (where the test writes the cell's output)."""

    def __init__(self, hub: str, tmp):
        self.port = free_port()
        self.hub = hub
        self.blank = f"http://127.0.0.1:{self.port}{hub}notebook"
        self.loop = asyncio.new_event_loop()
        started = threading.Event()
        self.thread = threading.Thread(target=self._run, args=(started,), daemon=True)
        self.thread.start()
        assert started.wait(30), "the proxy did not start"

    def _run(self, started) -> None:
        from aiohttp import web as aw

        asyncio.set_event_loop(self.loop)
        app = aw.Application()
        app.router.add_get(self.hub + "notebook", self._notebook)
        app.router.add_route("*", self.hub + r"proxy/{port:\d+}/{rest:.*}", self._forward)
        self.runner = aw.AppRunner(app)
        self.loop.run_until_complete(self.runner.setup())
        self.loop.run_until_complete(aw.TCPSite(self.runner, "127.0.0.1", self.port).start())
        started.set()
        self.loop.run_forever()

    async def _notebook(self, request):
        from aiohttp import web as aw

        return aw.Response(text="<!doctype html><html><body></body></html>",
                           content_type="text/html")  # fmt: skip

    async def _forward(self, request):
        import aiohttp
        from aiohttp import web as aw

        target = f"127.0.0.1:{request.match_info['port']}/{request.match_info['rest']}"
        query = f"?{request.query_string}" if request.query_string else ""
        if request.headers.get("Upgrade", "").lower() == "websocket":
            return await self._socket(request, f"ws://{target}{query}")
        hop = {"connection", "upgrade", "transfer-encoding", "content-length",
               "content-encoding", "keep-alive"}  # fmt: skip
        headers = {k: v for k, v in request.headers.items() if k.lower() not in hop}
        async with aiohttp.ClientSession(auto_decompress=True) as s, s.request(
            request.method, f"http://{target}{query}", headers=headers,
            data=await request.read(), allow_redirects=False,
        ) as r:  # fmt: skip
            body = await r.read()
            back = {k: v for k, v in r.headers.items() if k.lower() not in hop}
            return aw.Response(status=r.status, body=body, headers=back)

    async def _socket(self, request, url: str):
        import aiohttp
        from aiohttp import web as aw

        page = aw.WebSocketResponse(max_msg_size=0)
        await page.prepare(request)
        passed = {k: v for k, v in request.headers.items() if k.lower() in ("host", "origin")}
        async with (
            aiohttp.ClientSession() as s,
            s.ws_connect(url, max_msg_size=0, headers=passed) as server,
        ):

            async def pump(src, dst):
                async for msg in src:
                    if msg.type == aiohttp.WSMsgType.TEXT:
                        await dst.send_str(msg.data)
                    elif msg.type == aiohttp.WSMsgType.BINARY:
                        await dst.send_bytes(msg.data)
                    else:
                        break
                await dst.close()

            await asyncio.gather(pump(page, server), pump(server, page))
        return page

    def stop(self) -> None:
        asyncio.run_coroutine_threadsafe(self.runner.cleanup(), self.loop).result(30)
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(30)
        self.loop.close()


class JupyterProxy:
    """``jupyter server`` under base URL ``hub`` with jupyter-server-proxy (as a JupyterHub
    user's server; no token: the browser would hold the hub's login cookie), its files and
    settings in ``tmp``; :attr:`blank`, an empty page of its origin (a page of Jupyter's own
    forbids frames: an HTTP server of the test's, through the proxy)."""

    def __init__(self, hub: str, tmp):
        from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

        class Blank(BaseHTTPRequestHandler):
            def do_GET(self):
                body = b"<!doctype html><html><body></body></html>"
                self.send_response(200)
                self.send_header("Content-Type", "text/html")
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body)

            def log_message(self, *args):
                pass

        self.page = ThreadingHTTPServer(("127.0.0.1", 0), Blank)
        threading.Thread(target=self.page.serve_forever, daemon=True).start()
        self.port = free_port()
        self.blank = f"http://127.0.0.1:{self.port}{hub}proxy/{self.page.server_port}/"
        env = dict(os.environ, **{f"JUPYTER_{k}_DIR": str(tmp / k.lower())
                                  for k in ("RUNTIME", "CONFIG", "DATA")})  # fmt: skip
        self.log = tmp / "jupyter.log"
        with open(self.log, "w") as out:
            self.proc = subprocess.Popen([
                sys.executable, "-m", "jupyter_server", "--no-browser", "--allow-root",
                f"--ServerApp.port={self.port}", "--ServerApp.port_retries=0",
                "--ServerApp.ip=127.0.0.1", f"--ServerApp.base_url={hub}",
                "--IdentityProvider.token=", f"--ServerApp.root_dir={tmp}",
                '--ServerApp.jpserver_extensions={"jupyter_server_proxy": True}',
            ], stdout=out, stderr=subprocess.STDOUT, env=env)  # fmt: skip
        end = time.monotonic() + START_TIMEOUT
        while not self._up():
            if self.proc.poll() is not None or time.monotonic() > end:
                self.stop()
                pytest.fail("jupyter server did not start:\n" + self.log.read_text())
            time.sleep(0.1)

    def _up(self) -> bool:
        import urllib.request

        try:
            with urllib.request.urlopen(self.blank, timeout=5) as r:
                return r.status == 200
        except OSError:
            return False

    def stop(self) -> None:
        self.page.shutdown()
        self.page.server_close()
        end_process(self.proc, 30)


def jupyter_proxy(hub: str, tmp) -> JupyterProxy:
    if importlib.util.find_spec("jupyter_server_proxy") is None:
        pytest.skip("jupyter-server-proxy is not installed (the test extra)")
    return JupyterProxy(hub, tmp)


#: the page's websockets, recorded in every document of the tab (the cell's iframe too)
RECORD_SOCKETS = """
const Native = window.WebSocket;
window.__sockets = [];
window.WebSocket = function (url, ...rest) {
  window.__sockets.push(String(url));
  return new Native(url, ...rest);
};
window.WebSocket.prototype = Native.prototype;
Object.assign(window.WebSocket, {CONNECTING: 0, OPEN: 1, CLOSING: 2, CLOSED: 3});
"""


@pytest.fixture(scope="module")
def kernel(tmp_path_factory):
    """A "kernel" under JupyterHub: ``show()`` called with ``JUPYTERHUB_SERVICE_PREFIX``
    set; yields the cell's displayed HTML."""
    need_browser()
    tmp = tmp_path_factory.mktemp("jupyter")
    env = dict(os.environ, JUPYTERHUB_SERVICE_PREFIX=HUB, PHONG_EXPLORER_KERNELS=SERVER_KERNELS,
               PHONG_EXPLORER_MATERIALS=str(tmp / "presets"))  # fmt: skip
    env.pop(OWN, None)
    log = tmp / "kernel.log"
    with open(log, "w") as out:
        proc = subprocess.Popen([sys.executable, "-c", KERNEL], stdin=subprocess.PIPE,
                                stdout=out, stderr=subprocess.STDOUT, env=env)  # fmt: skip
    end = time.monotonic() + START_TIMEOUT
    while not (html := re.search(r"^HTML (.*)$", log.read_text(errors="replace"), re.M)):
        if proc.poll() is not None or time.monotonic() > end:
            end_process(proc)
            proc.stdin.close()
            pytest.fail("show() did not display:\n" + log.read_text(errors="replace"))
        time.sleep(0.1)
    yield html.group(1)
    proc.stdin.close()
    end_process(proc, 30)


@pytest.mark.web
@pytest.mark.parametrize("make_proxy", [jupyter_proxy, PrefixProxy],
                         ids=["jupyter-server-proxy", "aiohttp"])  # fmt: skip
def test_the_cell_shows_the_explorer_through_a_prefix_proxy(kernel, make_proxy, tmp_path):
    """The cell's HTML written into a page of the proxy's origin (as Jupyter shows a cell's
    output): its iframe loads the explorer through the proxy, every resource and the websocket
    under ``/user/ana/proxy/<port>/``; the picture comes, and kd typed in the page changes
    the state and the picture."""
    from test_web import KNOWN_CONSOLE_ERRORS, by_name, kd, picture_src, report, type_value, wait

    src = re.search(r'<iframe src="([^"]+)"', kernel).group(1)
    # JupyterHub: through the proxy, with the page's token
    assert re.fullmatch(r"/user/ana/proxy/\d+/\?secret=[A-Za-z0-9_-]+", src), src
    src = src.split("?")[0]
    proxy = make_proxy(HUB, tmp_path)
    driver = new_browser(tmp_path)
    try:
        driver.execute_cdp_cmd("Page.addScriptToEvaluateOnNewDocument", {"source": RECORD_SOCKETS})
        driver.get(proxy.blank)
        driver.execute_script("document.open(); document.write(arguments[0]); document.close()",
                              f"<!doctype html><html><body>{kernel}</body></html>")  # fmt: skip
        driver.switch_to.frame(driver.find_element("css selector", "iframe"))
        page = f"http://127.0.0.1:{proxy.port}{src}"
        # the iframe's address resolved against the notebook's origin (trame answers / with
        # its index.html)
        wait("the iframe's page", lambda: driver.execute_script("return location.href")
             .startswith(page))  # fmt: skip
        first = wait("the first picture through the proxy", lambda: picture_src(driver))
        sockets = driver.execute_script("return window.__sockets")
        assert sockets == [f"ws://127.0.0.1:{proxy.port}{src}ws"], sockets
        loaded = driver.execute_script(
            "return performance.getEntriesByType('resource').map(e => e.name)"
        )
        assert loaded and all(u.startswith(page) for u in loaded), loaded
        now = kd(report(driver))  # the kernel serves each proxy in turn: a value it has not
        target = max(("0.3", "0.6"), key=lambda v: abs(float(v) - now))
        type_value(driver, "kd", target)
        wait(f"kd {target} in the state", lambda: abs(kd(report(driver)) - float(target)) < 1e-9)
        wait("a new picture", lambda: picture_src(driver) not in (None, first))
        assert by_name(driver, "kd").get_attribute("value") == f"{float(target):.3f}"
        known = (*KNOWN_CONSOLE_ERRORS, f"{proxy.port}/favicon.ico")  # the notebook's icon
        errors = [e["message"] for e in driver.get_log("browser") if e["level"] == "SEVERE"
                  and not any(k in e["message"] for k in known)]  # fmt: skip
        assert not errors, errors
    except BaseException:
        driver.save_screenshot(str(tmp_path / "page.png"))
        print(f"the page: {tmp_path / 'page.png'}")
        raise
    finally:
        driver.quit()
        proxy.stop()
