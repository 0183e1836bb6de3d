"""Where everything sits in the explorer window, and which key does what.

One module for the layout so that the app (:mod:`explorer.app.window`), its tests and its docs
agree. Coordinates of sliders and text are *normalised display* coordinates: ``(0, 0)`` is the
window's bottom-left corner, ``(1, 1)`` its top-right, so they follow the window when it is
resized. Buttons are placed in pixels from those same normalised anchors (and placed again when
the window is resized). The lobe inset is in pixels from the bottom-left corner, so it stays
square.
"""

from __future__ import annotations

#: window title (the real-window test finds the window by it)
TITLE = "phong-explorer"
#: default window size (width, height) in pixels
WINDOW_SIZE = (1100, 720)
#: the control panel covers the right part of the window, from this x to 1
PANEL_X = 0.68
#: panel background (RGB) and opacity
PANEL_COLOR = (0.16, 0.16, 0.17)
PANEL_OPACITY = 0.9
#: colour of text and slider titles
TEXT_COLOR = (0.92, 0.92, 0.92)
#: colour of error messages
ERROR_COLOR = (1.0, 0.45, 0.40)
#: accent colour: slider knobs, buttons that are on
ACCENT_COLOR = (0.30, 0.60, 1.00)
#: slider tubes, buttons that are off
DIM_COLOR = (0.42, 0.42, 0.45)
#: font size (pixels) of labels, the status line and the help overlay
FONT_SIZE = 14
HELP_FONT_SIZE = 14

# -- sliders: the slider line runs from SLIDER_X[0] to SLIDER_X[1] at height SLIDER_Y[name] ----
SLIDER_X = (0.715, 0.975)
#: the four material sliders, named like the material keys
MATERIAL_SLIDERS = ("ka", "kd", "ks", "shininess")
#: the three light sliders
LIGHT_SLIDERS = ("azimuth", "elevation", "distance")
SLIDER_Y = {
    "ka": 0.835,
    "kd": 0.755,
    "ks": 0.675,
    "shininess": 0.595,
    "azimuth": 0.290,
    "elevation": 0.210,
    "distance": 0.130,
}
#: slider geometry (VTK's vtkSliderRepresentation2D; lengths are fractions of the window
#: width, text heights fractions of the window height)
SLIDER_GEOMETRY = {
    "slider_length": 0.014,
    "slider_width": 0.028,
    "tube_width": 0.008,
    "end_cap_length": 0.004,
    "end_cap_width": 0.028,
    "title_height": 0.018,
    "label_height": 0.018,
}
#: label format of the sliders that show their value (shininess shows it in its title)
SLIDER_FORMAT = {
    "ka": "%.3f",
    "kd": "%.3f",
    "ks": "%.3f",
    "azimuth": "%.0f",
    "elevation": "%.0f",
    "distance": "%.2f",
}
#: slider ranges that do not depend on the mesh; the shininess slider holds log10(n)
SHININESS_SLIDER_RANGE = (0.0, 3.0)  # n from 1 to 1000
AZIMUTH_RANGE = (-180.0, 180.0)
ELEVATION_RANGE = (-90.0, 90.0)
#: distance slider range, in mesh radii (the slider itself shows world units)
DISTANCE_RANGE = (1.0, 10.0)

# -- buttons: name -> (x, y) of the bottom-left corner, normalised display --------------------
BUTTON_SIZE = 18  # pixels
BUTTONS = {
    "preset_previous": (0.715, 0.895),
    "preset_next": (0.955, 0.895),
    "blinn": (0.715, 0.510),
    "phong": (0.830, 0.510),
    "ambient": (0.715, 0.460),
    "diffuse": (0.815, 0.460),
    "specular": (0.905, 0.460),
    "directional": (0.715, 0.350),
    "point": (0.840, 0.350),
    "spot": (0.915, 0.350),
    "mesh_previous": (0.715, 0.040),
    "mesh_next": (0.955, 0.040),
    "difference": (0.010, 0.905),  # top left of the view: the heat map's toggle
}
#: radio groups: exactly one button of a group is on
RADIO_GROUPS = {"model": ("blinn", "phong"), "light_type": ("directional", "point", "spot")}
#: term toggles (check boxes)
TERM_BUTTONS = ("ambient", "diffuse", "specular")
#: push buttons (always drawn off; a click acts once)
PUSH_BUTTONS = ("preset_previous", "preset_next", "mesh_previous", "mesh_next")
#: text of each button: right of it, or inside it for the push buttons' arrows
BUTTON_LABELS = {
    "blinn": "blinn",
    "phong": "phong",
    "ambient": "ambient",
    "diffuse": "diffuse",
    "specular": "specular",
    "directional": "directional",
    "point": "point",
    "spot": "spot",
    "preset_previous": "<",
    "preset_next": ">",
    "mesh_previous": "<",
    "mesh_next": ">",
    "difference": "difference",
}
#: gap between a button and its label, normalised display
LABEL_GAP = 0.022

# -- text: name -> (x, y) of the bottom-left corner, normalised display ------------------------
TEXT = {
    "heading_material": (0.715, 0.950),
    "preset": (0.745, 0.897),  # the preset's name, between the two arrows
    "heading_light": (0.715, 0.405),
    "light": (0.790, 0.405),  # which light, and where
    "heading_mesh": (0.715, 0.080),
    "mesh": (0.745, 0.042),
    "status": (0.010, 0.012),  # one line: preset, mesh, model, light, frame time
    "message": (0.010, 0.045),  # the last message (saved..., error: ...)
    "hint": (0.010, 0.960),
    "difference": (0.010, 0.835),  # the heat map's legend (two lines), while it is on
    "advice": (0.010, 0.765),  # which mesh is fine enough (two lines), while it is on
}

# -- the specular lobe inset (pixels from the bottom-left corner) -----------------------------
#: (x, y, side): a square plot of r = cos^n(t), -90° <= t <= 90°, as the lecture notes draw it
LOBE_BOX = (12, 80, 150)
LOBE_SAMPLES = 181
LOBE_COLOR = (1.0, 0.85, 0.35)
#: the n = 1 lobe (a circle through the origin) drawn faintly for reference
LOBE_REFERENCE_COLOR = (0.55, 0.55, 0.58)
LOBE_FRAME_COLOR = DIM_COLOR

# -- the light handle ---------------------------------------------------------------------------
#: radius of the handle sphere, in mesh radii
HANDLE_RADIUS = 0.07
HANDLE_COLOR = (1.0, 0.95, 0.55)

# -- keys (VTK key symbols) -----------------------------------------------------------------------
#: key -> what it does (the help overlay lists exactly these, in this order)
KEYS = {
    "h": "show / hide this help",
    "n": "next preset",
    "p": "previous preset",
    "m": "next mesh",
    "M": "previous mesh",
    "b": "switch the specular model (blinn / phong)",
    "t": "switch the light type (directional / point / spot)",
    "l": "control the next light of the scene",
    "1": "show / hide the ambient term",
    "2": "show / hide the diffuse term",
    "3": "show / hide the specular term",
    "d": "show / hide the per-pixel difference (heat map) and which mesh is fine enough",
    "s": "save the material as a new preset (never overwrites)",
    "i": "save a screenshot (PNG, never overwrites)",
    "r": "reset to the start",
    "q": "quit",
}
#: mouse controls, listed in the help overlay after the keys
MOUSE = (
    ("left drag", "rotate the camera (the camera is the viewer: highlights move)"),
    ("right drag / wheel", "zoom"),
    ("middle drag", "pan"),
    ("drag the yellow sphere", "move the light"),
)
