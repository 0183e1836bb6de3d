"""Turntables: the camera orbiting the mesh, one picture per step, as a GIF or an MP4.

The viewer and the lights turn together about the vertical (+y) axis through the mesh's
centre, a full turn in ``frames`` equal steps: the camera orbits with its lights, which is the
object turning on a turntable in a fixed studio. Every frame is lit from the same side as seen
from the camera, and the highlights slide over the surface as it turns. Each frame is shaded
for its own viewer and lights. An infinite viewer is framed by the mesh's bounding sphere, so
the picture does not zoom from frame to frame.

Encoding uses imageio (GIF through Pillow, MP4 through imageio-ffmpeg's bundled ffmpeg).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError
from explorer.core.scene import Viewer
from explorer.geometry.meshes import Mesh
from explorer.render.camera import FRAME_MARGIN, Camera, camera_for
from explorer.render.offscreen import BACKGROUND, OffscreenRenderer

#: ``render --turntable --out`` suffixes
TURNTABLE_SUFFIXES = (".gif", ".mp4")
#: frames per second of the animation
FPS = 24


def check_frames(frames: int) -> int:
    """``frames`` if it is a whole number in [2, MAX_TURNTABLE_FRAMES], else an error."""
    if not isinstance(frames, int) or not 2 <= frames <= tol.MAX_TURNTABLE_FRAMES:
        raise ExplorerError(
            f"--turntable takes a number of frames from 2 to {tol.MAX_TURNTABLE_FRAMES}, "
            f"got {frames!r}"
        )
    return frames


def _turn(v, centre, angle: float) -> tuple[float, float, float]:
    """``v`` (a point) turned by ``angle`` radians about the +y axis through ``centre``."""
    c, s = math.cos(angle), math.sin(angle)
    x, y, z = (float(a) - float(b) for a, b in zip(v, centre, strict=True))
    return (centre[0] + c * x + s * z, centre[1] + y, centre[2] - s * x + c * z)


#: light fields that are points (turned about the mesh's centre) and directions (turned only)
_POINTS, _DIRECTIONS = ("position",), ("to_light", "aim")
_ORIGIN = (0.0, 0.0, 0.0)


def orbit_scene(scene, mesh: Mesh, angle: float):
    """``scene`` with its viewer and lights turned by ``angle`` radians about +y through the
    mesh's centre (an eye or a light position moves on a circle; a direction turns)."""
    centre = tuple(float(c) for c in mesh.centre)
    viewer = scene.viewer
    if viewer.eye is not None:
        viewer = Viewer(eye=_turn(viewer.eye, centre, angle))
    else:
        viewer = Viewer(to_viewer=_turn(viewer.to_viewer, _ORIGIN, angle))
    lights = []
    for light in scene.lights:
        changes = {k: _turn(getattr(light, k), centre, angle) for k in _POINTS if hasattr(light, k)}
        changes.update(
            {k: _turn(getattr(light, k), _ORIGIN, angle) for k in _DIRECTIONS if hasattr(light, k)}
        )
        lights.append(light.replace(**changes))
    return scene.replace(viewer=viewer, lights=tuple(lights))


def orbit_camera(scene, mesh: Mesh, aspect: float) -> Camera:
    """The frame's camera: :func:`camera_for`, with a parallel view fitted to the cylinder
    about the turning axis that holds the mesh (the same size and centre in every frame)."""
    cam = camera_for(scene, mesh, aspect)
    if not cam.parallel:
        return cam
    p = mesh.positions
    lo, hi = p.min(axis=0), p.max(axis=0)
    centre = np.array([0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])])
    r_xz = float(np.sqrt(np.max((p[:, 0] - centre[0]) ** 2 + (p[:, 2] - centre[2]) ** 2)))
    half_y = 0.5 * float(hi[1] - lo[1])
    toward = np.subtract(cam.position, cam.focal_point)
    toward = toward / np.linalg.norm(toward)
    tilt = abs(float(toward[1]))  # sine of the viewer's elevation
    flat = math.sqrt(max(0.0, 1.0 - tilt * tilt))
    half_h = half_y * flat + r_xz * tilt
    scale = max(half_h, r_xz / aspect, 1e-12) * FRAME_MARGIN
    dist = float(np.linalg.norm(np.subtract(cam.position, cam.focal_point)))
    return Camera(
        tuple(centre + toward * dist),
        tuple(centre),
        cam.view_up,
        True,
        scale,
        cam.view_angle,
        cam.clipping_range,
    )


def turntable_frames(
    scene,
    mesh: Mesh,
    frames: int,
    colors_of: Callable,
    size: Sequence[int],
    *,
    background=BACKGROUND,
    progress: Callable[[int, int], None] | None = None,
) -> np.ndarray:
    """(frames, height, width, 3) uint8 pictures of the orbit.

    colors_of : ``colors_of(scene) -> (n, 3)`` display colours of the mesh's vertices for that
        frame's scene (its viewer and lights turned: :func:`orbit_scene`)
    progress : called as ``progress(done, frames)`` after each frame
    """
    check_frames(frames)
    w, h = size
    out = np.empty((frames, h, w, 3), np.uint8)
    with OffscreenRenderer(size, background) as r:
        for k in range(frames):
            s = orbit_scene(scene, mesh, 2.0 * math.pi * k / frames)
            cam = orbit_camera(s, mesh, w / h)
            out[k] = r.render(s, mesh, colors_of(s), camera=cam)
            if progress is not None:
                progress(k + 1, frames)
    return out


def encode(frames: np.ndarray, suffix: str, fps: float = FPS) -> bytes:
    """The frames as a looping GIF or an H.264 MP4 (by ``suffix``), as bytes."""
    import imageio.v3 as iio

    suffix = suffix.lower()
    if suffix == ".gif":
        return iio.imwrite("<bytes>", frames, extension=".gif", duration=1000.0 / fps, loop=0)
    if suffix == ".mp4":
        h, w = frames.shape[1:3]
        if h % 2 or w % 2:  # H.264 in yuv420p needs even sides
            raise ExplorerError(f"an MP4 needs an even width and height, got {w}x{h}")
        return iio.imwrite(
            "<bytes>", frames, extension=".mp4", fps=fps, macro_block_size=1, codec="libx264"
        )
    raise ExplorerError(f"a turntable is written as {' or '.join(TURNTABLE_SUFFIXES)}")
