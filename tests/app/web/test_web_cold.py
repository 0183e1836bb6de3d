"""On a cold compile cache the page draws at once with the numpy tier (the same colours) and
says so; once the background compile is done the compiled kernels serve (as the desktop's
window does: tests/app/qt/test_window.py). The explorer is served in this process
(``explorer.app.web.show``), so that the engine's tiers can be made cold."""

from __future__ import annotations

import pytest

from explorer.geometry.meshes import get_mesh

pytestmark = pytest.mark.web


def test_a_cold_cache_serves_the_numpy_tier_then_the_compiled_one(cold_tiers, tmp_path):
    from test_web import by_name, check_probe, open_page, report, type_value, wait
    from webserver import need_browser, new_browser

    from explorer.app import web
    from explorer.shading import tiers

    need_browser()
    with pytest.warns(Warning, match="preparing the compiled engine"):
        shown = web.show(mesh="sphere")
    driver = new_browser(tmp_path)
    try:
        open_page(driver, shown.url)
        assert "preparing the compiled engine" in by_name(driver, "engine").text
        mesh = get_mesh("sphere", 128, uv=True)
        check_probe(driver, mesh)
        drawing = shown.app.view.drawings[0].shader
        assert drawing.stats["numpy"] >= 1 and drawing.stats["pass"] == 0
        cold_tiers.write_text("{}")  # the background compile is done
        type_value(driver, "kd", "0.4")
        wait("the compiled kernels", lambda: tiers.loaded(), 600)
        type_value(driver, "kd", "0.5")
        wait("kd 0.5", lambda: report(driver)["session"]["scene"]["material"] is not None
             and abs(shown.state.material.scalars()[1] - 0.5) < 1e-12)  # fmt: skip
        wait("the engine line to go", lambda: not by_name(driver, "engine").is_displayed())
        assert drawing.stats["pass"] >= 1  # the compiled kernels drew
        check_probe(driver, mesh)
    finally:
        driver.quit()
        shown.stop()
