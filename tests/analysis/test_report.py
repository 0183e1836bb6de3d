"""The accuracy report (explorer.analysis.report): the Markdown from its template, the Pareto
front."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from explorer.analysis import report as R
from explorer.analysis.advice import load_table
from explorer.core.errors import ExplorerError

ROOT = Path(__file__).resolve().parents[2]


@given(st.lists(st.tuples(st.floats(0, 100), st.floats(0, 100)), min_size=1, max_size=40))
def test_pareto_front_by_brute_force(points):
    t = [p[0] for p in points]
    e = [p[1] for p in points]
    front = R.pareto_front(t, e)
    for i in range(len(points)):
        dominated = any(
            (t[j] <= t[i] and e[j] <= e[i]) and (t[j] < t[i] or e[j] < e[i])
            for j in range(len(points))
        )
        if dominated:
            assert i not in front
    kept = {(t[i], e[i]) for i in front}
    for i in range(len(points)):
        if not any((t[j] <= t[i] and e[j] <= e[i]) and (t[j], e[j]) != (t[i], e[i])
                   for j in range(len(points))):  # fmt: skip
            assert (t[i], e[i]) in kept  # every undominated point is on the front once
    assert len(kept) == len(front)
    assert [t[i] for i in front] == sorted(t[i] for i in front)


# -- the Markdown ----------------------------------------------------------------------------------


def test_report_of_the_shipped_table_is_docs_accuracy_md():
    """docs/accuracy.md is the report of the shipped table, byte for byte (made with
    ``--out-dir docs``, so the plot is linked as ``accuracy.png``)."""
    table = load_table()
    text = R.markdown(table, plot="accuracy.png", command=table["command"])
    assert text.encode("utf-8") == (ROOT / "docs" / "accuracy.md").read_bytes()


def _trimmed(table):
    """A table without the optional parts: one size, no adaptive rows, no per-pixel cost, no
    OpenGL or load figures, one repeat."""
    t = copy.deepcopy(table)
    t["sides"] = [t["main_side"]]
    t["rows"] = [r for r in t["rows"] if r["side"] == t["main_side"] and r["mesh"] != "adaptive"]
    t["per_pixel"] = []
    t["repeats"] = 1
    t["quick"] = True
    for key in ("opengl", "load_before", "load_after"):
        del t["machine"][key]
    return t


def test_optional_sections_follow_the_table():
    full = R.markdown(load_table(), plot="a/b.png", command="x")
    trimmed = R.markdown(_trimmed(load_table()), plot=None, command="x")
    sections = {
        "- OpenGL: ": "- OpenGL: llvmpipe",
        "- Load average": "- Timing under load",
        "![error against time per frame, Pareto front marked](a/b.png)": "the dashed line",
        "Per-pixel reference itself": "| material | pixels | shade ms |",
        "## Adaptive refinement": "| threshold | vertices |",
        "## Picture size": "| 100x100 | 200x200 | 400x400 | 800x800 |",
    }
    for head, body in sections.items():
        assert head in full and body.lower() in full.lower()
        assert head not in trimmed and body.lower() not in trimmed.lower()
    assert "<!--" not in full + trimmed and "$" not in full + trimmed
    assert "medians of 5 runs" in full and "medians of 1 run " in trimmed
    assert "Quick run" in trimmed and "Quick run" not in full
    # nothing but the optional parts goes: the same headings otherwise, and no double blank line
    for heading in ("## Machine", "## Findings", "## Tessellation", "## Phong against Blinn",
                    "## How fine must the mesh be?"):  # fmt: skip
        assert heading in full and heading in trimmed
    assert "\n\n\n" not in full and "\n\n\n" not in trimmed
    assert full.endswith(".\n") and trimmed.endswith(".\n")


def test_fill_resolves_sections_and_placeholders():
    template = "a ${x}\n<!-- if y -->\ny is ${y}\n<!-- end y -->\nb $x\n"
    assert R.fill(template, {"x": "1", "y": "2"}) == "a 1\ny is 2\nb 1\n"
    assert R.fill(template, {"x": "$y", "y": ""}) == "a $y\nb $y\n"  # values are not templates
    with pytest.raises(ExplorerError, match=r"without a value \['y'\]"):
        R.fill(template, {"x": "1"})
    with pytest.raises(ExplorerError, match=r"without a place \['z'\]"):
        R.fill(template, {"x": "1", "y": "", "z": "3"})


def test_the_template_is_package_data():
    text = R.template_text()
    assert text.startswith("# What accuracy costs in time\n")
    assert (ROOT / "explorer" / "analysis" / R.TEMPLATE).read_text(encoding="utf-8") == text
