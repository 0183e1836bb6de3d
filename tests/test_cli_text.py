"""User text reaches the terminal escaped: a mesh file named with ``ESC ] 0 ; ... BEL`` (set the
window title) or ``ESC [ 2 J`` (clear the screen) was printed raw by render, sheet, turntables
and plan. Every CLI message with user text goes through ``core/text.say``."""

from __future__ import annotations

import ast
import json
from pathlib import Path

import pytest

from explorer.cli import main

ROOT = Path(__file__).resolve().parents[1]
NASTY = "m\x1b]0;owned\x07\x1b[2J\u202e"


@pytest.fixture
def nasty_mesh(tmp_path):
    path = tmp_path / f"{NASTY}.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n")
    return path


def _commands(tmp_path, mesh):
    scene = tmp_path / "s.yaml"
    scene.write_text(f"mesh: {json.dumps(str(mesh))}\nlights: [{{type: point, position: [2, 2, 2], "
                     "shadows: true}]\n")  # fmt: skip
    out = tmp_path / f"out{NASTY}"
    return {
        "render": ["render", "--mesh", str(mesh), "--out", f"{out}.png", "--size", "32x32"],
        "render --out obj": ["render", "--mesh", str(mesh), "--out", f"{out}.obj"],
        "render --out ply": ["render", "--mesh", str(mesh), "--out", f"{out}.ply"],
        "sheet": ["sheet", "--mesh", str(mesh), "--out", f"{out}-s.png", "--tile", "32x32"],
        "turntable": [
            "render",
            "--mesh",
            str(mesh),
            "--out",
            f"{out}.gif",
            "--turntable",
            "2",
            "--size",
            "32x32",
        ],  # fmt: skip
        "plan": ["plan", str(scene)],
    }


@pytest.mark.parametrize("command", ["render", "render --out obj", "render --out ply", "sheet",
                                     "turntable", "plan"])  # fmt: skip
def test_each_command_prints_a_nasty_mesh_name_escaped(tmp_path, nasty_mesh, command, capsys):
    argv = _commands(tmp_path, nasty_mesh)[command]
    assert main(argv) == 0
    out = capsys.readouterr()
    text = out.out + out.err
    assert "\\x1b]0;owned\\x07\\x1b[2J\\u202e" in text  # the name is there, escaped
    assert "\x1b" not in text and "\x07" not in text and "\u202e" not in text


def test_cli_modules_print_only_through_say():
    """No bare ``print(`` in explorer/cli: messages go through ``say`` (escaped) or a stream
    write of ``printable`` text; a ``print`` of a constant string is fine."""
    bad = []
    paths = sorted((ROOT / "explorer" / "cli").glob("*.py"))
    assert len(paths) > 5
    for path in paths:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                    and node.func.id == "print"
                    and not all(isinstance(a, ast.Constant) for a in node.args)):  # fmt: skip
                bad.append(f"{path.name}:{node.lineno}")
    assert not bad, f"print user text through explorer.core.text.say: {bad}"
