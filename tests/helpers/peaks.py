"""Where the engine's lobe peaks: what the lobe plot's pixels are checked against in both front
ends (tests/app/qt/test_window_litsphere.py, tests/app/web/test_web_litsphere.py)."""

from __future__ import annotations

import math

import numpy as np

from explorer.analysis import litsphere as LS
from explorer.core.scene import Viewer
from explorer.shading.shader import shade


def engine_peak(scene, theta_i: float) -> float:
    """The view angle (degrees, in the plane of incidence, the mirror side positive) where the
    engine's colour of a surface point facing +z, lit at ``theta_i`` (radians) by the lit
    sphere's light, is brightest (steps of 0.25°)."""
    lit = LS.sphere_scene(scene, theta_i)
    angles = np.radians(np.arange(-89.0, 89.01, 0.25))
    up = np.array([[0.0, 0.0, 1.0]])
    got = [
        shade(lit.replace(viewer=Viewer(to_viewer=(math.sin(t), 0.0, math.cos(t)))), up * 0.0, up)[
            0
        ].sum()
        for t in angles
    ]
    return float(np.degrees(angles[int(np.argmax(got))]))
