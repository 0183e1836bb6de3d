"""A turntable of the explorer's state made one frame at a time, so the window keeps painting
(and its Cancel button keeps working) while it is made. No Qt here.

The window calls :meth:`TurntableJob.step` from a timer: each call draws the next frame of the
orbit (:func:`explorer.render.turntable.orbit_scene`: the camera and the lights turn about the
mesh, as ``render --turntable`` does; the first frame is the view's camera) in an off-screen
VTK window; after the last frame the
frames are encoded in a thread (GIF or MP4, :func:`explorer.render.turntable.encode`) and the
file is written atomically. Cancelling at any point writes nothing: the file appears whole, or
not at all.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import math
import os
import threading
from pathlib import Path

import numpy as np

from explorer.app.model import parse_number
from explorer.core import tolerances as tol
from explorer.core.atomic import check_target, write_atomic
from explorer.core.errors import ExplorerError
from explorer.geometry.meshes import Mesh
from explorer.render.camera import Camera
from explorer.render.offscreen import BACKGROUND, OffscreenRenderer
from explorer.render.turntable import (
    TURNTABLE_SUFFIXES,
    check_frames,
    check_turntable,
    encode,
    orbit_camera,
    orbit_scene,
)
from explorer.shading.display import group_vertex_colors, vertex_colors

#: how many frames the window's turntable dialog offers first
DEFAULT_FRAMES = 36
#: what both front ends ask for the number of frames (the window's dialog, the page's field)
FRAMES_LABEL = "frames in a full turn"
#: why a turntable cannot be an MP4 here (said where MP4 is not offered)
MP4_NEEDS = "MP4 needs imageio-ffmpeg (pip install imageio-ffmpeg)"


def turntable_formats() -> tuple[str, ...]:
    """The turntable formats the explorer can write here: a GIF always, an MP4 when
    imageio-ffmpeg (its bundled ffmpeg) is installed, as ``render --turntable`` needs it."""
    return (".gif", ".mp4") if importlib.util.find_spec("imageio_ffmpeg") else (".gif",)


def format_name(suffix: str) -> str:
    """A turntable format's name as the front ends show it (``.gif`` -> ``GIF``)."""
    return suffix[1:].upper()


def read_frames(text) -> int:
    """The number of frames typed (``text``: a whole number, or its text, from 2 to
    :data:`~explorer.core.tolerances.MAX_TURNTABLE_FRAMES`); else one line naming
    ``frames``."""
    n = parse_number("frames", str(text), 2, tol.MAX_TURNTABLE_FRAMES)
    if n != int(n):
        raise ExplorerError(f"frames: a whole number of frames, got {text!r}")
    return int(n)


