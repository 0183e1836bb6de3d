"""The term strip off screen (:mod:`explorer.shading.strip`): one labelled picture.

::

    emission | ambient | diffuse | specular | sum | overflow       all lights (weighted)
    emission | ambient | diffuse | specular | sum | overflow       light 1: directional
    ...                                                            (``lights=True``)
    overflow: 3.2% of the surface: ...                             the caption

Every tile is drawn by the same renderer with the same camera as ``phong-explorer render``
(:func:`~explorer.render.offscreen.camera_for` at the tile's size), and without text on it: the
sum tile of the first row *is* the render of the scene at that size, bit for bit. The names are
drawn in bands of their own above the rows, the caption in one below them. The ``overflow`` tile
is the sum tile with every vertex the display clamped in :data:`OVERFLOW_COLOR`.

A row per light (``lights=True``) shows what that light alone adds: its own ambient, diffuse and
specular terms and their sum, with no emission and no scene ambient
(:func:`~explorer.shading.strip.light_scene`).

A mesh file's own materials (``materials``: one per group of ``mesh.groups``, as ``render``
draws the file) give each group's tiles its own material's terms
(:func:`~explorer.shading.strip.grouped_strip`): the sum tile is then ``render`` of the file in
its materials, bit for bit. VTK is imported inside the functions.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from explorer.core.errors import ExplorerError
from explorer.geometry.meshes import Mesh
from explorer.render.images import check_picture_pixels, check_size
from explorer.render.offscreen import BACKGROUND, LABEL_COLOR, OffscreenRenderer, OffscreenWindow
from explorer.shading.display import engine_clamps, to_bytes
from explorer.shading.shader import Shader
from explorer.shading.strip import (
    TERMS,
    Strip,
    caption,
    grouped_strip,
    light_scene,
    shader_strip,
)

#: the tiles of a row: the strip's terms, then the overflow mask
COLUMNS = (*TERMS, "overflow")
#: the colour of the vertices the display clamped, on the overflow tile (magenta: no material
#: preset has it, so it reads on gold, jade and chrome alike)
OVERFLOW_COLOR = (1.0, 0.0, 1.0)
#: the caption of a strip of several materials (each row's title gives its own overflow)
OVERFLOW_NOTE = (
    "overflow (magenta): where the terms add up to more than 1 the sum tile saturates "
    "(clamped), so the 8-bit tiles add up to more than it"
)
#: default tile size of the strip (pixels)
STRIP_TILE = (160, 160)
#: the text bands' height as a multiple of their font size
BAND_LINE = 1.6


@dataclass(frozen=True)
class StripPicture:
    """The picture (H, W, 3) uint8, the strips of its rows (the scene's first, then one per
    light) and their names, the tile boxes ``(x, y, w, h)`` (pixels, origin top-left) by
    (row, column name), and the caption line."""

    image: np.ndarray
    strips: tuple
    rows: tuple
    boxes: dict
    caption: str


def scene_rows(scene, *, lights: bool = False, materials=None) -> list:
    """``(name, Scene, materials)`` rows of a strip: the scene, and with ``lights`` each of its
    lights alone (:func:`~explorer.shading.strip.light_scene`; the groups' ``materials``, when
    given, with no emission either)."""
    rows = [("all lights", scene, materials)]
    if lights:
        dark = materials
        if materials is not None:
            dark = tuple(m.replace(emission=(0.0, 0.0, 0.0)) for m in materials)
        for i, light in enumerate(scene.lights):
            rows.append((f"light {i + 1}: {light.type}", light_scene(scene, i), dark))
    return rows


def mesh_strip(scene, mesh: Mesh, mode: str = "weighted", materials=None) -> Strip:
    """The strip of ``scene`` on the mesh's vertices (float64, the mesh's triangles for
    shadows), as the render draws them; ``materials``: one per group of ``mesh.groups``, each
    group's tiles in its own (:func:`~explorer.shading.strip.grouped_strip`)."""
    shader = Shader(
        scene,
        mesh.positions,
        mesh.normals,
        precision="float64",
        clamp=engine_clamps(scene),
        faces=mesh.faces,
    )
    if materials is None:
        return shader_strip(shader, mode)
    groups = mesh.groups
    if groups is None or len(materials) != len(groups.names):
        n = 0 if groups is None else len(groups.names)
        raise ExplorerError(f"need one material per group of the mesh ({n}), got {len(materials)}")
    rows = [groups.vertices(g) for g in range(len(groups.names))]
    return grouped_strip(shader, rows, materials, mode)


def overflow_colors(strip: Strip) -> np.ndarray:
    """The overflow tile's colours: the sum tile's, :data:`OVERFLOW_COLOR` where clamped."""
    c = np.array(strip.tiles["sum"], np.float64)
    c[strip.overflow] = OVERFLOW_COLOR
    return c


