"""The view port both front ends share (explorer.app.viewport.PlotterView, and side B's
explorer.app.sides.SideB) on an off-screen plotter, with no toolkit: fake pictures that record
what would reach the person (a picture sent, the controls shown, the legend) and a fake pane B;
the pixels read from the plotter."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from helpers.controllers import icosphere_controller

from explorer.app import model as M
from explorer.app.controller import ports as P
from explorer.app.difference import PENDING, run_job
from explorer.app.sides import SideB
from explorer.app.viewport import PlotterView, controls_changed
from explorer.geometry import meshes as G
from explorer.render.images import decode_png
from explorer.render.vtk import plotter
from explorer.shading.display import to_bytes

SIZE = (320, 240)  # room for the mesh beside the lobe inset (a fixed size in pixels)


class FakePictures:
    """What the view port asks of its front end, recorded; a picture is sent as the Qt window
    sends one (a frame drawn now)."""

    def __init__(self):
        self.view = None
        self.sent = 0
        self.controls: list = []
        self.legends: list = []
        self.after = 0

    def send(self):
        self.sent += 1
        self.view.plotter.render_window.Render()

    def show_controls(self, state):
        self.controls.append(state)

    def show_legend(self, legend, advice):
        self.legends.append((legend, advice))

    def after_frame(self):
        self.after += 1


class FakePane:
    """Side B's pane: an off-screen plotter of the same size; what is asked recorded."""

    handles = True

    def __init__(self):
        self.made_plotters: list = []
        self.shown: list = []
        self.followed = 0

    def make_plotter(self):
        pl = plotter(SIZE, (0.2, 0.2, 0.2))
        self.made_plotters.append(pl)
        return pl

    def made(self, pl, view):
        pass

    def show_pane(self, visible):
        self.shown.append(visible)

    def follow(self):
        self.followed += 1

    def beside(self, img):
        return np.concatenate([img, np.zeros_like(img)], axis=1)


@pytest.fixture(scope="module")
def mesh():
    return G.get_mesh("icosphere", 3)


@pytest.fixture
def port(mesh, tmp_path, monkeypatch):
    """A PlotterView attached to a controller on the icosphere, with side B in a fake pane."""
    pictures, pane = FakePictures(), FakePane()
    view = PlotterView(plotter(SIZE, (0.1, 0.1, 0.1)), pictures)
    pictures.view = view
    c = icosphere_controller(mesh, view, tmp_path, monkeypatch, 3)
    view.attach(c, mesh, side_b=SideB(view, pane), lod_vertices=100, lod_target=60)
    c.start()
    view.show_start(c.state)
    view.redraw()
    view.pictures, view.pane = pictures, pane
    yield view
    for pl in (view.plotter, *pane.made_plotters):
        pl.close()


def picture(view) -> np.ndarray:
    return view.plotter.screenshot(return_img=True)[:, :, :3]


def probe_pixel(view) -> np.ndarray:
    i = view.view.probe_vertex()
    x, y = view.view.world_to_window(view.view.mesh.positions[i])
    return picture(view)[y, x].astype(int), i


def test_it_is_the_view_port(port):
    assert isinstance(port, P.View)
    assert port.size() == SIZE and port.aspect() == pytest.approx(SIZE[0] / SIZE[1])
    assert port.background() == pytest.approx((26 / 255,) * 3)  # VTK keeps 8-bit colours
    assert port.colors().shape == (port.view.mesh.n_vertices, 3) and not port.dragging()
    port.fixed_aspect = 2.0  # a window not shown yet
    assert port.aspect() == 2.0


def test_a_change_sends_one_picture_with_the_engines_colours(port):
    c, pictures = port.controller, port.pictures
    sent, frames, controls = pictures.sent, port.frames, len(pictures.controls)
    c.set_value("kd", 0.3, merge=False)
    assert pictures.sent == sent + 1 and port.frames == frames + 1  # one picture, one frame
    assert len(pictures.controls) == controls + 1 and pictures.controls[-1] is c.state
    assert pictures.after == port.frames  # the front end's step after every frame
    pixel, i = probe_pixel(port)
    want = port.view.displayed_colors()[i].astype(int)
    assert np.array_equal(want, to_bytes(port.colors())[i])
    assert np.abs(pixel - want).max() <= 2  # the probe vertex's own colour (Gouraud between)


def test_a_camera_drag_pushes_no_state_and_its_end_sends_one_picture(port):
    c, pictures = port.controller, port.pictures
    controls, sent, camera = len(pictures.controls), pictures.sent, c.state.camera
    port.begin_drag()
    assert port.dragging() and port.view.lod_active
    port.plotter.camera.Azimuth(25.0)
    port.plotter.render_window.Render()  # a frame of the drag: the camera goes into the state
    assert c.state.camera != camera
    assert len(pictures.controls) == controls and pictures.sent == sent  # nothing pushed
    assert not c.store.can_undo  # the camera is no undo step
    port.end_drag()
    assert not port.dragging() and not port.view.lod_active
    assert pictures.sent == sent + 1 and len(pictures.controls) == controls


def test_a_refused_value_shows_the_controls_again_and_draws_nothing(port):
    c, pictures = port.controller, port.pictures
    sent, frames = pictures.sent, port.frames
    c.set_value("kd", -1.0)  # refused: said, and the controls show the state again
    assert pictures.controls[-1] is c.state and pictures.sent == sent and port.frames == frames


