"""The web tests' server and browser (a module of its own name: ``from conftest import``
would find whichever conftest came first on the path when tests/web runs with other test
folders): a ``phong-explorer web`` process, as a user starts it, and a headless Chromium
(Debian's ``chromium`` and ``chromium-driver``, driven by Selenium)."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

#: how long the server may take to print its URL (the first start compiles nothing: the numpy
#: tier serves while numba's cache is cold)
START_TIMEOUT = 120
CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


#: the engine's tier in the servers these tests start. The suite runs in mode ``compiled``
#: (tests/conftest.py), which compiles a missing kernel in the calling process: in a server that
#: holds the interpreter for tens of seconds on a cold cache and freezes the page (CI's cold run
#: timed out on the difference view). A user's server never compiles in-process (mode ``auto``:
#: the numpy tier serves while the background compile runs, tests/web/test_web_cold.py), so the
#: page tests' servers run the numpy tier: the same colours (the tiers' contract), no compile.
SERVER_KERNELS = "numpy"


class Server:
    """A ``phong-explorer web`` process: its URL, its output, whether it still runs."""

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
        self.url = f"http://{host}:{self.port}/"
        end = time.monotonic() + START_TIMEOUT
        while self.url not in log.read_text(errors="replace"):
            if self.proc.poll() is not None or time.monotonic() > end:
                self.stop()
                pytest.fail(f"the server did not start:\n{log.read_text(errors='replace')}")
            time.sleep(0.1)

    def output(self) -> str:
        return self.log.read_text(errors="replace")

    def stop(self) -> None:
        end_process(self.proc)
        self._out.close()


def end_process(proc: subprocess.Popen, wait: float = 10) -> None:
    """Ask ``proc`` to end (SIGTERM), and kill it if it still runs ``wait`` seconds later."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(wait)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def need_browser() -> None:
    for f in (CHROMIUM, CHROMEDRIVER):
        if not os.path.exists(f):
            pytest.skip(f"{f} is not installed (apt-get install chromium chromium-driver)")
    pytest.importorskip("selenium")
    pytest.importorskip("trame")


def new_browser(downloads: Path):
    """A headless Chromium at 1280x900 that saves downloads into ``downloads`` and keeps the
    page's console log."""
    from selenium import webdriver

    opts = webdriver.ChromeOptions()
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--window-size=1280,900",
              "--disable-dev-shm-usage", "--force-device-scale-factor=1"):  # fmt: skip
        opts.add_argument(a)
    opts.binary_location = CHROMIUM
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    opts.add_experimental_option("prefs", {
        "download.default_directory": str(downloads), "download.prompt_for_download": False,
    })  # fmt: skip
    service = webdriver.ChromeService(executable_path=CHROMEDRIVER)
    return webdriver.Chrome(options=opts, service=service)
