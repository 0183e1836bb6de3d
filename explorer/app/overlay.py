"""2D drawings over a VTK view in display pixels (origin bottom-left): lines and filled
triangles, for the lobe inset, the handle's ring and the arrows toward handles out of view.
VTK is imported inside the functions."""

from __future__ import annotations

import numpy as np

from explorer.shading.display import to_bytes


def overlay(plotter, color, width: float, *, filled: bool = False):
    """An empty 2D polydata drawn over the view in display pixels (lines, or filled triangles
    coloured per cell when ``filled``); returns the polydata and its actor."""
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
    from vtkmodules.vtkRenderingCore import vtkActor2D, vtkPolyDataMapper2D

    poly = vtkPolyData()
    poly.SetPoints(vtkPoints())
    poly.SetLines(vtkCellArray())
    mapper = vtkPolyDataMapper2D()
    mapper.SetInputData(poly)
    if filled:
        mapper.SetScalarModeToUseCellData()
        mapper.SetColorModeToDirectScalars()
    else:
        mapper.ScalarVisibilityOff()
    actor = vtkActor2D()
    actor.SetMapper(mapper)
    actor.GetProperty().SetColor(*color)
    actor.GetProperty().SetLineWidth(width)
    plotter.renderer.AddViewProp(actor)
    return poly, actor


def _cells(shapes):
    """vtkPoints and a vtkCellArray of ``shapes`` (each (k, 2) display pixels), one cell each."""
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray

    pts = vtkPoints()
    cells = vtkCellArray()
    for shape in shapes:
        ids = [pts.InsertNextPoint(float(x), float(y), 0.0) for x, y in shape]
        cells.InsertNextCell(len(ids), ids)
    return pts, cells


def set_triangles(poly, triangles, colours) -> None:
    """Filled triangles (each (3, 2) pixels), one colour (RGB in [0, 1]) each."""
    from vtkmodules.util.numpy_support import numpy_to_vtk

    pts, polys = _cells(triangles)
    poly.SetPoints(pts)
    poly.SetPolys(polys)
    rgb = to_bytes(np.asarray(colours, np.float64).reshape(-1, 3))
    arr = numpy_to_vtk(np.ascontiguousarray(rgb), deep=True)
    arr.SetName("colors")
    poly.GetCellData().SetScalars(arr)
    poly.Modified()


def set_lines(poly, polylines) -> None:
    """Polylines (each (k, 2) pixels) in the overlay's colour."""
    pts, lines = _cells(polylines)
    poly.SetPoints(pts)
    poly.SetLines(lines)
    poly.Modified()
