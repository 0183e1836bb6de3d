"""Turntables: the camera orbiting the mesh, one picture per step, as a GIF or an MP4.

The viewer and the lights turn together about the vertical (+y) axis through the mesh's
centre, a full turn in ``frames`` equal steps: the camera orbits with its lights, which is the
object turning on a turntable in a fixed studio. Every frame is lit from the same side as seen
from the camera, and the highlights slide over the surface as it turns. Each frame is shaded
for its own viewer and lights. An infinite viewer is framed by the mesh's bounding sphere, so
the picture does not zoom from frame to frame.

Encoding streams the frames as they are rendered (:func:`iter_frames` into :func:`encode`): an
MP4 goes to imageio-ffmpeg's bundled ffmpeg one frame at a time (memory: one frame), a GIF to
Pillow, whose encoder keeps every frame in its palette (one byte a pixel). What a turntable may
cost is checked before its first frame renders (:func:`check_turntable`): the frame count, an
MP4's even sides, and the total pixels (:data:`~explorer.core.tolerances.MAX_TURNTABLE_PIXELS`
for a streamed MP4, :data:`~explorer.core.tolerances.MAX_TURNTABLE_HELD_PIXELS` when the frames
are held: a GIF, the window's turntable).
"""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Callable, Iterable, Iterator, Sequence

import numpy as np

from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError
from explorer.core.scene import Viewer
from explorer.geometry.meshes import Mesh
from explorer.render.camera import FRAME_MARGIN, Camera, camera_for, vector_length
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


