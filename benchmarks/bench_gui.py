"""GUI benchmark: time from a slider change to the rendered frame, beside VTK's own lighting.

    python benchmarks/bench_gui.py                    # prints the table, writes docs/gui_bench.md
    python benchmarks/bench_gui.py --repeat 15 --no-write

Everything runs off-screen in one process, 800x600, anti-aliasing and multisampling off, on the
same meshes:

- 100k vertices (the Utah teapot at tessellation 56), 1, 4 and 8 point lights:
  * ``explorer``: the explorer window's update path (its Store and SceneView: mesh, handle,
    lobe inset; no Qt widgets) as a slider's action arrives:
    the engine's update (kd: compose only; shininess: the lobe; azimuth: every light sum), the
    uint8 colour upload and the frame;
  * ``engine + unlit mesh``: the same engine update and upload on a bare window (no widgets);
  * ``VTK lighting``: VTK's own per-pixel Phong lighting of the same mesh with as many
    positional lights, a material property changed (what a slider would do) and the frame.
- 1M vertices (a UV sphere): a slider frame while dragging (the level of detail is drawn), the
  frame on release (the full mesh shaded and drawn), and a slider frame with no level of detail.

Each row: median and best over ``--repeat`` frames after a warm-up (the first, compiling frame is
never timed), and the ratio to VTK's lighting. A frame ends when VTK's ``Render()`` returns and
``WaitForCompletion()`` (``glFinish``) says the GPU (here Mesa llvmpipe) is done. Wall times
vary with load: the load average before and after is printed with the table.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from common import publish, uv_sphere  # benchmarks/common.py

import explorer
from explorer.app import model as AM
from explorer.app.start import first_state, start_xvfb
from explorer.app.view import SceneView, framed_camera, view_camera
from explorer.core.lights import PointLight
from explorer.core.presets import find_preset
from explorer.core.scene import Scene, Viewer
from explorer.geometry import meshes as M
from explorer.render.camera import camera_for
from explorer.render.offscreen import BACKGROUND
from explorer.render.vtk import add_unlit, plotter, polydata, set_camera
from explorer.shading.display import to_bytes

SIZE = (800, 600)
DOCS = Path(__file__).resolve().parent.parent / "docs" / "gui_bench.md"


def machine(plotter) -> list[str]:
    """The engine benchmark's machine line, plus VTK, PyVista and the OpenGL renderer."""
    import pyvista as pv
    import vtk
    from bench_engine import machine as engine_machine  # this script's directory is on sys.path

    from explorer.analysis.benchmark import machine_info

    gl = ""
    for line in (plotter.render_window.ReportCapabilities() or "").splitlines():
        if line.startswith("OpenGL renderer string:"):
            gl = line.split(":", 1)[1].strip()
    # an EGL window that has not drawn yet reports nothing: ask a fresh off-screen context
    gl = gl or machine_info(opengl=True).get("opengl", {}).get("renderer") or "unknown"
    return [
        engine_machine(),
        f"VTK {vtk.vtkVersion.GetVTKVersion()}, PyVista {pv.__version__}; OpenGL renderer: {gl}; "
        f"window {SIZE[0]}x{SIZE[1]} off-screen, no anti-aliasing",
    ]


def load() -> str:
    if not hasattr(os, "getloadavg"):
        return "n/a"
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def timed(step, repeat: int, warm: int = 2) -> tuple[float, float]:
    """Median and best wall time (ms) of ``step(i)`` over ``repeat`` calls after ``warm``."""
    for i in range(warm):
        step(i)
    ts = []
    for i in range(repeat):
        t = time.perf_counter()
        step(warm + i)
        ts.append(1000.0 * (time.perf_counter() - t))
    return statistics.median(ts), min(ts)


def lights_around(mesh, count: int) -> tuple:
    """``count`` white point lights spread over the upper front of the mesh."""
    out = []
    for i in range(count):
        az = -60.0 + 120.0 * (i + 0.5) / count
        el = 20.0 + 25.0 * (i % 2)
        out.append(PointLight().placed(az, el, 3.0 * mesh.radius, mesh.centre))
    return tuple(out)


