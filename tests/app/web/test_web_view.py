"""The page's view port in the server's process, with no browser: the explorer of
``explorer.app.web`` made (not served) and read through its report."""

from __future__ import annotations

import pytest

from explorer.app import model as M


def test_a_session_in_the_compare_view_starts_with_side_b(tmp_path, monkeypatch):
    """Side B is drawn from the start (a session saved in the compare view), as in the window:
    it was made only at the first change, and the page's side B showed an empty picture."""
    pytest.importorskip("trame")
    from explorer.app.web import WebExplorer, notebook_state

    monkeypatch.setenv("PHONG_EXPLORER_MATERIALS", str(tmp_path / "presets"))
    state, mesh = notebook_state(mesh="sphere")
    state = M.set_compare_model(M.set_compare(state, True), "phong")
    app = WebExplorer(state, mesh, size=(160, 120), name="test-compare-start")
    try:
        rep = app.report_state()
        assert rep["compare"] is not None and rep["compare"]["size"] == [160, 120]
        assert not rep["errors"]
    finally:
        app.close()
