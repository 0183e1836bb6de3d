"""What a change re-renders in the page (issue 42: the browser's CPU per change): a kd change
writes the kd row, the diffuse colour's row (its value follows kd) and nothing else of the
drawer's rows (in the tab's one slot, every row of the tab was re-rendered twice a kd change:
Vue's patch of about 20 rows, their inputs' values written again;
benchmarks/trace_web_change.py counts the mutations per change)."""

from __future__ import annotations

import time

import pytest
from test_web import open_page, wait

from explorer.app import panelmodel

pytestmark = pytest.mark.web

#: from now on, every mutation in the page, kept as the ``aria-label`` of the nearest labelled
#: ancestor of the node that changed (``-``: none)
OBSERVE_JS = """
window.seen = [];
const label = (n) => {
  const e = n.nodeType === 1 ? n : n.parentElement;
  const a = e && e.closest('[aria-label]');
  return a ? a.getAttribute('aria-label') : '-';
};
window.observer = new MutationObserver((ms) => {
  for (const m of ms) window.seen.push(label(m.target));
});
window.observer.observe(document, {subtree: true, childList: true, attributes: true,
                                   characterData: true});
"""


@pytest.fixture(scope="module")
def page(server, browser):
    open_page(browser, server.url)
    return browser


def test_a_kd_change_re_renders_only_its_rows(page):
    """kd set as its slider sets it: the kd row and the diffuse colour's row change in the
    drawer, no other row of the material tab (failed before: every row of the tab, group,
    preset, ka, ks, shininess... had its input's value written again, twice)."""
    rows = {r.key for r in panelmodel.rows("material")}
    assert {"kd", "diffuse", "ka", "shininess"} <= rows
    state = "return window.trame.state.get(arguments[0])"
    wait("the drawer's kd", lambda: page.execute_script(state, "kd_text"))
    time.sleep(1.0)  # (the start's pictures and state settled)

    def change(step: int, watch: bool) -> list:
        before = page.execute_script(state, "kd_text")
        if watch:
            page.execute_script(OBSERVE_JS)
        page.execute_script("window.trame.state.set('kd_step', arguments[0]);", step)
        wait("the server's kd", lambda: page.execute_script(state, "kd_text") != before)
        wait("the server done", lambda: not page.execute_script(state, "trame__busy"))
        time.sleep(0.5)  # (Vue's patch of the answer, the still picture)
        return page.execute_script("window.observer?.disconnect(); return window.seen;")

    # the first change marks the material edited (material_line's "(edited)"): not watched
    change(300 if page.execute_script(state, "kd_step") > 500 else 700, watch=False)
    seen = change(900 if page.execute_script(state, "kd_step") < 500 else 100, watch=True)
    touched = {s.removesuffix("_slider").removesuffix(" picker") for s in seen} & rows
    assert touched == {"kd", "diffuse"}, sorted(touched)
