"""The window's 3D view read from its real pixels (pytest-qt on a private Xvfb): translucency
drawn as the off-screen renders, the lobe inset inside its frame, the light handles under the
pointer through real mouse events, a light move that keeps the camera, arrows toward handles
out of the view, every light's handle, and the compare view's screenshot."""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.insets import panel_extent
from PySide6 import QtCore, QtGui, QtWidgets

from explorer.analysis import lobe
from explorer.app import lobeinset as LI
from explorer.app import model as M
from explorer.app import view as V
from explorer.render.images import read_png
from explorer.render.offscreen import render_image

pytestmark = pytest.mark.usefixtures("xdisplay")


def pixels(pl) -> np.ndarray:
    """(h, w, 3) uint8: what the pane shows now (origin top-left)."""
    pl.render()
    return np.asarray(pl.screenshot(return_img=True)[:, :, :3])


def offscreen_of(pl, state) -> np.ndarray:
    """The off-screen render (`phong-explorer render`'s renderer) of ``state`` with the pane's
    camera and size."""
    cam = V.view_camera(pl.camera, state.centre, state.radius)
    return render_image(state.shown_scene(), win_mesh(state), tuple(pl.window_size), camera=cam)


_MESHES = {}


def win_mesh(state):
    return _MESHES[state.mesh]


def mesh_pixels_match(got, want, background) -> tuple[float, int]:
    """Over the pixels the mesh covers in ``want``: the fraction differing by more than 3
    levels, and the largest difference."""
    covered = np.abs(want.astype(int) - np.asarray(background)).max(axis=2) > 2
    diff = np.abs(got.astype(int) - want.astype(int)).max(axis=2)[covered]
    return float((diff > 3).mean()), int(diff.max())


@pytest.mark.parametrize("opacity", [0.5, 0.95, 0.99])
def test_translucency_is_drawn_as_the_offscreen_render_in_every_pane(open_window, opacity):
    w = open_window("--preset", "jade")
    _MESHES[w.controller.state.mesh] = w.view.mesh
    w.controller.act(M.set_opacity, opacity)
    for handle in w.view.handles:
        handle.Off()  # the handle and the inset are not in the off-screen render
    w.view.lobe_caption.SetVisibility(False)
    got = pixels(w.plotter)
    s = w.controller.state
    want = offscreen_of(w.plotter, s)
    probe = w.view.probe_vertex()
    x, y = w.view.world_to_window(w.view.mesh.positions[probe])
    probe_diff = np.abs(got[y, x].astype(int) - want[y, x].astype(int)).max()
    assert probe_diff <= 3, (got[y, x], want[y, x])
    bg = (np.asarray(w.plotter.renderer.GetBackground()) * 255).round()
    x0, y0, bw, bh = w.view.lobe.box
    got[-(y0 + bh) :, : x0 + bw + 1] = want[-(y0 + bh) :, : x0 + bw + 1]  # the inset's place
    bad, worst = mesh_pixels_match(got, want, bg)
    assert bad < 0.005, f"{bad:.1%} of the mesh's pixels differ (up to {worst} levels)"
    # the compare view: both panes as `render` draws their sides
    w.panel.view.compare.click()
    w.controller.act(M.set_compare_preset, "jade", w.controller.state.material)
    w.view_b.lobe_caption.SetVisibility(False)
    w.view.lobe_caption.SetVisibility(False)
    for handle in w.view_b.handles:
        handle.Off()  # pane B shows the shared lights' handles too
    for pl, side in ((w.plotter, s), (w.plotter_b, M.side_b(w.controller.state))):
        got, want = pixels(pl), offscreen_of(pl, side)
        view = w.view if pl is w.plotter else w.view_b
        x0, y0, bw, bh = view.lobe.box
        got[-(y0 + bh) :, : x0 + bw + 1] = want[-(y0 + bh) :, : x0 + bw + 1]
        top = got.shape[0] // 10  # the pane's caption
        got[:top] = want[:top]
        bad, worst = mesh_pixels_match(got, want, bg)
        assert bad < 0.005, f"{pl.objectName()}: {bad:.1%} differ (up to {worst} levels)"


