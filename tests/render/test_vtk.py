"""The VTK side: the plotter factory, the cell array and the mesh builder."""

from __future__ import annotations

import os

import numpy as np
import pytest

from explorer.geometry import meshes as M
from explorer.render.vtk import WINDOW_ENV, cells, headless_egl, plotter, polydata

pytest.importorskip("pyvista")


def test_cells_are_vtk_triangles():
    faces = np.array([[0, 1, 2], [2, 1, 3]])
    assert cells(faces).tolist() == [3, 0, 1, 2, 3, 2, 1, 3]
    assert cells(faces).dtype == np.int64
    assert cells(np.zeros((0, 3), np.int64)).shape == (0,)


def test_polydata():
    m = M.cube()
    colors = np.arange(m.n_vertices * 3, dtype=np.uint8).reshape(-1, 3)
    poly = polydata(m, colors)
    assert poly.n_points == 24 and poly.n_cells == 12
    assert np.array_equal(poly.faces.reshape(-1, 4)[:, 1:], m.faces)
    assert np.allclose(poly.point_data["Normals"], m.normals)
    assert poly.points.dtype == np.float64 and np.array_equal(poly.points, m.positions)
    assert np.array_equal(poly.point_data["colors"], colors)


def test_polydata_float32_no_normals_and_a_drawing_order():
    m = M.cube()
    order = m.faces[::-1]
    poly = polydata(m, float32=True, normals=False, faces=order)
    assert poly.points.dtype == np.float32
    assert np.array_equal(poly.points, m.positions.astype(np.float32))
    assert "Normals" not in poly.point_data and "colors" not in poly.point_data
    assert np.array_equal(poly.faces.reshape(-1, 4)[:, 1:], order)


def test_headless_egl_is_taken_back(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.delenv(WINDOW_ENV, raising=False)
    with headless_egl():
        assert os.environ[WINDOW_ENV] == "vtkEGLRenderWindow"
    assert WINDOW_ENV not in os.environ
    # a choice of the user's, or a display, is left alone
    monkeypatch.setenv(WINDOW_ENV, "vtkOSOpenGLRenderWindow")
    with headless_egl():
        assert os.environ[WINDOW_ENV] == "vtkOSOpenGLRenderWindow"
    assert os.environ[WINDOW_ENV] == "vtkOSOpenGLRenderWindow"
    monkeypatch.delenv(WINDOW_ENV)
    monkeypatch.setenv("DISPLAY", ":99")
    with headless_egl():
        assert WINDOW_ENV not in os.environ


def test_plotter_draws_without_extras():
    pl = plotter((40, 30), (0.25, 0.5, 0.75))
    try:
        assert tuple(pl.window_size) == (40, 30)
        assert pl.render_window.GetMultiSamples() == 0
        assert not pl.renderer.GetUseOIT() and not pl.renderer.GetUseDepthPeeling()
        assert pl.renderer.GetLights().GetNumberOfItems() == 0
        assert np.allclose(pl.renderer.GetBackground(), (0.25, 0.5, 0.75), atol=0.5 / 255)
        img = pl.screenshot(return_img=True)
        assert img.shape[:2] == (30, 40)
        assert np.all(img[..., :3] == np.rint(np.array([0.25, 0.5, 0.75]) * 255))
    finally:
        pl.close()


def test_one_thread_draws_at_a_time():
    """A frame of a plotter holds DRAW_LOCK from its start to its end, and an off-screen picture
    made in another thread (the difference worker's) waits for it: VTK drawing in two threads
    at once crashed the window."""
    import threading
    import time

    import explorer
    from explorer.render.offscreen import OffscreenRenderer
    from explorer.render.vtk import DRAW_LOCK

    pl = plotter((64, 48), (0.2, 0.2, 0.2))
    held = []
    pl.renderer.AddObserver("StartEvent", lambda *_: held.append(DRAW_LOCK._is_owned()))
    pl.render_window.Render()
    assert held and all(held)  # held through the frame
    assert DRAW_LOCK.acquire(blocking=False)  # and let go after it (in this thread)
    DRAW_LOCK.release()

    renderer = OffscreenRenderer((64, 48))
    scene, mesh = explorer.load_scene({"material": "gold"}), M.sphere(8)
    renderer.render(scene, mesh)  # (the window made before the race)
    done = threading.Event()
    worker = threading.Thread(target=lambda: (renderer.render(scene, mesh), done.set()))
    with DRAW_LOCK:  # a frame of the window, as it were
        worker.start()
        time.sleep(0.3)
        assert not done.is_set()  # the worker's picture waits for the frame
    worker.join(30)
    assert done.is_set()
    renderer.close()
    pl.close()
