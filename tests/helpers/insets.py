"""The lobe inset's panel read from a view's pixels, for the front ends' tests: its width and
height as the runs of the panel's colour from inside its bottom-left corner."""

from __future__ import annotations

import numpy as np

from explorer.app import lobeinset as LI
from explorer.shading.display import to_bytes

#: how far (8-bit levels, each channel) a pixel may be from the panel's colour and still count
#: as the panel (the page's picture is a JPEG)
PANEL_LEVELS = 8


def panel_extent(img: np.ndarray) -> tuple[int, int]:
    """The inset's panel in ``img`` (h, w, 3), a view's pixels (origin top-left): its width
    and height in pixels, counted along the row and the column two pixels inside its
    bottom-left corner (in the panel's padding: nothing is drawn there)."""
    h = img.shape[0]
    colour = to_bytes(np.asarray(LI.LOBE_PANEL_COLOR)).astype(int)
    near = np.abs(img.astype(int) - colour).max(axis=2) <= PANEL_LEVELS
    m = LI.LOBE_MARGIN
    row, col = near[h - 1 - m - 2, m:], near[: h - m, m + 2][::-1]

    def run(line) -> int:
        off = np.flatnonzero(~line)
        return int(off[0]) if off.size else len(line)

    return run(row), run(col)
