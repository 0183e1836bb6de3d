"""The docs' pictures of the explorer window (docs/gui*.png), taken from the real window on a
private Xvfb server: the window at (0, 0) on an empty screen, grabbed from the screen (so an
open menu is in the picture too).

    python docs/screenshots.py                 # every picture, into docs/
    python docs/screenshots.py --only gui_compare --out-dir /tmp/shots
    python docs/screenshots.py --web-tour --out-dir /tmp/tour   # the page, 3 sizes x 3 tabs

Needs Xvfb and ImageMagick's ``import`` (the packages the window tests need). The user's
presets, recent files and last session are not read or written (a temporary folder stands in
for them). Look at every picture before committing it.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
#: the window's size in the pictures (the default pictures)
SIZE = (1100, 720)
#: the longest wait (seconds) for the compiled engine or the difference view
WAIT_S = 300.0


def settle(app, seconds: float = 0.4) -> None:
    """Let Qt lay out and draw for ``seconds``."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        app.processEvents()
        time.sleep(0.02)


def wait_for(app, what: str, ready) -> None:
    end = time.monotonic() + WAIT_S
    while not ready():
        if time.monotonic() > end:
            raise SystemExit(f"screenshots: gave up waiting for {what}")
        settle(app, 0.1)


def open_window(app, tmp: Path, argv=(), size=SIZE):
    """The window of ``phong-explorer gui ARGV`` at ``size``, at the screen's top left, drawn
    on the compiled engine."""
    from explorer.app.qt.window import ExplorerWindow
    from explorer.cli import build_parser
    from explorer.cli.gui import start_state

    warnings: list[str] = []  # as `gui` starts: the start mesh's warnings in the message log
    state, mesh = start_state(build_parser().parse_args(["gui", *argv]), warnings)
    w = ExplorerWindow(state, mesh, output_dir=tmp, last_session=tmp / "last.yaml", size=size,
                       start_warnings=tuple(warnings))  # fmt: skip
    w.move(0, 0)
    w.show()
    settle(app)
    wait_for(app, "the compiled engine", lambda: w.engine_label.text() == "")
    w.render()
    settle(app)
    return w


def grab(display: str, path: Path, size, crop=None) -> None:
    """The screen's top-left ``size`` (or ``crop`` = (w, h, x, y)) as a PNG."""
    w, h, x, y = crop or (*size, 0, 0)
    subprocess.run(["import", "-display", display, "-window", "root", "-crop",
                    f"{w}x{h}+{x}+{y}", "+repage", str(path)], check=True)  # fmt: skip


