"""The compiled kernels' layouts, each declared once (:class:`explorer.core.slots.Slots`): the
option slots of a pass (``O_*``), a block's scratch rows (``R_*``), the constants passed in the
working precision (``K_*``) and a chunk's bounds (``B_*``). A light's row of parameters (``P_*``)
is :mod:`explorer.core.lightrow`'s, where the lights that pack it read it.

The kernels (:mod:`explorer.shading.kernels`), the engine that fills their inputs
(:mod:`explorer.shading.shader`, :mod:`~explorer.shading.prepared`) and the tests read the
names from here. numba freezes them into the compiled code, so this module is one of
:data:`explorer.geometry.kernelcache.CONSTANT_MODULES`: an edit recompiles the kernels.
"""

from __future__ import annotations

from explorer.core import tolerances as tol
from explorer.core.slots import Slots

# option slots of a pass, (N_OPTS,) int64 (explorer.shading.shader.pass_options fills them)
_opts = Slots()
O_LOCAL = _opts.slot()  # a local viewer (else V is constant)
O_TWO_SIDED = _opts.slot()  # N -> -N where the vertex shows its back face
O_PHONG = _opts.slot()  # Phong's lobe (else Blinn's)
O_FLAT = _opts.slot()  # shininess 0: a flat lobe
O_DO_AMB = _opts.slot()  # recompute the ambient sum in this pass
O_DO_DIF = _opts.slot()  # ... the diffuse sum
O_DO_SPEC = _opts.slot()  # ... the specular sum
O_STORE = _opts.slot()  # store the recomputed sums
O_STORE_LOBE = _opts.slot()  # store each light's lobe base and weight
O_COMPOSE = _opts.slot()  # write the colours
O_CLAMP = _opts.slot()  # clamp them to [0, 1]
O_TRACK = _opts.slot()  # mark the ambiguous float32 lanes
O_VIEW = _opts.slot()  # V rows are needed even for a flat lobe (Fresnel)
N_OPTS = _opts.count

# a block's scratch rows, (N_ROWS + 1) * ROW elements of the working precision
_rows = Slots()
R_PX, R_PY, R_PZ = _rows.slot(), _rows.slot(), _rows.slot()  # positions (frame)
R_NX, R_NY, R_NZ = _rows.slot(), _rows.slot(), _rows.slot()  # unit normals (flipped two-sided)
R_VX, R_VY, R_VZ = _rows.slot(), _rows.slot(), _rows.slot()  # V, toward the viewer
R_AX, R_AY, R_AZ = _rows.slot(), _rows.slot(), _rows.slot()  # the ambient sum
R_DX, R_DY, R_DZ = _rows.slot(), _rows.slot(), _rows.slot()  # the diffuse sum
R_SX, R_SY, R_SZ = _rows.slot(), _rows.slot(), _rows.slot()  # the specular sum
R_LX, R_LY, R_LZ = _rows.slot(), _rows.slot(), _rows.slot()  # L of a light on the row path
R_W = _rows.slot()  # its weight w (attenuation, spot, shadow, Fresnel)
R_BASE = _rows.slot()  # its lobe's base (base² in float64, see kernels.lobe_power)
R_WS = _rows.slot()  # its lobe's weight
# R_TRK holds, per lane, the smallest margin met so far: a quantity that decides a sign or a
# policy (N·L, N·H, the cone test, |l|², |L + V|²) over its ambiguity band's width
# (explorer.core.tolerances.AMBIGUOUS_*); a lane whose margin ends below 1 is marked ambiguous
R_TRK = _rows.slot()
R_GD, R_GS = _rows.slot(), _rows.slot()  # the grey diffuse and specular sums
R_NV = _rows.slot()  # N·V (after a two-sided flip), for the inline lobes
R_PACK = _rows.slot()  # the float64 lobe loop's packed bases (see kernels._split_lobe)
R_LOBE = _rows.slot()  # ... and their powers
N_ROWS = _rows.count

# constants passed in the working precision (a float literal would promote float32 to float64),
# each with its value (explorer.shading.kernels.constants makes the array)
_consts = Slots()
K_ZERO = _consts.value(0.0)
K_ONE = _consts.value(1.0)
K_TWO = _consts.value(2.0)
K_POINT_EPS = _consts.value(tol.POINT_EPS)
K_HALF_EPS2 = _consts.value(tol.HALFWAY_EPS2)
K_ATT_FLOOR = _consts.value(tol.ATTENUATION_FLOOR)
K_INF = _consts.value(float("inf"))
K_NORMAL_EPS2 = _consts.value(tol.NORMAL_EPS**2)
# margins: a quantity over its band's width (< 1: inside the band)
K_MARGIN_DOT = _consts.value(1.0 / tol.AMBIGUOUS_DOT)
K_MARGIN_LEN2 = _consts.value(1.0 / tol.AMBIGUOUS_LEN2)
K_MARGIN_DIST2 = _consts.value(1.0 / tol.AMBIGUOUS_DIST**2)
N_CONSTS = _consts.count
#: the constants' values, in slot order
CONSTANTS = tuple(_consts.values)

# a chunk's bounds, (N_BOUNDS, chunks) float64 (see kernels.bounds): its bounding sphere (centre,
# radius) and its cone of normals (unit axis, cosine and sine of the half-angle; cosine -1 where
# the cone is 90° or wider, or some normal is absent: such a chunk is never culled)
_bounds = Slots()
B_CX, B_CY, B_CZ, B_R = _bounds.slot(), _bounds.slot(), _bounds.slot(), _bounds.slot()
B_AX, B_AY, B_AZ = _bounds.slot(), _bounds.slot(), _bounds.slot()
B_COS, B_SIN = _bounds.slot(), _bounds.slot()
N_BOUNDS = _bounds.count
