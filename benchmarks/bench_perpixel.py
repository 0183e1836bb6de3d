"""Per-pixel benchmark (issue 39): a slider change and a camera change drawn per pixel
(:class:`explorer.render.live.LivePixels`) beside the same change drawn per vertex, in one run.

    python benchmarks/bench_perpixel.py           # prints the table, writes docs/perpixel_bench.md
    python benchmarks/bench_perpixel.py --repeat 9 --no-write
    python benchmarks/bench_perpixel.py --view --repeat 15   # the drag through the real view

800x600 off-screen, anti-aliasing and multisampling off, the 100,578-vertex teapot (tessellation
56) under 1 and 8 white point lights, gold, the local viewer of ``bench_gui`` (its scene), float32
(the interactive precision) on both paths:

- ``per vertex``: the engine's cached update of the mesh's vertices (kd: compose; shininess: the
  lobe; azimuth: every light sum), the uint8 colour upload into VTK and the frame (VTK draws the
  mesh, colours interpolated): ``bench_gui``'s bare-window path;
- ``per pixel``: the same change through ``LivePixels.frame`` (the covered pixels' cached sums
  recomposed, the display, the picture's bytes), the picture uploaded as the window's background
  texture (an image layer: one texel per pixel) and the frame;
- a camera change (3° about the mesh, the local viewer moving with the camera): per vertex every
  specular sum and the frame; per pixel a new G-buffer (the compiled rasteriser and the surface
  points, :func:`explorer.render.perpixel.compiled_hits`) and every light sum of the pixels,
  with where that time goes.

``--view``: a camera drag through the real view layer instead (:func:`view_run`): the page's
``PlotterView`` (the one the window's is too) at 800x600 on the explorer's start teapot, 1
and 8 lights, the camera turning 1 degree a frame, per vertex and per pixel alternated; frames/s,
CPU ms per frame and the load (printed, not written: docs/perpixel_bench.md quotes it).

Each row: median and best (ms) over ``--repeat`` frames after two warm-up ones; the per-pixel
rows carry the ratio to the per-vertex row of the same change. A frame ends when VTK's
``Render()`` returns and ``WaitForCompletion()`` says the GPU (Mesa llvmpipe here) is done. Wall
times vary with load: the load average before and after is printed with the table.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from bench_gui import SIZE, finish, load, machine, scene_for  # (this script's directory)
from common import publish  # benchmarks/common.py (the compiled tier)

import explorer
from explorer.geometry import meshes as M
from explorer.render.camera import camera_for
from explorer.render.live import LivePixels
from explorer.render.offscreen import BACKGROUND
from explorer.render.vtk import add_unlit, plotter, polydata, set_camera
from explorer.shading.display import to_bytes

DOCS = Path(__file__).resolve().parent.parent / "docs" / "perpixel_bench.md"

#: slider -> the scene of its i-th frame (two values, alternating)
SLIDERS = {
    "kd slider (compose)": lambda s, i: s.replace(
        material=s.material.with_scalars(kd=0.3 + 0.4 * (i % 2))
    ),
    "shininess slider (lobe)": lambda s, i: s.replace(
        material=s.material.replace(shininess=16.0 + 48.0 * (i % 2))
    ),
    "azimuth slider (all light sums)": lambda s, i: s.replace(
        lights=tuple(lt.replace(position=_turned(lt.position, 10.0 * (i % 2))) for lt in s.lights)
    ),
}


def _turned(p, degrees: float) -> tuple:
    """``p`` turned by ``degrees`` about the vertical axis through the origin."""
    a = np.radians(degrees)
    x, y, z = p
    return (x * np.cos(a) + z * np.sin(a), y, -x * np.sin(a) + z * np.cos(a))


def _orbit(scene, mesh, i: int):
    """The scene and camera of the i-th camera frame: the eye 3° to one side or the other."""
    eye = np.asarray(scene.viewer.eye) - mesh.centre
    eye = mesh.centre + np.asarray(_turned(eye, 3.0 if i % 2 else -3.0))
    moved = scene.replace(viewer=scene.viewer.replace(eye=tuple(eye)))
    return moved, camera_for(moved, mesh, SIZE[0] / SIZE[1])


class VertexPath:
    """Per vertex: the engine's cached update, the uint8 upload, VTK's frame of the mesh."""

    def __init__(self, mesh, scene):
        self.mesh = mesh
        self.shader = explorer.Shader(scene, mesh.positions, mesh.normals, precision="float32")
        self.pl = plotter(SIZE, BACKGROUND)
        poly = polydata(mesh, to_bytes(self.shader.colors), float32=True, normals=False)
        add_unlit(self.pl, poly)
        set_camera(self.pl, camera_for(scene, mesh, SIZE[0] / SIZE[1]))
        self.arr = poly.GetPointData().GetArray("colors")
        from vtkmodules.util.numpy_support import vtk_to_numpy

        self.rgb = vtk_to_numpy(self.arr)

    def draw(self, scene, camera=None) -> None:
        self.shader.set_scene(scene)
        if camera is not None:
            set_camera(self.pl, camera)
        to_bytes(self.shader.colors, out=self.rgb)
        self.arr.Modified()
        self.pl.render_window.Render()
        finish(self.pl)

    def close(self) -> None:
        self.pl.close()


class PixelPath:
    """Per pixel: ``LivePixels.frame``, the picture as the window's background texture (one
    texel per pixel), VTK's frame."""

    def __init__(self, mesh):
        from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
        from vtkmodules.vtkCommonDataModel import vtkImageData
        from vtkmodules.vtkRenderingCore import vtkTexture

        self.mesh = mesh
        self.live = LivePixels(mesh, precision="float32")
        self.pl = plotter(SIZE, BACKGROUND)
        w, h = SIZE
        data = vtkImageData()
        data.SetDimensions(w, h, 1)
        self.arr = numpy_to_vtk(np.zeros((w * h, 3), np.uint8), deep=True)
        data.GetPointData().SetScalars(self.arr)
        self.texels = vtk_to_numpy(self.arr).reshape(h, w, 3)
        tex = vtkTexture()
        tex.SetInputData(data)
        tex.InterpolateOff()
        self.pl.renderer.SetBackgroundTexture(tex)
        self.pl.renderer.SetTexturedBackground(True)
        self.data = data

    def draw(self, scene, camera) -> tuple[float, float, float]:
        """One frame; returns the CPU ms of its parts: the G-buffer (0 when none was made), the
        shading and display (``LivePixels.frame``), the upload and the frame."""
        c0 = time.process_time()
        self.live.gbuffer(camera, SIZE)
        c1 = time.process_time()
        frame = self.live.frame(scene, camera, SIZE)
        c2 = time.process_time()
        self.texels[:] = frame.rgb[::-1]  # VTK's rows start at the bottom
        self.arr.Modified()
        self.data.Modified()
        self.pl.render_window.Render()
        finish(self.pl)
        c3 = time.process_time()
        return tuple(1000.0 * x for x in (c1 - c0, c2 - c1, c3 - c2))

    def close(self) -> None:
        self.live.close()
        self.pl.close()


