"""The explorer's difference view: the per-pixel error of the current view as a heat map,
computed off the GUI thread.

The toggle ``difference`` compares what the window shows, per-vertex colours interpolated
across each triangle, with the same lighting evaluated at every pixel
(:func:`explorer.analysis.comparison.compare_view`: the exact sphere for the built-in spheres,
ray casting with interpolated normals for any other mesh, or the rasteriser's triangles while
the compiled ray kernels are not loaded: see :func:`explorer.analysis.comparison.rasterised`),
for the current camera, view size,
mesh, material and lights. The error of each pixel, in 1/255 levels, is drawn with
:func:`explorer.analysis.comparison.heat_map` as the renderer's background while the mesh is
hidden, so the map sits exactly where the mesh is drawn.

One comparison costs two off-screen renders and the per-pixel reference, so it runs in
:class:`DifferenceWorker`'s thread (which keeps its off-screen windows from one comparison to
the next while the view's size holds): a new request cancels the one running (``compare_view``'s
``cancelled`` callable stops its ray casts between chunks; a result that finishes anyway is
dropped), so frames keep coming and a stale map is never shown as the current one. No Qt here: the
worker hands results to a callback, which the window forwards to its GUI thread.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass

import numpy as np

from explorer.analysis import advice as A
from explorer.analysis import comparison as C
from explorer.core.errors import Cancelled
from explorer.shading.display import to_bytes

#: the error (1/255 levels) drawn white; the ramp below it is logarithmic (see heat_map)
VMAX = 16.0
#: the legend while a comparison is being made or waits for a drag to end
PENDING = "difference: computing the map for this view (the live view meanwhile)"
#: meshes the measured accuracy table is about (others get its advice as a guide only)
TABLE_MESHES = ("sphere", "icosphere")


@dataclass(frozen=True)
class Job:
    """One comparison to make. key : what the map is for (the window decides what goes in
    it); scene, mesh, colors (n, 3) in [0, 1], camera, size (w, h), background RGB in [0, 1];
    materials : each group's material as shown when the mesh shows its own, else None"""

    key: object
    scene: object
    mesh: object
    colors: np.ndarray
    camera: object
    size: tuple
    background: tuple
    materials: tuple | None = None


@dataclass(frozen=True)
class Result:
    """A finished comparison: the job, the heat map (h, w, 3) uint8, the comparison, the
    advice line, the time it took (ms); or the error that stopped it."""

    job: Job
    image: np.ndarray | None = None
    comparison: object = None
    advice: str = ""
    ms: float = 0.0
    error: BaseException | None = None


def run_job(job: Job, cancelled=lambda: False, comparer=None) -> Result:
    """Make one comparison (in any thread).

    comparer : a :class:`~explorer.analysis.comparison.ViewComparer` of ``job.size`` made in
        this thread, whose off-screen windows are reused (default: new ones for this job)
    The highlight peak's error is not computed (the map and its legend do not show it).
    """
    t = time.perf_counter()
    if comparer is None:
        with C.ViewComparer(job.size) as own:
            return run_job(job, cancelled, own)
    c = comparer.compare(job.scene, job.mesh, camera=job.camera, colors=job.colors,
                         cancelled=cancelled, peak=False, materials=job.materials)  # fmt: skip
    bg = tuple(int(v) for v in to_bytes([job.background])[0])
    image = C.heat_map(c.levels, c.mask, vmax=VMAX, background=bg)
    m = job.scene.material
    advice = A.advice(m.shininess, job.size, model=job.scene.model)
    mesh_name = getattr(job.mesh, "name", "")
    if not any(mesh_name.startswith(name) for name in TABLE_MESHES):
        advice = f"measured on spheres (a guide for this mesh): {advice}"
    return Result(job, image, c, advice, 1000.0 * (time.perf_counter() - t))


class DifferenceWorker:
    """One background thread making the latest requested comparison.

    deliver : called with each :class:`Result` that was not cancelled, in the worker's thread
    """

    def __init__(self, deliver):
        self._deliver = deliver
        self._lock = threading.Condition()
        self._pending: Job | None = None
        self._running: Job | None = None
        self._cancel = threading.Event()
        self._closed = False
        self._thread = threading.Thread(target=self._loop, name="difference", daemon=True)
        self._thread.start()

    def submit(self, job: Job) -> None:
        """Make ``job`` next; the one running and any waiting are cancelled."""
        with self._lock:
            self._pending = job
            self._cancel.set()
            self._lock.notify()

    def cancel(self) -> None:
        """Drop what is waiting and cancel what runs."""
        with self._lock:
            self._pending = None
            self._cancel.set()

    @property
    def busy(self) -> bool:
        with self._lock:
            return self._pending is not None or self._running is not None

    def close(self, timeout: float = 30.0) -> None:
        with self._lock:
            self._closed = True
            self._pending = None
            self._cancel.set()
            self._lock.notify()
        self._thread.join(timeout)

    def _loop(self) -> None:
        comparer = None  # off-screen windows made in this thread, kept while the size holds
        try:
            while True:
                with self._lock:
                    while self._pending is None and not self._closed:
                        self._lock.wait()
                    if self._closed:
                        return
                    job, self._pending, self._running = self._pending, None, self._pending
                    self._cancel = cancel = threading.Event()
                try:
                    if comparer is not None and comparer.size != tuple(job.size):
                        comparer.close()
                        comparer = None
                    if comparer is None:
                        comparer = C.ViewComparer(job.size)
                    result = run_job(job, cancel.is_set, comparer)
                except Exception as exc:  # noqa: BLE001 - handed to the window, which shows it
                    result = None if isinstance(exc, Cancelled) else Result(job, error=exc)
                with self._lock:
                    self._running = None
                    stale = cancel.is_set() or self._closed
                if result is not None and not stale:
                    self._deliver(result)
        finally:
            if comparer is not None:
                comparer.close()


class HeatMap:
    """The heat map shown as a renderer's background (the mesh hidden meanwhile)."""

    def __init__(self, renderer):
        self.renderer = renderer
        self.result: Result | None = None
        self.shown = False
        self._texture = None

    def set(self, result: Result) -> None:
        from vtkmodules.util.numpy_support import numpy_to_vtk
        from vtkmodules.vtkCommonDataModel import vtkImageData
        from vtkmodules.vtkRenderingCore import vtkTexture

        image = result.image
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
        self.result = result

    def show(self, visible: bool) -> None:
        """Draw the heat map as the background (True) or the plain background (False)."""
        visible = bool(visible) and self._texture is not None
        self.shown = visible
        self.renderer.SetTexturedBackground(visible)

    def legend(self) -> str:
        """What the map shows: its RMSE and worst pixel, and the colour ramp."""
        if self.result is None:
            return PENDING
        c = self.result.comparison
        return (
            f"per-pixel difference from the exact lighting: RMSE {c.rmse:.2f}, worst pixel "
            f"{c.max} levels (1/255); black 0, blue 1, then green, yellow, red, white "
            f">= {VMAX:g} levels; {int(c.mask.sum()):,} pixels compared"
        )

    def state(self) -> dict:
        r = self.result
        c = None if r is None else r.comparison
        return {
            "shown": self.shown,
            "rmse": None if c is None else c.rmse,
            "max": None if c is None else c.max,
            "pixels": None if c is None else int(c.mask.sum()),
            "ms": None if r is None else r.ms,
            "advice": None if r is None else r.advice,
        }


def advice_lines(text: str) -> str:
    """:func:`explorer.analysis.advice.advice`'s one line split after its ``;`` (it is wide)."""
    return text.replace("; ", ";\n")