def render_strip(
    scene,
    mesh: Mesh,
    *,
    tile: Sequence[int] = STRIP_TILE,
    mode: str = "weighted",
    lights: bool = False,
    background=BACKGROUND,
    materials=None,
) -> StripPicture:
    """The strip of ``scene`` on ``mesh`` as one labelled picture (see the module docstring),
    captioned with the first row's overflow (:func:`~explorer.shading.strip.caption`);
    ``materials``: the mesh file's own, one per group."""
    rows = scene_rows(scene, lights=lights, materials=materials)
    return strip_picture(rows, mesh, tile=tile, mode=mode, background=background)


def strip_picture(
    rows,
    mesh: Mesh,
    *,
    tile: Sequence[int] = STRIP_TILE,
    mode: str = "weighted",
    background=BACKGROUND,
    gap: int = 2,
    note: str | None = None,
) -> StripPicture:
    """A strip per ``(name, Scene)`` or ``(name, Scene, materials)`` of ``rows`` on ``mesh``
    (``materials``: None, or one per group of ``mesh.groups``), one row of tiles each under a
    band with its name, the mode and its overflow, and a band of the tiles' names; ``note``
    (default: the first row's caption) in a band below them."""
    tw, th = check_size(tile)
    rows = list(rows)
    if not rows:
        raise ExplorerError("no rows to put in the strip")
    cols = len(COLUMNS)
    width = cols * tw + (cols + 1) * gap
    font = max(8, min(16, th // 10))
    band = max(16, int(round(BAND_LINE * font)))  # (the smallest window: 16 pixels)
    height = len(rows) * (2 * band + th) + band + gap
    check_picture_pixels(width, height, f"strip of {len(rows)} rows of {tw}x{th} tiles")
    out = np.empty((height, width, 3), np.uint8)
    out[:] = to_bytes([background])[0]
    boxes, strips, names = {}, [], []
    centres = [gap + i * (tw + gap) + tw / 2.0 for i in range(cols)]
    heads = [(x, c, "centre") for x, c in zip(centres, COLUMNS, strict=True)]
    with OffscreenRenderer((tw, th), background) as r, TextBand((width, band), background) as t:
        y = 0
        for row, (name, scene, *own) in enumerate(rows):
            strip = mesh_strip(scene, mesh, mode, own[0] if own else None)
            title = f"{name} ({mode}), overflow {100.0 * strip.overflow_fraction:.1f}%"
            out[y : y + band] = t.draw([(gap + 4, title, "left")], font)
            out[y + band : y + 2 * band] = t.draw(heads, font)
            y += 2 * band
            for i, col in enumerate(COLUMNS):
                colors = overflow_colors(strip) if col == "overflow" else strip.tiles[col]
                x = gap + i * (tw + gap)
                out[y : y + th, x : x + tw] = r.render(scene, mesh, colors)
                boxes[(row, col)] = (x, y, tw, th)
            y += th
            strips.append(strip)
            names.append(name)
        line = caption(strips[0]) if note is None else note
        out[y : y + band] = t.draw([(gap + 4, line, "left")], font)
    return StripPicture(out, tuple(strips), tuple(names), boxes, line)


class TextBand(OffscreenWindow):
    """An off-screen window of one band of text: :meth:`draw` puts strings at x positions
    (pixels from the left, each ``left`` aligned or ``centre``d), vertically centred, each
    made smaller (down to 7 px) while it is wider than the band allows it."""

    def _forget(self) -> None:
        self._actors: list = []

    def draw(self, items, font: int) -> np.ndarray:
        import vtkmodules.vtkRenderingFreeType  # noqa: F401 - registers the text renderer
        from vtkmodules.vtkRenderingCore import vtkTextActor

        pl = self.plotter
        w, h = self.size
        for a in self._actors:
            pl.renderer.RemoveActor(a)
        self._actors = []
        room = w / max(len(items), 1) if len(items) > 1 else w - 8
        for x, text, align in items:
            if align not in ("left", "centre"):
                raise ExplorerError(f"align must be left or centre, got {align!r}")
            a = vtkTextActor()
            a.SetInput(str(text))
            prop = a.GetTextProperty()
            prop.SetColor(*LABEL_COLOR)
            prop.SetFontFamilyToArial()
            prop.ShadowOff()
            prop.SetVerticalJustificationToCentered()
            if align == "centre":
                prop.SetJustificationToCentered()
            size = font
            while size > 7:
                prop.SetFontSize(size)
                extent = [0.0, 0.0]
                a.GetSize(pl.renderer, extent)
                if extent[0] <= room - 4:
                    break
                size -= 1
            prop.SetFontSize(size)
            a.SetPosition(float(x), h / 2.0)
            pl.renderer.AddActor(a)
            self._actors.append(a)
        pl.render()
        return np.ascontiguousarray(pl.screenshot(return_img=True)[:, :, :3])
