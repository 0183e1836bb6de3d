"""The lobe inset at the bottom left of the 3D view: the plot of
:mod:`explorer.analysis.lobe` for the selected light, the model in use and the material, in a
panel of its own (everything drawn inside it). VTK is imported inside the functions."""

from __future__ import annotations

import math

import numpy as np

from explorer.analysis import lobe
from explorer.app.model import State, handle_point
from explorer.app.overlay import overlay, set_lines, set_triangles
from explorer.shading.effects.energy import specular_scale

#: the lobe inset (:mod:`explorer.analysis.lobe`): left and bottom margin in pixels, its width
#: as a fraction of the view's smaller side held within LOBE_SIDE (pixels), its inner padding
#: (pixels), its colours (the text's contrast on the panel is at least 4.5:1, tested)
LOBE_MARGIN = 12
LOBE_FRACTION = 0.3
LOBE_SIDE = (130, 200)
LOBE_PAD = 6
LOBE_PANEL_COLOR = (0.12, 0.12, 0.13)
LOBE_FRAME_COLOR = (0.45, 0.45, 0.48)
LOBE_TEXT_COLOR = (0.93, 0.93, 0.93)
LOBE_COLOR = (1.0, 0.85, 0.2)
LOBE_DIFFUSE_COLOR = (0.62, 0.62, 0.68)
LOBE_INCIDENT_COLOR = (1.0, 1.0, 1.0)
LOBE_MIRROR_COLOR = (0.4, 0.8, 1.0)