def scene_for(mesh, count: int) -> Scene:
    eye = mesh.centre + 6.0 * mesh.radius * np.array([0.0, 0.3, 1.0]) / np.hypot(0.3, 1.0)
    return Scene(
        material=find_preset("gold"),
        lights=lights_around(mesh, count),
        viewer=Viewer(eye=tuple(eye)),
    )


def finish(plotter) -> None:
    plotter.render_window.WaitForCompletion()


# -- the three ways of drawing a slider change ----------------------------------------------------


class Driven:
    """The explorer window's update path without Qt: a Store and the window's SceneView in an
    off-screen plotter. A change goes state -> view (engine update, uint8 upload) -> frame, and
    each frame records the camera into the state first, exactly as the window does; the Qt
    widgets and event loop are not part of it."""

    def __init__(self, mesh, scene, **kw):
        self.plotter = plotter(SIZE, BACKGROUND)
        state = first_state(scene, mesh, name=mesh.name)
        state = AM.set_camera(state, framed_camera(state, mesh, SIZE[0] / SIZE[1]))
        self.store = AM.Store(state)
        self.view = SceneView(self.plotter, mesh, state, **kw)
        self.view.add_handles(*(lambda *_: None,) * 3)
        self.view.apply_camera(state.camera)
        self.store.subscribe(lambda old, new: self.view.show_state(new))

    def render(self) -> None:
        s = self.store.state
        cam = view_camera(self.plotter.camera, s.centre, s.radius)
        self.store.set_camera(cam)
        self.view.before_frame(cam)
        self.plotter.render_window.Render()

    def close(self) -> None:
        self.plotter.close()


#: slider name -> the action its value sends
SLIDERS = {
    "kd": lambda i: (AM.set_coefficient, "kd", 0.3 + 0.4 * (i % 2)),
    "shininess": lambda i: (AM.set_shininess, round(10 ** (1.2 + 0.8 * (i % 2)), 1)),
    "azimuth": lambda i: (AM.place_light, 20.0 + 30.0 * (i % 2)),
}


def explorer_frames(mesh, count: int, repeat: int, **kw) -> dict:
    """The explorer's update path: a slider's action, then the frame."""
    app = Driven(mesh, scene_for(mesh, count), **kw)
    app.render()
    out = {}
    for name, action in SLIDERS.items():

        def step(i, action=action):
            app.store.apply(*action(i), merge="bench")
            app.render()
            finish(app.plotter)

        out[name] = timed(step, repeat)

    def rotate(i):
        app.plotter.camera.Azimuth(3.0 if i % 2 else -3.0)
        app.render()
        finish(app.plotter)

    out["camera"] = timed(rotate, repeat)
    out["app"] = app
    return out


def bare_engine_frames(mesh, count: int, repeat: int) -> dict:
    """The engine's update and upload on a bare window: the cost without the widgets."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    scene = scene_for(mesh, count)
    shader = explorer.Shader(scene, mesh.positions, mesh.normals, precision="float32")
    pl = plotter(SIZE, BACKGROUND)
    poly = polydata(mesh, to_bytes(shader.colors), float32=True, normals=False)
    add_unlit(pl, poly)
    set_camera(pl, camera_for(scene, mesh, SIZE[0] / SIZE[1]))
    arr = poly.GetPointData().GetArray("colors")
    rgb = vtk_to_numpy(arr)
    m = scene.material

    def step(i):
        shader.set_material(m.with_scalars(kd=0.3 + 0.4 * (i % 2)))
        to_bytes(shader.colors, out=rgb)
        arr.Modified()
        pl.render_window.Render()
        finish(pl)

    result = timed(step, repeat)
    pl.close()
    return {"kd": result}


def vtk_lighting_frames(mesh, count: int, repeat: int) -> dict:
    """VTK's own per-pixel lighting of the same mesh, a material property changed per frame."""
    import pyvista as pv

    scene = scene_for(mesh, count)
    m = scene.material
    pl = plotter(SIZE, BACKGROUND)
    poly = polydata(mesh)
    actor = pl.add_mesh(
        poly,
        color=m.diffuse,
        ambient=max(m.ambient) / max(m.diffuse),
        diffuse=1.0,
        specular=max(m.specular),
        specular_power=m.shininess,
        smooth_shading=True,
        interpolation="phong",
    )
    for light in scene.lights:
        pl.add_light(
            pv.Light(position=light.position, focal_point=tuple(mesh.centre), positional=True,
                     cone_angle=180.0, light_type="scene light")
        )  # fmt: skip
    set_camera(pl, camera_for(scene, mesh, SIZE[0] / SIZE[1]))
    prop = actor.GetProperty()

    def step(i):
        prop.SetDiffuse(0.4 + 0.5 * (i % 2))
        pl.render_window.Render()
        finish(pl)

    result = timed(step, repeat)
    assert pl.renderer.GetLights().GetNumberOfItems() == count
    pl.close()
    return {"kd": result}


