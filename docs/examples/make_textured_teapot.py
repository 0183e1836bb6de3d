"""Writes the textured example: textured_teapot.obj (Newell's teapot, 6 samples per patch edge,
with each Bézier patch's own (u, v) as ``vt``), textured_teapot.mtl (one material whose
``map_Kd`` names tiles.png) and tiles.png (a 32 x 32 pattern of coloured tiles with a white
grout, made here). Run from the repository root: ``python docs/examples/make_textured_teapot.py``.

Then ``phong-explorer render --mesh docs/examples/textured_teapot.obj --out teapot.png`` draws
it as OpenGL 2.1 would (GL_MODULATE), ``--color-control separate`` with the highlight added
after the texture (docs/formats.md, "Textures").
"""

from pathlib import Path

import numpy as np

from explorer.core.atomic import write_atomic
from explorer.core.material import Material
from explorer.geometry import meshes as M
from explorer.render.exports import obj_files
from explorer.render.images import encode_png

HERE = Path(__file__).resolve().parent
#: the tiles' colours (8-bit RGB), one per tile of a 4 x 4 grid
TILES = np.array(
    [
        [[214, 96, 77], [244, 180, 62], [92, 168, 112], [70, 120, 190]],
        [[244, 180, 62], [92, 168, 112], [70, 120, 190], [214, 96, 77]],
        [[92, 168, 112], [70, 120, 190], [214, 96, 77], [244, 180, 62]],
        [[70, 120, 190], [214, 96, 77], [244, 180, 62], [92, 168, 112]],
    ],
    np.uint8,
)
#: the material: a glossy glaze whose diffuse colour the tiles modulate
MATERIAL = Material(
    ambient=(0.2, 0.2, 0.2),
    diffuse=(1.0, 1.0, 1.0),
    specular=(0.8, 0.8, 0.8),
    shininess=40.0,
    diffuse_map="tiles.png",
)


def tiles(size: int = 32) -> np.ndarray:
    """(size, size, 3) uint8: the 4 x 4 tiles, each with a one-pixel white grout."""
    cell = size // 4
    image = np.repeat(np.repeat(TILES, cell, axis=0), cell, axis=1)
    grout = (np.arange(size) % cell) == 0
    image[grout, :] = 255
    image[:, grout] = 255
    return image


def main() -> None:
    mesh = M.teapot(6, uv=True)
    obj, mtl = obj_files(mesh, [("Tiles", MATERIAL)], "textured_teapot.mtl")
    write_atomic(HERE / "textured_teapot.obj", obj, overwrite=True)
    write_atomic(HERE / "textured_teapot.mtl", mtl, overwrite=True)
    write_atomic(HERE / "tiles.png", encode_png(tiles()), overwrite=True)


if __name__ == "__main__":
    main()
