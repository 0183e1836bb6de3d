"""Which triangle each pixel shows, from the rasteriser: a picture of triangle indices.

An off-screen window draws every triangle flat, unlit, in a colour that spells its index plus one
in 24 bits (red the high byte), on a black background (0: no triangle), with no multisampling or
anti-aliasing (:func:`explorer.render.vtk.plotter`), so each pixel holds exactly one index: the
triangle nearest the camera at the pixel's centre, by the depth test, as the per-vertex picture
of the same mesh and camera covers it. :func:`explorer.render.perpixel.raster_hits` turns it into
the surface points the pixels see without casting rays through a hierarchy: the window's
difference view uses it while the compiled ray kernels are not ready (a fresh install), where
the numpy tier's rays would take seconds.

VTK is imported only inside the methods that draw.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from explorer.core.errors import ExplorerError
from explorer.geometry.meshes import Mesh
from explorer.render.camera import Camera, mesh_frame
from explorer.render.offscreen import OffscreenWindow
from explorer.render.vtk import DRAW_LOCK, polydata, set_camera

#: triangles a picture of indices can tell apart (24 bits; 0 is the background)
MAX_FACES = (1 << 24) - 1


def index_colors(m: int) -> np.ndarray:
    """(m, 3) uint8: triangle i as the 24-bit number i + 1, red the high byte."""
    if m > MAX_FACES:
        raise ExplorerError(f"a picture of triangle indices holds at most {MAX_FACES:,}, got {m:,}")
    code = np.arange(1, m + 1, dtype=np.uint32)
    return np.stack([code >> 16, (code >> 8) & 255, code & 255], axis=1).astype(np.uint8)


def decode(picture: np.ndarray) -> np.ndarray:
    """(h, w) int64 triangle indices of a picture (h, w, 3) uint8 drawn in
    :func:`index_colors`; -1 on the background."""
    p = np.asarray(picture, np.int64)
    return (p[..., 0] << 16 | p[..., 1] << 8 | p[..., 2]) - 1


class FaceIdRenderer(OffscreenWindow):
    """An off-screen window that draws pictures of triangle indices (see the module
    docstring). Use as a context manager, or call :meth:`close`.

    size : (width, height) in pixels
    """

    def __init__(self, size: Sequence[int]):
        super().__init__(size, (0.0, 0.0, 0.0))

    def _forget(self) -> None:
        self._mesh = self._actor = self._frame = None

    def render(self, mesh: Mesh, camera: Camera) -> np.ndarray:
        """(h, w) int64: the index of the triangle of ``mesh`` each pixel shows, -1 where none
        (see :func:`decode`)."""
        # the window changed, drawn and read with no other thread drawing (actors added and
        # removed make and free OpenGL buffers: DRAW_LOCK covers them too)
        with DRAW_LOCK:
            pl = self.plotter
            if self._mesh is not mesh:
                if self._actor is not None:
                    pl.remove_actor(self._actor)
                self._frame = mesh_frame(mesh)  # VTK draws in the mesh's frame: any scale
                poly = polydata(mesh, normals=False, frame=self._frame)
                poly.cell_data["index"] = index_colors(mesh.n_faces)
                self._actor = pl.add_mesh(poly, scalars="index", rgb=True, lighting=False,
                                          preference="cell", show_scalar_bar=False,
                                          reset_camera=False)  # fmt: skip
                self._mesh = mesh
            set_camera(pl, camera, self._frame)
            pl.render()
            picture = pl.screenshot(return_img=True)[:, :, :3]
        return decode(picture)
