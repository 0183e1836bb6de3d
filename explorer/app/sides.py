"""The compare view's side B, for both front ends (no toolkit): side B's
:class:`~explorer.app.view.SceneView` given side B's state, or "A − B" (the difference of the two
sides' colours per vertex, largest channel in 1/255 levels, in the difference view's colours),
and both sides' captions."""

from __future__ import annotations

import numpy as np

from explorer.app import model as M
from explorer.shading.display import to_bytes


def show_side_b(view_a, view_b, old: M.State | None, new: M.State) -> None:
    """``view_b`` (side B's SceneView beside ``view_a``, side A's) shows ``new``'s side B, or
    A − B; the captions say which side is which. ``new.compare`` must be set."""
    b = M.side_b(new)
    if view_b.mesh is not view_a.mesh:
        view_b.set_mesh(view_a.mesh, b)
    else:
        view_b.show_state(b)
    if new.compare_difference:
        a = view_a.displayed_colors().astype(np.int16)
        other = to_bytes(view_b.drawings[0].colors()).astype(np.int16)
        view_b.paint_levels(np.abs(a - other).max(axis=1))
    elif old is not None and old.compare_difference:
        view_b.drawings[0].upload()
    view_a.set_caption(f"A: {new.preset or 'scene material'} ({new.scene.model})")
    view_b.set_caption("A − B (levels, as the difference view)" if new.compare_difference
                       else f"B: {new.compare_preset or 'material'} "
                       f"({new.compare_model})")  # fmt: skip
