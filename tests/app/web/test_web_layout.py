"""The page's finish, in a real browser: pane B of the compare view with the light handles
and the arrows at its edge (dragged there as in pane A), and the panel's sliders lined up at
every size."""

from __future__ import annotations

import time

import numpy as np
import pytest
from test_web import click, open_page, report, type_value, view_pixels, wait

pytestmark = pytest.mark.web

#: a handle's pixels are its light's colour, lit by nothing (a white light's: white); the
#: page's picture is a JPEG, so a level or two off
WHITE = 225


def picture_patch(driver, view: str, px, size) -> np.ndarray:
    """The page's pixels (k, 3) int of view ``view``'s picture around its pixel ``px``
    (the server's picture, origin top-left, ``size`` its width and height): a 3x3 patch."""
    shot, box = view_pixels(driver, view)
    w, h = size
    x = round((box["x"] + (px[0] + 0.5) * box["w"] / w) * box["dpr"] - 0.5)
    y = round((box["y"] + (px[1] + 0.5) * box["h"] / h) * box["dpr"] - 0.5)
    return shot[y - 1 : y + 2, x - 1 : x + 2].reshape(-1, 3).astype(int)


def drag_in(driver, view: str, size, start, moves) -> None:
    """Press at pixel ``start`` of view ``view``'s picture (``size`` its width and height,
    origin top-left), move by each ``(dx, dy)`` of ``moves`` (CSS pixels) and release."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    img = driver.find_element(By.CSS_SELECTOR, f'[aria-label="{view}"] img')
    w, h = size
    r = driver.execute_script("return arguments[0].getBoundingClientRect().toJSON()", img)
    ox = start[0] * r["width"] / w - r["width"] / 2
    oy = start[1] * r["height"] / h - r["height"] / 2
    chain = ActionChains(driver).move_to_element_with_offset(img, round(ox), round(oy))
    chain.click_and_hold()
    for dx, dy in moves:
        chain.move_by_offset(dx, dy)
    chain.release().perform()


def shows(driver, view: str, px, size) -> bool:
    """Whether view ``view``'s picture is white (a white light's handle or arrow) at ``px``."""
    return bool((picture_patch(driver, view, px, size).mean(axis=0) >= WHITE).all())


def test_pane_b_draws_the_handles_and_a_drag_there_moves_the_light(server, browser):
    """Compare A | B: pane B draws the arrow at its edge toward a handle out of it and the
    handle where the light projects (its pixels white, a white light's), and a drag on B's
    handle moves the light in both panes, ending under the pointer (issue 42: pane B had
    neither handles nor arrows)."""
    open_page(browser, server.url)
    click(browser, "view tab")
    click(browser, "compare")
    rep = wait("side B's arrow", lambda: (r := report(browser))["compare"]
               and r["compare"]["arrows_px"] and r)  # fmt: skip
    light = rep["session"]["light"] - 1
    size = rep["compare"]["size"]
    arrow = np.asarray(rep["compare"]["arrows_px"][str(light)]).mean(axis=0)
    wait("B's arrow in its picture", lambda: shows(browser, "view_b", arrow, size))
    click(browser, "lights tab")
    type_value(browser, "azimuth", "10")  # the handle in B's half-width view
    w, h = size

    def inside(r):
        x, y = r["compare"]["handles_px"][light]
        return 20 <= x < w - 20 and 20 <= y < h - 20 and r

    rep = wait("B's handle in its view", lambda: inside(report(browser)))
    hx, hy = rep["compare"]["handles_px"][light]
    wait("B's handle in its picture", lambda: shows(browser, "view_b", (hx, hy), size))
    before = rep["placement"]
    a_before = rep["handles_px"][light]
    sx, sy = (-1 if hx > w / 2 else 1), (1 if hy < h / 2 else -1)  # toward the middle
    drag_in(browser, "view_b", size, (hx, hy), [(8 * sx, 5 * sy)] * 10)
    target = (hx + 80 * sx, hy + 50 * sy)

    def moved(r):
        x, y = r["compare"]["handles_px"][light]
        near = abs(x - target[0]) <= 3 and abs(y - target[1]) <= 3
        return near and r["placement"] != before and not r["errors"] and r

    end = time.monotonic() + 10
    while not (rep := moved(report(browser))) and time.monotonic() < end:
        time.sleep(0.05)
    assert rep, ("B's handle ended away from the pointer", target, report(browser))
    assert rep["handles_px"][light] != a_before  # the light moved in pane A too
    wait("B's handle where it was put", lambda: shows(browser, "view_b", target, size))
    click(browser, "undo")
    click(browser, "undo")
    wait("undo", lambda: report(browser)["placement"] != rep["placement"])
    click(browser, "view tab")
    click(browser, "compare")
    wait("side B gone", lambda: report(browser)["compare"] is None)
    click(browser, "material tab")
