"""The package's docstrings as reST: a small ``autodoc-process-docstring`` hook.

The docstrings follow one plain convention, readable in ``help()``: ``name : what it is`` lines,
each possibly continued on lines indented under it, often straight after a paragraph line.
reST reads an indented line after a paragraph as an error ("Unexpected indentation") and a
term over an indented line as a definition list that must end with a blank line, so the API
reference would not build with warnings as errors. This hook, which changes no source file:

- joins each continuation line to the line it continues (an indented line after a non-blank
  line, outside a literal block: after ``::`` or a ``>>>`` example everything indented is
  kept as it is);
- turns each run of ``name : what`` lines into a bullet list, ``name`` set as code, with a
  blank line before and after it (a line right after an item that does not start with a
  capital letter continues the item, as ``help()`` reads it).

So the site shows the docstrings as ``help()`` does, one item a line.
"""

from __future__ import annotations

import re

#: a "name : what" item: a short name (words, commas, brackets, dots, ``|``, ``*``), " : ",
#: then its description
ITEM = re.compile(r"^(?P<name>[\w*][\w\s,.*|()\[\]`'/-]{0,60}?) : (?P<what>\S.*)$")


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip())


def rewrite(lines: list[str]) -> list[str]:
    """The docstring's lines (as autodoc hands them, common indentation removed), as reST."""
    joined: list[str] = []
    literal_at: int | None = None  # the indentation of the line that opened a literal block
    for line in lines:
        if literal_at is not None:
            if not line.strip() or _indent(line) > literal_at:
                joined.append(line)
                continue
            literal_at = None
        stripped = line.strip()
        if stripped.endswith("::") or stripped.startswith(">>>"):
            literal_at = _indent(line)
            joined.append(line)
            continue
        previous = joined[-1] if joined else ""
        if stripped and previous.strip() and _indent(line) > _indent(previous):
            joined[-1] = f"{previous.rstrip()} {stripped}"
        else:
            joined.append(line)
    out: list[str] = []
    in_list = False
    for line in joined:
        m = ITEM.match(line) if _indent(line) == 0 else None
        if m and " " in m["name"].strip() and m["name"][0].isupper():
            m = None  # a sentence ("Returns colours : ..."), not a name
        if m:
            if not in_list and out and out[-1].strip():
                out.append("")
            out.append(f"- ``{m['name'].strip()}`` : {m['what']}")
            in_list = True
            continue
        if in_list and line.strip() and not line.strip()[0].isupper():
            out[-1] = f"{out[-1].rstrip()} {line.strip()}"  # an item continued unindented
            continue
        if in_list and line.strip():
            out.append("")
        in_list = False
        out.append(line)
    return out


def _process(app, what, name, obj, options, lines) -> None:
    lines[:] = rewrite(lines)


def setup(app):
    app.connect("autodoc-process-docstring", _process, priority=600)  # after napoleon
    return {"parallel_read_safe": True, "parallel_write_safe": True}