def shoot(name: str, app, display: str, tmp: Path, out: Path) -> None:
    """Set up the window for picture ``name`` and grab it into ``out/name.png``."""
    from PySide6.QtWidgets import QWidget

    from explorer.app import intents
    from explorer.app import model as M

    size, argv, crop = SIZE, (), None
    if name == "gui_800x500":
        size = (800, 500)
    elif name == "gui_640x480":
        size = (640, 480)
    elif name == "gui_translucent":
        argv = ("--preset", "jade")
    elif name == "gui_per_pixel":  # the 24-vertex cube lit near its front face
        light = ("--light-type", "point", "--light-position", "0.2", "0.3", "1.6")
        eye = ("--viewer-eye", "2.5", "2", "5")
        argv = ("--mesh", "cube", "--preset", "glossy_plastic", *light, *eye, "--per-pixel")
    elif name == "gui_gouraud_vs_per_pixel":
        argv = ("--mesh", "icosphere", "--resolution", "2", "--preset", "polished_silver")
    elif name == "gui_strip":  # the compare view's two strips, each under its side's caption
        argv = ("--mesh", "teapot", "--preset", "gold")
    elif name == "gui_strip_per_pixel":
        argv = ("--mesh", "torus", "--preset", "glossy_plastic", "--per-pixel")
    elif name == "gui_lobes":
        argv = ("--mesh", "sphere", "--preset", "chrome")
    elif name == "maps_window":  # the map rows (docs/gui.md): the textured teapot at 1000x700
        size, argv = (1000, 700), ("--mesh", str(HERE / "examples" / "textured_teapot.obj"))
    w = open_window(app, tmp, argv, size)
    c = w.controller
    if name == "gui_640x480":
        w.panel.setCurrentIndex(1)  # the lights tab
    elif name in ("gui_lobe_phong", "gui_lobe_blinn"):
        c.act(M.set_model, name.rsplit("_", 1)[1])
        x, y, vw, vh = w.widget_box(w.plotter)
        crop = (540, 428, x, y + vh - 428)  # the view's lower left: the mesh and the lobe plot
    elif name == "gui_compare":
        w.panel.setCurrentIndex(2)
        w.panel.view.compare.click()
        c.act(M.set_compare_model, "phong")
        c.act(M.place_light, 12.0, 30.0)  # the handle in both narrow panes
    elif name in ("gui_per_pixel", "gui_gouraud_vs_per_pixel"):
        w.panel.setCurrentIndex(2)  # the view tab: the shading row
        if name == "gui_gouraud_vs_per_pixel":
            intents.run("gouraud_vs_per_pixel", c, {})
            wait_for(app, "the line", lambda: w.viewport.side_b.figures is not None)
    elif name in ("gui_strip", "gui_strip_per_pixel"):
        w.panel.setCurrentIndex(2)  # the view tab: the strip's rows
        c.set_value("strip", True)
        if name == "gui_strip":
            c.set_value("compare", True, merge=False)
            c.act(M.set_compare_model, "phong")
            c.act(M.place_light, 12.0, 30.0)
    elif name == "gui_lobes":
        w.panel.setCurrentIndex(2)  # the view tab: the inset's rows
        c.set_value("lobes", "models")
    elif name == "maps_window":  # emission map turned off, the material tab at the map rows
        c.set_value("emission_map", str(HERE / "examples" / "tiles.png"), merge=False)
        c.set_value("emission_map", False, merge=False)
        w.panel.setCurrentIndex(0)
        w.panel.areas[0].ensureWidgetVisible(w.panel.material.findChild(QWidget, "bump_map"))
    elif name == "gui_difference":
        w.panel.setCurrentIndex(2)
        c.toggle_difference()
        wait_for(app, "the difference view", lambda: w.heat.shown)
    elif name == "gui_file_menu":
        w.close()
        w = open_window(app, tmp, ("--mesh", str(HERE / "examples" / "teapot_parts.obj")))
        w.controller.files.keep_recent(["/home/user/models/teapot_parts.obj",
                                        "/home/user/sessions/glazes.yaml"])  # fmt: skip
        file_menu = w.menuBar().actions()[0]
        w.menuBar().setActiveAction(file_menu)
        settle(app)
        menu = file_menu.menu()
        menu.setActiveAction(w.recent_menu.menuAction())
        settle(app, 1.0)  # the submenu opens on its own after a hover delay
        if not w.recent_menu.isVisible():
            item = menu.actionGeometry(w.recent_menu.menuAction())
            w.recent_menu.popup(menu.mapToGlobal(item.topRight()))
    w.render()
    settle(app, 0.8)
    grab(display, out / f"{name}.png", size, crop)
    w.close()
    settle(app)


#: the page's pictures (docs/web*.png this script takes): ``phong-explorer web`` on a session,
#: in headless Chromium (Debian's chromium and chromium-driver, driven by Selenium)
WEB_NAMES = ("web_strip",)
#: the browser's window in the page's pictures
WEB_SIZE = (1280, 760)


def _web_server(tmp: Path, name: str, *args: str) -> tuple[subprocess.Popen, str]:
    """``phong-explorer web --port 0 ARGS`` started with its output in ``tmp/name.log``; the
    process and the page's URL (with its secret) once it says it."""
    import re

    log = tmp / f"{name}.log"
    with open(log, "w") as output:
        server = subprocess.Popen(
            [sys.executable, "-m", "explorer.cli", "web", "--port", "0", *args],
            stdout=output,
            stderr=subprocess.STDOUT,
        )
    end = time.monotonic() + WAIT_S
    while not (url := re.search(r"http://\S+\?secret=[\w-]+", log.read_text())):
        if server.poll() is not None or time.monotonic() > end:
            server.terminate()
            raise SystemExit(f"screenshots: the server did not start:\n{log.read_text()}")
        time.sleep(0.2)
    return server, url.group(0)


def _browser(size: tuple[int, int]):
    """Debian's headless Chromium through Selenium, its page's viewport ``size`` (w, h) CSS
    pixels at a device scale of 1 (the window is larger by the browser's own frame)."""
    from explorer.app.browser import new_browser, set_viewport

    driver = new_browser(size)
    set_viewport(driver, *size)
    return driver


#: true once the view named by the argument shows a picture, whichever element carries it (an
#: ``<img>`` loaded from the server's picture, or a canvas it was drawn into)
PICTURE_SHOWN_JS = """
const v = document.querySelector(`[aria-label="${arguments[0]}"]`);
const i = v && v.querySelector('img');
const c = v && v.querySelector('canvas');
return (i !== null && i.complete && i.naturalWidth > 0) || (c !== null && c.width > 0);
"""


def _wait_picture(driver, view: str) -> None:
    end = time.monotonic() + WAIT_S
    while not driver.execute_script(PICTURE_SHOWN_JS, view):
        if time.monotonic() > end:
            raise SystemExit("screenshots: gave up waiting for the page's picture")
        time.sleep(0.2)


