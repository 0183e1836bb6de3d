"""The page's parity with the desktop, in a real browser: materials imported from an uploaded
.mtl (and a bad one refused with the desktop's message), the message log, the turntable's frame
count and format, the colour pickers beside the ``r, g, b`` fields (the swatch's real pixels),
and ``web --last``."""

from __future__ import annotations

import importlib.util
import io
import os
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from helpers.frames import read_frames
from PIL import Image
from test_web import by_name, click, console_errors, kd, open_page, report, type_value, wait

import explorer
from explorer.core import tolerances as tol
from explorer.core.presets import list_presets

pytestmark = pytest.mark.web

GOOD_MTL = """# two materials for the page's import
newmtl web_red
Ka 0.1 0.0 0.0
Kd 0.8 0.1 0.1
Ks 0.5 0.5 0.5
Ns 40

newmtl web_teal
Kd 0.1 0.6 0.6
Ks 0.2 0.2 0.2
Ns 12
"""
BAD_MTL = "newmtl web_bad\nKd 0.5 zz 0.1\n"


def status(driver) -> str:
    return by_name_role(driver, "status").text


def by_name_role(driver, role: str):
    from selenium.webdriver.common.by import By

    return driver.find_element(By.CSS_SELECTOR, f'[role="{role}"]')


def drawn(driver, name: str) -> bool:
    """Whether control ``name`` is drawn (a select's own input is transparent: its field is
    what shows)."""
    element = by_name(driver, name)
    return driver.execute_script("return arguments[0].closest('.v-input')", element) \
        .is_displayed() if element.tag_name == "input" else element.is_displayed()  # fmt: skip


def user_presets(server) -> Path:
    return server.log.parent / "presets"


def test_materials_imported_from_an_uploaded_mtl_are_presets_in_the_list(server, browser,
                                                                          tmp_path):  # fmt: skip
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys

    open_page(browser, server.url)
    good = tmp_path / "two.mtl"
    good.write_text(GOOD_MTL)
    by_name(browser, "import materials").send_keys(str(good))
    wait("the presets written", lambda: {p.name for p in user_presets(server).glob("*.yaml")}
         >= {"web_red.yaml", "web_teal.yaml"})  # fmt: skip
    wait("the import said", lambda: "imported 2 presets from two.mtl" in status(browser))
    # the imported presets are in the page's preset list (the searchable autocomplete)
    field = by_name(browser, "preset")
    click(browser, "preset")
    field.send_keys(Keys.CONTROL, "a")
    field.send_keys("web_te")
    option = wait("web_teal offered", lambda: next(
        (o for o in browser.find_elements(By.CSS_SELECTOR, '[role="option"]')
         if "web_teal" in o.text), None))  # fmt: skip
    browser.save_screenshot(str(server.log.parent / "import.png"))
    option.click()
    rep = wait("web_teal shown", lambda: (r := report(browser))
               and r["session"]["preset"] == "web_teal" and r)  # fmt: skip
    shown = explorer.load_scene(rep["session"]["scene"]).material
    assert shown.diffuse == pytest.approx((0.1, 0.6, 0.6))
    # readable by the presets' own reader
    assert {p.name for p in list_presets([user_presets(server)])} >= {"web_red", "web_teal"}
    assert not console_errors(browser)


def test_a_bad_mtl_is_refused_with_the_desktops_message_and_nothing_written(server, browser,
                                                                             tmp_path):  # fmt: skip
    open_page(browser, server.url)
    before = sorted(user_presets(server).glob("*")) if user_presets(server).is_dir() else []
    bad = tmp_path / "bad.mtl"
    bad.write_text(BAD_MTL)
    by_name(browser, "import materials").send_keys(str(bad))
    # the reader's message, naming the file (by its own name, not the server's folder) and line
    text = wait("the error", lambda: "bad.mtl:2: Kd: 'zz' is not a number" in (t := status(
        browser)) and t)  # fmt: skip
    assert "Nothing was imported" in text and "phong-explorer-web-" not in text, text
    assert (sorted(user_presets(server).glob("*")) if user_presets(server).is_dir()
            else []) == before  # fmt: skip
    assert "Traceback" not in server.output(), server.output()
    # too large for an .mtl: refused before it is written or read (limits.md)
    big = tmp_path / "big.mtl"
    big.write_bytes(b"#" * (tol.MAX_MTL_FILE_BYTES + 1))
    by_name(browser, "import materials").send_keys(str(big))
    wait("the size refused", lambda: "material library 'big.mtl' is too large" in status(browser))
    assert "Traceback" not in server.output(), server.output()


