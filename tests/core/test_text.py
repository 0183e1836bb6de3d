"""Text from files shown on a terminal (explorer.core.text)."""

from __future__ import annotations

from explorer.core.errors import Problem
from explorer.core.text import printable


def test_printable_escapes_what_a_terminal_acts_on_and_keeps_the_rest():
    assert printable("\x1b[2J\x07\x7f\x9b") == "\\x1b[2J\\x07\\x7f\\x9b"
    assert printable("a\rb\tc\nd") == "a\\rb\\tc\\nd"
    assert printable("a\nb", keep="\n") == "a\nb"
    assert printable("\u202eabc\u2028\u200b\U000e0001") == "\\u202eabc\\u2028\\u200b\\U000e0001"
    assert printable("café  Ω 金 \\x1b C:\\dir") == "café  Ω 金 \\x1b C:\\dir"
    assert printable(printable("\x1b")) == printable("\x1b")


def test_a_problem_shows_its_file_key_and_message_escaped():
    p = Problem("bad\x1b[1A\nnext", file="f\x1b.yaml", line=3, key="k\r")
    assert str(p) == "f\\x1b.yaml:3: k\\r: bad\\x1b[1A\nnext"
