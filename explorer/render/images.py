"""Pictures as arrays and files: sizes, PNG encoding and decoding (VTK's codec)."""

from __future__ import annotations

import os
import re

import numpy as np

from explorer.core.errors import ExplorerError
from explorer.core.tolerances import MAX_PICTURE_PIXELS

#: default image size (width, height)
DEFAULT_SIZE = (400, 400)
#: smallest and largest accepted image side in pixels
SIZE_RANGE = (16, 8192)


# -- sizes and files -----------------------------------------------------------------------


def check_size(size) -> tuple[int, int]:
    """(width, height) as ints in :data:`SIZE_RANGE`, or an :class:`ExplorerError`."""
    lo, hi = SIZE_RANGE
    try:
        w, h = (int(v) for v in size)
        ok = all(float(v) == int(v) for v in size)
    except (TypeError, ValueError):
        ok = False
    if not ok or not (lo <= w <= hi and lo <= h <= hi):
        raise ExplorerError(
            f"image size must be two whole numbers of pixels, each in [{lo}, {hi}], got {size!r}"
        )
    check_picture_pixels(w, h, "image size")
    return w, h


def check_picture_pixels(width: int, height: int, what: str) -> None:
    """An :class:`ExplorerError` naming ``what`` when a ``width`` x ``height`` picture is more
    than :data:`~explorer.core.tolerances.MAX_PICTURE_PIXELS`; call it before allocating."""
    if width * height > MAX_PICTURE_PIXELS:
        raise ExplorerError(
            f"{what}: {width}x{height} is {width * height} pixels, more than the limit of "
            f"{MAX_PICTURE_PIXELS} (8192x8192); use a smaller size"
        )


_SIZE_RE = re.compile(r"^\s*(\d+)\s*[xX×]\s*(\d+)\s*$")


def parse_size(text: str) -> tuple[int, int]:
    """``"400x300"`` -> (400, 300) (width x height), checked against :data:`SIZE_RANGE`."""
    m = _SIZE_RE.match(str(text))
    if not m:
        raise ExplorerError(f"size must look like WIDTHxHEIGHT, e.g. 400x400, got {text!r}")
    return check_size((int(m.group(1)), int(m.group(2))))


def encode_png(image) -> bytes:
    """PNG file contents of an (h, w, 3|4) uint8 image (VTK's PNG writer)."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkPNGWriter

    img = np.asarray(image)
    if img.dtype != np.uint8 or img.ndim != 3 or img.shape[2] not in (3, 4):
        raise ValueError(f"image must be (h, w, 3|4) uint8, got {img.shape} {img.dtype}")
    h, w, c = img.shape
    data = vtkImageData()
    data.SetDimensions(w, h, 1)
    flat = np.ascontiguousarray(img[::-1].reshape(-1, c))  # VTK rows go bottom-up
    arr = numpy_to_vtk(flat, deep=True)
    arr.SetNumberOfComponents(c)
    data.GetPointData().SetScalars(arr)
    writer = vtkPNGWriter()
    writer.SetWriteToMemory(True)
    writer.SetInputData(data)
    writer.Write()
    result = writer.GetResult()
    return bytes(memoryview(result))


def read_png(path) -> np.ndarray:
    """An (h, w, 3|4) uint8 image from a PNG file."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOImage import vtkPNGReader

    path = os.fspath(path)
    reader = vtkPNGReader()
    if not os.path.isfile(path) or not reader.CanReadFile(path):
        raise ExplorerError(f"{path}: not a readable PNG file")
    reader.SetFileName(path)
    reader.Update()
    img = reader.GetOutput()
    w, h, _ = img.GetDimensions()
    arr = vtk_to_numpy(img.GetPointData().GetScalars())
    c = arr.shape[1] if arr.ndim == 2 else 1
    return np.ascontiguousarray(arr.reshape(h, w, c)[::-1]).astype(np.uint8)


def side_by_side(left, right, gap: int = 0, fill=(0, 0, 0)) -> np.ndarray:
    """Two pictures (h1, w1, 3) and (h2, w2, 3) uint8 in one, ``gap`` columns of ``fill``
    between them, the shorter one padded at the bottom with ``fill``:
    (max(h1, h2), w1 + gap + w2, 3) uint8."""
    a, b = np.asarray(left, np.uint8), np.asarray(right, np.uint8)
    h = max(a.shape[0], b.shape[0])
    out = np.empty((h, a.shape[1] + int(gap) + b.shape[1], 3), np.uint8)
    out[:] = np.asarray(fill, np.uint8)
    out[: a.shape[0], : a.shape[1]] = a
    out[: b.shape[0], a.shape[1] + int(gap) :] = b
    return out
