"""Texture maps per pixel: every map of a material on the exact light sums of each pixel.

A per-pixel picture (:class:`explorer.render.live.LivePixels`, ``render --per-pixel``) knows of
each covered pixel its triangle and barycentrics ``(b1, b2)`` (the G-buffer's
:class:`~explorer.render.perpixel.Hits`), so the pixel's texture coordinate is the mesh's
``(u, v)`` interpolated there, ``(1-b1-b2)·uv0 + b1·uv1 + b2·uv2`` (:func:`pixel_uv`), looked up
at ``(u·su + ou, v·sv + ov)`` (the map's ``scale`` and ``offset``) and sampled nearest
(``GL_NEAREST``), repeated or clamped to the edge (``clamp``), as the per-vertex picture samples
its ``diffuse_map`` (:func:`explorer.render.textures.sample_nearest`). Each map then scales its
own term of the engine's sums at that pixel (:func:`compose_maps`)::

    colour = e·Te + a·A·Ta + d·D·Td + s·ts·S(n·tn)     (clamped to [0, 1] as the engine clamps)

- ``emission_map`` ``Te``, ``ambient_map`` ``Ta``, ``diffuse_map`` ``Td``: the RGB texel / 255,
  multiplying the emission, the ambient sum ``A`` (the scene's ambient included) and the
  diffuse sum ``D``;
- ``specular_map`` ``ts`` and ``shininess_map`` ``tn``: scalars / 255, the map's ``channel``
  (:func:`scalar_texels`): the specular colour times ``ts``; the shininess ``n·tn``, so each
  pixel has its own lobe (``S`` is the specular sum at that exponent: three.js's
  ``specular_f90`` sum is scaled by ``ts`` and taken at that exponent too);
- ``bump_map``: the normal tilted before the engine shades (:func:`bumped_normals`).

A map absent is a factor of 1: the colour is then ``compose_terms``'s, bit for bit in float64.
The sums are the per-pixel shader's kept ones (:func:`explorer.shading.shader.kept_sums`): a
change of the material's colours or of a colour or scalar map composes again with no light
pass. A shininess map needs the specular sum at each exponent its pixels have (at most 256: one
8-bit channel): on the compiled tier the lobe alone at each, from the bases the shader stores
after its first shininess change (the numpy tier computes each anew). A bump map changes the
normals: the light sums are computed anew.

GL 2.1 has no per-pixel lighting, so ``color_control`` plays no part here: the specular is
never multiplied by the diffuse texture (as under ``separate``, and every term its own map).
"""

from __future__ import annotations

import numpy as np

from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError
from explorer.core.texture import TextureMap
from explorer.render.textures import (
    file_stamp,
    gl_rows,
    read_texture,
    sample_nearest,
    texel_index,
)
from explorer.shading.shader import kept_sums

#: the maps that scale a colour term, and the material colour each scales
COLOUR_MAPS = {"emission_map": "emission", "ambient_map": "ambient", "diffuse_map": "diffuse"}
#: the maps read as one scalar per texel (their ``channel``)
SCALAR_MAPS = ("specular_map", "shininess_map", "bump_map")
#: ITU-R 601-2 luma weights of red, green and blue: an image's luminance ``l`` as Pillow's
#: ``convert("L")`` computes it
LUMA = (0.299, 0.587, 0.114)
#: how many images a :class:`PixelMaps` keeps read
_KEPT_IMAGES = 16


def any_maps(materials) -> bool:
    """Whether any of ``materials`` wears a map a per-pixel picture draws (every map does)."""
    return any(m.maps() for m in materials)


def bare(material):
    """``material`` without its maps (the same object when it has none)."""
    maps = material.maps()
    return material.replace(**dict.fromkeys(maps)) if maps else material


def pixel_uv(mesh, triangles, barycentrics) -> np.ndarray:
    """(k, 2) float64 the mesh's (u, v) at hits on ``triangles`` (k,) with ``barycentrics``
    (k, 2) ``(b1, b2)``: ``(1-b1-b2)·uv0 + b1·uv1 + b2·uv2`` over the triangle's corners."""
    if mesh.uv is None:
        raise ExplorerError(
            f"mesh '{mesh.name}' has no texture coordinates, so it cannot wear a texture map "
            "(an OBJ needs vt lines; a built-in mesh has its own)"
        )
    F = np.asarray(mesh.faces, np.int64).reshape(-1, 3)[np.asarray(triangles, np.int64)]
    uv = np.asarray(mesh.uv, np.float64)
    b = np.asarray(barycentrics, np.float64)
    b1, b2 = b[:, :1], b[:, 1:2]
    return (1.0 - b1 - b2) * uv[F[:, 0]] + b1 * uv[F[:, 1]] + b2 * uv[F[:, 2]]


