"""The kernel's row of light parameters: one row of :data:`N_PARAMS` floats and one int32 of
flag bits per light, in the normalised frame (:mod:`explorer.geometry.frame`).

Plain constants, so that a light (:mod:`explorer.core.lights`) and an effect
(:mod:`explorer.shading.effects`) pack their own slots without importing the compiled kernels
(:mod:`explorer.shading.kernels`), which read the same slots.
"""

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

# per-light parameter columns
P_POS = 0  # position, or the unit vector toward a directional light (3)
P_AXIS = 3  # spot axis, the unit vector it shines along (3)
P_ATT = 6  # kc, kl·scale, kq·scale² (3)
P_COS = 9  # cos(cutoff)
P_EXP = 10  # spot exponent
P_AMB = 11  # ambient colour × constant factor (3)
P_DIF = 14  # diffuse colour × constant factor (3)
P_SPEC = 17  # specular colour × constant factor (3)
P_H = 20  # constant halfway vector (3)
P_F0 = 23  # Schlick F0 (Fresnel)
N_PARAMS = 24
