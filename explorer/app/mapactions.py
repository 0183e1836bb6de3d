"""The actions on the material's texture maps from the explorer's panel (the ``image`` rows of
:mod:`explorer.app.panelmodel`): a map's image chosen or taken away, a map turned off and on
again. A map turned off stays in the material; its key is in :attr:`State.hidden
<explorer.app.model.State.hidden>` (the terms' set: a session keeps it), and the scene shaded
and drawn (:meth:`State.shown_scene <explorer.app.model.State.shown_scene>`) has none. Each is a
pure action of the :mod:`explorer.app.model` kind (one undo step).
"""

from __future__ import annotations

import os
from dataclasses import replace

from explorer.app.model import State
from explorer.app.model import _material as with_material
from explorer.core.errors import ExplorerError
from explorer.core.texture import MAP_KEYS, TextureMap
from explorer.render.textures import read_texture


def set_map(state: State, key: str, file: str | None) -> State:
    """Texture map ``key`` of the material read from image ``file`` (its options kept), or
    taken away (None). The image is read first (:func:`explorer.render.textures.read_texture`:
    a missing, damaged, too large or non-image file is one line and nothing changes); a map
    set or taken away is drawn (it is no longer turned off)."""
    if key not in MAP_KEYS:
        raise ExplorerError(f"map must be one of {', '.join(MAP_KEYS)}, got {key!r}")
    tmap = None
    if file is not None:
        old = getattr(state.material, key)
        tmap = TextureMap(os.path.abspath(os.fspath(file)))
        if old is not None:
            tmap = replace(old, file=tmap.file)
        read_texture(tmap, key)
    state = with_material(state, state.material.replace(**{key: tmap}))
    return state.replace(hidden=state.hidden - {key})


def show_map(state: State, key: str, on: bool) -> State:
    """Texture map ``key`` drawn or turned off (the material keeps it)."""
    if key not in MAP_KEYS or getattr(state.material, key) is None:
        raise ExplorerError(f"the material has no {key} to turn on or off")
    hidden = set(state.hidden)
    (hidden.discard if on else hidden.add)(key)
    return state.replace(hidden=frozenset(hidden))
