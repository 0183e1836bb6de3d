"""VTK's PNG codec (the package's until issue 34): the independent codec the package's own
(Pillow's, :mod:`explorer.render.images`) is checked against in tests/render/test_render.py,
and timed beside in benchmarks/bench_png.py. It shares no code with Pillow's (VTK bundles its
own libpng)."""

from __future__ import annotations

import os

import numpy as np


def encode(img: np.ndarray) -> bytes:
    """PNG file contents of an (h, w, c) uint8 or uint16 image (c = 1, 3 or 4), through
    ``vtkPNGWriter`` (rows go bottom-up in VTK)."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkPNGWriter

    h, w, c = img.shape
    data = vtkImageData()
    data.SetDimensions(w, h, 1)
    arr = numpy_to_vtk(np.ascontiguousarray(img[::-1].reshape(-1, c)), deep=True)
    data.GetPointData().SetScalars(arr)
    writer = vtkPNGWriter()
    writer.SetWriteToMemory(True)
    writer.SetInputData(data)
    writer.Write()
    return bytes(memoryview(writer.GetResult()))


def read(path) -> np.ndarray:
    """An (h, w, c) image from a PNG file, through ``vtkPNGReader``."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOImage import vtkPNGReader

    reader = vtkPNGReader()
    reader.SetFileName(os.fspath(path))
    reader.Update()
    out = reader.GetOutput()
    w, h, _ = out.GetDimensions()
    arr = vtk_to_numpy(out.GetPointData().GetScalars())
    return np.ascontiguousarray(arr.reshape(h, w, -1)[::-1])