def scalar_of(texels, channel: str | None) -> np.ndarray:
    """(..., ) float64 in [0, 1]: one value per RGBA texel (..., 4) uint8 by ``channel``: ``r``,
    ``g``, ``b``, ``m`` (matte: the alpha), ``l`` the luminance (:data:`LUMA`), the default;
    ``z`` (depth) reads the luminance too (a PNG or JPEG holds no depth)."""
    t = np.asarray(texels, np.float64) / 255.0
    pick = {"r": 0, "g": 1, "b": 2, "m": 3}
    if channel in pick:
        return t[..., pick[channel]]
    return LUMA[0] * t[..., 0] + LUMA[1] * t[..., 1] + LUMA[2] * t[..., 2]


def colour_texels(image, tmap: TextureMap, uv) -> np.ndarray:
    """(k, 3) float64 in [0, 1]: the RGB texel / 255 of ``image`` at the mesh's ``uv`` (k, 2)."""
    rgba = sample_nearest(image, tmap.lookup(uv), clamp=tmap.clamp)
    return rgba[:, :3].astype(np.float64) / 255.0


def scalar_texels(image, tmap: TextureMap, uv) -> np.ndarray:
    """(k,) float64 in [0, 1]: the map's scalar (:func:`scalar_of` its ``channel``) at ``uv``."""
    return scalar_of(sample_nearest(image, tmap.lookup(uv), clamp=tmap.clamp), tmap.channel)


def height_gradient(image, tmap: TextureMap, uv) -> tuple[np.ndarray, np.ndarray]:
    """``(F_u, F_v)`` (k,) float64: the derivatives by u and v of the bump map's height
    ``F = bump_multiplier · h`` at ``uv`` (k, 2) (``h`` the scalar of :func:`scalar_of`).

    At the texel (i, j) ``GL_NEAREST`` picks, ``dh/ds = (h[j, i+1] - h[j, i-1]) · w / 2``: the
    central difference of its neighbours, wrapped around a repeated map, one-sided at a clamped
    map's edge (one texel is 1/w of s); likewise ``dh/dt`` along the rows (bottom first, as
    OpenGL's t). Then ``F_u = bump_multiplier · dh/ds · su`` (s = u·su + ou) and ``F_v`` alike.
    """
    heights = scalar_of(gl_rows(image), tmap.channel)  # (h, w), row 0 at t = 0
    h, w = heights.shape
    j, i = texel_index((h, w), tmap.lookup(uv), clamp=tmap.clamp)

    def along(n: int, at: np.ndarray):
        """The neighbours' indices before and after ``at`` on an axis of ``n`` texels, and
        their distance in texture units."""
        if tmap.clamp:
            lo, hi = np.maximum(at - 1, 0), np.minimum(at + 1, n - 1)
        else:
            lo, hi = (at - 1) % n, (at + 1) % n
        span = (hi - lo) if tmap.clamp else np.full(at.shape, 2)
        return lo, hi, np.where(span > 0, span, 1) / float(n), span > 0

    lo, hi, ds, ok_s = along(w, i)
    dh_ds = np.where(ok_s & (w > 1), (heights[j, hi] - heights[j, lo]) / ds, 0.0)
    lo, hi, dt, ok_t = along(h, j)
    dh_dt = np.where(ok_t & (h > 1), (heights[hi, i] - heights[lo, i]) / dt, 0.0)
    bm = float(tmap.bump_multiplier)
    return bm * dh_ds * float(tmap.scale[0]), bm * dh_dt * float(tmap.scale[1])