def check_turntable(frames: int, size: Sequence[int], suffix: str, *, held: bool = False) -> int:
    """Everything a turntable of ``frames`` pictures of ``size`` (width, height) written as
    ``suffix`` needs, checked before any frame renders: the frame count
    (:func:`check_frames`), an MP4's even sides (H.264 in yuv420p) and the total pixels,
    ``frames x width x height``, at most :data:`~explorer.core.tolerances.MAX_TURNTABLE_PIXELS`
    for a streamed MP4, :data:`~explorer.core.tolerances.MAX_TURNTABLE_HELD_PIXELS` when the
    frames are held (a GIF; ``held``: the caller keeps them). Returns ``frames``."""
    check_frames(frames)
    w, h = (int(v) for v in size)
    suffix = suffix.lower()
    if suffix not in TURNTABLE_SUFFIXES:
        raise ExplorerError(f"a turntable is written as {' or '.join(TURNTABLE_SUFFIXES)}")
    if suffix == ".mp4" and (w % 2 or h % 2):
        raise ExplorerError(
            f"--size {w}x{h}: an MP4 needs an even width and height (H.264); "
            f"try --size {w + w % 2}x{h + h % 2}"
        )
    held = held or suffix == ".gif"
    cap = tol.MAX_TURNTABLE_HELD_PIXELS if held else tol.MAX_TURNTABLE_PIXELS
    total = frames * w * h
    if total > cap:
        what = "frames held until the end (a GIF, or the window's turntable)" if held else "an MP4"
        raise ExplorerError(
            f"--turntable {frames} --size {w}x{h}: {total:,} pixels in all; {what} may have "
            f"at most {cap:,} (frames x width x height): fewer frames or a smaller --size"
            + ("; an .mp4 may have more" if suffix == ".gif" else "")
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
    d = np.stack([p[:, 0] - centre[0], p[:, 2] - centre[2]], axis=1)
    m = float(np.abs(d).max()) or 1.0  # scaled first: no overflow of the squares at 1e155
    r_xz = m * float(np.sqrt(np.max(np.einsum("ij,ij->i", d / m, d / m))))
    half_y = 0.5 * float(hi[1] - lo[1])
    toward = np.subtract(cam.position, cam.focal_point)
    dist = vector_length(toward)  # (scale-safe: a mesh of size 1e155 too)
    toward = toward / dist
    tilt = abs(float(toward[1]))  # sine of the viewer's elevation
    flat = math.sqrt(max(0.0, 1.0 - tilt * tilt))
    half_h = half_y * flat + r_xz * tilt
    scale = max(half_h, r_xz / aspect) * FRAME_MARGIN or cam.parallel_scale  # (a point: its own)
    return Camera(
        tuple(centre + toward * dist),
        tuple(centre),
        cam.view_up,
        True,
        scale,
        cam.view_angle,
        cam.clipping_range,
    )


def iter_frames(
    scene,
    mesh: Mesh,
    frames: int,
    colors_of: Callable,
    size: Sequence[int],
    *,
    background=BACKGROUND,
    progress: Callable[[int, int], None] | None = None,
) -> Iterator[np.ndarray]:
    """The (height, width, 3) uint8 pictures of the orbit, one at a time, as they render (the
    next one renders when it is asked for: feed them to :func:`encode`).

    colors_of : ``colors_of(scene) -> (n, 3)`` display colours of the mesh's vertices for that
        frame's scene (its viewer and lights turned: :func:`orbit_scene`)
    progress : called as ``progress(done, frames)`` after each frame
    """
    check_frames(frames)
    w, h = size
    with OffscreenRenderer(size, background) as r:
        for k in range(frames):
            s = orbit_scene(scene, mesh, 2.0 * math.pi * k / frames)
            cam = orbit_camera(s, mesh, w / h)
            yield r.render(s, mesh, colors_of(s), camera=cam)
            if progress is not None:
                progress(k + 1, frames)


def turntable_frames(scene, mesh: Mesh, frames: int, colors_of: Callable, size, **kw) -> np.ndarray:
    """(frames, height, width, 3) uint8: every picture of :func:`iter_frames` at once."""
    return np.stack(list(iter_frames(scene, mesh, frames, colors_of, size, **kw)))


def encode(frames: Iterable[np.ndarray], suffix: str, fps: float = FPS) -> bytes:
    """The frames, (height, width, 3) uint8 each (an iterable: each is encoded as it comes,
    not kept by this function), as a looping GIF or an H.264 MP4 (by ``suffix``), as bytes.
    An MP4 holds one frame at a time; a GIF's encoder keeps every frame in its palette."""
    suffix = suffix.lower()
    if suffix == ".gif":
        return _gif(iter(frames), fps)
    if suffix == ".mp4":
        return _mp4(iter(frames), fps)
    raise ExplorerError(f"a turntable is written as {' or '.join(TURNTABLE_SUFFIXES)}")


def _gif(frames: Iterator[np.ndarray], fps: float) -> bytes:
    """A looping GIF through Pillow, the frames taken one at a time."""
    import io

    from PIL import Image

    first = next(frames)
    buf = io.BytesIO()
    Image.fromarray(first).save(
        buf, format="GIF", save_all=True, append_images=(Image.fromarray(f) for f in frames),
        duration=1000.0 / fps, loop=0,
    )  # fmt: skip
    return buf.getvalue()


def _mp4(frames: Iterator[np.ndarray], fps: float) -> bytes:
    """An H.264 MP4 through imageio-ffmpeg, each frame piped to ffmpeg as it comes."""
    import imageio.v2 as iio2

    with tempfile.TemporaryDirectory(prefix="explorer-turntable-") as tmp:
        path = os.path.join(tmp, "turntable.mp4")
        writer = None
        try:
            for frame in frames:
                if writer is None:
                    h, w = frame.shape[:2]
                    if h % 2 or w % 2:  # H.264 in yuv420p (check_turntable says so first)
                        raise ExplorerError(f"an MP4 needs an even width and height, got {w}x{h}")
                    writer = iio2.get_writer(path, format="FFMPEG", mode="I", fps=fps,
                                             codec="libx264", macro_block_size=1)  # fmt: skip
                writer.append_data(frame)
        finally:
            if writer is not None:
                writer.close()
        if writer is None:
            raise ExplorerError("a turntable needs at least one frame")
        with open(path, "rb") as f:
            data = f.read()
    if not mp4_complete(data):  # imageio-ffmpeg does not look at ffmpeg's exit status
        raise ExplorerError(
            "the MP4 encoder (ffmpeg) did not finish the file (a full disk, or a file size "
            "limit?); nothing was written"
        )
    return data


def mp4_complete(data: bytes) -> bool:
    """Whether ``data`` is a whole MP4 file as ffmpeg finishes it: top-level boxes (a 4-byte
    big-endian size, a 4-byte type; size 1: a 64-bit size follows) that end exactly at the
    end of the data, among them ``ftyp``, ``mdat`` and ``moov`` (the index ffmpeg writes
    last: a file cut short by a full disk or a size limit lacks it, and does not play)."""
    seen, at = set(), 0
    while at < len(data):
        if at + 8 > len(data):
            return False
        size, kind = int.from_bytes(data[at : at + 4], "big"), data[at + 4 : at + 8]
        if size == 1:
            if at + 16 > len(data):
                return False
            size = int.from_bytes(data[at + 8 : at + 16], "big")
        if size < 8 or at + size > len(data):  # size 0 (to the end) is not what ffmpeg writes
            return False
        seen.add(kind)
        at += size
    return {b"ftyp", b"mdat", b"moov"} <= seen
