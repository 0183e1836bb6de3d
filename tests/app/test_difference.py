"""The difference view's worker (no Qt): its maps equal a direct comparison, it keeps its
off-screen windows between jobs of one size, and a cancelled or stale job delivers nothing."""

from __future__ import annotations

import threading

import numpy as np

from explorer.analysis import comparison as C
from explorer.app import difference as DV
from explorer.core.scene import load_scene
from explorer.geometry import meshes as M
from explorer.render.camera import camera_for
from explorer.shading.display import vertex_colors

SCENE = load_scene({"material": "gold", "lights": [{"type": "point", "position": [2, 3, 2]}]})


def _job(key, mesh, size, scene=SCENE):
    cam = camera_for(scene, mesh, size[0] / size[1])
    return DV.Job(key, scene, mesh, vertex_colors(scene, mesh), cam, size, (0.1, 0.1, 0.1))


class _Inbox:
    def __init__(self):
        self.results = []
        self.event = threading.Event()

    def __call__(self, result):
        self.results.append(result)
        self.event.set()

    def wait(self):
        assert self.event.wait(120), "the worker delivered nothing"
        self.event.clear()
        return self.results[-1]


def test_worker_maps_equal_direct_comparisons_and_reuse_the_windows(monkeypatch):
    made = []
    real = C.ViewComparer

    class Counted(real):
        def __init__(self, size):
            made.append(tuple(size))
            super().__init__(size)

    monkeypatch.setattr(C, "ViewComparer", Counted)
    inbox = _Inbox()
    worker = DV.DifferenceWorker(inbox)
    try:
        jobs = [_job(0, M.teapot(4), (160, 120)), _job(1, M.sphere(12), (160, 120)),
                _job(2, M.teapot(4), (90, 70))]  # fmt: skip
        for job in jobs:
            worker.submit(job)
            r = inbox.wait()
            assert r.error is None and r.job is job
            direct = C.compare_view(job.scene, job.mesh, job.size, camera=job.camera,
                                    colors=job.colors)  # fmt: skip
            assert np.array_equal(r.comparison.levels, direct.levels)
            assert r.comparison.rmse == direct.rmse and r.comparison.mask.sum() > 500
            assert r.comparison.peak is None  # not shown by the map: not computed
            assert r.image.shape == (job.size[1], job.size[0], 3)
    finally:
        worker.close()
    # one set of windows per size (the direct comparisons made their own three)
    assert made.count((160, 120)) == 1 + 2 and made.count((90, 70)) == 1 + 1


def test_a_cancelled_job_delivers_nothing_and_the_next_one_is_whole():
    inbox = _Inbox()
    worker = DV.DifferenceWorker(inbox)
    try:
        stale = _job("stale", M.teapot(8), (400, 300))
        fresh = _job("fresh", M.teapot(4), (400, 300))
        worker.submit(stale)
        worker.submit(fresh)  # cancels the one running
        r = inbox.wait()
        assert r.job.key == "fresh"
        worker.cancel()
        assert not inbox.event.wait(0.5)
        assert [x.job.key for x in inbox.results] == ["fresh"]
        direct = C.compare_view(fresh.scene, fresh.mesh, fresh.size, camera=fresh.camera,
                                colors=fresh.colors)  # fmt: skip
        assert np.array_equal(r.comparison.levels, direct.levels)
    finally:
        worker.close()


def test_run_job_alone_makes_its_own_windows():
    job = _job(0, M.teapot(4), (100, 80))
    r = DV.run_job(job)
    direct = C.compare_view(job.scene, job.mesh, job.size, camera=job.camera, colors=job.colors)
    assert np.array_equal(r.comparison.levels, direct.levels) and r.ms > 0


def test_the_worker_makes_and_closes_its_windows_only_while_no_frame_is_drawn(monkeypatch):
    """The worker's off-screen windows are made and closed while no other thread draws
    (DRAW_LOCK): while a frame of the window holds the lock, a job of a new size (its old
    windows closed, new ones made) waits for the frame's end; closing the worker while it
    computes ends its thread with every window it made closed. (A full run under load crashed
    in the window while a difference thread lived; the worker closed its OpenGL windows
    outside the lock.)"""
    import time

    import pyvista as pv

    from explorer.render import offscreen
    from explorer.render.vtk import DRAW_LOCK

    frame = [False]  # a frame of the window is being drawn (this thread holds DRAW_LOCK)
    made, closed = [], []
    real_plotter, real_close = offscreen.plotter, pv.Plotter.close

    def plotter(*a, **k):
        made.append(frame[0])
        return real_plotter(*a, **k)

    def close(self, *a, **k):
        closed.append(frame[0])
        return real_close(self, *a, **k)

    monkeypatch.setattr(offscreen, "plotter", plotter)
    monkeypatch.setattr(pv.Plotter, "close", close)
    inbox = _Inbox()
    worker = DV.DifferenceWorker(inbox)
    try:
        worker.submit(_job(0, M.teapot(4), (160, 120)))
        inbox.wait()
        with DRAW_LOCK:
            frame[0] = True
            worker.submit(_job(1, M.teapot(4), (90, 70)))  # a new size: new windows
            time.sleep(0.5)
            frame[0] = False
        assert inbox.wait().job.key == 1
        worker.submit(_job(2, M.teapot(12), (300, 200)))  # a new size again, then closed
        time.sleep(0.2)
    finally:
        worker.close()
    assert not worker._thread.is_alive()
    assert len(made) >= 4 and len(closed) == len(made), (made, closed)  # (two a size at least)
    assert not any(made) and not any(closed), (made, closed)  # none while a frame was drawn