def test_translucency_below_one_is_brighter_than_half_and_darker_than_opaque(open_window):
    """The issue's numbers: jade at 0.95 under the probe vertex is about 0.95 of the opaque
    colour over the background, not about half of it."""
    w = open_window("--preset", "jade")
    probe = w.view.probe_vertex()
    x, y = w.view.world_to_window(w.view.mesh.positions[probe])
    seen = {}
    for opacity in (1.0, 0.99, 0.95):
        w.controller.act(M.set_opacity, opacity)
        seen[opacity] = pixels(w.plotter)[y, x].astype(float)
    for a in (0.99, 0.95):  # front over (mostly) the back: a·front + (1 - a)·(what is behind)
        assert np.all(seen[a] >= a * seen[1.0] - 3) and np.all(seen[a] <= seen[1.0] + 1)
    assert np.all(seen[0.99] >= seen[0.95])
    assert np.all(seen[0.95] > 0.8 * seen[1.0])  # not about half (the issue: 0.52)


def inset_pixels(w, state_changes) -> np.ndarray:
    """Pixels that change when the inset's actors are hidden: (k, 2) (x, y) top-left."""
    for change in state_changes:
        w.controller.act(*change)
    shown = pixels(w.plotter)
    shown_before = [a.GetVisibility() for a in w.view.lobe.actors]
    for a in w.view.lobe.actors:
        a.SetVisibility(False)
    hidden = pixels(w.plotter)
    for a, v in zip(w.view.lobe.actors, shown_before, strict=True):
        a.SetVisibility(v)
    ys, xs = np.nonzero(np.abs(shown.astype(int) - hidden.astype(int)).max(axis=2) > 0)
    return np.column_stack([xs, ys])


@pytest.mark.parametrize("n", [0.0, 0.3, 1000.0])
@pytest.mark.parametrize("model", ["phong", "blinn"])
def test_the_lobe_inset_draws_nothing_outside_its_frame(win, n, model):
    w = win
    w.view.handles[0].Off()
    changed = inset_pixels(w, [(M.set_model, model), (M.set_shininess, n)])
    _, h = w.plotter.window_size
    x0, y0, bw, bh = w.view.lobe.box  # display pixels, origin bottom-left
    assert len(changed) > 200  # the inset is drawn
    assert changed[:, 0].min() >= x0 and changed[:, 0].max() <= x0 + bw
    top = h - 1 - (y0 + bh)
    assert changed[:, 1].min() >= top and changed[:, 1].max() <= h - 1 - y0
    assert w.view.lobe_caption.GetInput().startswith(lobe.MODEL_LABELS[model])
    assert w.view.lobe_caption.GetInput().endswith(f"n = {n:g}")