def turntable_size(width: int, height: int) -> tuple[int, int]:
    """The picture size for a view of ``width`` x ``height`` pixels: even sides (an MP4 needs
    them), at least 16."""
    return max(16, int(width) // 2 * 2), max(16, int(height) // 2 * 2)


def turned_camera(camera: Camera, centre, angle: float) -> Camera:
    """``camera`` turned by ``angle`` radians about the +y axis through ``centre`` (3,), as
    :func:`~explorer.render.turntable.orbit_scene` turns the viewer and the lights."""
    c, s = math.cos(angle), math.sin(angle)
    turn = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    o = np.asarray(centre, dtype=np.float64)

    def point(p):
        return tuple(float(v) for v in o + turn @ (np.asarray(p, dtype=np.float64) - o))

    up = tuple(float(v) for v in turn @ np.asarray(camera.view_up, dtype=np.float64))
    return dataclasses.replace(camera, position=point(camera.position),
                               focal_point=point(camera.focal_point), view_up=up)  # fmt: skip


class TurntableJob:
    """``frames`` pictures of the orbit of ``scene`` around ``mesh`` into ``path``.

    scene : the scene shown (hidden terms already 0: ``State.shown_scene``)
    groups : one material per group of ``mesh.groups`` (the mesh's own materials), or None
    size : (width, height) of each frame; path : a ``.gif`` or ``.mp4`` file
    camera : the first frame's camera (the view's: the turntable starts from what the window
        shows), turned with the scene; None: each frame framed as ``render --turntable`` does
    overwrite : replace an existing file (the window asked first)

    ``stage`` is ``"render"``, then ``"encode"``, then ``"written"``; or ``"cancelled"``.
    """

    def __init__(self, scene, mesh: Mesh, frames: int, size, path, *, groups=None,
                 camera: Camera | None = None, background=BACKGROUND,
                 overwrite: bool = False):  # fmt: skip
        self.frames = check_frames(frames)
        self.path = Path(path)
        self.suffix = self.path.suffix.lower()
        if self.suffix not in TURNTABLE_SUFFIXES:
            raise ExplorerError(
                f"{self.path}: a turntable is written as {' or '.join(TURNTABLE_SUFFIXES)}"
            )
        # the frames are kept until they are encoded: the held budget, before any is drawn
        check_turntable(frames, size, self.suffix, held=True)
        check_target(self.path, overwrite=True)  # a folder, a FIFO, a name too long...
        if os.path.lexists(self.path) and not overwrite:
            raise ExplorerError(f"{self.path}: already exists (not replaced)")
        self.scene, self.mesh, self.groups, self.camera = scene, mesh, groups, camera
        self.size = (int(size[0]), int(size[1]))
        self.overwrite = bool(overwrite)
        w, h = self.size
        self.pictures = np.empty((self.frames, h, w, 3), np.uint8)
        self.done = 0
        self.stage = "render"
        self._renderer = OffscreenRenderer(self.size, background)
        self._encoded: bytes | None = None
        self._error: BaseException | None = None
        self._thread: threading.Thread | None = None

    def _colors(self, scene) -> np.ndarray:
        if self.groups is not None:
            return group_vertex_colors(scene, self.mesh, self.groups)
        return vertex_colors(scene, self.mesh)

    def angle(self, k: int) -> float:
        """How far frame ``k`` has turned (radians)."""
        return 2.0 * math.pi * k / self.frames

    def camera_at(self, k: int, scene=None) -> Camera:
        """Frame ``k``'s camera (``scene``: that frame's, turned)."""
        if self.camera is not None:
            return turned_camera(self.camera, self.mesh.centre, self.angle(k))
        scene = orbit_scene(self.scene, self.mesh, self.angle(k)) if scene is None else scene
        return orbit_camera(scene, self.mesh, self.size[0] / self.size[1])

    def step(self) -> str:
        """One step: the next frame, or a look at the encoder, or writing the file. Returns
        :attr:`stage` after it. An error (writing, encoding) ends the job and is raised."""
        if self.stage == "render":
            k = self.done
            s = orbit_scene(self.scene, self.mesh, self.angle(k))
            self.pictures[k] = self._renderer.render(s, self.mesh, self._colors(s),
                                                     camera=self.camera_at(k, s))  # fmt: skip
            self.done = k + 1
            if self.done == self.frames:
                self._renderer.close()
                self.stage = "encode"
                self._thread = threading.Thread(target=self._encode, daemon=True)
                self._thread.start()
        elif self.stage == "encode" and not self._thread.is_alive():
            if self._error is not None:
                self.stage = "cancelled"
                raise self._error
            write_atomic(self.path, self._encoded, overwrite=self.overwrite)
            self.stage = "written"
        return self.stage

    def _encode(self) -> None:
        try:
            self._encoded = encode(self.pictures, self.suffix)
        except Exception as exc:  # noqa: BLE001 - handed to the GUI thread in step()
            self._error = exc

    def cancel(self) -> None:
        """Stop: nothing is written (an encoding under way finishes in its thread and is
        dropped)."""
        if self.stage in ("render", "encode"):
            self.stage = "cancelled"
            self._renderer.close()
