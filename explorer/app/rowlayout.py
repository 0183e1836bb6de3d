"""How both front ends lay out and name the panel model's rows (:mod:`explorer.app.panelmodel`),
no toolkit here: a tab's rows in lines, grids and rows (:func:`lines`), each row's accessible
names (:func:`names`: the window's object and accessible names, the page's ``aria-label``), and
an image row's parts beside its thumbnail, their names and tooltips (:data:`IMAGE_PARTS`) and
what it says of its file (:func:`file_text`). The Qt rows (:mod:`explorer.app.qt.rows`) and the
page (:mod:`explorer.app.web.page`) draw them, each in its own widgets.
"""

from __future__ import annotations

import os

from explorer.app.panelmodel import Row


def lines(rows) -> list[tuple[str, tuple[Row, ...]]]:
    """``rows`` as both front ends lay them out, in order: ``("line", rows)``, a group of
    toggles or buttons side by side; ``("grid", rows)``, a group of colours or of choices
    not drawn inline (a label column and a control column; such a row alone is a grid of
    one); ``("row", (row,))``, any other row."""
    out: list[tuple[str, tuple[Row, ...]]] = []
    for r in rows:
        how = (
            "line"
            if r.kind in ("toggle", "button") and r.group
            else "grid"
            if r.kind in ("colour", "choice") and not r.inline
            else "row"
        )
        if (
            how != "row"
            and r.group
            and out
            and out[-1][0] == how
            and out[-1][1][-1].group == r.group
        ):
            out[-1] = (how, (*out[-1][1], r))
        else:
            out.append((how, (r,)))
    return out


#: an image row's parts that both front ends draw beside its thumbnail: the name's suffix ->
#: the part's tooltip (``{key}``: the row's key)
IMAGE_PARTS = {
    "file": "the {key}'s image file",
    "on": "draw the {key}",
    "choose": "choose the {key}'s image (PNG or JPEG)",
    "clear": "take the {key} away",
}


def part_name(key: str, part: str) -> str:
    """The accessible name of a part of row ``key`` in both front ends (the window's object
    and accessible name, the page's ``aria-label``): ``<key>_<part>``, as a number's
    ``slider`` and its optional ``on`` toggle, an image's :data:`IMAGE_PARTS`."""
    return f"{key}_{part}"


def image_part(r: Row, part: str) -> tuple[str, str]:
    """The accessible name and the tooltip of image row ``r``'s ``part`` (:data:`IMAGE_PARTS`)."""
    return part_name(r.key, part), IMAGE_PARTS[part].format(key=r.key)


def file_text(file: str | None) -> str:
    """What an image row says of its file: its name, or ``(none)``."""
    return "(none)" if file is None else os.path.basename(file)


def names(r: Row) -> tuple[str, ...]:
    """The accessible names of a row's widgets that both front ends give (:func:`part_name`):
    its key (the control, or the box of a control drawn as several widgets); a number's
    slider, ``<key>_slider``, and an optional number's ``<key>_on`` toggle; an image's file
    name, toggle, choose-file and clear (``<key>_file``, ``<key>_on``, ``<key>_choose``,
    ``<key>_clear``: :data:`IMAGE_PARTS`)."""
    if r.kind == "image":
        return r.key, *(image_part(r, p)[0] for p in IMAGE_PARTS)
    if r.kind == "number":
        on = (part_name(r.key, "on"),) if r.optional is not None else ()
        return r.key, part_name(r.key, "slider"), *on
    return (r.key,)
