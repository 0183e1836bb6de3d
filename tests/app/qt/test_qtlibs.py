"""The Qt start-up check (explorer/app/qtlibs.py): the libraries Qt's xcb platform lacks are
found before Qt is asked to start, and ``phong-explorer gui`` says so in one line with the apt
command, exit status 3, instead of Qt's abort (status 134)."""

from __future__ import annotations

import os
import shutil
import stat
import subprocess
import sys
import textwrap

import pytest

from explorer.app import qtlibs as Q
from explorer.app.start import NO_DISPLAY_STATUS

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux (X11) only")

#: ldd's output on a minimal Debian, abridged
LDD_OUTPUT = """\
\tlinux-vdso.so.1 (0x00007ffd1c9f2000)
\tlibQt6XcbQpa.so.6 => /opt/PySide6/Qt/plugins/platforms/../../lib/libQt6XcbQpa.so.6 (0x7f1)
\tlibxcb-cursor.so.0 => not found
\tlibxcb.so.1 => /lib/x86_64-linux-gnu/libxcb.so.1 (0x00007f5e4c5c5000)
\tlibxkbcommon-x11.so.0 => not found
\tlibxcb-cursor.so.0 => not found
\tlibX11-xcb.so.1 => not found
"""
ABSENT = "libphong-explorer-absent.so.0"


def test_ldd_output_is_read():
    assert Q.not_found_in_ldd(LDD_OUTPUT) == [
        "libxcb-cursor.so.0", "libxkbcommon-x11.so.0", "libX11-xcb.so.1",
    ]  # fmt: skip
    assert Q.not_found_in_ldd("\tlibc.so.6 => /lib/libc.so.6 (0x1)\n") == []


def test_ldd_is_run_on_the_plugin(tmp_path):
    fake = tmp_path / "ldd"
    fake.write_text(f"#!/bin/sh\ntest -f \"$1\" && cat <<'EOF'\n{LDD_OUTPUT}EOF\n")
    fake.chmod(fake.stat().st_mode | stat.S_IXUSR)
    plugin = tmp_path / "libqxcb.so"
    plugin.write_bytes(b"")
    assert Q.ldd_missing(plugin, ldd=[str(fake)])[0] == "libxcb-cursor.so.0"
    assert Q.ldd_missing(plugin, ldd=[str(tmp_path / "no-ldd")]) == []  # no ldd: the list answers


def test_a_broken_plugin_names_what_it_lacks(tmp_path):
    """The real ldd on a copy of PySide6's plugin away from Qt's libraries: they are missing."""
    plugins = Q.xcb_plugins({})
    if not plugins or shutil.which("ldd") is None:
        pytest.skip("needs PySide6's xcb plugin and ldd")
    copy = tmp_path / "platforms" / "libqxcb.so"
    copy.parent.mkdir()
    shutil.copy2(plugins[-1], copy)
    assert "libQt6XcbQpa.so.6" in Q.ldd_missing(copy)
    # Qt falls back to its own plugin when QT_QPA_PLATFORM_PLUGIN_PATH's does not load
    assert Q.xcb_plugins({"QT_QPA_PLATFORM_PLUGIN_PATH": str(copy.parent)})[0] == copy
    assert Q.missing_libraries({"QT_QPA_PLATFORM_PLUGIN_PATH": str(copy.parent)}) == []


def test_the_probe_finds_a_library_of_its_list_missing(monkeypatch):
    # this machine has every library of the list (the window tests need them)
    assert Q.missing_libraries() == []
    monkeypatch.setitem(Q.XCB_LIBRARIES, ABSENT, "libphong-explorer-absent0")
    assert Q.missing_libraries() == [ABSENT]


def test_debian_package_names():
    assert Q.debian_package("libxcb-cursor.so.0") == "libxcb-cursor0"
    assert Q.debian_package("libxcb-render-util.so.0") == "libxcb-render-util0"
    assert Q.debian_package("libxkbcommon-x11.so.0") == "libxkbcommon-x11-0"
    assert Q.debian_package("libX11-xcb.so.1") == "libx11-xcb1"
    assert Q.debian_package("libxcb-util.so.1") == "libxcb-util1"
    assert Q.debian_package("libdbus-1.so.3") == "libdbus-1-3"
    assert Q.debian_package("libglib-2.0.so.0") == "libglib2.0-0"


def test_the_message_is_one_line_with_the_apt_command():
    line = Q.missing_message(["libxcb-cursor.so.0", "libxkbcommon-x11.so.0"])
    assert "\n" not in line and line.startswith("phong-explorer: ")
    assert "libxcb-cursor.so.0, libxkbcommon-x11.so.0" in line
    assert "'sudo apt-get install libxcb-cursor0 libxkbcommon-x11-0'" in line
    assert "'phong-explorer render --out FILE.png'" in line
    broken = Q.missing_message(["libQt6XcbQpa.so.6"])
    assert "apt-get" not in broken and "pip install --force-reinstall PySide6" in broken


#: ``phong-explorer gui`` with one more library in the probe's list, one this system lacks
GUI_WITH_ABSENT_LIBRARY = textwrap.dedent(f"""
    import sys
    from explorer.app import qtlibs
    qtlibs.XCB_LIBRARIES[{ABSENT!r}] = "libphong-explorer-absent0"
    from explorer.cli import main
    sys.exit(main(sys.argv[1:]))
""")


def test_gui_says_what_is_missing_in_one_line_and_exits_3(xdisplay):
    env = dict(os.environ)
    env.pop("VTK_DEFAULT_OPENGL_WINDOW", None)
    cmd = [sys.executable, "-c", GUI_WITH_ABSENT_LIBRARY, "gui", "--exit-after", "5"]
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)
    lines = r.stderr.strip().splitlines()
    assert r.returncode == NO_DISPLAY_STATUS, r.stderr
    assert len(lines) == 1, lines
    assert f"lacks {ABSENT} (install: 'sudo apt-get install libphong-explorer-absent0')" in lines[0]
    assert "phong-explorer render" in lines[0] and r.stdout == ""


def test_docs_show_the_line_as_printed():
    """docs/dependencies.md (the README's *Dependencies and why*, moved) and docs/gui.md quote
    the line."""
    from pathlib import Path

    docs = Path(__file__).resolve().parents[3] / "docs"
    line = Q.missing_message(["libxcb-cursor.so.0", "libxcb-icccm.so.4"])
    for page in ("dependencies.md", "gui.md"):
        assert line in (docs / page).read_text(encoding="utf-8"), page
