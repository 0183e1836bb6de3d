"""The one progress bar (explorer/core/progress.py): drawn in place on a terminal only; the
turntable and the accuracy benchmark both use it."""

from __future__ import annotations

import io

import pytest

from explorer.core.progress import Progress


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_drawn_on_a_terminal_only():
    term, pipe = Terminal(), io.StringIO()
    for stream in (term, pipe):
        bar = Progress("turntable", stream=stream)
        for k in range(1, 5):
            bar.update(k, 4)
        bar.close()
    assert pipe.getvalue() == ""
    text = term.getvalue()
    assert text.count("\r") == 4 and text.endswith("\n") and text.count("\n") == 1
    assert "\rturntable [" + "#" * 15 + "-" * 15 + "] 2/4  " in text
    assert "] 4/4  " in text.splitlines()[-1]


def test_steps_show_their_note_and_cover_a_longer_line():
    term = Terminal()
    bar = Progress(stream=term)
    bar.total = 3  # set after construction, as the benchmark does
    bar.step("200px sphere (32, 96)")
    bar.step("short")
    bar.close()
    first, second = term.getvalue().rstrip("\n").split("\r")[1:]
    assert first.startswith("[" + "#" * 10 + "-" * 20 + "] 1/3  ") and "sphere (32, 96)" in first
    assert second.rstrip().endswith("  short") and len(second) == len(first)  # no leftovers
    assert bar.done == 3 - 1


def test_line_format_and_eta():
    bar = Progress("x", total=4, enabled=False)
    bar.update(1)
    assert bar.line("note", elapsed=2.0) == "x [" + "#" * 7 + "-" * 23 + "] 1/4  2s  eta 6s  note"
    bar.update(9)  # more than the total: a full bar
    assert bar.line().startswith("x [" + "#" * 30 + "] 9/4")


def test_the_turntable_command_draws_it(tmp_path, monkeypatch, capsys):
    from explorer.cli import main

    term = Terminal()
    monkeypatch.setattr("sys.stderr", term)
    out = tmp_path / "spin.gif"
    argv = ["render", "--preset", "gold", "--mesh", "cube", "--size", "32x32"]
    assert main([*argv, "--turntable", "3", "--out", str(out)]) == 0
    lines = term.getvalue().split("\r")
    assert [line.split("] ")[1].split()[0] for line in lines[1:]] == ["1/3", "2/3", "3/3"]
    assert lines[1].startswith("turntable [")


@pytest.mark.parametrize("enabled", [True, False])
def test_close_without_drawing_writes_nothing(enabled):
    term = Terminal()
    Progress(stream=term, enabled=enabled).close()
    assert term.getvalue() == ""
