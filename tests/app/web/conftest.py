"""The web explorer's fixtures: one ``phong-explorer web`` server per test module (a real
process, as a user starts it) and one headless Chromium (Debian's ``chromium`` and
``chromium-driver``, driven by Selenium) that downloads into a temporary folder."""

from __future__ import annotations

import os
import shutil

import pytest
from webserver import Server, need_browser, new_browser


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    """``phong-explorer web --mesh sphere`` with presets saved into a temporary folder."""
    need_browser()
    tmp = tmp_path_factory.mktemp("web")
    env = dict(os.environ, PHONG_EXPLORER_MATERIALS=str(tmp / "presets"))
    srv = Server(["--mesh", "sphere"], tmp / "server.log", env=env)
    yield srv
    srv.stop()


@pytest.fixture(scope="module")
def downloads(tmp_path_factory):
    return tmp_path_factory.mktemp("downloads")


@pytest.fixture(scope="module")
def browser(server, downloads):
    """A Chromium of the module's own. One Chromium for the whole session, each module in a
    fresh tab (other tabs closed, cookies and the origin's storage cleared, the window and the
    downloads folder set again), was measured and left: ``python benchmarks/cpu_tree.py
    /usr/bin/time -v python -m pytest -n 0 tests/app/web -q -p no:randomly``, alternated,
    load 2-6, gave 311.6 and 309.7 s of CPU before, 289.9 and 307.3 s after (``time``'s own
    figure, blind to Chromium's processes: 156.4, 158.5 against 150.9, 157.8 s); about 1 s a
    module (12 s over the 12 modules that would share it), under the 15 s that would pay for
    it. A test that opens a tab and closes the others (test_web's two tabs) closed the
    session's browser with them, and one of the two runs with shared tabs failed two page
    loads of test_web_parity (a Vue error as the page loaded; none in the three runs
    without)."""
    need_browser()
    driver = new_browser(downloads)
    yield driver
    driver.quit()
    shutil.rmtree(downloads, ignore_errors=True)


@pytest.hookimpl(wrapper=True, tryfirst=True)
def pytest_runtest_makereport(item, call):
    rep = yield
    if rep.when == "call":
        item.web_call_failed = rep.failed
    return rep


@pytest.fixture(autouse=True)
def evidence_of_a_failure(request, tmp_path):
    """A failed page test leaves the page's screenshot and the server's output beside the
    test's temporary folder, and names them in the report: what the page showed when a wait
    ran out is the first thing to look at."""
    yield
    if not getattr(request.node, "web_call_failed", False):
        return
    shot = tmp_path / "page.png"
    for name in ("browser", "server"):
        if name not in request.fixturenames:
            continue
        thing = request.getfixturevalue(name)
        if name == "browser":
            try:
                thing.save_screenshot(str(shot))
                print(f"the page at the failure: {shot}")
            except Exception as exc:  # noqa: BLE001 - the browser may be what failed
                print(f"no screenshot: {exc}")
        else:
            print("the server's output (last 40 lines):")
            print("\n".join(thing.output().splitlines()[-40:]))