def paired(vertex_step, pixel_step, repeat: int, warm: int = 2) -> tuple[dict, dict]:
    """Both paths' frames alternated (vertex, pixel, vertex, ...: a change in the machine's
    load falls on both): for each, the median and best wall ms and the median CPU ms of this
    process (every thread: numba's and llvmpipe's) over ``repeat`` frames after ``warm``."""
    out = ({"wall": [], "cpu": []}, {"wall": [], "cpu": []})
    for i in range(warm + repeat):
        for times, step in zip(out, (vertex_step, pixel_step), strict=True):
            t, c = time.perf_counter(), time.process_time()
            step(i)
            wall, cpu = 1000.0 * (time.perf_counter() - t), 1000.0 * (time.process_time() - c)
            if i >= warm:
                times["wall"].append(wall)
                times["cpu"].append(cpu)
    return tuple(
        {"ms": (statistics.median(x["wall"]), min(x["wall"])), "cpu": statistics.median(x["cpu"])}
        for x in out
    )


def run(mesh, count: int, repeat: int) -> dict:
    """Rows (change, path, times, ratio of median wall and CPU ms to per vertex, or None) for
    ``count`` lights, the pixels covered and the machine lines."""
    scene = scene_for(mesh, count)
    camera = camera_for(scene, mesh, SIZE[0] / SIZE[1])
    vertex, pixel = VertexPath(mesh, scene), PixelPath(mesh)
    rows = []

    def add(name, v, p):
        ratio = (p["ms"][0] / v["ms"][0], p["cpu"] / v["cpu"])
        rows.extend([(name, "per vertex", v, None), (name, "per pixel", p, ratio)])

    try:
        for name, change in SLIDERS.items():
            v, p = paired(
                lambda i, c=change: vertex.draw(c(scene, i)),
                lambda i, c=change: pixel.draw(c(scene, i), camera),
                repeat,
            )
            add(name, v, p)
        orbit = [_orbit(scene, mesh, i) for i in (0, 1)]  # (made before: not timed)
        shares = []
        v, p = paired(
            lambda i: vertex.draw(*orbit[i % 2]),
            lambda i: shares.append(pixel.draw(*orbit[i % 2])),
            repeat,
        )
        add("camera change", v, p)
        parts = ("the G-buffer", "shading + display", "upload + frame")
        for k, part in enumerate(parts):
            cpu = statistics.median(x[k] for x in shares[-repeat:])
            rows.append(("camera change", f"of it: {part}", {"cpu": cpu}, None))
        covered = int(pixel.live.gbuffer(camera, SIZE)[0].hits.mask.sum())
        import numba

        threads = (
            f"numba threading layer {numba.threading_layer()}; OMP_WAIT_POLICY "
            f"{os.environ.get('OMP_WAIT_POLICY', 'unset')}"
        )
        return {"rows": rows, "covered": covered, "machine": [*machine(vertex.pl), threads]}
    finally:
        vertex.close()
        pixel.close()