def field_text(driver, name: str) -> str:
    """What the field named ``name`` shows (its input's value)."""
    from selenium.webdriver.common.by import By

    e = by_name(driver, name)
    return (e if e.tag_name == "input" else e.find_element(By.CSS_SELECTOR, "input")).get_attribute(
        "value"
    )


@pytest.mark.parametrize(
    ("key", "text", "tab"),
    [("shininess", "5000", None), ("ka", "-1", None), ("kd", "abc", None),
     ("azimuth", "500", "lights tab"), ("intensity", "-2", "lights tab"),
     ("attenuation", "0,0,0", "lights tab")],
)  # fmt: skip
def test_a_refused_value_leaves_the_field_showing_the_state(server, browser, key, text, tab):
    """A typed value the explorer refuses (out of range, not a number, an attenuation of
    zero) is said, and the field shows the state's value again, as the window's does (it kept
    the refused text beside a slider showing the state)."""
    open_page(browser, server.url)
    if tab:
        click(browser, tab)
    shown = field_text(browser, key)
    type_value(browser, key, text)
    wait("the refusal", lambda: "error" in status(browser))
    wait("the state's value in the field", lambda: field_text(browser, key) == shown)
    server_errors = report(browser)["errors"]
    assert server_errors and key.split()[0] in server_errors[-1], server_errors
    browser.execute_script("window.phongIntent('reset_camera')")  # (a message that is no error)


def test_the_fields_show_units_and_decimals_as_the_windows_do(server, browser):
    """The page's number fields read as the window's: each control's decimals and unit
    (azimuth ``40.0°``, distance ``2.50 r``, intensity ``1.000``; the page said ``40``, ``2.5``
    and ``1`` beside ``0.247``), and a value typed with its unit is taken."""
    from explorer.core.controls import CONTROLS
    from explorer.core.controls import field_text as control_text

    rep = open_page(browser, server.url)
    click(browser, "lights tab")
    for key in ("azimuth", "elevation", "distance", "intensity"):
        text = wait(f"{key}'s field", lambda k=key: field_text_of(browser, k))
        c = CONTROLS[key]
        assert text == control_text(c, float(text.removesuffix(c.unit))), (key, text)
        assert len(text.removesuffix(c.unit).split(".")[1]) == c.decimals, (key, text)
    assert field_text_of(browser, "azimuth").endswith("°")
    assert field_text_of(browser, "distance").endswith(" r")
    type_value(browser, "azimuth", "45°")
    wait("azimuth 45", lambda: field_text_of(browser, "azimuth") == "45.0°")
    assert report(browser)["placement"][0] == pytest.approx(45.0)
    click(browser, "undo")
    wait("undo", lambda: report(browser)["session"] == rep["session"])
    click(browser, "material tab")


def field_text_of(driver, name: str) -> str | None:
    """The text the field named ``name`` shows, None while it shows none."""
    return field_text(driver, name) or None


def test_the_message_log_lists_the_sessions_messages(server, browser):
    open_page(browser, server.url)
    type_value(browser, "kd", "7")  # refused: the message names the key and the range
    wait("the refusal", lambda: "kd must be a number within" in status(browser))
    assert not shown(browser, "message log")
    click(browser, "messages")
    refused = "error: kd must be a number within"
    lines = wait("the refusal in the log", lambda: (got := log_lines(browser))
                 and any(refused in t for t in got) and got)  # fmt: skip
    browser.save_screenshot(str(server.log.parent / "messages.png"))
    assert all(t[:8].count(":") == 2 for t in lines), lines  # each with its time, HH:MM:SS
    assert not any("error: error" in t for t in lines), lines  # the level said once
    click(browser, "close messages")
    wait("the log closed", lambda: not shown(browser, "message log"))
    type_value(browser, "kd", "0.5")  # an edit that works takes the error away
    wait("the error gone", lambda: "kd must be" not in status(browser))


