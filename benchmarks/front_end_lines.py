"""The front ends' lines by kind, and their classes' sizes, at a git revision (issue 38's
measure: docs/architecture.md, "The kit").

    python benchmarks/front_end_lines.py 43b0e99
    python benchmarks/front_end_lines.py HEAD

Each module of ``explorer/app/qt`` and ``explorer/app/web`` is read at the revision
(``git show``) and its lines counted by kind, one kind per top-level definition (a class whole,
but for the methods :data:`METHODS` names; the comment block above a constant with it; the
module's docstring and imports with the module's kind): *widgets* (what a person sees and
does), *transport* (pictures, state and files between the server and the page or the screen),
*security* (who may connect and what a page may send), *logic* (a decision both front ends could
share), *other* (package docstrings, the test reports). Then the sizes of the front ends'
classes with their in-package mix-ins, as ``tests/test_architecture.py`` measures them. Prints
two Markdown tables.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from test_architecture import class_size  # noqa: E402 - the test's own measure

#: each module's kind (the rest of qt/ and web/ page, panel, intents: widgets)
MODULES = {
    "qt/__init__.py": "other",
    "qt/viewport.py": "transport",
    "web/__init__.py": "other",
    "web/compare.py": "transport",
    "web/files.py": "transport",
    "web/guard.py": "security",
    "web/wire.py": "security",
    "web/pictures.py": "transport",
    "web/server.py": "transport",
    "web/jupyter.py": "transport",
}
#: top-level definitions of another kind than their module's
DEFINITIONS = {
    "web/files.py": {
        **dict.fromkeys(
            (
                "UNSAFE",
                "MAX_UPLOAD_NAME",
                "BYTES",
                "upload_name",
                "upload_name_of",
                "upload_bytes",
                "check_size",
            ),
            "security",
        ),
        "turntable_formats": "logic",
    },
    "web/panel.py": {"page_value": "security", "_kind": "security", "MESH_REFUSED": "security"},
    "web/jupyter.py": {"notebook_state": "logic"},
}
#: methods of another kind than their class's
METHODS = {
    "qt/window.py": {"report_state": "other", "widget_box": "other"},
    "web/server.py": {"report_state": "other"},
    "web/files.py": {"page_text": "security", "_upload_limit": "security"},
}
KINDS = ("widgets", "transport", "security", "logic", "other")
#: the classes whose sizes are printed
CLASSES = (
    "ExplorerWindow",
    "RowWidgets",
    "Menus",
    "MessageLog",
    "LightsTab",
    "WebExplorer",
    "WebFiles",
    "PlotterView",
)


def git(*args: str) -> str:
    return subprocess.run(
        ["git", *args], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout


def names(node: ast.stmt) -> list[str]:
    """The names a top-level statement defines."""
    if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
        return [node.name]
    targets = node.targets if isinstance(node, ast.Assign) else [getattr(node, "target", None)]
    return [t.id for t in targets if isinstance(t, ast.Name)]


def kinds(rel: str, text: str) -> Counter:
    """Module ``rel``'s lines (``text``) by kind."""
    lines = text.splitlines()
    kind = [MODULES.get(rel, "widgets")] * (len(lines) + 1)
    body = ast.parse(text).body
    for i, node in enumerate(body):
        start, before = node.lineno, body[i - 1].end_lineno if i else 0
        while start - 1 > before and lines[start - 2].lstrip().startswith("#"):
            start -= 1  # its comment block
        for name in names(node):
            if name in DEFINITIONS.get(rel, {}):
                kind[start : node.end_lineno + 1] = [DEFINITIONS[rel][name]] * (
                    node.end_lineno + 1 - start
                )
        for m in getattr(node, "body", []) if isinstance(node, ast.ClassDef) else []:
            k = METHODS.get(rel, {}).get(getattr(m, "name", ""))
            if k:
                kind[m.lineno : m.end_lineno + 1] = [k] * (m.end_lineno + 1 - m.lineno)
    return Counter(kind[1:])


def main(rev: str) -> None:
    files = [
        f
        for f in git("ls-tree", "-r", "--name-only", rev, "explorer/").split()
        if f.endswith(".py")
    ]
    texts = {f: git("show", f"{rev}:{f}") for f in files}
    total, count = Counter(), 0
    print(f"| module ({rev}) | lines | " + " | ".join(KINDS) + " |")
    print("|---" * (len(KINDS) + 2) + "|")
    for f in files:
        rel = f.removeprefix("explorer/app/")
        if rel.split("/")[0] not in ("qt", "web"):
            continue
        c = kinds(rel, texts[f])
        total += c
        count += len(texts[f].splitlines())
        print(f"| {rel} | {sum(c.values())} | " + " | ".join(str(c[k]) for k in KINDS) + " |")
    print(f"| Qt + web | {count} | " + " | ".join(str(total[k]) for k in KINDS) + " |")
    classes: dict[str, list] = {}
    for f, text in texts.items():
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ClassDef):
                classes.setdefault(node.name, []).append((f, node))
    print(f"\n| class ({rev}) | lines | methods |\n|---|---|---|")
    for name in CLASSES:
        for f, node in classes.get(name, []):
            n_lines, n_methods = class_size(node, classes)
            print(f"| {f.removeprefix('explorer/app/')}:{name} | {n_lines} | {n_methods} |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "HEAD")
