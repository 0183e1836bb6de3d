"""An independent, scalar transcription of three.js's MeshPhongMaterial lighting (the GLSL of
``bsdfs.glsl.js``: BRDF_Lambert, F_Schlick, D_BlinnPhong, G_BlinnPhong_Implicit, BRDF_BlinnPhong,
and ``RE_Direct_BlinnPhong`` in ``lights_phong_pars_fragment.glsl.js``), sharing no code with the
engine. Each light's intensity is π times its OpenGL colour (the engine's ``threejs`` model);
ambient, emission, attenuation and spot cones are OpenGL's (the same scene dict as
:func:`helpers.gl21_oracle.gl_vertex_color`).

Used only by the tests: the engine's float64 ``threejs`` colours must equal these.
"""

from __future__ import annotations

import math

from helpers.gl21_oracle import _dot, _norm, _sub


def _saturate(x: float) -> float:
    return min(max(x, 0.0), 1.0)


def _brdf_blinn_phong(light_dir, view_dir, normal, specular, shininess) -> list[float]:
    h = _norm([light_dir[j] + view_dir[j] for j in range(3)])
    dot_nh = _saturate(_dot(normal, h))
    dot_vh = _saturate(_dot(view_dir, h))
    fresnel = 2.0 ** ((-5.55473 * dot_vh - 6.98316) * dot_vh)  # F_Schlick, f90 = 1
    f = [s * (1.0 - fresnel) + fresnel for s in specular]
    g = 0.25  # G_BlinnPhong_Implicit
    d = (1.0 / math.pi) * (shininess * 0.5 + 1.0) * (dot_nh**shininess if shininess else 1.0)
    return [fj * (g * d) for fj in f]


def threejs_vertex_color(vertex, normal, scene: dict) -> list[float]:
    """Colour of one vertex (clamped to [0, 1]); ``scene`` as for ``gl_vertex_color``. Light
    directions must not be opposite to the view direction (H undefined there)."""
    m = scene["material"]
    n = _norm(normal)
    c = [m["emission"][j] + m["ambient"][j] * scene["ambient"][j] for j in range(3)]
    v = _norm(_sub(scene["eye"], vertex)) if scene["local_viewer"] else _norm(scene["view_dir"])
    for light in scene["lights"]:
        pos = light["position"]
        if pos[3] == 0.0:
            l_vec, att = _norm(pos[:3]), 1.0
        else:
            d_vec = _sub([p / pos[3] for p in pos[:3]], vertex)
            d = math.sqrt(_dot(d_vec, d_vec))
            l_vec = _norm(d_vec)
            k0, k1, k2 = light["attenuation"]
            att = 1.0 / (k0 + k1 * d + k2 * d * d)
        if light["spot_cutoff"] != 180.0:  # OpenGL's cone and exponent
            x = -_dot(l_vec, _norm(light["spot_direction"]))
            inside = x >= math.cos(math.radians(light["spot_cutoff"]))
            att *= max(x, 0.0) ** light["spot_exponent"] if inside else 0.0
        dot_nl = _saturate(_dot(n, l_vec))
        spec = _brdf_blinn_phong(l_vec, v, n, m["specular"], m["shininess"])
        for j in range(3):
            diffuse_light = math.pi * att * light["diffuse"][j]  # three.js intensity = π·I
            specular_light = math.pi * att * light["specular"][j]
            c[j] += att * m["ambient"][j] * light["ambient"][j]
            c[j] += dot_nl * diffuse_light * (m["diffuse"][j] / math.pi)  # BRDF_Lambert
            c[j] += dot_nl * specular_light * spec[j]
    return [min(max(x, 0.0), 1.0) for x in c]
