"""Fixtures of the model's tests."""

import pytest

from explorer.core import presets


@pytest.fixture
def isolated_user_dir(tmp_path, monkeypatch):
    """An empty, not yet existing user preset directory of the test's own (and no notice
    remembered from an earlier test)."""
    d = tmp_path / "user-config" / "materials"
    monkeypatch.setenv(presets.ENV_VAR, str(d))
    monkeypatch.setattr(presets, "_NOTICED", set())
    return d
