"""An independent, scalar implementation of the OpenGL 2.1 fixed-function lighting equation
(spec section 2.14.1), written from the specification, sharing no code with the engine.

Used only by the tests: the engine's float64 colours must equal these to 1e-5.
"""

from __future__ import annotations

import math


def _sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _norm(a):
    n = math.sqrt(_dot(a, a))
    return [a[0] / n, a[1] / n, a[2] / n]


def gl_vertex_color(vertex, normal, scene: dict) -> list[float]:
    """Colour of one vertex. ``scene`` is a plain dict:

    material: {ambient, diffuse, specular, emission: [r, g, b], shininess}
    ambient: [r, g, b] (LIGHT_MODEL_AMBIENT)
    local_viewer: bool; eye: [x, y, z] (local) -- the infinite viewer looks along +V = view_dir
    view_dir: [x, y, z] (infinite viewer: direction toward the viewer)
    lights: list of {position: [x, y, z, w], ambient, diffuse, specular, spot_direction,
                     spot_cutoff, spot_exponent, attenuation: [k0, k1, k2]}
    """
    m = scene["material"]
    n = _norm(normal)
    c = [m["emission"][j] + m["ambient"][j] * scene["ambient"][j] for j in range(3)]
    if scene["local_viewer"]:
        v = _norm(_sub(scene["eye"], vertex))
    else:
        v = _norm(scene["view_dir"])
    for light in scene["lights"]:
        pos = light["position"]
        if pos[3] == 0.0:  # directional
            l_vec = _norm(pos[:3])
            att = 1.0
        else:
            pl = [pos[0] / pos[3], pos[1] / pos[3], pos[2] / pos[3]]
            d_vec = _sub(pl, vertex)
            d = math.sqrt(_dot(d_vec, d_vec))
            l_vec = _norm(d_vec)
            k0, k1, k2 = light["attenuation"]
            att = 1.0 / (k0 + k1 * d + k2 * d * d)
        if light["spot_cutoff"] == 180.0:
            spot = 1.0
        else:
            s_dir = _norm(light["spot_direction"])
            x = -_dot(l_vec, s_dir)
            if x >= math.cos(math.radians(light["spot_cutoff"])):
                spot = max(x, 0.0) ** light["spot_exponent"]
            else:
                spot = 0.0
        ndl = _dot(n, l_vec)
        h = _norm([l_vec[j] + v[j] for j in range(3)])
        f = 1.0 if ndl > 0.0 else 0.0
        ndh = max(_dot(n, h), 0.0)
        spec = f * (ndh ** m["shininess"] if m["shininess"] != 0.0 else 1.0)
        for j in range(3):
            c[j] += (
                att
                * spot
                * (
                    m["ambient"][j] * light["ambient"][j]
                    + max(ndl, 0.0) * m["diffuse"][j] * light["diffuse"][j]
                    + spec * m["specular"][j] * light["specular"][j]
                )
            )
    return [min(max(x, 0.0), 1.0) for x in c]
