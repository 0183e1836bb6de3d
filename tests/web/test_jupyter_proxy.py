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
import os
import re
import subprocess
import sys
import threading
import time

import pytest
from webserver import SERVER_KERNELS, START_TIMEOUT, free_port, need_browser, new_browser

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


def test_the_page_url_is_direct_or_under_the_proxy():
    assert web.page_url(8123, None) == "http://127.0.0.1:8123/"
    assert web.page_url(8123, "/user/ana/") == "/user/ana/proxy/8123/"
    shown = web.Shown(app=None, url=web.page_url(8123, "/user/a&b/"), height=500)
    assert 'src="/user/a&amp;b/proxy/8123/"' in shown._repr_html_()


# -- through a real proxy, in a real browser --------------------------------------------------
class PrefixProxy:
    """An aiohttp reverse proxy in a thread: ``<hub>proxy/<port>/<rest>`` (HTTP and
    websocket) to ``127.0.0.1:<port>/<rest>``, as jupyter-server-proxy; ``<hub>notebook``
    serves ``html`` (the cell's output). ``sockets`` counts the websockets it carried."""

    def __init__(self, hub: str, html: str):
        self.port = free_port()
        self.hub, self.html, self.sockets, self.paths = hub, html, 0, []
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

        return aw.Response(text=f'<!doctype html><html><head><link rel="icon" href="data:,"></head>'
                                f"<body>{self.html}</body></html>",
                           content_type="text/html")  # fmt: skip

    async def _forward(self, request):
        import aiohttp
        from aiohttp import web as aw

        target = f"127.0.0.1:{request.match_info['port']}/{request.match_info['rest']}"
        query = f"?{request.query_string}" if request.query_string else ""
        self.paths.append(request.path)
        if request.headers.get("Upgrade", "").lower() == "websocket":
            return await self._socket(request, f"ws://{target}{query}")
        hop = {"host", "connection", "upgrade", "transfer-encoding", "content-length",
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
        self.sockets += 1
        async with aiohttp.ClientSession() as s, s.ws_connect(url, max_msg_size=0) as server:

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
            proc.kill()
            proc.wait()
            proc.stdin.close()
            pytest.fail("show() did not display:\n" + log.read_text(errors="replace"))
        time.sleep(0.1)
    yield html.group(1)
    proc.stdin.close()
    try:
        proc.wait(30)  # the kernel's stdin closed: it ends
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


@pytest.mark.web
def test_the_cell_shows_the_explorer_through_a_prefix_proxy(kernel, tmp_path):
    from test_web import KNOWN_CONSOLE_ERRORS, by_name, kd, picture_src, report, type_value, wait

    src = re.search(r'<iframe src="([^"]+)"', kernel).group(1)
    assert re.fullmatch(r"/user/ana/proxy/\d+/", src), src  # JupyterHub: through the proxy
    proxy = PrefixProxy(HUB, kernel)
    driver = new_browser(tmp_path)
    try:
        driver.get(f"http://127.0.0.1:{proxy.port}{HUB}notebook")
        driver.switch_to.frame(driver.find_element("css selector", "iframe"))
        # the iframe's address resolved against the notebook's origin (trame answers with
        # its index.html)
        at = driver.execute_script("return location.href")
        assert at.startswith(f"http://127.0.0.1:{proxy.port}{src}"), at
        first = wait("the first picture through the proxy", lambda: picture_src(driver))
        assert proxy.sockets >= 1  # the page's websocket went through the proxy
        assert f"{src}ws" in proxy.paths
        before = report(driver)
        assert abs(kd(before) - 0.3) > 0.05
        type_value(driver, "kd", "0.3")
        wait("kd 0.3 in the state", lambda: abs(kd(report(driver)) - 0.3) < 1e-9)
        wait("a new picture", lambda: picture_src(driver) not in (None, first))
        assert by_name(driver, "kd").get_attribute("value") == "0.3"
        errors = [e["message"] for e in driver.get_log("browser") if e["level"] == "SEVERE"
                  and not any(k in e["message"] for k in KNOWN_CONSOLE_ERRORS)]  # fmt: skip
        assert not errors, errors
    except BaseException:
        driver.save_screenshot(str(tmp_path / "page.png"))
        print(f"the page: {tmp_path / 'page.png'}; proxied: {proxy.paths[-20:]}")
        raise
    finally:
        driver.quit()
        proxy.stop()