def table(mesh, results: dict, before: str, after: str, repeat: int) -> str:
    first = next(iter(results.values()))
    out = ["# Per-pixel benchmark", ""]
    out += [
        "A change drawn per pixel (`explorer.render.live.LivePixels`, float32) beside the same "
        "change drawn per vertex, in one run, off-screen (what is timed: "
        "`benchmarks/bench_perpixel.py`):",
        "",
        "- per vertex: the engine's cached update of the vertices, the colour upload, VTK's "
        "frame of the mesh (colours interpolated);",
        "- per pixel: `LivePixels.frame` (a camera change: a new G-buffer, the compiled "
        "rasteriser's triangle per pixel then the surface points, and every light sum of the "
        "pixels; a slider: "
        "the cached sums recomposed, or the lobe, or the sums of the lights), the picture "
        "uploaded as the window's background texture, VTK's frame.",
        "",
        "Machine:",
        "",
    ]
    out += [f"- {line}" for line in first["machine"]]
    out += [f"- load average before / after: {before} / {after}", ""]
    for count, res in results.items():
        out += [
            f"{mesh.n_vertices:,}-vertex teapot, {count} point light{'s' if count > 1 else ''}, "
            f"{SIZE[0]}x{SIZE[1]} ({res['covered']:,} pixels covered); wall ms median (best) and "
            f"CPU ms (median) over {repeat} frames, the two paths alternated:",
            "",
            "| change | path | wall ms | CPU ms | / per vertex (wall, CPU) | frames/s (wall) "
            "| frames/s (CPU) |",
            "|---|---|---:|---:|---:|---:|---:|",
        ]
        for name, path, t, ratio in res["rows"]:
            wall, fps, cpu_fps = "", "", ""
            if "ms" in t:
                wall, fps = f"{t['ms'][0]:.1f} ({t['ms'][1]:.1f})", f"{1000.0 / t['ms'][0]:.0f}"
                cpu_fps = f"{1000.0 / t['cpu']:.0f}"
            ratio_s = "" if ratio is None else f"{ratio[0]:.2f}, {ratio[1]:.2f}"
            out.append(
                f"| {name} | {path} | {wall} | {t['cpu']:.1f} | {ratio_s} | {fps} | {cpu_fps} |"
            )
        out.append("")
    out += summary(results, before)
    out += ["", f"Command: `python benchmarks/bench_perpixel.py --repeat {repeat}`"]
    return "\n".join(out) + "\n"