def tangent_frames(mesh, triangles) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(P_u, P_v, ok)``: the surface's derivatives by u and v (k, 3) float64 on each of the
    ``triangles`` (k,), from its corners' positions and (u, v): the edges ``e1 = p1 - p0``,
    ``e2 = p2 - p0`` are ``P_u·du + P_v·dv`` of their (u, v) differences, solved for P_u, P_v.
    ``ok`` (k,) bool: the triangle has a frame
    (:data:`~explorer.core.tolerances.BUMP_FRAME_EPS`)."""
    F = np.asarray(mesh.faces, np.int64).reshape(-1, 3)[np.asarray(triangles, np.int64)]
    P = np.asarray(mesh.positions, np.float64)
    uv = np.asarray(mesh.uv, np.float64)
    e1, e2 = P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]]
    d1, d2 = uv[F[:, 1]] - uv[F[:, 0]], uv[F[:, 2]] - uv[F[:, 0]]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    ok = np.abs(det) > tol.BUMP_FRAME_EPS
    inv = (1.0 / np.where(ok, det, 1.0))[:, None]
    Pu = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * inv
    Pv = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * inv
    return Pu, Pv, ok


def bumped_normals(mesh, triangles, barycentrics, normals, image, tmap: TextureMap):
    """(k, 3) float64 unit normals tilted by the bump map (Blinn 1978: the surface raised along
    its normal by the height ``F``, :func:`height_gradient`)::

        n' = normalize(n + σ·(F_u·(n × P_v) + F_v·(P_u × n)) / |P_u × P_v|)

    n the pixel's unit normal (``normals`` (k, 3)), P_u and P_v the triangle's tangent frame
    (:func:`tangent_frames`), ``σ = sign(n · (P_u × P_v))`` (so the height raises the surface
    along n whichever way the (u, v) turn). A plane ``P = (L·u, L·v, 0)`` with ``F = k·u`` tilts
    n = (0, 0, 1) to ``(-k/L, 0, 1)`` normalised: the normal of the surface ``z = k·x/L``. A pixel
    on a triangle without a frame, or with a zero normal, keeps its normal."""
    n = np.asarray(normals, np.float64)
    uv = pixel_uv(mesh, triangles, barycentrics)
    Fu, Fv = height_gradient(image, tmap, uv)
    Pu, Pv, ok = tangent_frames(mesh, triangles)
    cross = np.cross(Pu, Pv)
    area = np.linalg.norm(cross, axis=1)
    ok &= area > tol.BUMP_FRAME_EPS
    sigma = np.where(np.einsum("ij,ij->i", n, cross) < 0.0, -1.0, 1.0)
    scale = (sigma / np.where(ok, area, 1.0))[:, None]
    tilted = n + scale * (Fu[:, None] * np.cross(n, Pv) + Fv[:, None] * np.cross(Pu, n))
    length = np.linalg.norm(tilted, axis=1)
    keep = ~ok | (length <= tol.NORMAL_EPS) | (np.linalg.norm(n, axis=1) <= tol.NORMAL_EPS)
    out = tilted / np.where(keep, 1.0, length)[:, None]
    out[keep] = n[keep]
    return out


def compose_maps(material, aconst, sums, rows, factors, *, clamp: bool) -> np.ndarray:
    """(r, 3) float64 colours of the shader rows ``rows`` (r,) from the kept ``sums``
    (:func:`~explorer.shading.shader.kept_sums`: ``aconst`` (3,) added to the ambient sum;
    ``specular`` (and ``specular_f90``) already at each pixel's own exponent when ``sums`` is
    given per row: see :meth:`PixelMaps.colors`) and per-pixel ``factors``: key of
    :data:`COLOUR_MAPS` -> (r, 3), ``specular_map`` -> (r,); an absent key is 1. Summed in
    ``compose_terms``' order; clamped to [0, 1] when ``clamp``."""
    m = material

    def term(name):
        x = sums[name]
        return np.asarray(x if rows is None else x[rows], np.float64)

    def scaled(value, key):
        f = factors.get(key)
        return value if f is None else value * f

    ambient = term("ambient") + np.asarray(aconst, np.float64)
    c = scaled(np.broadcast_to(np.asarray(m.emission, np.float64), ambient.shape), "emission_map")
    c = c + scaled(np.asarray(m.ambient) * ambient, "ambient_map")
    c += scaled(np.asarray(m.diffuse) * term("diffuse"), "diffuse_map")
    ts = factors.get("specular_map")
    ts = None if ts is None else np.asarray(ts, np.float64)[:, None]
    specular = np.asarray(m.specular) * term("specular")
    c += specular if ts is None else specular * ts
    if "specular_f90" in sums:
        f90 = term("specular_f90")
        c += f90 if ts is None else f90 * ts
    if clamp:
        np.clip(c, 0.0, 1.0, out=c)
    return c