def shoot_web(name: str, tmp: Path, out: Path) -> None:
    """Start ``phong-explorer web`` on the session of picture ``name``, open the page in headless
    Chromium and save its screenshot into ``out/name.png`` once the picture is still."""
    from explorer.app import model as M
    from explorer.app.effectactions import gouraud_vs_per_pixel
    from explorer.app.session import save_session
    from explorer.cli import build_parser
    from explorer.cli.gui import start_state

    argv = ["gui", "--mesh", "torus", "--resolution", "48", "--preset", "glossy_plastic"]
    state, _ = start_state(build_parser().parse_args(argv))
    if name == "web_strip":  # Gouraud vs per-pixel, a strip under each pane
        state = gouraud_vs_per_pixel(state).replace(strip=True)
        state = M.set_compare_model(state, "phong")
    session = save_session(tmp / f"{name}.yaml", state, overwrite=True)
    server, url = _web_server(tmp, name, "--session", str(session))
    driver = None
    try:
        driver = _browser(WEB_SIZE)
        driver.get(url)
        _wait_picture(driver, "view_b")  # (pane B's first picture)
        driver.find_element("css selector", '[aria-label="view tab"]').click()
        time.sleep(8.0)  # the tab shown, the pictures still (then sent as PNGs, exact)
        driver.save_screenshot(str(out / f"{name}.png"))
    finally:
        if driver is not None:
            driver.quit()
        server.terminate()
        server.wait(10)


#: the page tour's browser sizes (issue 42: the page at each, every tab, looked at)
TOUR_SIZES = ((1280, 900), (900, 720), (640, 480))
#: the panel's tabs, by their accessible names
TOUR_TABS = ("material", "lights", "view")


def shoot_web_tour(tmp: Path, out: Path) -> list[Path]:
    """``phong-explorer web`` as it starts, in headless Chromium at each of :data:`TOUR_SIZES`
    (a server a size: the start is framed for the first page's view), one screenshot a tab:
    ``out/web_tour_WxH_TAB.png``. Not docs pictures: for looking at."""
    written = []
    for size in TOUR_SIZES:
        server, url = _web_server(tmp, "web_tour")
        driver = None
        try:
            driver = _browser(size)
            driver.get(url)
            _wait_picture(driver, "view")
            for tab in TOUR_TABS:
                driver.find_element("css selector", f'[aria-label="{tab} tab"]').click()
                time.sleep(2.0)  # the tab shown, the picture still (then lossless)
                path = out / f"web_tour_{size[0]}x{size[1]}_{tab}.png"
                driver.save_screenshot(str(path))
                written.append(path)
        finally:
            if driver is not None:
                driver.quit()
            server.terminate()
            server.wait(10)
    return written


NAMES = ("gui", "gui_800x500", "gui_640x480", "gui_file_menu", "gui_compare", "gui_difference",
         "gui_lobe_phong", "gui_lobe_blinn", "gui_translucent", "gui_per_pixel",
         "gui_gouraud_vs_per_pixel", "gui_strip", "gui_strip_per_pixel",
         "gui_lobes", "maps_window")  # fmt: skip


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out-dir", type=Path, default=HERE, help="where the PNGs go (docs/)")
    ap.add_argument(
        "--only", action="append", choices=NAMES + WEB_NAMES, help="this picture (repeatable)"
    )
    ap.add_argument(
        "--web-tour",
        action="store_true",
        help="only the page at 1280x900, 900x720 and 640x480, each tab (web_tour_*.png)",
    )
    args = ap.parse_args(argv)
    for tool in ("Xvfb", "import"):
        if shutil.which(tool) is None:
            raise SystemExit(f"screenshots: needs {tool} (apt-get install xvfb imagemagick)")
    from explorer.app.start import start_xvfb

    server, display = start_xvfb(size=(1400, 900))
    tmp = Path(tempfile.mkdtemp(prefix="phong-shots-"))
    os.environ.update(DISPLAY=display, QT_QPA_PLATFORM="xcb",
                      PHONG_EXPLORER_MATERIALS=str(tmp / "presets"))  # fmt: skip
    os.environ.pop("VTK_DEFAULT_OPENGL_WINDOW", None)
    from explorer.app.qtmain import application

    app = application()
    try:
        args.out_dir.mkdir(parents=True, exist_ok=True)
        if args.web_tour:
            for path in shoot_web_tour(tmp, args.out_dir):
                print(f"wrote {path}")
            return 0
        for name in args.only or NAMES + WEB_NAMES:
            if name in WEB_NAMES:
                shoot_web(name, tmp, args.out_dir)
            else:
                shoot(name, app, display, tmp, args.out_dir)
            print(f"wrote {args.out_dir / name}.png")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        server.terminate()
        server.wait()
    return 0


if __name__ == "__main__":
    sys.exit(main())