def test_the_difference_shows_the_heat_map_in_place_of_the_mesh(port):
    c, pictures = port.controller, port.pictures
    plain = picture(port)
    c.toggle_difference()
    assert pictures.legends[-1] == (PENDING, "")  # the live view meanwhile
    job = c.ports.worker.jobs[-1]
    c.on_difference(run_job(job))
    assert port.heat.shown and not port.view.drawings[0].actor.GetVisibility()
    legend, advice = pictures.legends[-1]
    assert legend == port.heat.legend() and "RMSE" in legend and advice
    heat = picture(port)
    assert np.abs(heat.astype(int) - plain).max() > 50  # the map, not the shaded mesh
    c.toggle_difference()
    assert not port.heat.shown and port.view.drawings[0].actor.GetVisibility()
    assert pictures.legends[-1] == ("", "")
    assert np.array_equal(picture(port), plain)


def test_a_mesh_switch_draws_the_new_mesh(port):
    c = port.controller
    c.files.choose_mesh("torus")
    assert (
        port.view.mesh is c.meshes["torus"]
        and port.colors().shape[0] == c.meshes["torus"].n_vertices
    )


def test_side_b_is_made_once_follows_each_frame_and_hides(port):
    c, pane = port.controller, port.pane
    assert port.side_b.view is None and not pane.made_plotters  # made when first shown
    c.act(M.set_compare, True)
    c.act(M.set_compare_model, "phong")
    assert len(pane.made_plotters) == 1 and pane.shown[-1] is True
    b = port.side_b
    assert b.plotter.renderer.camera is port.plotter.renderer.camera  # one camera
    assert len(b.view.handles) == len(c.state.scene.lights)  # the pane asked for handles
    followed = pane.followed
    port.redraw()
    assert pane.followed == followed + 1
    assert b.probe()["size"] == list(SIZE)
    img = decode_png(port.png())
    assert img.shape == (SIZE[1], 2 * SIZE[0], 3)  # side B beside, as the pane puts it
    c.act(M.set_compare, False)
    assert pane.shown[-1] is False and len(pane.made_plotters) == 1
    followed = pane.followed
    port.redraw()
    assert pane.followed == followed  # no picture of a hidden side B
    assert decode_png(port.png()).shape == (SIZE[1], SIZE[0], 3)


def test_a_callbacks_error_is_reported_not_raised(port):
    def broken():
        raise RuntimeError("boom")

    assert port.guard(broken, "a widget")() is None
    assert port.controller.errors[-1] == "a widget: RuntimeError: boom"


def test_only_a_camera_move_leaves_the_controls_alone(port):
    s = port.controller.state
    moved = M.set_camera(s, dataclasses.replace(s.camera, view_angle=s.camera.view_angle + 5))
    assert not controls_changed(s, moved)
    assert controls_changed(s, M.set_model(s, "phong"))


def test_letting_go_ends_the_drag_or_seals_the_steps(port):
    c = port.controller
    port.begin_drag()  # a slider pressed
    c.set_value("kd", 0.2)
    c.set_value("kd", 0.25)
    port.let_go()
    assert not port.dragging() and c.store.undo_label() == "kd"
    c.set_value("kd", 0.3)  # a new step: the drag's were sealed at its end
    c.undo()
    assert c.state.material.scalars()[1] == pytest.approx(0.25)
    c.set_value("ks", 0.4)  # a click (no drag): the release seals
    port.let_go()
    c.set_value("ks", 0.5)
    c.undo()
    assert c.state.material.scalars()[2] == pytest.approx(0.4)


def test_side_b_draws_its_mesh_while_side_a_shows_the_heat_map(port):
    """The two sides share one camera: side A's clipping range, set around what A draws, left
    out the mesh while A showed the heat map instead, and side B drew no mesh."""
    c, b = port.controller, port.side_b
    c.act(M.set_compare, True)
    port.redraw()
    before = b.plotter.screenshot(return_img=True)[:, :, :3].copy()
    c.toggle_difference()
    c.on_difference(run_job(c.ports.worker.jobs[-1]))
    assert port.heat.shown
    port.redraw()
    b.plotter.render_window.Render()
    assert np.array_equal(b.plotter.screenshot(return_img=True)[:, :, :3], before)


def test_a_watched_plotters_camera_interaction_is_a_drag(port):
    """Both front ends watch their plotters (side A's, side B's) through the view port: the
    interactor style's interaction is a drag, its end a picture."""
    port.watch_drags(port.plotter)
    style = port.plotter.iren.interactor.GetInteractorStyle()
    sent = port.pictures.sent
    style.InvokeEvent("StartInteractionEvent")
    assert port.dragging() and port.view.lod_active
    style.InvokeEvent("EndInteractionEvent")
    assert not port.dragging() and port.pictures.sent == sent + 1


def test_the_report_is_the_views_in_the_front_ends_pixels(port):
    """Both front ends report their view through the view port (the window in its own pixels,
    the page in the view's): JSON values, the probe and the handles where they are drawn."""
    import json

    c = port.controller
    c.set_value("kd", 0.4, merge=False)
    rep = port.report()
    json.dumps(rep)  # plain values
    i = rep["probe"]["vertex"]
    assert list(rep["probe"]["px"]) == list(port.view.world_to_window(port.view.mesh.positions[i]))
    assert len(rep["handles_px"]) == len(c.state.scene.lights) >= 1
    assert rep["frame"] == port.frames and rep["frame_ms"] > 0 and rep["can_undo"]
    assert rep["n_vertices"] == port.view.mesh.n_vertices and rep["errors"] == []
    assert rep["difference"]["shown"] is False and rep["pixels"]["frames"] == 0
    moved = port.report(at=lambda px: [px[0] + 10, px[1] + 20])
    assert list(moved["probe"]["px"]) == [rep["probe"]["px"][0] + 10, rep["probe"]["px"][1] + 20]