def lod_frames(mesh, repeat: int) -> dict:
    """1M vertices: slider frames while dragging (LOD), the frame on release, and slider frames
    drawn on the full mesh (no LOD)."""
    out = {}
    app = Driven(mesh, scene_for(mesh, 1))
    app.render()

    def drag(i):
        app.store.apply(*SLIDERS["kd"](i), merge="bench")
        app.render()
        finish(app.plotter)

    def rotate(i):
        app.plotter.camera.Azimuth(3.0 if i % 2 else -3.0)
        app.render()
        finish(app.plotter)

    app.view.begin_drag()
    out["lod vertices"] = app.view.drawings[1].mesh.n_vertices
    out["drag kd (LOD)"] = timed(drag, repeat)
    out["drag camera (LOD)"] = timed(rotate, repeat)

    def release(i):
        app.view.begin_drag()
        drag(i)
        t = time.perf_counter()
        app.view.end_drag()
        app.render()
        finish(app.plotter)
        return 1000.0 * (time.perf_counter() - t)

    app.view.end_drag()
    app.render()
    ts = [release(i) for i in range(max(3, repeat // 3))]
    out["release (full mesh)"] = (statistics.median(ts), min(ts))
    app.close()
    full = explorer_frames(mesh, 1, max(3, repeat // 3), lod_vertices=10**9)
    out["kd, no LOD (full mesh)"] = full["kd"]
    full["app"].close()
    return out


def qt_frames(mesh, repeat: int, view: tuple[int, int] | None = None) -> dict:
    """The Qt window itself (panel refresh included): a number field set, then the frame.
    ``view``: the window is resized so its 3D view is that many pixels (the page's view size,
    for bench_web). Needs an X display; a private Xvfb is started when DISPLAY is not set."""
    server = None
    if not os.environ.get("DISPLAY"):
        server, os.environ["DISPLAY"] = start_xvfb()
    from explorer.app.qt.window import ExplorerWindow
    from explorer.app.qtmain import application

    app = application()
    scene = scene_for(mesh, 1)
    win = ExplorerWindow(first_state(scene, mesh, name=mesh.name), mesh, size=(1150, 640))
    win.show()
    app.processEvents()
    for _ in range(3 if view else 0):  # (the window manager may round the first resize)
        w, h = win.plotter.window_size
        win.resize(win.width() + view[0] - w, win.height() + view[1] - h)
        app.processEvents()
    win.render()
    fields = win.panel.material.sliders
    values = {"kd": lambda i: 0.3 + 0.4 * (i % 2), "shininess": lambda i: 16.0 + 48.0 * (i % 2)}
    out = {"view": tuple(win.plotter.window_size)}
    for name, value in values.items():

        def step(i, name=name, value=value):
            fields[name].field.setValue(value(i))  # action, panel, engine, upload, frame
            finish(win.plotter)

        cpu = time.process_time()
        out[name] = timed(step, repeat)
        # the window's process CPU per change (its threads: Qt, the engine's, llvmpipe's)
        out.setdefault("cpu", {})[name] = 1e3 * (time.process_time() - cpu) / (repeat + 2)
    # where a kd change's time goes: the panel's refresh, the engine and upload, the frame
    state = win.controller.state
    out["panel refresh"] = timed(lambda i: win.panel.show_state(state, mesh.n_vertices), repeat)
    out["engine + upload"] = timed(
        lambda i: win.view.show_state(AM.set_coefficient(state, "kd", 0.3 + 0.4 * (i % 2))),
        repeat,
    )
    out["frame"] = timed(lambda i: (win.render(), finish(win.plotter)), repeat)
    win.close()
    app.processEvents()
    if server is not None:
        server.terminate()
        server.wait()
    return out


def fmt(t) -> str:
    return f"{t[0]:.1f} ({t[1]:.1f})"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=21, help="timed frames per row (21)")
    ap.add_argument("--lights", type=int, nargs="+", default=[1, 4, 8])
    ap.add_argument("--no-write", action="store_true", help="do not write docs/gui_bench.md")
    ap.add_argument("--skip-1m", action="store_true", help="leave out the 1M-vertex rows")
    ap.add_argument("--qt", action="store_true",
                    help="also time the Qt window itself (needs Xvfb or a display)")  # fmt: skip
    args = ap.parse_args(argv)

    before = load()
    teapot = M.teapot(56)
    rows = []  # (case, lights, median/best ms, ratio to VTK)
    info = None
    for count in args.lights:
        ex = explorer_frames(teapot, count, args.repeat)
        if info is None:
            info = machine(ex["app"].plotter)
        ex["app"].close()
        bare = bare_engine_frames(teapot, count, args.repeat)
        vtk_ = vtk_lighting_frames(teapot, count, args.repeat)
        ref = vtk_["kd"][0]
        rows.append(("VTK per-pixel lighting, property change", count, vtk_["kd"], 1.0))
        rows.append(
            ("engine + unlit mesh (bare window), kd", count, bare["kd"], bare["kd"][0] / ref)
        )
        for name, label in (
            ("kd", "explorer view, kd slider (compose)"),
            ("shininess", "explorer view, shininess slider (lobe)"),
            ("azimuth", "explorer view, azimuth slider (all light sums)"),
            ("camera", "explorer view, camera rotation (specular)"),
        ):
            rows.append((label, count, ex[name], ex[name][0] / ref))
    lod = None
    sphere = None
    if not args.skip_1m:
        sphere = uv_sphere(1000, 999)
        lod = lod_frames(sphere, args.repeat)
    qt = qt_frames(teapot, args.repeat) if args.qt else None
    after = load()

    lines = ["# GUI benchmark", "", "Machine:", ""]
    lines += [f"- {x}" for x in info]
    lines += [f"- load average before / after: {before} / {after}", ""]
    lines += [
        f"Slider change to rendered frame, {teapot.n_vertices:,}-vertex teapot, point lights; "
        f"median (best) ms over {args.repeat} frames:",
        "",
        "| case | lights | ms | / VTK |",
        "|---|---:|---:|---:|",
    ]
    lines += [f"| {c} | {n} | {fmt(t)} | {r:.2f} |" for c, n, t, r in rows]
    if lod is not None:
        lines += [
            "",
            f"1M vertices ({sphere.n_vertices:,}-vertex UV sphere, 1 point light; level of "
            f"detail {lod['lod vertices']:,} vertices); median (best) ms:",
            "",
            "| case | ms | frames/s |",
            "|---|---:|---:|",
        ]
        for k, t in lod.items():
            if k != "lod vertices":
                lines.append(f"| {k} | {fmt(t)} | {1000.0 / t[0]:.0f} |")
    if qt is not None:
        bare1 = next(t for c, n, t, _ in rows if n == 1 and c.startswith("engine + unlit"))
        vw, vh = qt["view"]
        lines += [
            "",
            f"The Qt window itself (1 point light, the same teapot, its view {vw}x{vh}): a "
            "number field set to a new value, through the action, the panel's refresh, the "
            "engine, the upload and the frame; median (best) ms, and the ratio to the bare "
            "mesh draw above (1 light; its window is 800x600):",
            "",
            "| case | ms | / bare draw |",
            "|---|---:|---:|",
        ]
        for k in ("kd", "shininess"):
            lines.append(f"| Qt window, {k} field | {fmt(qt[k])} | {qt[k][0] / bare1[0]:.2f} |")
        for k in ("panel refresh", "engine + upload", "frame"):
            lines.append(f"| of a kd change: {k} | {fmt(qt[k])} | |")
    qt_flag = " --qt" if qt is not None else ""
    lines += ["", f"Command: `python benchmarks/bench_gui.py --repeat {args.repeat}{qt_flag}`"]
    text = "\n".join(lines) + "\n"
    publish(text, DOCS, write=not args.no_write)
    return 0


if __name__ == "__main__":
    sys.exit(main())