def log_lines(driver) -> list[str] | None:
    """The lines of the message log shown in the page (None while it is not shown, or is
    being drawn anew)."""
    from selenium.common.exceptions import StaleElementReferenceException
    from selenium.webdriver.common.by import By

    try:
        if not shown(driver, "message log"):
            return None
        each = '[aria-label="message log"] [aria-label="message"]'
        found = driver.find_elements(By.CSS_SELECTOR, each)
        return [e.text for e in found]
    except StaleElementReferenceException:
        return None


def shown(driver, name: str):
    """The element named ``name`` when it is shown, else None (also while it is drawn anew)."""
    from selenium.common.exceptions import StaleElementReferenceException
    from selenium.webdriver.common.by import By

    try:
        found = driver.find_elements(By.CSS_SELECTOR, f'[aria-label="{name}"]')
        return found[0] if found and found[0].is_displayed() else None
    except StaleElementReferenceException:
        return None


def _choose(driver, name: str, text: str) -> None:
    """Pick the entry ``text`` of select ``name``."""
    from selenium.webdriver.common.by import By

    field = by_name(driver, name).find_element(
        By.XPATH, "./ancestor::div[contains(@class, 'v-field')][1]")  # fmt: skip
    wait(f"{name!r} open", lambda: field.click() or driver.find_elements(
        By.CSS_SELECTOR, '[role="option"]'))  # fmt: skip
    wait(f"{text!r} picked", lambda: next(
        (o.click() or True for o in driver.find_elements(By.CSS_SELECTOR, '[role="option"]')
         if o.text.strip() == text), False))  # fmt: skip


def _turntable(browser, downloads, frames: int, fmt: str, suffix: str) -> Path:
    """A turntable of ``frames`` frames made in the page as ``fmt``, downloaded."""
    for f in downloads.glob("*"):
        f.unlink()
    click(browser, "view tab")
    type_value(browser, "turntable frames", str(frames))
    _choose(browser, "turntable format", fmt)
    click(browser, "turntable")
    made = f"({frames} frames, {fmt})"  # the button names the turntable it downloads
    wait("the turntable", lambda: (b := shown(browser, "download turntable"))
         and made.lower() in b.text.lower(), 120)  # fmt: skip
    click(browser, "download turntable")
    path = wait("the download", lambda: next(
        (f for f in downloads.glob(f"*{suffix}") if f.stat().st_size > 0), None))  # fmt: skip
    time.sleep(0.3)
    click(browser, "material tab")
    return path


def test_the_turntable_has_the_frames_and_the_format_chosen_in_the_page(server, browser,
                                                                        downloads):  # fmt: skip
    open_page(browser, server.url)
    # a long one runs under the progress bar, and its Cancel leaves nothing to download
    click(browser, "view tab")
    type_value(browser, "turntable frames", str(tol.MAX_TURNTABLE_FRAMES))
    click(browser, "turntable")
    wait("the progress bar", lambda: shown(browser, "progress"))
    click(browser, "cancel")
    wait("the cancel", lambda: "turntable cancelled" in status(browser))
    assert not shown(browser, "progress") and not shown(browser, "download turntable")
    path = _turntable(browser, downloads, 5, "GIF", ".gif")
    with Image.open(path) as gif:
        assert gif.format == "GIF" and gif.n_frames == 5
    assert not console_errors(browser)


@pytest.mark.skipif(importlib.util.find_spec("imageio_ffmpeg") is None,
                    reason="MP4 needs imageio-ffmpeg")  # fmt: skip
def test_an_mp4_turntable_through_imageio_ffmpeg(server, browser, downloads):
    open_page(browser, server.url)
    path = _turntable(browser, downloads, 4, "MP4", ".mp4")
    frames = read_frames(path)
    assert frames.shape[0] == 4, frames.shape
    assert not console_errors(browser)


