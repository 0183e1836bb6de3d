"""A headless Chromium for the scripts and tests that look at the page (docs/screenshots.py's
pictures, the web tests, benchmarks/bench_web.py): Debian's ``chromium`` and
``chromium-driver``, driven by Selenium, and the page's viewport made a given size.

Selenium is imported inside the functions (it is a test and docs dependency, not the web
extra's): importing this module imports nothing beyond the standard library. Beside
:func:`explorer.app.start.start_xvfb` (the window's private X server for the same scripts and
tests), not in :mod:`explorer.app.web`: the page's front end keeps its widgets and its
picture transport, and no test tool.
"""

from __future__ import annotations

from pathlib import Path

#: Debian's Chromium and its driver (Selenium's own driver manager would try to download one)
CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
#: the browser's window size when none is given (CSS pixels; its viewport is smaller: the
#: browser's own frame, see :func:`set_viewport`)
WINDOW = (1280, 900)


def new_browser(
    size: tuple[int, int] = WINDOW,
    *,
    downloads: Path | None = None,
    console_log: bool = False,
    prefs: dict | None = None,
):
    """A headless Chromium (a Selenium ``webdriver.Chrome``) whose window is ``size`` (w, h)
    CSS pixels at a device scale of 1; ``downloads``: the folder it saves downloads into
    without asking; ``console_log``: it keeps the page's console log (``get_log("browser")``);
    ``prefs``: more of Chromium's preferences (e.g. cookies blocked). Needs ``selenium`` and
    the two files :data:`CHROMIUM` and :data:`CHROMEDRIVER`."""
    from selenium import webdriver

    opts = webdriver.ChromeOptions()
    for a in (
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        f"--window-size={size[0]},{size[1]}",
        "--disable-dev-shm-usage",
        "--force-device-scale-factor=1",
    ):
        opts.add_argument(a)
    opts.binary_location = CHROMIUM
    if console_log:
        opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    chosen = dict(prefs or {})
    if downloads is not None:
        chosen.update(
            {"download.default_directory": str(downloads), "download.prompt_for_download": False}
        )
    if chosen:
        opts.add_experimental_option("prefs", chosen)
    service = webdriver.ChromeService(executable_path=CHROMEDRIVER)
    return webdriver.Chrome(options=opts, service=service)


def set_viewport(driver, w: int, h: int) -> None:
    """The page's viewport (``window.innerWidth`` x ``innerHeight``) of ``driver`` made ``w``
    x ``h`` CSS pixels: Selenium's window size counts the browser's own frame (143 pixels of
    height in headless Chromium 156), so a 640x480 window shows a 640x337 page. Raises
    RuntimeError when three tries do not reach it."""
    for tries in range(4):  # (the size read again after each of the three)
        inner = driver.execute_script("return [window.innerWidth, window.innerHeight];")
        if inner == [w, h]:
            return
        if tries < 3:
            outer = driver.get_window_size()
            driver.set_window_size(outer["width"] + w - inner[0], outer["height"] + h - inner[1])
    raise RuntimeError(f"the page's viewport is {inner[0]}x{inner[1]}, not {w}x{h}")
