"""The panel model's rows of the material's texture maps (:mod:`explorer.app.panelmodel`'s
``image`` rows, after the material's own rows): each map of
:data:`~explorer.core.texture.MAP_KEYS` with its thumbnail, its file's name, on / off,
choose-file and clear, shown when the mesh has (u, v); else the line ``maps_note`` says why
not. Their actions are :mod:`explorer.app.mapactions`.
"""

from __future__ import annotations

from explorer.app import mapactions as A
from explorer.app import model as M
from explorer.core.texture import MAP_KEYS

#: why a mesh's texture maps are not shown
NO_UV = "this mesh has no texture coordinates: its texture maps are not shown"


def _map_edit(key: str):
    """An image row's edit: a file name chooses the map's image, None takes the map away,
    True / False turns it on / off; each one undo step named by what it did."""

    def edit(s: M.State, v):
        if isinstance(v, bool):
            return A.show_map, (key, v), f"{key} {'on' if v else 'off'}"
        if v is None:
            return A.set_map, (key, None), f"clear {key}"
        return A.set_map, (key, str(v)), f"{key} file"

    return edit


def map_rows() -> list:
    """The material's texture maps, after its own rows: shown when the mesh has (u, v), else
    one line says why not."""
    # the panel model calls this while it is made (its Row exists by then; it imports this)
    from explorer.app.panelmodel import Row
    from explorer.app.panelmodel import _read_only as read_only  # (as above)

    def shown(key):
        def value(s: M.State):
            tmap = getattr(s.material, key)
            return (None, False) if tmap is None else (tmap.file, key not in s.hidden)

        return value

    return [
        Row(
            "maps_note",
            "material",
            "text",
            lambda s: NO_UV,
            read_only("maps_note"),
            lambda s: not s.mesh_uv,
        ),
        *(
            Row(
                key,
                "material",
                "image",
                shown(key),
                _map_edit(key),
                lambda s: s.mesh_uv,
                tip=f"the material's {key}: choose an image (PNG or JPEG), turn it off, clear it",
            )
            for key in MAP_KEYS
        ),
    ]