def test_a_bad_frame_count_is_said_and_nothing_made(server, browser):
    open_page(browser, server.url)
    click(browser, "view tab")
    type_value(browser, "turntable frames", "1")
    click(browser, "turntable")
    wait("the refusal", lambda: f"frames must be a number within 2 .. "
         f"{tol.MAX_TURNTABLE_FRAMES}" in status(browser))  # fmt: skip
    type_value(browser, "turntable frames", "36")
    click(browser, "material tab")


def swatch_pixel(driver, name: str) -> np.ndarray:
    """The colour at the middle of element ``name`` in a screenshot of the page."""
    shot = np.asarray(Image.open(io.BytesIO(driver.get_screenshot_as_png())).convert("RGB"))
    r = driver.execute_script("const r = arguments[0].getBoundingClientRect();"
                              "return [r.left + r.width / 2, r.top + r.height / 2,"
                              " window.devicePixelRatio];", by_name(driver, name))  # fmt: skip
    return shot[round(r[1] * r[2]), round(r[0] * r[2])].astype(int)


def pick(driver, name: str, hex_text: str) -> None:
    """Open colour picker ``name``, type ``hex_text`` into its hex field (Enter), close it."""
    from selenium.webdriver.common.keys import Keys

    click(driver, f"{name} picker")
    box = wait("the picker", lambda: shown(driver, f"{name} picker colours"))
    field = box.find_element("css selector", 'input[aria-label="HEX value"]')
    field.send_keys(Keys.CONTROL, "a")
    field.send_keys(hex_text, Keys.ENTER)