def summary(results: dict, before: str = "") -> list[str]:
    """What the tables say against issue 39's targets (a slider per pixel within 1.3x the
    per-vertex frame; a camera change at 20 frames/s or more), and what was measured."""
    rows = [r for res in results.values() for r in res["rows"]]
    sliders = [r[3] for r in rows if r[3] is not None and r[0] != "camera change"]
    camera = {
        n: {r[1]: r[2] for r in res["rows"] if r[0] == "camera change"}
        for n, res in results.items()
    }
    lines = ["## What it says", ""]
    first = float(before.split()[0]) if before and before != "n/a" else 0.0
    cores = os.cpu_count() or 1
    if first > cores:
        lines.append(
            f"- Measured under load (load average {first:.1f} on {cores} cores: other work ran): "
            "wall times are then several times the work (a frame waits for a core), so the CPU "
            "columns and the ratios of the alternated paths are the figures to compare; "
            "frames/s are this run's, not the machine's."
        )
    lines.append(
        f"- A slider change per pixel takes {min(r[0] for r in sliders):.2f}x to "
        f"{max(r[0] for r in sliders):.2f}x the per-vertex frame's wall time "
        f"({min(r[1] for r in sliders):.2f}x to {max(r[1] for r in sliders):.2f}x its CPU "
        "time; target: at most 1.3x): the pixels' sums are cached, and an image layer is "
        "cheaper to draw than the 100k-vertex mesh."
    )
    for n, c in camera.items():
        pp, vv = c["per pixel"], c["per vertex"]
        share = {}
        for k, t in c.items():
            if k.startswith("of it: "):
                share[k[len("of it: ") :]] = 100.0 * t["cpu"] / pp["cpu"]
        lines.append(
            f"- A camera change per pixel, {n} light{'s' if n > 1 else ''}: "
            f"{pp['cpu']:.1f} ms of CPU, {1000.0 / pp['cpu']:.0f} frames/s on one core's CPU "
            f"time (target: 20 or more); {1000.0 / pp['ms'][0]:.0f} frames/s of this run's "
            f"wall time ({1000.0 / pp['ms'][1]:.0f} at best), "
            f"{pp['ms'][0] / vv['ms'][0]:.2f}x the per-vertex frame's wall time, "
            f"{pp['cpu'] / vv['cpu']:.2f}x its CPU time. Of the CPU time: the G-buffer "
            f"{share['the G-buffer']:.0f}% (the compiled rasteriser's triangle per pixel, then "
            "the surface points), the pixels' light sums and "
            f"display {share['shading + display']:.0f}%, the upload and frame "
            f"{share['upload + frame']:.0f}%."
        )
    lines.append(
        "- The per-pixel picture is drawn here as an image layer (the renderer's background "
        "texture, one texel per pixel, the mesh not drawn); the front ends draw it as a screen "
        "quad writing the surface's depth, the mesh not drawn either (the --view section: "
        "the drag through the real view)."
    )
    return lines


# -- through the real view layer (--view) --------------------------------------------------------

#: the camera's turn per frame of the --view drag (degrees about the view's up)
VIEW_TURN = 1.0
#: the --view section's heading in docs/perpixel_bench.md: it and the sections after it (the
#: page's slider, ``bench_web.py --per-pixel``'s figures) end the page; a run without --view
#: keeps them, a run with --view replaces its own section only
VIEW_HEADING = "## Through the real view (`--view`)"


def view_section(page: str) -> str:
    """The --view section of ``page`` (a docs/perpixel_bench.md) and the sections after it, to
    the end, or ""."""
    at = page.find(VIEW_HEADING)
    return "" if at < 0 else page[at:]