class PixelMaps:
    """The maps at the pixels of one G-buffer, kept while its hits last, and the images read
    (kept by file while its size and time are the same: a changed file is read again).

    A :class:`~explorer.render.live.LivePixels` holds one: :meth:`normals` gives the normals the
    shader shades (bumped), :meth:`colors` the colours composed from the shader's sums."""

    def __init__(self):
        self._images: dict[str, tuple[tuple, np.ndarray]] = {}
        self._hits = None  # the hits the values below are of
        self._values: dict = {}

    def image(self, key: str, tmap: TextureMap) -> np.ndarray:
        """The map's image (:func:`~explorer.render.textures.read_texture`: a bad file raises
        its one line), read again only when the file changed."""
        stamp = file_stamp(tmap.file)
        kept = self._images.get(tmap.file)
        if kept is not None and stamp is not None and kept[0] == stamp:
            return kept[1]
        image = read_texture(tmap, key)
        if len(self._images) >= _KEPT_IMAGES:
            self._images.pop(next(iter(self._images)))
        self._images[tmap.file] = (stamp, image)
        return image

    def _kept(self, hits, what, make):
        if self._hits is not hits:
            self._hits, self._values = hits, {}
        if what not in self._values:
            self._values[what] = make()
        return self._values[what]

    def uv(self, hits, mesh) -> np.ndarray:
        """(k, 2) the mesh's (u, v) at every hit (:func:`pixel_uv`)."""
        return self._kept(hits, "uv", lambda: pixel_uv(mesh, hits.triangles, hits.barycentrics))

    def factor(self, hits, mesh, key: str, tmap: TextureMap) -> np.ndarray:
        """The map's values at every hit: (k, 3) for a colour map, (k,) for a scalar one."""

        def make():
            uv, image = self.uv(hits, mesh), self.image(key, tmap)
            if key in COLOUR_MAPS:
                return colour_texels(image, tmap, uv)
            return scalar_texels(image, tmap, uv)

        return self._kept(hits, (key, tmap), make)

    def normals(self, hits, mesh, parts) -> np.ndarray:
        """The hits' normals with each part's bump map applied (``hits.normals`` itself when no
        part has one; the same array while the hits and bump maps are the same).
        parts : [(rows (r,) int64 of the hits, material)]"""
        bumps = tuple(m.bump_map for _, m in parts)
        if all(b is None for b in bumps):
            return hits.normals

        def make():
            out = np.array(hits.normals, np.float64)
            for (rows, _), tmap in zip(parts, bumps, strict=True):
                if tmap is not None and len(rows):
                    image = self.image("bump_map", tmap)
                    out[rows] = bumped_normals(
                        mesh, hits.triangles[rows], hits.barycentrics[rows], out[rows], image, tmap
                    )
            return out

        return self._kept(hits, ("normals", bumps), make)

    def colors(self, shader, hits, mesh, parts, first: int) -> np.ndarray:
        """(k, 3) float64 the colours of the hits, each part in its material with its maps
        (:func:`compose_maps`), from ``shader``'s kept sums (its rows: ``first`` + the hits').
        The shader is left with its own scene's material."""
        own = shader.scene.material
        out = np.zeros((len(hits.positions), 3))
        for rows, m in parts:
            if not len(rows):
                continue
            factors = {
                k: self.factor(hits, mesh, k, t)[rows]
                for k, t in m.maps().items()
                if k != "bump_map" and k != "shininess_map"
            }
            shader.set_material(m)
            aconst, sums = kept_sums(shader)
            srows = rows + first
            if m.shininess_map is not None:
                tn = self.factor(hits, mesh, "shininess_map", m.shininess_map)[rows]
                sums, srows = _own_lobes(shader, m, srows, tn, sums), None
            out[rows] = compose_maps(m, aconst, sums, srows, factors, clamp=shader.clamp)
        shader.set_material(own)
        return out


def _own_lobes(shader, material, srows, tn, sums) -> dict:
    """``sums`` at the shader rows ``srows`` (r, 3) float64 each, the specular (and three.js's
    ``specular_f90``) at each row's own exponent ``shininess · tn``: the shader's specular at
    each distinct exponent (after the first, the lobe alone on the compiled tier)."""
    out = {
        k: np.broadcast_to(np.asarray(v[srows], np.float64), (len(srows), 3)).copy()
        for k, v in sums.items()
    }
    exponents = material.shininess * np.asarray(tn, np.float64)
    for n in np.unique(exponents):
        pick = exponents == n
        shader.set_material(material.replace(shininess=float(n)))
        _, at_n = kept_sums(shader)
        for k in ("specular", "specular_f90"):
            if k in at_n:
                out[k][pick] = np.asarray(at_n[k][srows[pick]], np.float64)
    return out
