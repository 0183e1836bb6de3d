"""The golden folder as a whole: every file in tests/golden/ (subfolders too) belongs to a test.

This test runs after every other (tests/conftest.py puts it last) and looks at which goldens the
session's tests checked (tests/helpers/imagecompare.py records them). It can only judge a
session that ran every golden test; otherwise it is skipped and says why. When regenerating, it
removes the unused files instead of failing.
"""

from __future__ import annotations

import pytest
from helpers.imagecompare import (
    GOLDEN_DIR,
    INCOMPLETE,
    REGENERATE_COMMAND,
    USED,
    golden_files,
    regenerating,
)


def test_golden_files_all_used(request):
    if INCOMPLETE:
        pytest.skip("not every golden test ran, unused goldens not checked: " + INCOMPLETE[0])
    if request.session.testsfailed:
        pytest.skip("a test failed, unused goldens not checked")
    stale = sorted(golden_files() - USED)
    if regenerating():
        for name in stale:
            (GOLDEN_DIR / name).unlink()
        return
    assert not stale, (
        f"golden files no test uses, in {GOLDEN_DIR}: {stale}; remove them (`{REGENERATE_COMMAND}`"
        " does) or use them"
    )