def test_the_lobe_follows_the_light_and_its_text_reads(win):
    w = win
    w.controller.act(M.set_shininess, 30.0)
    pl = w.plotter
    w.render()
    x0, y0, bw, bh = w.view.lobe.box
    bw = w.view.lobe._plot_box[2] + 2 * LI.LOBE_PAD  # (the plot's part: the lit sphere beside)
    _, h = pl.window_size

    def yellow_column():
        img = pixels(pl)[h - (y0 + bh) : h - y0, x0 : x0 + bw].astype(int)
        lobe_px = (img[..., 0] > 200) & (img[..., 1] > 160) & (img[..., 2] < 120)  # LOBE_COLOR
        return np.nonzero(lobe_px)[1].mean(), img

    theta0 = math.degrees(LI.lobe_incidence(w.controller.state))
    before, img = yellow_column()
    az, el, d = w.controller.state.placement()
    # toward the viewer: the incidence falls, the lobe (at the mirror) leans back to the normal
    w.controller.act(M.place_light, 0.0, 20.0, d)
    theta1 = math.degrees(LI.lobe_incidence(w.controller.state))
    after, _ = yellow_column()
    assert theta1 < theta0 - 10 and f"incidence {theta1:.0f}°" in w.view.lobe_caption.GetInput()
    assert after < before - 5  # the lobe's pixels moved left, toward the plot's middle
    # the text's contrast, from the pixels: the caption's brightest against the panel
    panel = img[-3, bw // 2] / 255.0
    caption = img[: bh // 3].reshape(-1, 3)
    brightest = caption[np.argmax(caption.sum(axis=1))] / 255.0
    assert lobe.contrast_ratio(brightest, panel) >= 4.5
    for c in (LI.LOBE_TEXT_COLOR, LI.LOBE_INCIDENT_COLOR, LI.LOBE_MIRROR_COLOR):
        assert lobe.contrast_ratio(c, LI.LOBE_PANEL_COLOR) >= 4.5


def mouse(w, kind, x, y, buttons, pane=None):
    """A real Qt mouse event on the view (or ``pane``) at its pixel (x, y) (top-left origin)."""
    left = QtCore.Qt.MouseButton.LeftButton
    ev = QtGui.QMouseEvent(kind, QtCore.QPointF(x, y), QtCore.QPointF(x, y), left, buttons,
                           QtCore.Qt.KeyboardModifier.NoModifier)  # fmt: skip
    QtWidgets.QApplication.sendEvent(w.plotter if pane is None else pane, ev)


def drag_handle(w, index, steps, side_b=False):
    """Press on light ``index``'s handle and move by ``steps`` (dx, dy) each, in the view (or
    the compare view's pane B); after each step the distance (pixels) from the pointer to the
    handle's centre and the handle's pixel."""
    Type, left = QtCore.QEvent.Type, QtCore.Qt.MouseButton.LeftButton
    pl, view = (w.plotter_b, w.view_b) if side_b else (w.plotter, w.view)
    x, y = view.world_to_window(M.handle_point(w.controller.state, index))
    mouse(w, Type.MouseButtonPress, x, y, left, pl)
    out = []
    for dx, dy in steps:
        x, y = x + dx, y + dy
        mouse(w, Type.MouseMove, x, y, left, pl)
        img = pixels(pl)
        hx, hy = view.world_to_window(M.handle_point(w.controller.state))
        out.append((math.hypot(hx - x, hy - y), img[y, x]))
    mouse(w, Type.MouseButtonRelease, x, y, QtCore.Qt.MouseButton.NoButton, pl)
    return out


@pytest.mark.parametrize(("zoom", "dolly"), [(1.0, 1.0), (1.8, 1.3), (0.7, 0.6)])
def test_the_handle_stays_under_the_pointer(win, zoom, dolly):
    w = win
    w.plotter.camera.Zoom(zoom)  # the view angle
    w.plotter.camera.Dolly(dolly)  # the camera's distance
    w.render()
    s = w.controller.state  # the light between the camera and the mesh, a little up and right
    cam = w.plotter.camera
    toward = np.subtract(cam.GetPosition(), s.centre)
    toward /= np.linalg.norm(toward)
    right = np.cross(toward, cam.GetViewUp())
    point = np.asarray(s.centre) + s.radius * (1.6 * toward + 0.25 * np.asarray(cam.GetViewUp())
                                               - 0.25 * right)  # fmt: skip
    w.controller.act(M.place_light, *M.angles_from_point(s, point))
    w.render()
    x, y = w.view.world_to_window(M.handle_point(w.controller.state))
    vw, vh = w.plotter.window_size
    assert 20 < x < vw - 20 and 20 < y < vh - 20
    sx, sy = (-250 if x > vw / 2 else 250) // 10, (150 if y < vh / 2 else -150) // 10
    cam = w.controller.state.camera
    trail = drag_handle(w, 0, [(sx, sy)] * 10)
    worst = max(d for d, _ in trail)
    assert worst <= 3.0, f"the handle ran {worst:.1f} px from the pointer: {trail}"
    colour = np.asarray(M.light_colour(w.controller.state.selected_light)[0]) * 255
    for _, px in trail:  # the handle is what the pointer is on (lit, so near its colour)
        assert np.abs(px.astype(int) - colour).max() < 110
    assert w.controller.state.camera == cam  # the drag moved the light, not the camera
    assert not w.view.dragging and w.controller.store.can_undo


def test_the_handle_ends_where_the_pointer_lets_go(win):
    """A move the front end dropped (the web page's view drops moves while it is busy): the
    release's position is the drag's last step, so the handle ends under the pointer."""
    Type, left = QtCore.QEvent.Type, QtCore.Qt.MouseButton.LeftButton
    w = win
    w.render()
    x, y = w.view.world_to_window(M.handle_point(w.controller.state))
    vw, vh = w.plotter.window_size
    sx, sy = (-1 if x > vw / 2 else 1), (1 if y < vh / 2 else -1)
    mouse(w, Type.MouseButtonPress, x, y, left)
    mouse(w, Type.MouseMove, x + 20 * sx, y + 12 * sy, left)
    end = (x + 60 * sx, y + 36 * sy)  # no move event reaches this point: only the release
    mouse(w, Type.MouseButtonRelease, *end, QtCore.Qt.MouseButton.NoButton)
    hx, hy = w.view.world_to_window(M.handle_point(w.controller.state))
    assert math.hypot(hx - end[0], hy - end[1]) <= 3.0, ((hx, hy), end)
    assert not w.view.dragging


def test_every_light_has_a_handle_and_clicking_one_selects_its_light(win):
    w = win
    w.controller.act(M.add_light)  # selected: light 1
    w.controller.act(M.set_light_colour, (0.0, 0.0, 1.0))
    w.controller.act(M.select_light, 0)
    w.controller.act(M.set_light_colour, (1.0, 0.0, 0.0))
    w.render()
    img = pixels(w.plotter)
    s = w.controller.state
    for i, want in ((0, (255, 0, 0)), (1, (0, 0, 255))):
        x, y = w.view.world_to_window(M.handle_point(s, i))
        patch = img[y - 2 : y + 3, x - 2 : x + 3].reshape(-1, 3).astype(int)
        hue = patch.mean(axis=0)
        k = int(np.argmax(want))
        assert hue[k] > 60 and hue[k] > 2 * np.delete(hue, k).max(), (i, hue)

    # the selected light's handle is ringed in RING_COLOR, the other not
    def ring_pixels(i):
        x, y = w.view.world_to_window(M.handle_point(w.controller.state, i))
        r = (
            w.view._pixel_radius(
                M.handle_point(w.controller.state, i), V.HANDLE_RADIUS * V.SELECTED_SCALE * s.radius
            )
            + V.RING_GAP
        )
        img = pixels(w.plotter)
        t = np.linspace(0, 2 * math.pi, 72, endpoint=False)
        xs, ys = (x + r * np.cos(t)).round().astype(int), (y - r * np.sin(t)).round().astype(int)
        return (img[ys, xs].min(axis=1) > 235).mean()

    assert ring_pixels(0) > 0.5 and ring_pixels(1) < 0.2
    # a click on light 1's handle selects it (and moves nothing)
    Type, left = QtCore.QEvent.Type, QtCore.Qt.MouseButton.LeftButton
    x, y = w.view.world_to_window(M.handle_point(w.controller.state, 1))
    before = w.controller.state.scene.lights
    mouse(w, Type.MouseButtonPress, x, y, left)
    mouse(w, Type.MouseButtonRelease, x, y, QtCore.Qt.MouseButton.NoButton)
    assert w.controller.state.light == 1 and w.controller.state.scene.lights == before
    assert ring_pixels(1) > 0.5 and ring_pixels(0) < 0.2


def test_a_light_move_keeps_the_camera_and_an_arrow_shows_a_handle_out_of_view(win):
    w = win
    tab = w.panel.lights
    cam = w.controller.state.camera
    tab.sliders["azimuth"].field.setValue(-80.0)
    tab.sliders["azimuth"].field.setValue(40.0)
    w.render()
    assert w.controller.state.camera == cam  # position, focal point and view angle
    tab.sliders["distance"].field.setValue(5.0)
    tab.sliders["elevation"].field.setValue(90.0)  # straight up: above the view
    w.render()
    assert w.controller.state.camera == cam
    vw, vh = w.plotter.window_size
    x, y = w.view.world_to_window(M.handle_point(w.controller.state))
    assert not (0 <= x < vw and 0 <= y < vh)
    tri = w.view.marker_triangles[0]  # display pixels, origin bottom-left
    assert tri[0][1] == pytest.approx(vh - V.MARKER_MARGIN, abs=1)  # at the top edge
    img = pixels(w.plotter)
    cx, cy = tri.mean(axis=0)
    px = img[int(round(vh - 1 - cy)), int(round(cx))]
    assert px.min() > 235  # the (white) light's colour, on the grey background
    tab.sliders["distance"].field.setValue(2.0)
    tab.sliders["elevation"].field.setValue(20.0)  # back in view: no arrow
    w.render()
    assert not w.view.marker_triangles
    assert w.controller.state.camera == cam


def test_the_screenshot_key_saves_both_compare_panes(win, qtbot):
    w = win
    w.panel.view.compare.click()
    qtbot.waitUntil(lambda: w.plotter_b.width() > 100)
    w.controller.act(M.set_compare_model, "phong")
    a, b = pixels(w.plotter), pixels(w.plotter_b)
    w.plotter.setFocus()
    qtbot.keyClick(w.plotter, "i")
    path = w.message.split("saved screenshot ", 1)[1]
    saved = read_png(path)
    gap = saved.shape[1] - a.shape[1] - b.shape[1]
    assert 0 <= gap <= 12 and saved.shape[0] == max(a.shape[0], b.shape[0])
    assert np.array_equal(saved[: a.shape[0], : a.shape[1]], a)
    assert np.array_equal(saved[: b.shape[0], a.shape[1] + gap :], b)


def scaled_sphere_obj(path, r: float):
    """An OBJ of the unit sphere (resolution 24) scaled by ``r``: what a user opens."""
    from explorer.geometry.meshes import sphere

    s = sphere(24)
    lines = ["v {:.17g} {:.17g} {:.17g}".format(*p) for p in s.positions * r]
    lines += ["vn {:.17g} {:.17g} {:.17g}".format(*n) for n in s.normals]
    lines += [f"f {a}//{a} {b}//{b} {c}//{c}" for a, b, c in s.faces + 1]
    path.write_text("\n".join(lines) + "\n")
    return path


def view_without_overlays(w) -> np.ndarray:
    """The view's pixels with the handles, their ring and the lobe inset left out (the
    off-screen render draws none of them)."""
    for handle in w.view.handles:
        handle.Off()
    w.view.lobe_caption.SetVisibility(False)
    got = pixels(w.plotter)
    for handle in w.view.handles:
        handle.On()
    w.view.lobe_caption.SetVisibility(True)
    return got


@pytest.mark.parametrize("scale", [1e-20, 1e39, 1e300])
def test_a_mesh_at_any_scale_is_framed_and_drawn_as_the_render(win, tmp_path, scale):
    """A scaled OBJ opened as the user opens it (File > Open): framed as the unit one, drawn
    as `render` draws it, the lobe plot the same, the handle under the pointer (a sphere
    scaled by 1e-20 was a dot in an empty view, by 1e39 a spray of broken triangles)."""
    w = win
    w.controller.files.open_file(scaled_sphere_obj(tmp_path / "unit.obj", 1.0))
    unit = view_without_overlays(w)
    caption = w.view.lobe_caption.GetInput()
    w.controller.files.open_file(scaled_sphere_obj(tmp_path / f"sphere_{scale:g}.obj", scale))
    s = w.controller.state
    assert s.radius == pytest.approx(scale) and not w.controller.errors
    _MESHES[s.mesh] = w.view.mesh
    got = view_without_overlays(w)
    want = offscreen_of(w.plotter, s)
    bg = (np.asarray(w.plotter.renderer.GetBackground()) * 255).round()
    x0, y0, bw, bh = w.view.lobe.box
    for img in (got, unit):
        img[-(y0 + bh) :, : x0 + bw + 1] = want[-(y0 + bh) :, : x0 + bw + 1]  # the inset
    covered = np.abs(got.astype(int) - bg).max(axis=2) > 2
    assert covered.mean() > 0.1, f"the mesh covers {covered.mean():.1%} of the view"
    bad, worst = mesh_pixels_match(got, want, bg)
    assert bad < 0.005, f"{bad:.1%} of the mesh's pixels differ from the render (up to {worst})"
    bad, worst = mesh_pixels_match(got, unit, bg)
    assert bad < 0.01, f"{bad:.1%} differ from the unit sphere's view (up to {worst})"
    assert w.view.lobe_caption.GetInput() == caption  # the same light, the same lobe
    x, y = w.view.world_to_window(M.handle_point(s))
    vw, vh = w.plotter.window_size
    assert 20 < x < vw - 20 and 20 < y < vh - 20
    trail = drag_handle(w, 0, [(-12, 10)] * 8)
    worst = max(d for d, _ in trail)
    assert worst <= 3.0, f"the handle ran {worst:.1f} px from the pointer: {trail}"
    assert M.handle_point(w.controller.state)[1] < M.handle_point(s)[1]  # it moved down
    assert not w.controller.errors, w.controller.errors


def test_a_mesh_too_large_to_frame_is_refused_as_render_refuses_it(win, tmp_path):
    from explorer.core.errors import ExplorerError
    from explorer.core.scene import Scene
    from explorer.geometry.meshes import load_mesh
    from explorer.render.camera import camera_for

    w = win
    path = scaled_sphere_obj(tmp_path / "huge.obj", 1.5e308)
    with pytest.raises(ExplorerError) as refused:  # `render`'s refusal
        camera_for(Scene(), load_mesh(path))
    before, shown = w.controller.state, pixels(w.plotter)
    w.controller.files.open_file(path)
    assert w.controller.errors == [f"mesh: {refused.value}"]
    assert "too large to frame" in w.message
    w.controller.errors.clear()
    assert w.controller.state == before  # the view keeps the mesh it showed
    assert np.array_equal(pixels(w.plotter), shown)


def test_pane_b_shows_the_handles_and_a_drag_there_moves_the_light(win, qtbot):
    """The lights are shared by both sides of the compare view: pane B draws every handle
    (in the light's colour, the selected one ringed) and a drag there moves the light, the
    handle under the pointer, as in pane A (pane B showed none)."""
    w = win
    w.panel.view.compare.click()
    qtbot.waitUntil(lambda: w.plotter_b.width() > 100)
    w.controller.act(M.add_light)
    w.controller.act(M.set_light_colour, (0.0, 0.0, 1.0))
    s = w.controller.state  # both lights between the camera and the mesh, in the narrow panes
    cam = w.plotter.camera
    toward = np.subtract(cam.GetPosition(), s.centre)
    toward /= np.linalg.norm(toward)
    up = np.asarray(cam.GetViewUp())
    for i, side in ((1, -0.3), (0, 0.3)):
        w.controller.act(M.select_light, i)
        point = np.asarray(s.centre) + s.radius * (
            1.6 * toward + 0.25 * up + side * np.cross(up, toward)
        )
        w.controller.act(M.place_light, *M.angles_from_point(w.controller.state, point))
    w.render()
    s = w.controller.state
    assert len(w.view_b.handles) == 2
    img = pixels(w.plotter_b)
    vw, vh = w.plotter_b.window_size
    for i in range(2):
        x, y = w.view_b.world_to_window(M.handle_point(s, i))
        colour = np.asarray(M.light_colour(s.scene.lights[i])[0]) * 255
        assert np.abs(img[y, x].astype(int) - colour).max() < 110, (i, img[y, x], colour)
    x, y = w.view_b.world_to_window(M.handle_point(s, 0))
    assert 20 < x < vw - 20 and 20 < y < vh - 20
    cam = s.camera
    trail = drag_handle(w, 0, [(-10, 12)] * 8, side_b=True)
    worst = max(d for d, _ in trail)
    assert worst <= 3.0, f"the handle ran {worst:.1f} px from the pointer in pane B: {trail}"
    moved = w.controller.state
    assert moved.scene.lights[0] != s.scene.lights[0] and moved.camera == cam
    assert moved.scene.lights[1] == s.scene.lights[1] and w.controller.store.can_undo
    w.render()  # pane A's handle is where the light went
    img_a = pixels(w.plotter)
    ax, ay = w.view.world_to_window(M.handle_point(moved, 0))
    assert np.abs(img_a[ay, ax].astype(int) - 255).max() < 110, img_a[ay, ax]


@pytest.mark.parametrize("mesh", ["torus", "teapot"])
def test_compare_pane_b_follows_the_lights_after_a_mesh_change(win, qtbot, mesh):
    """Compare on, then another mesh (the mesh chooser): side B still follows a light change,
    drawn as the off-screen render of side B's state (pane B had a second, stale copy of the
    mesh drawn over the live one: its body stayed lit at intensity 1 while A's went dark)."""
    w = win
    w.panel.view.compare.click()
    qtbot.waitUntil(lambda: w.plotter_b.width() > 100)
    assert w.controller.files.choose_mesh(mesh)
    w.controller.act(M.set_light_intensity, 0.3)
    w.render()
    s = w.controller.state
    _MESHES[s.mesh] = w.view.mesh
    vb, pl = w.view_b, w.plotter_b
    for handle in vb.handles:
        handle.Off()
    vb.lobe_caption.SetVisibility(False)
    got = pixels(pl)
    want = offscreen_of(pl, M.side_b(s))
    bad, worst = mesh_pixels_match(got, want, np.asarray(pl.renderer.GetBackground()) * 255)
    assert bad < 0.01 and worst < 60, (bad, worst)
    meshes = [a for a in pl.renderer.actors.values() if a.IsA("vtkActor")]
    drawn = [a for a in meshes if a.GetMapper().GetInput().GetNumberOfPoints() >= 1000]
    assert len(drawn) == len(vb.drawings)  # one actor per drawing, none left behind


def test_the_lobe_inset_covers_at_most_a_fifth_of_a_small_pane(open_window, qtbot):
    """At 640x480, compare on: in each pane the inset's panel, read from its pixels, covers at
    most LOBE_AREA of the pane and is still there (issue 42's small sizes; the page's own
    test is test_the_lobe_inset_covers_at_most_a_fifth_of_a_small_view)."""
    w = open_window()
    w.resize(640, 480)
    qtbot.waitUntil(lambda: (w.width(), w.height()) == (640, 480), timeout=5000)
    w.panel.view.compare.click()
    qtbot.waitUntil(lambda: w.plotter_b.isVisible() and w.plotter_b.width() > 50)
    QtWidgets.QApplication.processEvents()
    for pl in (w.plotter, w.plotter_b):
        img = pixels(pl)
        h, wide = img.shape[:2]
        side, height = panel_extent(img)
        assert side * height <= LI.LOBE_AREA * wide * h + 2 * (side + height), (wide, h)
        assert side >= LI.LOBE_MIN_SIDE - 2, (side, height)


def ring_pixels(w) -> np.ndarray:
    """(h, w) bool: the pixels of the selected handle's ring in the view's frame (the frame
    drawn with the ring against the frame drawn without it)."""
    props = w.plotter.renderer.GetViewProps()
    props.InitTraversal()
    actors = [props.GetNextProp() for _ in range(props.GetNumberOfItems())]
    mapper_inputs = [a.GetMapper() and a.GetMapper().GetInput() for a in actors]
    ring = actors[next(i for i, m in enumerate(mapper_inputs) if m is w.view._ring)]
    with_ring = pixels(w.plotter).astype(int)
    ring.SetVisibility(False)
    without = pixels(w.plotter).astype(int)
    ring.SetVisibility(True)
    return np.abs(with_ring - without).max(axis=2) > 0


#: an infinite viewer (a parallel camera) above the mesh's front
PARALLEL = ("--viewer-to-viewer", "0", "0.4", "1")


@pytest.mark.parametrize(
    ("size", "viewer"),
    [
        pytest.param((w, h), viewer, id=f"{w}x{h}" + ("-parallel" if viewer else ""))
        for (w, h), viewer in (
            *((s, ()) for s in ((500, 900), (400, 900), (640, 480), (1000, 700))),
            ((1200, 400), ()),
            ((1400, 350), ()),
            ((500, 900), PARALLEL),
            ((1400, 350), PARALLEL),
        )
    ],
)
def test_the_start_shows_the_handles_ring_inside_the_view_at_every_aspect(
    open_window, size, viewer
):
    """The start framed for a view of any shape (a perspective camera, or a parallel one for
    an infinite viewer) shows the selected light's handle with its whole ring inside the view,
    at least RING_MARGIN pixels from every edge, read from the frame's pixels. Before, the view
    was widened by a fixed tenth: the ring came 8 and 9 pixels from the edge at 640x480 and
    1400x350, it touched the edge of a parallel camera's 136x855 view (a 500x900 window's),
    and in a perspective one the handle was out of the view altogether (the widening stopped
    at 60 degrees of height: the width is what limits there)."""
    w = open_window("--mesh", "icosphere", "--resolution", "3", *viewer, size=size)
    assert w.controller.state.camera.parallel == bool(viewer)
    assert w.controller.state.selected_light is not None
    ring = ring_pixels(w)
    h, wide = ring.shape
    ys, xs = np.nonzero(ring)
    assert len(xs) >= 40, f"no ring drawn in the {wide}x{h} view: the handle is out of it"
    margins = (int(xs.min()), int(ys.min()), int(wide - 1 - xs.max()), int(h - 1 - ys.max()))
    assert min(margins) >= V.RING_MARGIN - 1, (wide, h, margins)  # (its line's antialiasing)