class LobeInset:
    """The inset in ``plotter``'s view, showing ``state``: :attr:`box` is its panel
    ``(x, y, width, height)`` in display pixels (origin bottom-left), :attr:`actors` all it
    draws, :attr:`caption` its text."""

    def __init__(self, plotter, state: State):
        """The inset's actors: a panel, its frame and surface line, the diffuse circle, the
        incident and mirror directions, the lobe, and the text (drawn in this order)."""
        self.plotter = plotter
        import vtkmodules.vtkRenderingFreeType  # noqa: F401 - registers the text renderer
        from vtkmodules.vtkRenderingCore import vtkTextActor

        panel, actor = overlay(self.plotter, LOBE_PANEL_COLOR, 1.0, filled=True)
        self._polys = {"panel": panel}
        self.actors = [actor]  # everything the inset draws
        for key, color, width in (
            ("frame", LOBE_FRAME_COLOR, 1.0),
            ("diffuse", LOBE_DIFFUSE_COLOR, 1.0),
            ("incident", LOBE_INCIDENT_COLOR, 1.5),
            ("mirror", LOBE_MIRROR_COLOR, 1.5),
            ("lobe", LOBE_COLOR, 2.0),
        ):
            self._polys[key], actor = overlay(self.plotter, color, width)
            self.actors.append(actor)
        self.caption = vtkTextActor()
        self._labels = {}
        for key, color in (("caption", LOBE_TEXT_COLOR), ("L", LOBE_INCIDENT_COLOR),
                           ("R", LOBE_MIRROR_COLOR)):  # fmt: skip
            t = self.caption if key == "caption" else vtkTextActor()
            prop = t.GetTextProperty()
            prop.SetColor(*color)
            prop.SetFontFamilyToArial()
            prop.ShadowOff()
            if key != "caption":
                t.SetInput(key)
                prop.SetJustificationToCentered()
                prop.SetVerticalJustificationToCentered()
            else:
                prop.SetVerticalJustificationToTop()
            self.plotter.renderer.AddViewProp(t)
            self._labels[key] = t
            self.actors.append(t)
        self._key = None
        self.box = None
        self.layout(state)

    def layout(self, state: State) -> None:
        """Size the inset for the view: :data:`LOBE_FRACTION` of its smaller side, held within
        :data:`LOBE_SIDE` and within the view; the caption's font the largest that fits."""
        w, h = self.plotter.window_size
        lo, hi = LOBE_SIDE
        side = int(min(max(LOBE_FRACTION * min(w, h), lo), hi, max(w - 2 * LOBE_MARGIN, 40)))
        if self.box is not None and self.box[2] == side:
            return
        font = self._font = 13 if side >= 170 else 11
        t = self.caption
        text = 2 * (font + 4)
        plot_h = side // 2
        height = plot_h + 3 * LOBE_PAD + text
        x0 = y0 = LOBE_MARGIN
        self.box = (x0, y0, side, height)  # display pixels, origin bottom-left
        self._plot_box = (x0 + LOBE_PAD, y0 + LOBE_PAD, side - 2 * LOBE_PAD, plot_h - LOBE_PAD)
        t.SetPosition(x0 + LOBE_PAD, y0 + height - LOBE_PAD)
        for key in ("L", "R"):
            self._labels[key].GetTextProperty().SetFontSize(max(font - 1, 8))
        corners = [(x0, y0), (x0 + side, y0), (x0 + side, y0 + height), (x0, y0 + height)]
        set_triangles(self._polys["panel"], [corners[:3], [corners[0], *corners[2:]]],
                       [LOBE_PANEL_COLOR] * 2)  # fmt: skip
        self._key = None
        self.update(state)

    def update(self, state: State) -> None:
        """Redraw the plot for the state's selected light, model and material (only when one
        of them changed)."""
        light = state.selected_light
        scene = state.shown_scene()
        m = scene.material
        _, kd, ks = m.scalars()
        theta = None if light is None else lobe_incidence(state)
        model, n = scene.model, m.shininess
        effects = {"fresnel": None if model == "threejs" else m.fresnel,
                   "energy": specular_scale(scene)}  # fmt: skip
        degrees = None if theta is None else round(math.degrees(theta), 1)
        key = (model, n, kd, ks, tuple(effects.values()), degrees)
        if key == self._key:
            return
        self._key = key
        box = self._plot_box
        x, y, w, h = box
        frame = [(x, y), (x + w, y), (x + w, y + h), (x, y + h), (x, y)]
        ox = x + 0.5 * w
        lines = {"frame": [frame, [(x, y), (x + w, y)], [(ox, y), (ox, y + 4)]]}
        label = lobe.MODEL_LABELS[model]
        if theta is None:
            lines.update(diffuse=[], incident=[], mirror=[], lobe=[])
            self.caption.SetInput(f"{label}\nno light, n = {n:g}")
            for key in ("L", "R"):
                self._labels[key].SetVisibility(False)
        else:
            plot = lobe.lobe_plot(model, n, theta, kd, ks, **effects)
            ray_l = lobe.to_box([(0.0, 0.0), plot.incident], box)
            ray_r = lobe.to_box([(0.0, 0.0), plot.mirror], box)
            dashes = [lobe.to_box([t * plot.mirror, (t + 0.06) * plot.mirror], box)
                      for t in np.arange(0.0, 1.0, 0.12)]  # fmt: skip
            lines.update(
                diffuse=[lobe.to_box(plot.diffuse, box)] if len(plot.diffuse) else [],
                incident=[ray_l, _arrow_head(ray_l)] if plot.lit else [],
                mirror=dashes if plot.lit else [],
                lobe=[lobe.to_box(plot.lobe, box)] if len(plot.lobe) else [],
            )
            for key, end, shown, away in (("L", ray_l[1], plot.lit, -9.0),
                                          ("R", ray_r[1], plot.lit, 9.0)):  # fmt: skip
                lx = min(max(end[0] + away, x + 6), x + w - 6)
                ly = min(max(end[1] - 4, y + 6), y + h - 6)
                self._labels[key].SetPosition(lx, ly)
                self._labels[key].SetVisibility(shown)
            deg = math.degrees(theta)
            where = f"incidence {deg:.0f}°" if plot.lit else f"light below ({deg:.0f}°)"
            self.caption.SetInput(f"{label}\n{where}, n = {n:g}")
        for key, polylines in lines.items():
            set_lines(self._polys[key], polylines)
        self._fit_caption()

    def _fit_caption(self) -> None:
        """The caption's font: the inset's own size, smaller (down to 8 px) while the text is
        wider than the panel."""
        t = self.caption
        font = self._font
        while font > 8:
            t.GetTextProperty().SetFontSize(font)
            extent = [0.0, 0.0]
            t.GetSize(self.plotter.renderer, extent)
            if extent[0] <= self.box[2] - 2 * LOBE_PAD:
                break
            font -= 1
        t.GetTextProperty().SetFontSize(font)


def lobe_incidence(state: State) -> float:
    """theta_i (radians) of the selected light at the mesh's point that faces the viewer: the
    angle between the directions from the mesh centre toward the viewer and toward the light's
    handle (:func:`explorer.analysis.lobe.incidence`)."""
    viewer = state.scene.viewer
    centre = np.asarray(state.centre)
    to_viewer = np.subtract(viewer.eye, centre) if viewer.local else viewer.to_viewer
    return lobe.incidence(to_viewer, handle_point(state) - centre)


def _arrow_head(ray) -> list:
    """Two short strokes at the start of ``ray`` ((2, 2) pixels from the origin out): an
    arrow head pointing at the origin (the light's ray arrives there)."""
    o, e = np.asarray(ray[0], float), np.asarray(ray[1], float)
    length = float(np.hypot(*(e - o)))
    if length < 1e-9:
        return []
    u = (e - o) / length
    side = np.array([-u[1], u[0]])
    a = o + 7.0 * u
    return [a + 3.5 * side, o, a - 3.5 * side]