def with_view_section(page: str, section: str) -> str:
    """``page`` with its --view section (to the next ``## `` heading) replaced by ``section``
    (added at the end when it had none)."""
    at = page.find(VIEW_HEADING)
    if at < 0:
        return page.rstrip("\n") + "\n\n" + section.rstrip("\n") + "\n"
    end = page.find("\n## ", at + len(VIEW_HEADING))
    tail = "" if end < 0 else "\n" + page[end + 1 :]
    return page[:at] + section.rstrip("\n") + "\n" + tail


def view_port(count: int, resolution: int):
    """The page's explorer (:class:`explorer.app.web.server.WebExplorer`, not served): the
    view layer both front ends share (:class:`explorer.app.viewport.PlotterView` over an
    off-screen plotter of 800x600, the window's ``QtInteractor`` being the other), on the
    explorer's start (``phong-explorer web --resolution RESOLUTION``: the teapot at that
    tessellation, 56 the issue's 100,578 vertices; gold, the start's light and camera), with
    ``count`` lights (white point lights added as the panel's "add light" does)."""
    from explorer.app import model as AM
    from explorer.app.web.server import WebExplorer
    from explorer.cli import build_parser
    from explorer.cli.explorerstart import start_state

    state, mesh = start_state(build_parser().parse_args(["web", "--resolution", str(resolution)]))
    app = WebExplorer(state, mesh, size=SIZE, name=f"bench-view-{count}", last_session=None)
    for _ in range(count - len(app.controller.state.scene.lights)):
        app.controller.act(AM.add_light)
    return app


def view_frames(app, mode: str, repeat: int, warm: int = 3) -> dict:
    """``repeat`` frames (after ``warm``) of a camera drag in ``mode`` (the shading): each frame
    the camera turned :data:`VIEW_TURN` degrees, then the render window's ``Render()`` (the
    view's own frame observers: the camera into the state, the per-pixel picture, side B, the
    page's frame step) and ``WaitForCompletion()``. Between ``begin_drag`` and ``end_drag``, as
    a mouse drag does (so the drag fallback to per vertex may act: counted), after ``warm``
    such frames without a drag (the fallback compares the last picture's time with the last
    frame's: a camera frame's, not the mode switch's). Returns the median and best wall ms,
    the median CPU ms of this process, the per-pixel pictures made and whether a frame fell
    back to per vertex."""
    vp, c = app.viewport, app.controller
    c.set_value("shading", mode, merge=False)
    vp.redraw()
    cam, window = app.plotter.camera, app.plotter.render_window
    for _ in range(warm):
        cam.Azimuth(VIEW_TURN)
        window.Render()
    walls, cpus = [], []
    made, fell = vp.pixels.frames, False
    vp.begin_drag()
    try:
        for i in range(warm + repeat):
            cam.Azimuth(VIEW_TURN)
            t, p = time.perf_counter(), time.process_time()
            window.Render()
            window.WaitForCompletion()
            wall, cpu = 1000.0 * (time.perf_counter() - t), 1000.0 * (time.process_time() - p)
            fell = fell or vp.pixels.fallback
            if i >= warm:
                walls.append(wall)
                cpus.append(cpu)
    finally:
        vp.end_drag()
    return {
        "ms": (statistics.median(walls), min(walls)),
        "cpu": statistics.median(cpus),
        "pictures": vp.pixels.frames - made,
        "fallback": fell,
    }


def view_run(counts, repeat: int, resolution: int, rounds: int = 2) -> dict:
    """For each light count: per-vertex and per-pixel drags through the real view, alternated
    ``rounds`` times (a change in the load falls on both); each mode's best round (by median
    wall) is kept."""
    out = {}
    for n in counts:
        app = view_port(n, resolution)
        try:
            best: dict = {}
            for _ in range(rounds):
                for mode in ("per-vertex", "per-pixel"):
                    r = view_frames(app, mode, repeat)
                    if mode not in best or r["ms"][0] < best[mode]["ms"][0]:
                        best[mode] = r
            view = app.viewport.view
            out[n] = {
                "modes": best,
                "vertices": view.mesh.n_vertices,
                "lights": len(app.controller.state.scene.lights),
                "machine": machine(app.plotter),
            }
        finally:
            app.plotter.close()
    return out


