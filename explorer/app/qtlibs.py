"""Whether Qt's xcb platform can load here, asked before Qt is: no Qt, VTK or PyVista.

Qt's xcb platform plugin (PySide6's ``Qt/plugins/platforms/libqxcb.so``) links X libraries a
minimal Linux system lacks. Without them Qt prints its own five-line message naming one of them
and aborts the process (status 134). :func:`missing_libraries` finds every missing one first:
``ldd`` on the plugin (what it links, through Qt's own libraries) and a load of each library of
:data:`XCB_LIBRARIES` (what the plugin needs on every Qt 6 we know; it also serves where ``ldd``
or the plugin cannot be found). The ``gui`` command then prints :func:`missing_message`, one
line, and exits with status 3 (as without a display). It takes some tens of milliseconds (one
``ldd`` process) and caches nothing.
"""

from __future__ import annotations

import ctypes
import importlib.util
import os
import re
import subprocess
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

#: the libraries Qt's xcb platform needs that a minimal Debian lacks, with their Debian
#: packages (docs/dependencies.md's list and .ci/run's apt line)
XCB_LIBRARIES: dict[str, str] = {
    "libxcb-cursor.so.0": "libxcb-cursor0",
    "libxcb-icccm.so.4": "libxcb-icccm4",
    "libxcb-keysyms.so.1": "libxcb-keysyms1",
    "libxkbcommon-x11.so.0": "libxkbcommon-x11-0",
    "libxcb-image.so.0": "libxcb-image0",
    "libxcb-render-util.so.0": "libxcb-render-util0",
    "libxcb-shape.so.0": "libxcb-shape0",
    "libxcb-xinerama.so.0": "libxcb-xinerama0",
    "libxcb-randr.so.0": "libxcb-randr0",
}
#: Debian packages whose name does not follow the soname rule of :func:`debian_package`
PACKAGE_EXCEPTIONS: dict[str, str] = {"libglib-2.0.so.0": "libglib2.0-0"}
#: the prefixes of libraries PySide6 ships itself (missing: a broken PySide6, not apt's)
PYSIDE_OWN = ("libQt6", "libpyside6", "libshiboken6", "libicu")
#: longest wait for ``ldd`` (seconds); past it the known list alone answers
LDD_TIMEOUT = 10.0

_NOT_FOUND = re.compile(r"^\s*(\S+)\s+=>\s+not found\s*$", re.MULTILINE)
_SONAME = re.compile(r"^(lib.+?)\.so\.(\d+)")


def xcb_plugins(environ: Mapping[str, str] | None = None) -> list[Path]:
    """Qt's xcb platform plugins in the order Qt tries them: in ``QT_QPA_PLATFORM_PLUGIN_PATH``
    when that is set, then PySide6's own (Qt takes the first that loads); empty when there is
    none (Qt decides)."""
    env = os.environ if environ is None else environ
    dirs = [Path(d) for d in env.get("QT_QPA_PLATFORM_PLUGIN_PATH", "").split(os.pathsep) if d]
    spec = importlib.util.find_spec("PySide6")  # finds the package without importing it
    if spec is not None and spec.origin:
        dirs.append(Path(spec.origin).parent / "Qt" / "plugins" / "platforms")
    return [d / "libqxcb.so" for d in dirs if (d / "libqxcb.so").is_file()]


def not_found_in_ldd(text: str) -> list[str]:
    """The libraries ``ldd``'s output ``text`` reports as ``NAME => not found``, in order."""
    return list(dict.fromkeys(_NOT_FOUND.findall(text)))


def ldd_missing(plugin: Path, ldd: Sequence[str] = ("ldd",)) -> list[str]:
    """The libraries ``plugin`` links that the dynamic loader cannot find (``ldd``); empty when
    ``ldd`` is absent, fails or takes longer than :data:`LDD_TIMEOUT`."""
    try:
        r = subprocess.run([*ldd, str(plugin)], capture_output=True, text=True,
                           timeout=LDD_TIMEOUT, env=dict(os.environ, LC_ALL="C"))  # fmt: skip
    except (OSError, subprocess.SubprocessError):
        return []
    return not_found_in_ldd(r.stdout)


def unloadable(names: Sequence[str]) -> list[str]:
    """The libraries of ``names`` the dynamic loader cannot load (it loads the others into this
    process, as Qt is about to)."""
    missing = []
    for name in names:
        try:
            ctypes.CDLL(name)
        except OSError:
            missing.append(name)
    return missing


def missing_libraries(environ: Mapping[str, str] | None = None) -> list[str]:
    """The libraries Qt's xcb platform needs and this system lacks (sonames, the plugin's
    ``ldd`` order then :data:`XCB_LIBRARIES`' order); empty off Linux."""
    if not sys.platform.startswith("linux"):
        return []
    found: list[str] = []
    for plugin in xcb_plugins(environ):
        lacking = ldd_missing(plugin)
        if not lacking:  # Qt loads this one
            found = []
            break
        found = found or lacking  # the first plugin Qt tries names what is missing
    return list(dict.fromkeys(found + unloadable(list(XCB_LIBRARIES))))


def debian_package(soname: str) -> str:
    """The Debian package of a library by Debian's naming rule: ``libxcb-cursor.so.0`` ->
    ``libxcb-cursor0``, ``libxkbcommon-x11.so.0`` -> ``libxkbcommon-x11-0`` (a hyphen between
    two digits), lower case; :data:`XCB_LIBRARIES` and :data:`PACKAGE_EXCEPTIONS` first."""
    known = XCB_LIBRARIES.get(soname) or PACKAGE_EXCEPTIONS.get(soname)
    if known:
        return known
    m = _SONAME.match(soname)
    if not m:
        return soname
    stem, version = m.group(1).lower(), m.group(2)
    return f"{stem}-{version}" if stem[-1].isdigit() else f"{stem}{version}"


def missing_message(missing: Sequence[str]) -> str:
    """The one line printed when Qt's xcb platform lacks ``missing`` (sonames): which, the apt
    command that installs them, and the off-screen commands that need none of them."""
    system = [n for n in missing if not n.startswith(PYSIDE_OWN)]
    own = [n for n in missing if n.startswith(PYSIDE_OWN)]
    fixes = []
    if system:
        packages = " ".join(dict.fromkeys(debian_package(n) for n in system))
        fixes.append(f"sudo apt-get install {packages}")
    if own:
        fixes.append("pip install --force-reinstall PySide6-Essentials")
    return (
        f"phong-explorer: Qt's xcb platform lacks {', '.join(missing)} (install: "
        f"'{' && '.join(fixes)}'), so the explorer window cannot open; for pictures run "
        "'phong-explorer render --out FILE.png' or 'phong-explorer sheet --out FILE.png' "
        "(off-screen, no Qt needed)"
    )
