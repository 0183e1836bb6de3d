"""The explorer's difference view: the per-pixel error of the current view as a heat map.

The toggle ``difference`` (a check box in the mesh section of the panel, key ``d``) compares
what the window shows, per-vertex colours interpolated across each triangle, with the same
lighting evaluated at every pixel (:func:`explorer.analysis.comparison.compare_view`: the exact
sphere for the built-in spheres, ray casting with interpolated normals for any other mesh), for
the current camera, window size, mesh, material and lights. The error of each pixel, in 1/255
levels, is drawn with :func:`explorer.analysis.comparison.heat_map` as the renderer's background
while the mesh is hidden, so the map sits exactly where the mesh is drawn. A legend gives the
RMSE and the worst pixel, and a second text gives :func:`explorer.analysis.advice.advice`: which
tessellation keeps the error within one level for the current shininess at this window's size.

One comparison costs two off-screen renders and the per-pixel reference at the window's size
(a few hundred ms), so the explorer computes it once a change is complete: at once after a key
or a button, on release after a drag; while something is dragged the live view is shown.
PyVista and VTK are imported only inside the methods that need them.
"""

from __future__ import annotations

import numpy as np

from explorer.analysis import comparison as A
from explorer.shading.display import to_bytes

#: the error (1/255 levels) drawn white; the ramp below it is logarithmic (see heat_map)
VMAX = 16.0

#: what the legend says while a comparison is being made or waits for a drag to end
PENDING = "difference: waiting for the change to end (the live view meanwhile)"


class DifferenceView:
    """The heat map, shown in a renderer's background, and what it was computed for.

    renderer : the explorer's vtkRenderer
    on : the toggle
    comparison : the last :class:`explorer.analysis.comparison.Comparison` (or None)
    key : what the shown map was computed for (the explorer decides what goes in it)
    """

    def __init__(self, renderer):
        self.renderer = renderer
        self.on = False
        self.comparison = None
        self.key = None
        self.shown = False
        self._comparer = None
        self._texture = None

    def stale(self, key) -> bool:
        """Whether the shown map no longer matches ``key``."""
        return self.comparison is None or key != self.key

    def compute(self, scene, mesh, colors, camera, size, key, background) -> None:
        """Compare the view and make its heat map (not shown until :meth:`show`).

        scene, mesh : what the window shows; colors : (n, 3) the displayed colours in [0, 1]
        camera : an :class:`explorer.render.camera.Camera` of the window's camera
        size : (width, height) of the window; background : RGB in [0, 1] for uncovered pixels
        """

        size = tuple(int(v) for v in size)
        if self._comparer is None or self._comparer.size != size:
            self.close()
            self._comparer = A.ViewComparer(size)
        c = self._comparer.compare(scene, mesh, camera=camera, colors=colors)
        bg = tuple(int(v) for v in to_bytes([background])[0])
        self._set_image(A.heat_map(c.levels, c.mask, vmax=VMAX, background=bg))
        self.comparison = c
        self.key = key

    def _set_image(self, image: np.ndarray) -> None:
        from vtkmodules.util.numpy_support import numpy_to_vtk
        from vtkmodules.vtkCommonDataModel import vtkImageData
        from vtkmodules.vtkRenderingCore import vtkTexture

        h, w, _ = image.shape
        data = vtkImageData()
        data.SetDimensions(w, h, 1)
        rows = np.ascontiguousarray(image[::-1].reshape(-1, 3))  # VTK's rows start at the bottom
        arr = numpy_to_vtk(rows, deep=True)
        arr.SetName("heat")
        data.GetPointData().SetScalars(arr)
        tex = vtkTexture()
        tex.SetInputData(data)
        tex.InterpolateOff()  # one texel per pixel: no blur
        self._texture = tex
        self.renderer.SetBackgroundTexture(tex)

    def show(self, visible: bool) -> None:
        """Draw the heat map as the background (True) or the plain background (False)."""
        visible = bool(visible) and self._texture is not None
        self.shown = visible
        self.renderer.SetTexturedBackground(visible)

    def legend(self) -> str:
        """Two lines: what the map shows, with its RMSE and worst pixel, and the colour ramp."""
        c = self.comparison
        if c is None:
            return PENDING
        return (
            f"per-pixel difference from the exact lighting: RMSE {c.rmse:.2f}, worst pixel "
            f"{c.max} levels (1/255)\nblack 0, blue 1, then green, yellow, red, white "
            f">= {VMAX:g} levels; {int(c.mask.sum()):,} pixels compared"
        )

    def state(self) -> dict:
        c = self.comparison
        return {
            "on": self.on,
            "shown": self.shown,
            "rmse": None if c is None else c.rmse,
            "max": None if c is None else c.max,
            "pixels": None if c is None else int(c.mask.sum()),
        }

    def close(self) -> None:
        """Release the off-screen windows (made again when needed)."""
        if self._comparer is not None:
            self._comparer.close()
            self._comparer = None


def advice_lines(text: str) -> str:
    """:func:`explorer.analysis.advice.advice`'s one line split after its ``;`` (it is wide)."""
    return text.replace("; ", ";\n")
