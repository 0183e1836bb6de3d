"""The lobe inset at the bottom left of the 3D view: the plot of
:mod:`explorer.analysis.lobe` for the selected light, the model in use and the material, in a
panel of its own (everything drawn inside it).

The state's ``lobes`` turns it into a plot of several lobes (:mod:`explorer.analysis.lobes`):
``models`` the three models' for the material, ``lights`` the scene's for each light, ``sides``
A's and B's of the compare view; each in its colour, named in the legend under the caption;
``lobe_view`` polar or cartesian, ``lobe_quantity`` intensity, brdf or albedo, ``lobe_log`` and
``lobe_ndl`` (× N·L): the panel model's rows (:data:`ROWS`' actions here). Beside the plot,
the lit sphere (:mod:`explorer.app.litsphere`): the material at the plot's incidence, which a
drag on it sets (``lobe_incidence``). VTK is imported inside the functions."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from explorer.analysis import lobe
from explorer.analysis import lobes as many
from explorer.app.litsphere import LitSphere
from explorer.app.model import State, handle_point
from explorer.app.overlay import overlay, set_lines, set_triangles
from explorer.core.controls import CONTROLS
from explorer.core.errors import ExplorerError
from explorer.shading.effects.energy import specular_scale

#: the lobe inset (:mod:`explorer.analysis.lobe`): left and bottom margin in pixels, its width
#: as a fraction of the view's smaller side held within LOBE_SIDE (pixels), its inner padding
#: (pixels), its colours (the text's contrast on the panel is at least 4.5:1, tested)
LOBE_MARGIN = 12
LOBE_FRACTION = 0.3
LOBE_SIDE = (130, 200)
LOBE_PAD = 6
#: the most of the view's area the inset covers (a share): in a small view it narrows below
#: LOBE_SIDE's least width, down to LOBE_MIN_SIDE pixels, and is then the plot alone (its
#: caption and the L and R labels hidden: at 8 pixels and less they were not legible). The
#: 640x480 page's compare pane (183x251 pixels) was 32% covered by the 130-pixel inset
LOBE_AREA = 0.2
LOBE_MIN_SIDE = 72
LOBE_PANEL_COLOR = (0.12, 0.12, 0.13)
LOBE_FRAME_COLOR = (0.45, 0.45, 0.48)
LOBE_TEXT_COLOR = (0.93, 0.93, 0.93)
LOBE_COLOR = (1.0, 0.85, 0.2)
LOBE_DIFFUSE_COLOR = (0.62, 0.62, 0.68)
LOBE_INCIDENT_COLOR = (1.0, 1.0, 1.0)
LOBE_MIRROR_COLOR = (0.4, 0.8, 1.0)
#: the state's ``lobes``: one lobe (the selected light's, as before) or several
LOBE_SETS = ("selected", "models", "lights", "sides")
#: the albedo's quadrature nodes in the inset (a plot of pixels: the interaction stays quick)
INSET_NODES = (24, 24)
#: the Greek letters of a plot's title written out (VTK's own fonts have none)
LATIN = {"ρ": "rho", "θ": "theta"}
#: the lit sphere is drawn beside the plot while the inset with it takes at most this share of
#: the view's width (a small view keeps the plot alone)
SPHERE_SHARE = 0.5
#: the legend's font size (pixels), and the smallest it is drawn at before an entry is shortened
LEGEND_FONT = 10
LEGEND_MIN_FONT = 8
#: a hidden lobe's legend entry (its lobe not drawn; a click on it shows it again)
LEGEND_HIDDEN_COLOR = (0.6, 0.6, 0.6)
#: the lobes the panel has a ``show_lobe_<i>`` row for (the first ones of the set; every
#: legend entry drawn toggles its lobe by a click)
LOBE_ROWS = 8


def set_lobe_option(state: State, name: str, value) -> State:
    """One of the inset's options: ``lobes`` (:data:`LOBE_SETS`), ``lobe_view``
    (:data:`explorer.analysis.lobes.VIEWS`), ``lobe_quantity``
    (:data:`explorer.analysis.lobes.QUANTITIES`), ``lobe_log`` or ``lobe_ndl`` (on / off)."""
    allowed = {"lobes": LOBE_SETS, "lobe_view": many.VIEWS, "lobe_quantity": many.QUANTITIES}
    if name in allowed:
        if value not in allowed[name]:
            raise ExplorerError(f"{name} must be one of {allowed[name]}, got {value!r}")
    elif name in ("lobe_log", "lobe_ndl"):
        value = bool(value)
    else:
        raise ExplorerError(f"no lobe option named {name!r}")
    return state.replace(**{name: value})


def set_lobe_incidence(state: State, degrees) -> State:
    """The lobe plot's incidence θ_i in degrees (the lit sphere's drag; the range of
    :data:`explorer.core.controls.CONTROLS`' ``lobe_incidence``), or None: the selected
    light's."""
    if degrees is not None:
        c = CONTROLS["lobe_incidence"]
        if not isinstance(degrees, (int, float)) or not c.lo <= degrees <= c.hi:
            raise ExplorerError(
                f"lobe_incidence must be a number from {c.lo:g} to {c.hi:g}"
                f" degrees, or off, got {degrees!r}"
            )
        degrees = float(degrees)
    return state.replace(lobe_incidence=degrees)


