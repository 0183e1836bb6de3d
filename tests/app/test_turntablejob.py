"""The window's turntable job without a window: its cameras turn as the scene's viewer and
lights do, starting from the view's; it refuses what it must not write."""

from __future__ import annotations

import math

import numpy as np
import pytest

import explorer
from explorer.app.turntablejob import TurntableJob, turned_camera, turntable_size
from explorer.core.errors import ExplorerError
from explorer.core.scene import Viewer
from explorer.geometry import meshes as G
from explorer.render.camera import Camera
from explorer.render.turntable import orbit_scene


@pytest.fixture
def mesh():
    return G.icosphere(1)


CAMERA = Camera((0.5, 1.0, 4.0), (0.1, 0.0, 0.2), (0.0, 1.0, 0.0), False, 1.0, 30.0, (0.1, 10.0))


def test_the_camera_turns_as_the_viewer_and_lights(mesh):
    scene = explorer.load_scene({"material": "gold"}).replace(viewer=Viewer(eye=CAMERA.position))
    assert turned_camera(CAMERA, mesh.centre, 0.0) == CAMERA
    for angle in (0.3, math.pi / 2, 2.0):
        cam = turned_camera(CAMERA, mesh.centre, angle)
        eye = orbit_scene(scene, mesh, angle).viewer.eye
        assert cam.position == pytest.approx(eye, abs=1e-12)
        d0 = np.linalg.norm(np.subtract(CAMERA.focal_point, CAMERA.position))
        assert np.linalg.norm(np.subtract(cam.focal_point, cam.position)) == pytest.approx(d0)
        assert cam.view_up == pytest.approx((0.0, 1.0, 0.0))
    full = turned_camera(CAMERA, mesh.centre, 2.0 * math.pi)
    assert full.position == pytest.approx(CAMERA.position)


def test_the_first_frame_is_the_view(mesh, tmp_path):
    scene = explorer.load_scene({"material": "gold"})
    job = TurntableJob(scene, mesh, 4, (32, 32), tmp_path / "t.gif", camera=CAMERA)
    assert job.camera_at(0) == CAMERA and job.camera_at(2).position == pytest.approx(
        turned_camera(CAMERA, mesh.centre, math.pi).position)  # fmt: skip
    job.cancel()
    assert job.stage == "cancelled" and not (tmp_path / "t.gif").exists()


def test_what_the_job_refuses(mesh, tmp_path):
    scene = explorer.load_scene({"material": "gold"})
    (tmp_path / "there.gif").write_bytes(b"mine")
    for path, words in ((tmp_path / "t.png", "written as .gif or .mp4"),
                        (tmp_path / "there.gif", "already exists"),
                        (tmp_path / "no" / "t.gif", "does not exist")):  # fmt: skip
        with pytest.raises(ExplorerError, match=words):
            TurntableJob(scene, mesh, 4, (32, 32), path)
    with pytest.raises(ExplorerError, match="from 2 to"):
        TurntableJob(scene, mesh, 1, (32, 32), tmp_path / "t.gif")
    assert (tmp_path / "there.gif").read_bytes() == b"mine"
    assert turntable_size(721, 9) == (720, 16)