def view_table(results: dict, before: str, after: str, repeat: int, resolution: int) -> list[str]:
    """The --view section's lines (markdown)."""
    first = next(iter(results.values()))
    out = [
        VIEW_HEADING,
        "",
        "A camera drag through the view layer both front ends share (`PlotterView`, the page's "
        f"off-screen plotter at {SIZE[0]}x{SIZE[1]}; the explorer's start: the "
        f"{first['vertices']:,}-vertex teapot, gold): per frame the camera turns "
        f"{VIEW_TURN:g} degree and the render window draws with every observer of the view "
        "(the camera into the state, the per-pixel picture, the page's frame step), between "
        "`begin_drag` and `end_drag` as a mouse drag. Per pixel, the picture is a screen quad "
        "writing the G-buffer's depth (the mesh is not rasterised).",
        "",
        *(f"- {line}" for line in first["machine"]),
        f"- load average before / after: {before} / {after}",
        "",
        "| lights | shading | wall ms median (best) | CPU ms | frames/s (wall) "
        "| per-pixel pictures | fell back to per vertex |",
        "|---:|---|---:|---:|---:|---:|---|",
    ]
    for res in results.values():
        for mode, r in res["modes"].items():
            fell = "" if mode != "per-pixel" else ("yes" if r["fallback"] else "no")
            out.append(
                f"| {res['lights']} | {mode} | {r['ms'][0]:.1f} ({r['ms'][1]:.1f}) | "
                f"{r['cpu']:.1f} | {1000.0 / r['ms'][0]:.0f} | {r['pictures']} | {fell} |"
            )
    out.append("")
    for res in results.values():
        v, p = res["modes"]["per-vertex"], res["modes"]["per-pixel"]
        out.append(
            f"- {res['lights']} light{'s' if res['lights'] > 1 else ''}: a per-pixel drag "
            f"frame takes {p['cpu']:.1f} ms of CPU ({1000.0 / p['cpu']:.0f} frames/s of CPU "
            f"time), {p['cpu'] / v['cpu']:.2f}x the per-vertex frame's CPU and "
            f"{p['ms'][0] / v['ms'][0]:.2f}x its wall time; {1000.0 / p['ms'][0]:.0f} frames/s "
            f"of this run's wall time (target: 20 or more, idle)."
        )
    out += [
        "",
        f"Each row: the best of two alternated rounds of {repeat} frames (after 3 warm-up "
        "frames, and 3 in the drag), its median and best wall time per frame and its median "
        "CPU time (this process, every thread).",
        "",
        f"Command: `python benchmarks/bench_perpixel.py --view --repeat {repeat}` "
        f"(`--view-resolution {resolution}`)",
    ]
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=15, help="timed frames per row (15)")
    ap.add_argument("--lights", type=int, nargs="+", default=[1, 8])
    ap.add_argument("--no-write", action="store_true", help="do not write the docs page")
    ap.add_argument(
        "--view",
        action="store_true",
        help="only the camera drag through the real view layer (prints its section)",
    )
    ap.add_argument(
        "--view-resolution",
        type=int,
        default=56,
        help="--view: the start teapot's tessellation (56: the issue's 100,578 vertices)",
    )
    args = ap.parse_args(argv)
    before = load()
    if args.view:
        results = view_run(args.lights, args.repeat, args.view_resolution)
        lines = view_table(results, before, load(), args.repeat, args.view_resolution)
        print("\n".join(lines))
        if not args.no_write:
            DOCS.write_text(with_view_section(DOCS.read_text(), "\n".join(lines)))
            print(f"wrote {DOCS}", file=sys.stderr)
        return 0
    mesh = M.teapot(56)
    results = {n: run(mesh, n, args.repeat) for n in args.lights}
    text = table(mesh, results, before, load(), args.repeat)
    kept = view_section(DOCS.read_text()) if DOCS.exists() else ""
    publish(with_view_section(text, kept) if kept else text, DOCS, write=not args.no_write)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
