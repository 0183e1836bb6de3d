"""The lobe plots of :mod:`explorer.analysis.lobes` as a picture: ``render --lobes``.

Each :class:`~explorer.analysis.lobes.Chart` is a panel: its title above, the plot (a half disc
with rings and spokes every 30°, or axes with the angle below and the scale's values at the
left), every visible lobe's curve in its colour, and the legend below (a hidden lobe's entry
greyed). An albedo panel draws the line ρ = 1, where a surface reflects all it receives. Drawn
with Pillow (lines, text): no VTK, no window.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from explorer.analysis.lobe import incidence
from explorer.analysis.lobes import COLOURS, Chart, chart, model_lobes, scene_lobe
from explorer.core.errors import ExplorerError
from explorer.render.images import check_picture_pixels, check_size
from explorer.render.offscreen import BACKGROUND
from explorer.shading.display import to_bytes

#: one panel's size (pixels)
PANEL = (380, 300)
#: the panels' text, grid and frame colours (RGB in [0, 1]; the text on the background: at least
#: 4.5:1, as the window's inset)
TEXT_COLOUR = (0.95, 0.95, 0.95)
GRID_COLOUR = (0.45, 0.45, 0.47)
HIDDEN_COLOUR = (0.6, 0.6, 0.6)
#: the line ρ = 1 of an albedo panel
UNIT_COLOUR = (1.0, 1.0, 1.0)
#: font size (pixels), line widths
FONT = 13
CURVE_WIDTH = 2


#: a font with Greek letters, found where the system keeps fonts (Pillow looks there), else
#: Pillow's own (Latin only: θ, ρ and · are then written out, :data:`ASCII`)
FONT_FILE = "DejaVuSans.ttf"
ASCII = {"θ": "theta", "ρ": "rho", "·": "."}


class _Text:
    """The panels' font and how it writes: :meth:`__call__` draws a string."""

    def __init__(self, size: int):
        from PIL import ImageFont

        try:
            self.font, self.greek = ImageFont.truetype(FONT_FILE, size), True
        except OSError:  # no such font on this system
            self.greek = False
            try:
                self.font = ImageFont.load_default(size=size)  # (Pillow >= 10.1: scalable)
            except TypeError:  # older Pillow: its bitmap font
                self.font = ImageFont.load_default()

    def written(self, text: str) -> str:
        if not self.greek:
            for k, v in ASCII.items():
                text = text.replace(k, v)
        return text

    def width(self, text: str) -> float:
        return float(self.font.getlength(self.written(text)))

    def __call__(self, d, xy, text: str, colour) -> None:
        d.text(xy, self.written(text), fill=_rgb(colour), font=self.font)


def _rgb(c) -> tuple:
    return tuple(int(v) for v in to_bytes([c])[0])


def draw_chart(chart: Chart, size: Sequence[int] = PANEL, background=BACKGROUND) -> np.ndarray:
    """One panel (height, width, 3) uint8 (see the module docstring)."""
    return _draw(chart, size, background)[0]


def chart_pixels(chart: Chart, points, size: Sequence[int] = PANEL) -> np.ndarray:
    """Where :func:`draw_chart` puts plot points (k, 2) of ``chart`` in a panel of ``size``:
    (k, 2) pixel coordinates (x right, y down; what a test reads the picture at)."""
    return _draw(chart, size, BACKGROUND)[1](np.asarray(points, np.float64).reshape(-1, 2))


