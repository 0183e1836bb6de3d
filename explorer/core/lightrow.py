"""The kernel's row of light parameters: one row of :data:`N_PARAMS` floats and one int32 of
flag bits per light, in the normalised frame (:mod:`explorer.geometry.frame`).

Plain constants, so that a light (:mod:`explorer.core.lights`) and an effect
(:mod:`explorer.shading.effects`) pack their own slots without importing the compiled kernels
(:mod:`explorer.shading.kernels`), which read the same slots. The columns are one table
(:class:`explorer.core.slots.Slots`): each declares its width, and its offset follows.
"""

from explorer.core.slots import Slots

# per-light flag bits (int32)
POSITIONAL = 1
ATTEN = 2
SPOT = 4
SPOT_EXP = 8
AMBIENT = 16  # per-vertex (attenuated) ambient
DIFFUSE = 32
SPECULAR = 64
CONST_H = 128  # Blinn with a directional light and an infinite viewer
SHADOW = 256  # w *= visibility row (explorer.shading.shadows) for diffuse and specular
FRESNEL = 512  # specular weight *= Schlick F = F0 + (1 - F0)(1 - V·H)^5
GREY = 1024  # diffuse and specular colours have r = g = b (one sum per vertex, not three)

# per-light parameter columns, each as wide as its comment says (a light's row: N_PARAMS floats)
_params = Slots()
P_POS = _params.slot(3)  # position, or the unit vector toward a directional light
P_AXIS = _params.slot(3)  # spot axis, the unit vector it shines along
P_ATT = _params.slot(3)  # kc, kl·scale, kq·scale²
P_COS = _params.slot()  # cos(cutoff)
P_EXP = _params.slot()  # spot exponent
P_AMB = _params.slot(3)  # ambient colour × constant factor
P_DIF = _params.slot(3)  # diffuse colour × constant factor
P_SPEC = _params.slot(3)  # specular colour × constant factor
P_H = _params.slot(3)  # constant halfway vector
P_F0 = _params.slot()  # Schlick F0 (Fresnel)
N_PARAMS = _params.count
