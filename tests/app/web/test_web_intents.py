"""The page's menus, keyboard shortcuts and help from the intent registry, in real Chromium:
every intent the page has is in the desktop's menu with the desktop's title (or on its key),
the help lists every key, a key runs its intent, and the same letter typed into a field is
text, not a shortcut."""

from __future__ import annotations

import time

import numpy as np
import pytest
from test_web import by_name, click, console_errors, drag, open_page, report, wait

from explorer.app import intents as X

pytestmark = pytest.mark.web


def press(driver, key: str, *mods: str) -> None:
    """Press ``key`` (a character, or a name of Selenium's ``Keys``: ``F1``, ``ESCAPE``) with
    modifier keys ``mods`` (``Keys`` names) where the page's keyboard focus is."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.keys import Keys

    chain = ActionChains(driver)
    for m in mods:
        chain.key_down(getattr(Keys, m))
    chain.send_keys(key if len(key) == 1 else getattr(Keys, key))
    for m in reversed(mods):
        chain.key_up(getattr(Keys, m))
    chain.perform()


def shown(driver, name: str) -> bool:
    """Whether an element named ``name`` is on the page and shown."""
    from selenium.common.exceptions import StaleElementReferenceException
    from selenium.webdriver.common.by import By

    try:
        found = driver.find_elements(By.CSS_SELECTOR, f'[aria-label="{name}"]')
        return any(e.is_displayed() for e in found)
    except StaleElementReferenceException:  # removed while asked
        return False


def same_camera(a: dict, b: dict) -> bool:
    """Whether two cameras of the session are one (within float32's rounding: the view's
    camera goes through VTK's)."""
    return a.keys() == b.keys() and all(np.allclose(a[k], b[k], rtol=1e-5, atol=1e-6) for k in a)


def test_every_intent_of_the_page_is_in_its_menu_with_the_desktops_title(server, browser):
    from selenium.webdriver.common.by import By

    open_page(browser, server.url)
    assert {i.id for i in X.INTENTS if not i.page} == {"quit"}  # the desktop's alone
    for name in X.MENUS:
        click(browser, f"menu {name}")
        wait(f"menu {name} open", lambda n=name: shown(browser, f"menu {n} entries"))
        for i in X.INTENTS:
            if i.page and i.menu == name:
                item = by_name(browser, f"intent {i.id}")
                title = item.find_element(By.CSS_SELECTOR, ".v-list-item-title")
                assert title.get_attribute("textContent").strip() == i.label, i.id
        press(browser, "ESCAPE")  # closes the menu
        wait(f"menu {name} closed", lambda n=name: not shown(browser, f"menu {n} entries"))
    assert not console_errors(browser)


def test_f1_opens_the_help_and_it_lists_every_key_of_the_page(server, browser):
    open_page(browser, server.url)
    click(browser, "view")
    press(browser, "F1")
    wait("the help", lambda: shown(browser, "help text"))
    text = by_name(browser, "help text").text
    said = set()
    for line in text.splitlines():
        keys, _, what = line.strip().partition("   ")
        said |= {(k, what) for k in keys.split(" / ")}
    for i in X.INTENTS:
        for key in i.web_keys():
            assert (key, i.page_what) in said, (key, i.id)
    assert ("Ctrl+T", X.BY_ID["export_turntable"].page_what) not in said  # the browser's tab
    click(browser, "close help")


def test_keys_run_their_intents_but_not_while_typing_in_a_field(server, browser):
    rep = open_page(browser, server.url)
    errors = rep["errors"]  # the server's, since it started
    assert rep["session"]["difference"] is False
    click(browser, "ks")  # a number field: "d" typed there is text
    press(browser, "d")
    assert "d" in by_name(browser, "ks").get_attribute("value")  # typed where the caret is
    press(browser, "BACKSPACE")  # the field as it was: no change to confirm
    click(browser, "view")  # the keyboard off the field
    assert report(browser)["session"]["difference"] is False
    press(browser, "d")
    wait("the difference view", lambda: report(browser)["session"]["difference"] is True)
    press(browser, "d")
    wait("the difference view off", lambda: report(browser)["session"]["difference"] is False)
    w, h = rep["size"]
    camera = report(browser)["session"]["camera"]
    drag(browser, (w // 2, h // 2 + 40), [(12, 0)] * 8)
    wait("the camera to turn", lambda: report(browser)["session"]["camera"] != camera)
    press(browser, "r")
    wait("the camera reset", lambda: same_camera(report(browser)["session"]["camera"], camera))
    press(browser, "b")
    wait("the next model", lambda: report(browser)["session"]["scene"]["model"] != "blinn")
    press(browser, "z", "CONTROL")
    wait("undo", lambda: report(browser)["session"]["scene"]["model"] == "blinn")
    press(browser, "m", "CONTROL")  # the message log: a dialog in the browser
    wait("the message log", lambda: shown(browser, "message log"))
    click(browser, "close messages")
    assert report(browser)["errors"] == errors and not console_errors(browser)


def test_a_menu_entry_runs_its_intent_and_the_page_refuses_a_desktop_one(server, browser):
    open_page(browser, server.url)
    click(browser, "menu View")
    click(browser, "intent toggle_difference")
    wait("the difference view", lambda: report(browser)["session"]["difference"] is True)
    click(browser, "menu View")
    click(browser, "intent toggle_difference")
    wait("the difference view off", lambda: report(browser)["session"]["difference"] is False)
    said = browser.execute_async_script(
        "const done = arguments[0];"
        "window.trame.trigger('intent', ['quit']).then(() => done('ran'), e => done(String(e)));"
    )
    assert said == "ran"  # the trigger answers, but quit does not run: the page says why
    wait(
        "the refusal", lambda: any("no intent named 'quit'" in e for e in report(browser)["errors"])
    )


def test_the_browsers_own_intents_a_download_a_tab_and_a_field(server, browser, downloads):
    """The intents the page runs in the browser: Ctrl+Shift+E downloads the view's PNG,
    Ctrl+Shift+S shows the material tab with the preset's name field taking the keyboard, Ctrl+E
    opens the export menu."""
    errors = open_page(browser, server.url)["errors"]  # the server's, since it started
    for f in downloads.glob("*"):
        f.unlink()
    click(browser, "view tab")
    click(browser, "view")
    press(browser, "e", "CONTROL", "SHIFT")
    path = wait(
        "the download",
        lambda: next((f for f in downloads.glob("*.png") if f.stat().st_size > 0), None),
    )
    time.sleep(0.2)
    assert path.read_bytes().startswith(b"\x89PNG")
    press(browser, "s", "CONTROL", "SHIFT")
    wait(
        "the preset name field",
        lambda: (
            browser.execute_script("return document.activeElement.getAttribute('aria-label')")
            == "preset name"
        ),
    )
    click(browser, "view")
    press(browser, "e", "CONTROL")
    wait("the export menu", lambda: shown(browser, "export png"))
    press(browser, "ESCAPE")
    assert report(browser)["errors"] == errors and not console_errors(browser)


def test_the_toolbars_tooltips_are_the_registrys_words_and_keys(server, browser):
    """Each toolbar button's tooltip (its ``title``) is its intent's, words and keys, from the
    registry (:func:`explorer.app.intents.tooltip`): undo's and redo's name the step they would
    undo or redo, and redo's says both its keys (the page wrote ``(Ctrl+Shift+Z)`` itself)."""
    open_page(browser, server.url)

    def title(name: str) -> str:
        return by_name(browser, name).get_attribute("title")

    for name, intent in (
        ("save session", "save_session"),
        ("open session", "open"),
        ("export", "export_material"),
        ("messages", "messages"),
    ):
        assert title(name) == X.tooltip(intent, page=True), name
    click(browser, "view")  # the keyboard to the page, off any field
    press(browser, "b")  # the next specular model: one step to undo (the last one)
    wait("the next model", lambda: report(browser)["session"]["scene"]["model"] != "blinn")
    head, tail = X.tooltip("undo", "\0", page=True).split("\0")
    assert head == "undo " and tail == " (Ctrl+Z)"
    wait("undo's step named", lambda: title("undo").startswith(head) and title("undo") != head)
    step = title("undo").removeprefix(head).removesuffix(tail)
    assert step and title("undo") == X.tooltip("undo", step, page=True)
    click(browser, "undo")
    wait("redo's step named", lambda: title("redo") == X.tooltip("redo", step, page=True))
    assert title("redo") == f"redo {step} (Ctrl+Shift+Z / Ctrl+Y)"  # both keys