def _draw(chart: Chart, size, background) -> tuple:
    """The panel and its plot-to-pixel map."""
    from PIL import Image, ImageDraw

    w, h = check_size(size)
    img = Image.new("RGB", (w, h), _rgb(background))
    d = ImageDraw.Draw(img)
    text = _Text(FONT)
    line = FONT + 5
    entries = [e[0] if e[2] else f"{e[0]} (hidden)" for e in chart.legend]
    cols = 2 if max((text.width(e) for e in entries), default=0.0) < w / 2 - 34 else 1
    legend_rows = -(-len(chart.legend) // cols)
    top, bottom = line + 4, h - legend_rows * line - line - 6
    left, right = 44, w - 10
    text(d, (8, 3), chart.title, TEXT_COLOUR)
    if chart.view == "polar":
        to_px = _polar(d, chart, (left, top, right, bottom), text)
    else:
        to_px = _cartesian(d, chart, (left, top, right, bottom), text)
    if chart.quantity == "albedo" and chart.floor is None and chart.top >= 1.0:
        _unit_line(d, chart, to_px)
    for curve in chart.curves:
        pts = [tuple(p) for p in to_px(curve.points)]
        if len(pts) > 1:
            d.line(pts, fill=_rgb(curve.lobe.colour), width=CURVE_WIDTH, joint="curve")
    y0 = h - legend_rows * line - 4
    for i, (_, colour, visible) in enumerate(chart.legend):
        x = 8 + (i % cols) * (w // 2)
        y = y0 + (i // cols) * line
        c = _rgb(colour if visible else HIDDEN_COLOUR)
        d.line([(x, y + line // 2), (x + 18, y + line // 2)], fill=c, width=3)
        text(d, (x + 24, y + 1), entries[i], TEXT_COLOUR if visible else HIDDEN_COLOUR)
    return np.asarray(img, np.uint8).copy(), to_px


def _scale_text(chart: Chart, r: float) -> str:
    """The value at radius / height ``r`` of the chart's scale."""
    if chart.floor is None:
        return f"{chart.top * r:.3g}"
    return f"{chart.floor * 10.0 ** (r * math.log10(chart.top / chart.floor)):.2g}"


def _polar(d, chart: Chart, box, text):
    """The half disc: rings at quarter radii labelled with their values, spokes every 30°."""
    left, top, right, bottom = box
    radius = min(0.5 * (right - left), bottom - top)
    ox, oy = 0.5 * (left + right), bottom
    grid = _rgb(GRID_COLOUR)
    for q in (0.25, 0.5, 0.75, 1.0):
        rr = q * radius
        d.arc([ox - rr, oy - rr, ox + rr, oy + rr], 180, 360, fill=grid)
        text(d, (ox + 3, oy - rr - FONT - 1), _scale_text(chart, q), GRID_COLOUR)
    for deg in range(-90, 91, 30):
        a = math.radians(deg)
        d.line([(ox, oy), (ox + radius * math.sin(a), oy - radius * math.cos(a))], fill=grid)
    if chart.quantity != "albedo":  # each lobe's light, toward -θ_i
        for curve in chart.curves:
            a = -curve.lobe.theta_i
            end = (ox + radius * math.sin(a), oy - radius * math.cos(a))
            d.line([(ox, oy), end], fill=_rgb(curve.lobe.colour), width=1)
    return lambda p: np.column_stack([ox + radius * p[:, 0], oy - radius * p[:, 1]])


def _cartesian(d, chart: Chart, box, text):
    """Axes: the angle below (θ_v from -90° to 90°, or θ_i from 0 to 90°), the scale's values
    at the left, a grid line at each quarter."""
    left, top, right, bottom = box
    bottom -= FONT + 4  # the angle's labels
    grid = _rgb(GRID_COLOUR)
    albedo = chart.quantity == "albedo"
    x0 = 0.0 if albedo else -1.0
    for q in (0.0, 0.25, 0.5, 0.75, 1.0):
        y = bottom - q * (bottom - top)
        d.line([(left, y), (right, y)], fill=grid)
        y = min(y, bottom - FONT // 2 - 2)  # (the lowest clear of the angles' labels)
        text(d, (4, y - FONT // 2 - 1), _scale_text(chart, q), GRID_COLOUR)
    ticks = range(0, 91, 15) if albedo else range(-90, 91, 30)
    for deg in ticks:
        x = left + (deg / 90.0 - x0) / (1.0 - x0) * (right - left)
        d.line([(x, top), (x, bottom)], fill=grid)
        text(d, (x - 8, bottom + 2), f"{deg}°", GRID_COLOUR)
    name = "θ_i" if albedo else "θ_v"
    text(d, (right - 40, bottom - FONT - 4), name, TEXT_COLOUR)

    def to_px(p):
        x = left + (p[:, 0] - x0) / (1.0 - x0) * (right - left)
        return np.column_stack([x, bottom - p[:, 1] * (bottom - top)])

    return to_px


def _unit_line(d, chart: Chart, to_px) -> None:
    """ρ = 1 across an albedo panel (a ring on a polar one)."""
    r = 1.0 / chart.top
    if chart.view == "polar":
        t = np.linspace(-0.5 * math.pi, 0.5 * math.pi, 91)
        pts = to_px(np.column_stack([r * np.sin(t), r * np.cos(t)]))
    else:
        pts = to_px(np.array([[0.0, r], [1.0, r]]))
    d.line([tuple(p) for p in pts], fill=_rgb(UNIT_COLOUR), width=1)


def lobe_picture(charts, panel: Sequence[int] = PANEL, background=BACKGROUND) -> np.ndarray:
    """The charts' panels side by side, 2 pixels apart: (H, W, 3) uint8."""
    charts = list(charts)
    if not charts:
        raise ExplorerError("no lobe plots to draw")
    pw, ph = check_size(panel)
    width = len(charts) * pw + (len(charts) + 1) * 2
    check_picture_pixels(width, ph + 4, f"{len(charts)} lobe panels of {pw}x{ph}")
    out = np.empty((ph + 4, width, 3), np.uint8)
    out[:] = to_bytes([background])[0]
    for i, c in enumerate(charts):
        x = 2 + i * (pw + 2)
        out[2 : 2 + ph, x : x + pw] = draw_chart(c, (pw, ph), background)
    return out


def light_incidences(scene, centre) -> list[float]:
    """θ_i (radians) of each light of the scene at the point of a mesh centred at ``centre``
    (3,) that faces the viewer (:func:`explorer.analysis.lobe.incidence`, as the window's inset
    measures it): between the directions toward the viewer and toward the light."""
    c = np.asarray(centre, np.float64)
    viewer = scene.viewer
    to_viewer = np.subtract(viewer.eye, c) if viewer.local else viewer.to_viewer
    out = []
    for light in scene.lights:
        to_light = light.to_light if light.type == "directional" else np.subtract(light.position, c)
        out.append(incidence(to_viewer, to_light))
    return out


def scene_charts(scene, incidences) -> list[Chart]:
    """The panels of ``render --lobes`` for a scene whose lights are at ``incidences``
    (radians, one per light): the three models' lobes for its material at the first light's
    incidence, polar (intensity per unit light) and Cartesian (BRDF, log); their albedo beside
    the phong and blinn lobes with ``energy_conserving`` switched; and with several lights, the
    scene's lobe for each (polar)."""
    if not incidences:
        raise ExplorerError("the lobe plot needs a light: the scene has none")
    ti = incidences[0]
    three = model_lobes(scene, ti)
    on = scene.material.energy_conserving
    other = scene.replace(material=scene.material.replace(energy_conserving=not on))
    word = "energy_conserving" if not on else "not energy_conserving"
    switched = [
        scene_lobe(other, ti, f"{m}, {word}", COLOURS[3 + i], model=m)
        for i, m in enumerate(("phong", "blinn"))
    ]
    charts = [
        chart(three, view="polar", quantity="intensity"),
        chart(three, view="cartesian", quantity="brdf", log=True),
        chart(three + switched, view="cartesian", quantity="albedo"),
    ]
    if len(incidences) > 1:
        per_light = [
            scene_lobe(
                scene, t, f"light {i + 1} ({math.degrees(t):.0f}°)", COLOURS[i % len(COLOURS)]
            )
            for i, t in enumerate(incidences)
        ]
        charts.append(chart(per_light, view="polar", quantity="intensity"))
    return charts