def close_picker(driver, name: str) -> None:
    """Close colour picker ``name`` (Escape) if Enter has not closed it already."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.keys import Keys

    def closed():
        if not shown(driver, f"{name} picker colours"):
            return True
        ActionChains(driver).send_keys(Keys.ESCAPE).perform()
        return False

    wait("the picker closed", closed)


def test_a_colour_picked_sets_the_value_and_the_swatch_shows_it(server, browser):
    rep = open_page(browser, server.url)
    start = rep["session"]["scene"]["material"]["diffuse"]
    assert "8-bit" in by_name(browser, "diffuse picker").get_attribute("title")
    pick(browser, "diffuse", "#336699")
    rep = wait("diffuse picked", lambda: (r := report(browser))
               and r["session"]["scene"]["material"]["diffuse"] != start and r)  # fmt: skip
    assert rep["session"]["scene"]["material"]["diffuse"] == pytest.approx((0.2, 0.4, 0.6))
    browser.save_screenshot(str(server.log.parent / "picker.png"))
    close_picker(browser, "diffuse")
    assert by_name(browser, "diffuse").get_attribute("value") == "0.200, 0.400, 0.600"
    wait("the swatch", lambda: (swatch_pixel(browser, "diffuse picker")
                                == (0x33, 0x66, 0x99)).all())  # fmt: skip
    # the swatch follows the value typed exactly into the field (8-bit: 0.5 is 128)
    type_value(browser, "diffuse", "0.5, 0.25, 1")
    wait("the swatch again", lambda: (swatch_pixel(browser, "diffuse picker")
                                      == (128, 64, 255)).all())  # fmt: skip
    # the light's colour too
    click(browser, "lights tab")
    pick(browser, "color", "#ff8000")
    rep = wait("the light's colour", lambda: (r := report(browser)) and r["session"]["scene"][
        "lights"][r["session"]["light"] - 1]["diffuse"][1] != 1.0 and r)  # fmt: skip
    light = explorer.load_scene(rep["session"]["scene"]).lights[rep["session"]["light"] - 1]
    assert np.asarray(light.diffuse) / max(light.diffuse) == pytest.approx((1.0, 128 / 255, 0.0))
    close_picker(browser, "color")
    wait("the light swatch", lambda: (swatch_pixel(browser, "color picker")
                                      == (255, 128, 0)).all())  # fmt: skip
    click(browser, "material tab")
    assert not console_errors(browser)


def test_web_last_reopens_the_session_kept_when_the_server_stopped(tmp_path, downloads):
    from webserver import Server, need_browser, new_browser

    need_browser()
    env = dict(os.environ, PHONG_EXPLORER_MATERIALS=str(tmp_path / "presets"),
               PHONG_EXPLORER_LAST_SESSION=str(tmp_path / "last.yaml"))  # fmt: skip
    first = Server(["--mesh", "cube"], tmp_path / "first.log", env=env)
    driver = new_browser(downloads)
    try:
        open_page(driver, first.url)
        type_value(driver, "kd", "0.37")
        wait("kd 0.37", lambda: abs(kd(report(driver)) - 0.37) < 1e-9)
        kept = report(driver)["session"]
        first.stop()  # SIGTERM, as a service manager stops it
        assert first.proc.returncode == 0, first.output()
        saved = yaml.safe_load((tmp_path / "last.yaml").read_text())
        assert saved["mesh"] == "cube"
        driver.quit()  # its page lost the server (and says so leaving): a new browser
        driver = new_browser(downloads)
        again = Server(["--last"], tmp_path / "again.log", env=env)
        try:
            rep = open_page(driver, again.url)
            assert rep["session"]["mesh"] == "cube" and abs(kd(rep) - 0.37) < 1e-9
            assert explorer.load_scene(rep["session"]["scene"]) == explorer.load_scene(
                kept["scene"])  # fmt: skip
        finally:
            again.stop()
    finally:
        driver.quit()
        first.stop()


def test_web_refuses_session_and_last_together(capsys, tmp_path):
    from explorer.cli import main

    assert main(["web", "--session", str(tmp_path / "s.yaml"), "--last"]) == 2
    assert capsys.readouterr().err.strip() == (
        "error: --session and --last both name a session: give one")  # fmt: skip


def test_a_mesh_files_own_materials_are_chosen_by_group_and_drawn_again(tmp_path, downloads):
    """An OBJ with its .mtl: the page says the file brings its own materials, the group
    chooser lists them, the controls edit the chosen group (its kd in the field), a preset
    covers the mesh and the button draws the file's materials again (as the desktop's box)."""
    from test_web import choose
    from webserver import Server, need_browser, new_browser

    need_browser()
    obj = Path(__file__).resolve().parents[3] / "docs" / "examples" / "teapot_parts.obj"
    env = dict(os.environ, PHONG_EXPLORER_MATERIALS=str(tmp_path / "presets"),
               PHONG_EXPLORER_LAST_SESSION=str(tmp_path / "last.yaml"))  # fmt: skip
    srv = Server(["--mesh", str(obj)], tmp_path / "parts.log", env=env)
    driver = new_browser(downloads)
    try:
        open_page(driver, srv.url)
        wait("the mesh's materials", lambda: drawn(driver, "group"))
        line = by_name(driver, "mesh_materials").text
        assert "teapot_parts.obj brings its own materials, one per group (3)" in line, line
        assert "edit group 'Porcelain'" in line, line
        assert by_name(driver, "kd").get_attribute("value") == "0.920"
        assert not by_name(driver, "use_mesh_materials").is_displayed()
        click(driver, "messages")  # the warnings printed at the start are in the page's log
        lines = wait("the start's warnings", lambda: (got := log_lines(driver))
                     and sum(t.count("teapot_parts.mtl:") for t in got) == 3 and got)  # fmt: skip
        assert any("Ns 180 is above OpenGL's largest GL_SHININESS (128)" in t for t in lines)
        click(driver, "close messages")
        wait("the log closed", lambda: not shown(driver, "message log"))
        choose(driver, "group", "Cobalt_Glaze")
        wait("the cobalt group's kd", lambda: by_name(driver, "kd").get_attribute("value")
             == "0.620")  # fmt: skip
        assert "edit group 'Cobalt_Glaze'" in by_name(driver, "mesh_materials").text
        assert report(driver)["session"]["groups"]["group"] == 2
        choose(driver, "preset", "bronze")
        wait("the button that draws them again",
             lambda: by_name(driver, "use_mesh_materials").is_displayed())  # fmt: skip
        assert "preset 'bronze' covers the whole mesh" in by_name(driver, "mesh_materials").text
        assert not drawn(driver, "group")
        click(driver, "use_mesh_materials")
        wait("the groups again", lambda: drawn(driver, "group"))
        assert report(driver)["session"]["groups"] is not None
        assert not console_errors(driver)
        assert "Traceback" not in srv.output()
    finally:
        driver.quit()
        srv.stop()