def set_lobe_shown(state: State, index: int, on: bool) -> State:
    """Lobe ``index`` (0-based, in the set the state's ``lobes`` asks for) drawn or not (its
    legend entry stays, greyed)."""
    if not isinstance(index, int) or index < 0:
        raise ExplorerError(f"a lobe's index must be a whole number from 0, got {index!r}")
    hidden = set(state.lobe_hidden)
    (hidden.discard if on else hidden.add)(index)
    return state.replace(lobe_hidden=frozenset(hidden))


def lobe_set(state: State) -> list:
    """The lobes of :func:`lobe_set_all`, those the state hides (``lobe_hidden``) with
    ``visible`` off."""
    return [
        lb if i not in state.lobe_hidden else replace(lb, visible=False)
        for i, lb in enumerate(lobe_set_all(state))
    ]


def lobe_set_all(state: State) -> list:
    """The lobes the state's ``lobes`` asks for (:class:`explorer.analysis.lobes.Lobe`), each in
    its colour: the three models', each light's, or sides A and B (B while it is shown)."""
    scene = state.shown_scene()
    if state.lobes == "lights":
        out = []
        for i in range(len(scene.lights)):
            t = _incidence(state, i)
            name = f"light {i + 1} ({math.degrees(t):.0f}°)"
            out.append(many.scene_lobe(scene, t, name, many.COLOURS[i % len(many.COLOURS)]))
        return out
    if not scene.lights:
        return []
    theta = lobe_incidence(state)
    if state.lobes == "models":
        return many.model_lobes(scene, theta)
    out = [many.scene_lobe(scene, theta, "A", many.COLOURS[0])]
    if state.compare is not None:
        b = scene.replace(material=state.compare, model=state.compare_model or scene.model)
        out.append(many.scene_lobe(b, theta, "B", many.COLOURS[1]))
    return out


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
        self.labelled = True  # the caption and the L and R labels drawn (a large enough inset)
        self._peak = None  # the one lobe's point farthest from the plot's origin (pixels)
        self._side = None  # (the plot's part of the panel, whether the sphere is beside it)
        self._curves: list = []  # (polydata, actor) of the several lobes' curves, one a colour
        self._legend: list = []  # their legend's text actors
        self.chart = None  # the plot of several lobes shown, or None
        self.sphere = LitSphere(self.plotter, LOBE_PANEL_COLOR)  # beside the plot
        self.actors += self.sphere.actors
        self.layout(state)

    def layout(self, state: State) -> None:
        """Size the inset for the view: :data:`LOBE_FRACTION` of its smaller side, held within
        :data:`LOBE_SIDE` and within the view, and narrower while it would cover more than
        :data:`LOBE_AREA` of the view (down to :data:`LOBE_MIN_SIDE`, the plot alone below
        LOBE_SIDE's least width); the lit sphere right of the plot while the inset with it takes
        at most :data:`SPHERE_SHARE` of the view's width; the caption's font the largest that
        fits."""
        w = self.plotter.window_size[0]
        side = inset_side(*self.plotter.window_size)
        ball = side // 2 - LOBE_PAD  # the lit sphere's side, right of the plot
        room = side + ball + LOBE_PAD <= SPHERE_SHARE * w  # (else no sphere: a small view)
        if self.box is not None and self._side == (side, room):
            return
        self._side = (side, room)
        font = self._font = 13 if side >= 170 else 11
        t = self.caption
        self.labelled = side >= LOBE_SIDE[0]
        t.SetVisibility(self.labelled)
        plot_h = side // 2
        height = inset_height(side)
        x0 = y0 = LOBE_MARGIN
        self.sphere.place(x0 + side, y0 + LOBE_PAD, ball if room else 0)
        side_all = side + ball + LOBE_PAD if room else side
        self.box = (x0, y0, side_all, height)  # display pixels, origin bottom-left
        self._plot_box = (x0 + LOBE_PAD, y0 + LOBE_PAD, side - 2 * LOBE_PAD, plot_h - LOBE_PAD)
        t.SetPosition(x0 + LOBE_PAD, y0 + height - LOBE_PAD)
        for key in ("L", "R"):
            self._labels[key].GetTextProperty().SetFontSize(max(font - 1, 8))
        corners = [(x0, y0), (x0 + side_all, y0), (x0 + side_all, y0 + height), (x0, y0 + height)]
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
        set_by_sphere = state.lobe_incidence is not None
        theta = None if light is None and not set_by_sphere else lobe_incidence(state)
        self.sphere.update(scene, theta)
        model, n = scene.model, m.shininess
        effects = {"fresnel": None if model == "threejs" else m.fresnel,
                   "energy": specular_scale(scene)}  # fmt: skip
        degrees = None if theta is None else round(math.degrees(theta), 1)
        key = (model, n, kd, ks, tuple(effects.values()), degrees)
        if state.lobes != "selected":
            key = (
                state.lobes,
                state.lobe_view,
                state.lobe_quantity,
                state.lobe_log,
                state.lobe_ndl,
                tuple(lobe_set(state)),
            )
        if key == self._key:
            return
        self._key = key
        if state.lobes != "selected":
            self._show_many(state)
            return
        self._hide_many()
        box = self._plot_box
        x, y, w, h = box
        frame = [(x, y), (x + w, y), (x + w, y + h), (x, y + h), (x, y)]
        ox = x + 0.5 * w
        lines = {"frame": [frame, [(x, y), (x + w, y)], [(ox, y), (ox, y + 4)]]}
        label = lobe.MODEL_LABELS[model]
        self._peak = None  # the lobe's point farthest from the plot's origin (pixels)
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
            self._peak = (
                lines["lobe"][0][np.argmax(np.hypot(*(plot.lobe.T)))] if len(plot.lobe) else None
            )
            for key, end, shown, away in (("L", ray_l[1], plot.lit, -9.0),
                                          ("R", ray_r[1], plot.lit, 9.0)):  # fmt: skip
                lx = min(max(end[0] + away, x + 6), x + w - 6)
                ly = min(max(end[1] - 4, y + 6), y + h - 6)
                self._labels[key].SetPosition(lx, ly)
                self._labels[key].SetVisibility(shown and self.labelled)
            deg = math.degrees(theta)
            where = f"incidence {deg:.0f}°" if plot.lit else f"light below ({deg:.0f}°)"
            self.caption.SetInput(f"{label}\n{where}, n = {n:g}")
        for key, polylines in lines.items():
            set_lines(self._polys[key], polylines)
        self._fit_caption()

    def _show_many(self, state: State) -> None:
        """The plot of several lobes (:func:`lobe_set`) in the panel: the single lobe's
        lines hidden, a curve per lobe in its colour, the caption the plot's title, the legend
        under it."""
        x, y, w, h = self._plot_box
        frame = [(x, y), (x + w, y), (x + w, y + h), (x, y + h), (x, y)]
        axis = [(x + 0.5 * w, y), (x + 0.5 * w, y + h)]
        if state.lobe_view == "cartesian" and state.lobe_quantity == "albedo":
            axis = [(x, y), (x, y + h)]
        lines = {"frame": [frame, [(x, y), (x + w, y)], axis]}
        lines.update(diffuse=[], incident=[], mirror=[], lobe=[])
        for key, polylines in lines.items():
            set_lines(self._polys[key], polylines)
        for key in ("L", "R"):
            self._labels[key].SetVisibility(False)
        found = lobe_set(state)
        self.chart = many.chart(found, view=state.lobe_view, quantity=state.lobe_quantity,
                                log=state.lobe_log, times_ndl=state.lobe_ndl,
                                nodes=INSET_NODES)  # fmt: skip
        while len(self._curves) < len(self.chart.curves):
            self._curves.append(overlay(self.plotter, (1.0, 1.0, 1.0), 2.0))
            self.actors.append(self._curves[-1][1])
        for i, (poly, actor) in enumerate(self._curves):
            if i < len(self.chart.curves):
                c = self.chart.curves[i]
                actor.GetProperty().SetColor(*c.lobe.colour)
                set_lines(poly, [self.to_pixels(c.points)])
            else:
                set_lines(poly, [])
        title = self.chart.title
        for k, v in LATIN.items():  # (VTK's own fonts have no Greek letters)
            title = title.replace(k, v)
        self.caption.SetInput(f"{title}\n{state.lobes}: {len(found)} lobes")
        self._fit_caption()
        self._show_legend()

    def to_pixels(self, points) -> np.ndarray:
        """Plot points (k, 2) of :attr:`chart` in display pixels (origin bottom-left): x from
        -1 to 1 across the plot's box, y from 0 to 1 up it (the albedo's Cartesian plot: x
        from 0 to 1)."""
        x, y, w, h = self._plot_box
        p = np.asarray(points, np.float64).reshape(-1, 2)
        if self.chart.view == "cartesian":
            x0 = 0.0 if self.chart.quantity == "albedo" else -1.0
            return np.column_stack([x + (p[:, 0] - x0) / (1.0 - x0) * w, y + p[:, 1] * h])
        return lobe.to_box(p, self._plot_box)

    def _show_legend(self) -> None:
        """A line of text per lobe in its colour, over the plot's top left."""
        import vtkmodules.vtkRenderingFreeType  # noqa: F401 - registers the text renderer
        from vtkmodules.vtkRenderingCore import vtkTextActor

        entries = self.chart.legend
        while len(self._legend) < len(entries):
            t = vtkTextActor()
            prop = t.GetTextProperty()
            prop.SetFontFamilyToArial()
            prop.SetFontSize(LEGEND_FONT)
            prop.ShadowOff()
            prop.SetVerticalJustificationToTop()
            self.plotter.renderer.AddViewProp(t)
            self._legend.append(t)
            self.actors.append(t)
        x, y, w, h = self._plot_box
        for i, t in enumerate(self._legend):
            if i < len(entries):
                label, colour, shown = entries[i]
                self._fit_legend(t, label, w - 6)
                t.GetTextProperty().SetColor(*(colour if shown else LEGEND_HIDDEN_COLOR))
                t.SetPosition(x + 3, y + h - 2 - i * (LEGEND_FONT + 2))
            t.SetVisibility(i < len(entries))

    def _fit_legend(self, t, label: str, room: float) -> None:
        """A legend entry within ``room`` pixels (the plot's width: the lit sphere is right of
        it): the label at :data:`LEGEND_FONT`, else smaller (down to
        :data:`LEGEND_MIN_FONT`), else its words from the end dropped (``three.js (n/2+1)/4
        (N·H)^n`` -> ``three.js``)."""
        prop = t.GetTextProperty()
        words = label.split(" ")
        for n in range(len(words), 0, -1):
            t.SetInput(" ".join(words[:n]))
            for font in range(LEGEND_FONT, LEGEND_MIN_FONT - 1, -1):
                prop.SetFontSize(font)
                extent = [0.0, 0.0]
                t.GetSize(self.plotter.renderer, extent)
                if extent[0] <= room:
                    return

    def report(self) -> dict | None:
        """What a test of a front end reads (plain JSON values): each curve's label, colour
        (8-bit) and 24 of its points in window pixels (origin top-left); None for one lobe."""
        if self.chart is None:
            return None
        _, h = self.plotter.window_size
        out = []
        for c in self.chart.curves:
            px = self.to_pixels(c.points)
            pick = np.linspace(0, len(px) - 1, 24).astype(int)
            out.append(
                {
                    "label": c.lobe.label,
                    "colour": [int(round(v * 255)) for v in c.lobe.colour],
                    "px": [[int(round(x)), int(round(h - 1 - y))] for x, y in px[pick]],
                }
            )
        legend = [
            [round(x), round(h - y - bh), round(bw), round(bh)]
            for x, y, bw, bh in self.legend_boxes()
        ]
        shown = [bool(v) for _, _, v in self.chart.legend]
        return {"title": self.chart.title, "curves": out, "legend": legend, "shown": shown}

    def sphere_report(self) -> dict | None:
        """What a test of a front end reads of the lit sphere (:meth:`LitSphere.report`) and
        of the one lobe's plot: its origin and the lobe's farthest point (its peak) in window
        pixels (origin top-left; None while no lobe is drawn)."""
        rep = self.sphere.report()
        if rep is None:
            return None
        _, h = self.plotter.window_size
        x, y, w, _ = self._plot_box
        peak = self._peak
        rep["origin"] = [x + 0.5 * w, h - 1 - y]
        rep["peak"] = (
            None
            if peak is None or self.chart is not None
            else [float(peak[0]), h - 1 - float(peak[1])]
        )
        return rep

    def legend_at(self, px: float, py: float) -> int | None:
        """The legend entry (its lobe's index) at display pixel ``(px, py)`` (origin
        bottom-left), or None."""
        if self.chart is None:
            return None
        for i, (x, y, w, h) in enumerate(self.legend_boxes()):
            if x <= px <= x + w and y <= py <= y + h:
                return i
        return None

    def legend_boxes(self) -> list:
        """Each legend entry's box ``(x, y, width, height)`` in display pixels (origin
        bottom-left): the line of its text, as wide as the text."""
        out = []
        for t in self._legend[: len(self.chart.legend) if self.chart is not None else 0]:
            extent = [0.0, 0.0]
            t.GetSize(self.plotter.renderer, extent)
            x, top = t.GetPosition()
            out.append((x, top - (LEGEND_FONT + 2), max(extent[0], 12.0), LEGEND_FONT + 2))
        return out

    def _hide_many(self) -> None:
        self.chart = None
        for poly, _ in self._curves:
            set_lines(poly, [])
        for t in self._legend:
            t.SetVisibility(False)

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


