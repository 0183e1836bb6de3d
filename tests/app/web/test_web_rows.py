"""The panel model's rows on the page (issue 38), in a real browser: every row of
:mod:`explorer.app.panelmodel` is in the DOM of its tab under the name the window gives it, its
parts too (a number's ``<key>_slider``, ...: ``rowlayout.names``; tests/app/qt/test_panel.py
reads the same names from the Qt widgets), and the effect rows, drawn
with no code of their own, change the picture, are undone, and reach the session. This module's
server is its own (the effects it turns on stay out of the other modules' pictures)."""

from __future__ import annotations

import pytest
from test_web import by_name, choose, click, open_page, picture_src, report, wait

from explorer.app import panelmodel as P
from explorer.app import rowlayout

pytestmark = pytest.mark.web


def shown(driver, name: str) -> bool:
    """An element named ``name`` is laid out on the page (none of its ancestors hidden: a
    select's own input is transparent, so Selenium's ``is_displayed`` does not serve)."""
    return driver.execute_script(
        'return [...document.querySelectorAll(`[aria-label="${arguments[0]}"]`)]'
        ".some(e => e.getClientRects().length > 0);",
        name,
    )


def test_every_row_is_on_the_page_in_its_tab_named_as_in_the_window(server, browser):
    from selenium.webdriver.common.by import By

    rep = open_page(browser, server.url)
    click(browser, "lights tab")
    wait("the lights tab", lambda: shown(browser, "type"))
    choose(browser, "type", "spot")
    wait("a spot light", lambda: shown(browser, "cutoff"))
    click(browser, "view tab")
    wait("the view tab", lambda: shown(browser, "hdr"))
    click(browser, "hdr")
    wait("the HDR display's rows", lambda: shown(browser, "exposure"))
    click(browser, "compare")
    wait("side B's rows", lambda: shown(browser, "compare_preset"))
    choose(browser, "lobes", "models")
    wait("the several lobes' rows", lambda: shown(browser, "lobe_view"))
    click(browser, "lobe_incidence_on")
    wait("the lobe incidence's number", lambda: shown(browser, "lobe_incidence"))
    click(browser, "strip")
    wait("the strip's mode", lambda: shown(browser, "strip_mode"))
    click(browser, "material tab")
    wait("the material tab", lambda: shown(browser, "fresnel_on"))
    click(browser, "fresnel_on")
    wait("fresnel's number", lambda: shown(browser, "fresnel"))
    # the lists, the buttons and the views' toggles are rows too, drawn by no code of the page's
    assert {"preset", "light", "add_light", "difference", "compare", "swap"} <= set(P.BY_KEY)
    # a mesh file's own materials are shown with an OBJ's groups (test_web_parity.py): here
    # they are on the page, hidden; so are the lobes past the three models' and the line that
    # says a mesh has no (u, v) (the start's sphere has them: its maps' rows are shown), and
    # the line saying the scene has no lights (it has one)
    hidden = (
        "no_lights",
        "mesh_materials",
        "group",
        "use_mesh_materials",
        *(f"show_lobe_{i}" for i in range(4, 9)),
        "maps_note",
    )
    for tab in P.TABS:
        click(browser, f"{tab} tab")
        wait(f"the {tab} tab", lambda t=tab: shown(browser, P.rows(t)[-1].key))
        for r in P.rows(tab):
            for name in rowlayout.names(r):
                assert shown(browser, name) != (name in hidden), (tab, name)
                assert browser.find_elements(By.CSS_SELECTOR, f'[aria-label="{name}"]'), name
    for _ in range(7):  # fresnel, the strip, the incidence, the lobes, compare, hdr, the spot
        click(browser, "undo")
    wait("the start again", lambda: report(browser)["session"] == rep["session"])


