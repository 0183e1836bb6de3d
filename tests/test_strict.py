"""The suite is strict, as pyproject.toml's [tool.pytest.ini_options] says: a marker typo, a
passing xfail and an unexpected warning each fail the run. Checked by running pytest with the
project's settings on three small test files outside the suite; and each run names its slowest
tests."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

FILES = {
    "test_marker.py": "import pytest\n\n@pytest.mark.slwo\ndef test_typo():\n    pass\n",
    "test_xfail.py": "import pytest\n\n@pytest.mark.xfail\ndef test_passes():\n    pass\n",
    "test_warns.py": (
        "import warnings\n\ndef test_warns():\n"
        "    warnings.warn('something changed', DeprecationWarning)\n"
    ),
    "test_expected.py": (
        "import warnings\n\nimport pytest\n\ndef test_expected():\n"
        "    with pytest.warns(DeprecationWarning):\n"
        "        warnings.warn('on purpose', DeprecationWarning)\n"
    ),
}


def _pytest(directory: Path, *names: str) -> tuple[int, str]:
    # in one process (-n 0 after addopts' -n 2): the settings checked are the same, and two
    # workers for a few lines of tests made a run outlast its timeout on a loaded machine
    cmd = [sys.executable, "-m", "pytest", "-c", str(ROOT / "pyproject.toml"), "--rootdir",
           str(directory), "-p", "no:cacheprovider", "-q", "-rA", "-n", "0", *names]  # fmt: skip
    r = subprocess.run(cmd, cwd=directory, capture_output=True, text=True, timeout=120)
    return r.returncode, r.stdout + r.stderr


def test_marker_typos_passing_xfails_and_warnings_fail(tmp_path):
    for name, text in FILES.items():
        (tmp_path / name).write_text(text)
    # a marker typo stops the run at collection; pytest's words for it vary by version
    # ("Unknown pytest.mark.slwo" up to 9.0, "'slwo' not found in `markers` ..." from 9.2)
    status, out = _pytest(tmp_path, "test_marker.py")
    assert status != 0 and "slwo" in out and "1 passed" not in out, out
    status, out = _pytest(tmp_path, "test_xfail.py", "test_warns.py", "test_expected.py")
    assert status != 0, out
    assert "FAILED test_xfail.py::test_passes" in out and "XPASS(strict)" in out, out
    assert "FAILED test_warns.py::test_warns - DeprecationWarning: something changed" in out, out
    assert "PASSED test_expected.py::test_expected" in out, out
    # and every run names its slowest tests (addopts' --durations=25), so that each CI log
    # shows where the suite's time goes
    assert "slowest 25 durations" in out, out
