"""The documentation site's parts that can be checked in seconds (the build itself is CI's
step after the tests, ``.ci/run``; the gallery's pictures: tests/docs/test_gallery.py).

README.md is the front door (at most 200 lines, the window's and the page's pictures, every link
to a file that exists), ``.ci/run`` finds both of its commands, the docstrings' ``name : what``
lines become reST that builds without warnings (docs/_ext/plain_docstrings.py), and the preset
page holds every built-in preset in its three forms (docs/_ext/preset_pages.py).
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "docs" / "_ext"))

import plain_docstrings  # noqa: E402
import preset_pages  # noqa: E402

#: the README is a front door: what the explorer is, install, the commands, the front ends, links
README_MAX_LINES = 200


def _readme() -> str:
    return (ROOT / "README.md").read_text(encoding="utf-8")


def test_readme_is_a_front_door():
    text = _readme()
    assert len(text.splitlines()) <= README_MAX_LINES
    assert "](docs/gui.png)" in text and "](docs/web.png)" in text
    missing = [
        link
        for link in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text)
        if "://" not in link and not (ROOT / link).exists()
    ]
    assert not missing, missing


def test_ci_runs_the_readme_commands():
    """``.ci/run``'s own function finds the test command and then the docs command."""
    script = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    function = re.search(r"^readme_command\(\) \{\n.*?^\}\n", script, re.M | re.S)
    assert function, "no readme_command in .ci/run"
    assert "for step in test-command docs-command" in script
    found = [
        subprocess.run(
            ["bash", "-c", f"{function.group(0)}readme_command {step}"],
            cwd=ROOT, capture_output=True, text=True, check=True, timeout=30,
        ).stdout.strip()
        for step in ("test-command", "docs-command")
    ]  # fmt: skip
    assert found == [
        'pip install -e ".[test]" && python -m pytest',
        'pip install -e ".[docs]" && python -m sphinx -W --keep-going -b html docs '
        "docs/_build/html",
    ]


def test_docstring_items_become_a_list():
    lines = [
        "The per-pixel reference.",
        "",
        "scene, mesh : what is shown",
        "size : (width, height) of the",
        "    pictures compared",
        "camera : an explorer.render.camera.Camera (default",
        ":func:`camera_for`)",
        "Returns a :class:`Reference`.",
        "",
        "Example::",
        "",
        "    x : kept",
        "        as it is",
    ]
    assert plain_docstrings.rewrite(lines) == [
        "The per-pixel reference.",
        "",
        "- ``scene, mesh`` : what is shown",
        "- ``size`` : (width, height) of the pictures compared",
        "- ``camera`` : an explorer.render.camera.Camera (default :func:`camera_for`)",
        "",
        "Returns a :class:`Reference`.",
        "",
        "Example::",
        "",
        "    x : kept",
        "        as it is",
    ]


def test_preset_page_holds_every_builtin_preset_in_three_forms():
    presets = preset_pages.builtin_presets()
    names = [name for name, _, _ in presets]
    assert len(names) == len(list((ROOT / "materials").glob("*.yaml"))) and "gold" in names
    page = preset_pages.page(presets, "swatches")
    for name, path, _ in presets:
        assert f"## {name}\n" in page and f"](swatches/{name}.png)" in page
        assert path.read_text(encoding="utf-8").rstrip() in page  # the YAML as it is
        assert f"newmtl {name}\n" in page  # the .mtl form
    assert page.count('"type": "MeshPhongMaterial"') == len(names)  # the three.js form


def test_every_page_is_in_the_site():
    """Each docs/*.md page is in a toctree of docs/index.md (the build refuses a page in none;
    this says so in seconds, before the build, and names the line to add)."""
    index = (ROOT / "docs" / "index.md").read_text(encoding="utf-8")
    listed = set()
    for block in re.findall(r"```\{toctree\}\n(.*?)```", index, re.S):
        listed |= {line.strip() for line in block.splitlines() if line.strip()[:1].isalnum()}
    pages = {p.stem for p in (ROOT / "docs").glob("*.md")} - {"index"}
    assert not pages - listed, (
        f"pages in no toctree of docs/index.md: {sorted(pages - listed)}; add each to the "
        "'User guide' or 'Reference' toctree there"
    )
    assert not {name for name in listed - pages if "/" not in name}, listed - pages