def inset_side(w: int, h: int) -> int:
    """The inset's width (pixels) in a view of ``w`` x ``h`` pixels (see
    :meth:`LobeInset.layout`)."""
    lo, hi = LOBE_SIDE
    side = int(min(max(LOBE_FRACTION * min(w, h), lo), hi, max(w - 2 * LOBE_MARGIN, 40)))
    while side > LOBE_MIN_SIDE and side * inset_height(side) > LOBE_AREA * w * h:
        side -= 2
    return side


def inset_height(side: int) -> int:
    """The inset's height (pixels) for its width ``side``: the plot (half the width), the
    padding, and two lines of caption when it is labelled (``side`` at least LOBE_SIDE's
    least width; the caption's font is 13 pixels from 170 on, else 11)."""
    text = 2 * ((13 if side >= 170 else 11) + 4) if side >= LOBE_SIDE[0] else 0
    return side // 2 + 3 * LOBE_PAD + text


def lobe_incidence(state: State) -> float:
    """theta_i (radians) of the selected light at the mesh's point that faces the viewer: the
    angle between the directions from the mesh centre toward the viewer and toward the light's
    handle (:func:`explorer.analysis.lobe.incidence`); the state's ``lobe_incidence`` instead
    when the lit sphere (or its row) set one."""
    if state.lobe_incidence is not None:
        return math.radians(state.lobe_incidence)
    return _incidence(state, None)


def _incidence(state: State, index) -> float:
    """:func:`lobe_incidence` of light ``index`` (None: the selected one)."""
    viewer = state.scene.viewer
    centre = np.asarray(state.centre)
    to_viewer = np.subtract(viewer.eye, centre) if viewer.local else viewer.to_viewer
    return lobe.incidence(to_viewer, handle_point(state, index) - centre)


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