@pytest.mark.parametrize(
    ("tab", "name", "check"),
    [
        ("material", "energy_conserving", lambda s: s["scene"]["material"]["energy_conserving"]),
        ("material", "fresnel_on", lambda s: s["scene"]["material"]["fresnel"] == 0.04),
        ("view", "hdr", lambda s: s["scene"]["hdr"]["tone_map"] == "reinhard"),
    ],
)
def test_an_effect_row_changes_the_picture_and_undo_restores_it(server, browser, tab, name, check):
    rep = open_page(browser, server.url)
    click(browser, f"{tab} tab")
    wait(f"the {tab} tab", lambda: shown(browser, name))
    before = picture_src(browser)
    click(browser, name)
    wait(f"{name} in the session", lambda: check(report(browser)["session"]))
    wait("a new picture", lambda: picture_src(browser) not in (None, before))
    click(browser, "undo")
    wait("the start again", lambda: report(browser)["session"] == rep["session"])


def test_a_lights_shadows_two_sided_lighting_and_the_viewer_reach_the_session(server, browser):
    rep = open_page(browser, server.url)
    click(browser, "lights tab")
    wait("the lights tab", lambda: shown(browser, "shadows"))
    click(browser, "shadows")
    wait(
        "shadows on",
        lambda: (
            (s := report(browser)["session"])["scene"]["lights"][s["light"] - 1].get("shadows")
            is True
        ),
    )
    click(browser, "view tab")
    wait("the view tab", lambda: shown(browser, "two_sided"))
    click(browser, "two_sided")
    wait("two-sided", lambda: report(browser)["session"]["scene"]["two_sided"] is True)
    click(browser, "local_viewer")
    wait(
        "an infinite viewer",
        lambda: (
            (s := report(browser)["session"])["local_viewer"] is False
            and "to_viewer" in s["scene"]["viewer"]
        ),
    )
    for _ in range(3):
        click(browser, "undo")
    wait("the start again", lambda: report(browser)["session"] == rep["session"])


def test_the_preset_search_finds_presets_by_their_descriptions(server, browser):
    """Typing "stone" into the preset list's search lists the presets whose descriptions say
    stone, jade and turquoise, as the window's search does (the page searched names only and
    found none)."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys

    open_page(browser, server.url)
    click(browser, "preset")
    field = by_name(browser, "preset")
    field = field if field.tag_name == "input" else field.find_element(By.CSS_SELECTOR, "input")
    field.send_keys(Keys.CONTROL, "a")
    field.send_keys("stone")

    def listed():
        items = browser.find_elements(By.CSS_SELECTOR, ".v-overlay--active .v-list-item-title")
        return sorted({e.text for e in items if e.text}) or None

    assert wait("the search's items", listed) == ["jade", "turquoise"]
    field.send_keys(Keys.ESCAPE)


def test_the_page_names_the_material_and_says_when_it_is_edited(server, browser):
    """The line above the preset list, as the window's: ``preset: NAME``, then ``(edited)``
    after a change (the page had no such line), and again without it after undo."""
    from test_web import type_value

    rep = open_page(browser, server.url)
    line = wait("the material's line", lambda: by_name(browser, "material_line").text or None)
    assert line == f"preset: {rep['session']['preset']}", line
    type_value(browser, "kd", "0.25")
    wait("(edited)", lambda: by_name(browser, "material_line").text == f"{line} (edited)")
    click(browser, "undo")
    wait("the line again", lambda: by_name(browser, "material_line").text == line)


def test_the_lights_tab_says_when_the_scene_has_no_lights(server, browser):
    """The panel model's ``no_lights`` row, the window's label before the kit: on the page
    too, once the last light is removed; undo brings the light and hides the line."""
    rep = open_page(browser, server.url)
    n = len(rep["session"]["scene"]["lights"])
    click(browser, "lights tab")
    wait("the lights tab", lambda: shown(browser, "remove_light"))
    for k in range(n):
        click(browser, "remove_light")
        wait(
            "a light removed",
            lambda k=k: len(report(browser)["session"]["scene"]["lights"]) == n - k - 1,
        )
    wait("the no-lights line", lambda: shown(browser, "no_lights"))
    assert by_name(browser, "no_lights").text == P.NO_LIGHTS
    for _ in range(n):
        click(browser, "undo")
    wait("the lights back", lambda: report(browser)["session"] == rep["session"])
    assert not shown(browser, "no_lights")
    click(browser, "material tab")
