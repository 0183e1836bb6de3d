"""Meshes: vertex positions, unit vertex normals and triangles, built in or read from a file.

Built-in meshes are centred on the origin and fit the cube [-1, 1]³ (their largest half-extent
is 1), y up, facing the default viewer on +z:

=============  ===============================================  ==============================
name           shape                                            ``resolution`` means
=============  ===============================================  ==============================
``sphere``     UV sphere, radius 1, poles on ±y                 segments around (rings = half)
``icosphere``  subdivided icosahedron, radius 1                 subdivisions (0 = icosahedron)
``torus``      ring radius 0.7, tube radius 0.3, axis z         segments around the ring
``cube``       side 2, vertices split per face (flat normals)   (none)
``plane``      2 × 2 square in the xy plane, normal +z          subdivisions per side
``teapot``     Newell's Utah teapot from his 32 Bézier patches  samples per patch edge
=============  ===============================================  ==============================

Files are read with trimesh (OBJ, STL, PLY, OFF, GLB/GLTF and the rest it knows); scenes are
flattened with their transforms. Normals stored in the file are kept; where a file has none,
vertices at the same position are welded and given smooth area-weighted normals.

Every array of a :class:`Mesh` is read-only.

Texture coordinates (``Mesh.uv``, (n, 2), None for a mesh without them): an OBJ's ``vt``; a
built-in mesh asked for them (``get_mesh(name, uv=True)``) gets its own parametrisation
(:mod:`explorer.geometry.uv`), the vertices on a seam split so each side keeps its (u, v).
"""

from __future__ import annotations

import io
import os
import warnings
from dataclasses import dataclass

import numpy as np

from explorer.core.errors import ExplorerError, Notice
from explorer.core.validate import suggest
from explorer.geometry import teapot_patches as data
from explorer.geometry.frame import check_faces, check_vertices, frame_of
from explorer.geometry.meshfile import (
    drop_unused,
    file_uv,
    material_name,
    part_uv,
    read_mesh_file,
    say_unread_materials,
    triangle_parts,
    used_vertices,
)
from explorer.geometry.sidefiles import CheckedResolver, library_names, obj_material_names
from explorer.geometry.uv import spherical_corners, split_by_uv, wrapped_corners

#: resolution option of each built-in mesh: (default, lowest, highest); None = no option
RESOLUTION: dict[str, tuple[int, int, int] | None] = {
    "sphere": (64, 3, 1024),
    "icosphere": (4, 0, 7),
    "torus": (64, 3, 1024),
    "cube": None,
    "plane": (32, 1, 1024),
    "teapot": (12, 1, 64),
}
#: names accepted by :func:`get_mesh` besides file paths
BUILTIN_MESHES: tuple[str, ...] = tuple(RESOLUTION)
#: default mesh of a scene without one
DEFAULT_MESH = "sphere"

#: mesh sizes (largest half-extent) whose normals are computed where the mesh is; outside, the
#: squared coordinates in a cross product could overflow or underflow
NORMALS_IN_PLACE = (1e-100, 1e100)
#: file suffixes :func:`load_mesh` is meant for (trimesh may read more)
MESH_SUFFIXES = (".obj", ".stl", ".ply", ".off", ".glb", ".gltf")


@dataclass(frozen=True, eq=False)
class Mesh:
    """A triangle mesh with per-vertex normals.

    positions : (n, 3) float64
    normals : (n, 3) float64, unit length (zero only for a file vertex that lies in degenerate
        triangles alone, where no normal exists; the engine gives such a vertex no diffuse or
        specular light)
    faces : (m, 3) int64 indices into positions, counter-clockwise seen from outside
    name : the built-in name or the file name
    groups : the file's material groups (an OBJ's ``usemtl``), or None
    uv : (n, 2) float64 texture coordinates (an OBJ's ``vt``, a built-in's own), or None: the
        mesh has none and cannot wear a texture
    """

    positions: np.ndarray
    normals: np.ndarray
    faces: np.ndarray
    name: str = "mesh"
    groups: MaterialGroups | None = None
    uv: np.ndarray | None = None

    def __post_init__(self):
        # the engine's checks (shapes, real finite numbers, index ranges), then read-only
        # float64 / int64 copies; a mesh needs a vertex (bounds and radius of nothing are not
        # defined)
        p, n = check_vertices(self.positions, self.normals)
        if len(p) == 0:
            raise ExplorerError(f"mesh '{self.name}': positions must hold at least one vertex")
        f = check_faces(self.faces, len(p))
        if self.groups is not None and len(self.groups.of_vertex) != len(p):
            raise ExplorerError(
                f"mesh '{self.name}': groups.of_vertex must hold one group per vertex "
                f"({len(p)}), got {len(self.groups.of_vertex)}"
            )
        object.__setattr__(self, "positions", _frozen(p, np.float64))
        object.__setattr__(self, "normals", _frozen(n, np.float64))
        object.__setattr__(self, "faces", _frozen(f, np.int64))
        if self.uv is not None:
            uv = np.asarray(self.uv)
            if uv.shape != (len(p), 2) or not np.isfinite(uv).all():
                raise ExplorerError(
                    f"mesh '{self.name}': uv must be ({len(p)}, 2) finite texture coordinates, "
                    f"got shape {uv.shape}"
                )
            object.__setattr__(self, "uv", _frozen(uv, np.float64))

    @property
    def n_vertices(self) -> int:
        return len(self.positions)

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    @property
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lowest and highest corner of the bounding box, each (3,) float64."""
        return self.positions.min(axis=0), self.positions.max(axis=0)

    @property
    def centre(self) -> np.ndarray:
        """(3,) float64 centre of the bounding box."""
        lo, hi = self.bounds
        return 0.5 * lo + 0.5 * hi

    @property
    def radius(self) -> float:
        """Radius of the smallest sphere about :attr:`centre` holding every vertex (in the
        normalised frame: no overflow near 1e308, no underflow at 1e-300)."""
        centre, scale = frame_of(self.positions)
        d = self.positions / scale - centre / scale
        return float(np.sqrt(np.max(np.einsum("ij,ij->i", d, d)))) * scale

    def face_normals(self) -> np.ndarray:
        """(m, 3) float64 unit normals of the triangles (zero for degenerate ones)."""
        return _unit_rows(_face_cross(self.positions, self.faces))


@dataclass(frozen=True, eq=False)
class MaterialGroups:
    """Which material each vertex of a mesh file has: an OBJ's ``usemtl`` groups. A vertex is
    in one group only: where two groups meet, the file's vertices are split (each side keeps
    its own copy), so each side keeps its colour.

    names : the ``usemtl`` names, in the order first met
    of_vertex : (n,) int32 index into ``names`` of each vertex, read-only
    libraries : the ``mtllib`` files the OBJ names, as paths next to it
    used : every name the OBJ's ``usemtl`` lines give (faces whose material no library
        defines are in the group named ``""``)
    """

    names: tuple[str, ...]
    of_vertex: np.ndarray
    libraries: tuple[str, ...] = ()
    used: tuple[str, ...] = ()

    def __post_init__(self):
        keys = np.array(self.of_vertex, dtype=np.int32, copy=True)
        if keys.ndim != 1 or (len(keys) and not 0 <= keys.min() <= keys.max() < len(self.names)):
            raise ExplorerError(
                f"of_vertex must be (n,) indices into the {len(self.names)} group names"
            )
        keys.flags.writeable = False
        object.__setattr__(self, "of_vertex", keys)

    def vertices(self, group: int) -> np.ndarray:
        """(k,) int64 indices of the vertices of ``group``."""
        return np.flatnonzero(self.of_vertex == group)


def _frozen(a: np.ndarray, dtype) -> np.ndarray:
    """A read-only C-contiguous copy of a checked (n, 3) (or (n, 2)) array."""
    arr = np.array(a, dtype=dtype, copy=True, order="C")
    arr.flags.writeable = False
    return arr


# -- helpers -------------------------------------------------------------------------------


def _face_cross(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(m, 3) cross products (b - a) × (c - a); length is twice the triangle's area."""
    a, b, c = (positions[faces[:, k]] for k in range(3))
    return np.cross(b - a, c - a)


def has_area(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(m,) bool: which triangles have a non-zero area, decided at any scale.

    positions : (n, 3) finite float; faces : (m, 3) int
    The cross products are taken in the normalised frame (:func:`frame_of`: coordinates in
    [-1, 1]), so they neither overflow to inf or NaN for coordinates near 1e308 nor underflow
    to zero for a mesh of size 1e-300."""
    centre, scale = frame_of(positions)
    p = (np.asarray(positions, np.float64) - centre) / scale
    return np.linalg.norm(_face_cross(p, faces), axis=1) > 0


def _unit_rows(v: np.ndarray) -> np.ndarray:
    """Rows scaled to unit length; zero rows stay zero."""
    length = np.linalg.norm(v, axis=1, keepdims=True)
    return np.divide(v, length, out=np.zeros_like(v), where=length > 0)


def area_weighted_normals(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Smooth vertex normals: the sum of the adjacent faces' normals weighted by their areas.

    positions : (n, 3) float; faces : (m, 3) int
    Returns (n, 3) float64, unit length, zero where a vertex has no face of non-zero area.
    """
    positions = np.asarray(positions, np.float64)
    faces = np.asarray(faces, np.int64).reshape(-1, 3)
    acc = np.zeros((len(positions), 3))
    centre, scale = frame_of(positions)
    if not NORMALS_IN_PLACE[0] < scale < NORMALS_IN_PLACE[1]:
        # cross products of coordinates near 1e308 overflow, near 1e-300 underflow: take them
        # in the normalised frame (same directions, same relative areas)
        positions = (positions - centre) / scale
    cross = _face_cross(positions, faces)  # |cross| = 2·area, direction = face normal
    for k in range(3):
        np.add.at(acc, faces[:, k], cross)
    return _unit_rows(acc)


def _weld(
    positions, normals, faces, keys=None, decimals: int = 9, *, sources: bool = False, kept=None
):
    """Merge vertices at the same position (and the same key); average their normals; drop
    triangles that become degenerate. keys : (n,) int group of each vertex or None.
    sources : also return (k,) the index of a source vertex of each new vertex.
    kept : a list that receives the (m,) bool mask of the triangles kept."""
    q = np.round(positions, decimals)
    q[q == 0] = 0.0  # -0.0 and 0.0 are the same place
    table = q if keys is None else np.column_stack([q, keys])
    _, first, inverse = np.unique(table, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.ravel()
    order = np.argsort(first)  # keep the first-seen order of vertices
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    remap = rank[inverse]
    new_p = positions[first[order]]
    acc = np.zeros((len(order), 3))
    np.add.at(acc, remap, normals)
    new_f = remap[faces]
    keep = (
        (new_f[:, 0] != new_f[:, 1]) & (new_f[:, 1] != new_f[:, 2]) & (new_f[:, 0] != new_f[:, 2])
    )
    if kept is not None:
        kept.append(keep)
    if sources:
        return new_p, _unit_rows(acc), new_f[keep], first[order]
    return new_p, _unit_rows(acc), new_f[keep]


def _with_uv(mesh: Mesh, corner_uv: np.ndarray) -> Mesh:
    """``mesh`` with its vertices split by ``corner_uv`` (:func:`split_by_uv`), wearing them."""
    src, faces, uv = split_by_uv(mesh.faces, corner_uv)
    return Mesh(mesh.positions[src], mesh.normals[src], faces, mesh.name, uv=uv)


def _spherical_uv(mesh: Mesh) -> Mesh:
    """The sphere's and icosphere's (u, v) (:func:`explorer.geometry.uv.spherical_corners`)."""
    return _with_uv(mesh, spherical_corners(mesh.positions, mesh.faces))


def _grid_faces(rows: int, cols: int, wrap_cols: bool = False, offset: int = 0) -> np.ndarray:
    """Two triangles per cell of a rows × cols vertex grid (index = r * cols + c), wound
    counter-clockwise about (d/dr) × (d/dc)."""
    c_max = cols if wrap_cols else cols - 1
    r, c = np.meshgrid(np.arange(rows - 1), np.arange(c_max), indexing="ij")
    r, c = r.ravel(), c.ravel()
    c1 = (c + 1) % cols
    a = r * cols + c
    b = (r + 1) * cols + c
    d = (r + 1) * cols + c1
    e = r * cols + c1
    tris = np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, e], 1)])
    return tris + offset


def _check_resolution(name: str, value) -> int:
    spec = RESOLUTION[name]
    assert spec is not None
    default, lo, hi = spec
    if value is None:
        return default
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise ExplorerError(
                f"mesh '{name}': resolution must be a whole number in [{lo}, {hi}], got {value!r}"
            )
    if not lo <= value <= hi:
        raise ExplorerError(f"mesh '{name}': resolution must be in [{lo}, {hi}], got {value}")
    return int(value)


# -- built-in meshes -----------------------------------------------------------------------


def sphere(resolution: int | None = None, *, uv: bool = False) -> Mesh:
    """UV sphere of radius 1 centred on the origin, poles on ±y.

    resolution : segments around the y axis (default 64); there are resolution // 2 bands
    (at least 2) from pole to pole, one vertex at each pole, no seam (watertight).
    uv : give it texture coordinates (its seam split; see the module docstring)
    """
    seg = _check_resolution("sphere", resolution)
    bands = max(2, seg // 2)
    theta = np.pi * np.arange(1, bands) / bands  # polar angle from +y, poles excluded
    phi = 2.0 * np.pi * np.arange(seg) / seg
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    ring = np.stack([np.sin(th) * np.sin(ph), np.cos(th), np.sin(th) * np.cos(ph)], -1)
    ring = ring.reshape(-1, 3)
    top, bottom = len(ring), len(ring) + 1
    pos = np.vstack([ring, [[0.0, 1.0, 0.0], [0.0, -1.0, 0.0]]])
    # rows run down from the top (d/dr ~ -y), columns eastward (d/dc ~ +φ): -y × φ̂ points out
    body = _grid_faces(bands - 1, seg, wrap_cols=True)
    j = np.arange(seg)
    j1 = (j + 1) % seg
    last = (bands - 2) * seg
    caps = np.concatenate(
        [
            np.stack([np.full(seg, top), j, j1], 1),
            np.stack([np.full(seg, bottom), last + j1, last + j], 1),
        ]
    )
    faces = np.concatenate([body, caps])
    mesh = Mesh(pos, pos.copy(), _outward(pos, faces), "sphere")
    return _spherical_uv(mesh) if uv else mesh


def _outward(pos, faces):
    """Wind every triangle of a star-shaped (about the origin) mesh so its normal points out."""
    cross = _face_cross(pos, faces)
    centroid = pos[faces].mean(axis=1)
    flip = np.einsum("ij,ij->i", cross, centroid) < 0
    faces = faces.copy()
    faces[flip] = faces[flip][:, ::-1]
    return faces


_PHI = (1.0 + 5.0**0.5) / 2.0
_ICO_VERTICES = np.array(
    [
        [-1, _PHI, 0], [1, _PHI, 0], [-1, -_PHI, 0], [1, -_PHI, 0],
        [0, -1, _PHI], [0, 1, _PHI], [0, -1, -_PHI], [0, 1, -_PHI],
        [_PHI, 0, -1], [_PHI, 0, 1], [-_PHI, 0, -1], [-_PHI, 0, 1],
    ],
    dtype=np.float64,
)  # fmt: skip
_ICO_FACES = np.array(
    [
        [0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11],
        [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
        [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9],
        [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1],
    ],
    dtype=np.int64,
)  # fmt: skip


def icosphere(subdivisions: int | None = None, *, uv: bool = False) -> Mesh:
    """Subdivided icosahedron of radius 1: 10·4^k + 2 vertices, 20·4^k triangles.

    subdivisions : k, how often each triangle is split in four (default 4)
    uv : give it the sphere's texture coordinates (see the module docstring)
    """
    k = _check_resolution("icosphere", subdivisions)
    pos = _ICO_VERTICES / np.linalg.norm(_ICO_VERTICES, axis=1, keepdims=True)
    faces = _ICO_FACES
    for _ in range(k):
        edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
        edges.sort(axis=1)
        unique, inverse = np.unique(edges, axis=0, return_inverse=True)
        inverse = inverse.ravel()
        mid = pos[unique[:, 0]] + pos[unique[:, 1]]
        mid /= np.linalg.norm(mid, axis=1, keepdims=True)
        m = len(faces)
        ab, bc, ca = (inverse[i * m : (i + 1) * m] + len(pos) for i in range(3))
        a, b, c = faces[:, 0], faces[:, 1], faces[:, 2]
        faces = np.concatenate(
            [np.stack(t, 1) for t in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))]
        )
        pos = np.vstack([pos, mid])
    mesh = Mesh(pos, pos.copy(), _outward(pos, faces), "icosphere")
    return _spherical_uv(mesh) if uv else mesh


def torus(
    resolution: int | None = None, major: float = 0.7, minor: float = 0.3, *, uv: bool = False
) -> Mesh:
    """Torus about the z axis (its hole faces the default viewer), centred on the origin.

    resolution : segments around the ring (default 64); the tube gets resolution // 2 (>= 3)
    major, minor : ring and tube radii (defaults 0.7 and 0.3: the torus fits [-1, 1]³)
    uv : give it texture coordinates (its seams split; see the module docstring)
    """
    seg = _check_resolution("torus", resolution)
    if not (0 < minor < major):
        raise ExplorerError(f"torus radii must satisfy 0 < minor < major, got {minor}, {major}")
    tube = max(3, seg // 2)
    u = 2.0 * np.pi * np.arange(seg) / seg  # around the ring
    v = 2.0 * np.pi * np.arange(tube) / tube  # around the tube
    uu, vv = np.meshgrid(u, v, indexing="ij")
    normals = np.stack([np.cos(vv) * np.cos(uu), np.cos(vv) * np.sin(uu), np.sin(vv)], -1)
    centre = np.stack([major * np.cos(uu), major * np.sin(uu), np.zeros_like(uu)], -1)
    pos = (centre + minor * normals).reshape(-1, 3)
    normals = normals.reshape(-1, 3)
    # rows follow u (ring), columns v (tube); wrap both ways
    faces = _grid_faces(seg + 1, tube, wrap_cols=True)
    faces = faces % (seg * tube)
    # d/du × d/dv points outward from the tube for this parametrisation
    mesh = Mesh(pos, normals, faces, "torus")
    if not uv:
        return mesh
    tex = np.column_stack([(uu / (2.0 * np.pi)).ravel(), (vv / (2.0 * np.pi)).ravel()])
    return _with_uv(mesh, wrapped_corners(tex, faces, wrap=(True, True)))


def cube(*, uv: bool = False) -> Mesh:
    """Cube of side 2 centred on the origin: 24 vertices (4 per face, so each face keeps its
    own flat normal) and 12 triangles. uv : each face the whole [0, 1]² square."""
    pos, nrm, faces, tex = [], [], [], []
    for axis in range(3):
        for sign in (1.0, -1.0):
            n = np.zeros(3)
            n[axis] = sign
            u = np.zeros(3)
            u[(axis + 1) % 3] = 1.0
            v = np.cross(n, u)  # (u, v, n) right-handed: u × v = n
            base = len(pos)
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                pos.append(n + a * u + b * v)
                nrm.append(n)
                tex.append(((a + 1) / 2.0, (b + 1) / 2.0))
            faces += [[base, base + 1, base + 2], [base, base + 2, base + 3]]
    return Mesh(np.array(pos), np.array(nrm), np.array(faces), "cube", uv=tex if uv else None)


def plane(resolution: int | None = None, *, uv: bool = False) -> Mesh:
    """Square [-1, 1]² in the xy plane (z = 0) with normal +z, facing the default viewer.

    resolution : subdivisions per side (default 32): (resolution + 1)² vertices. Per-vertex
    lighting needs them for a point or spot light's pool of light to show.
    uv : texture coordinates ((x + 1) / 2, (y + 1) / 2)
    """
    k = _check_resolution("plane", resolution)
    t = np.linspace(-1.0, 1.0, k + 1)
    yy, xx = np.meshgrid(t, t, indexing="ij")
    pos = np.stack([xx, yy, np.zeros_like(xx)], -1).reshape(-1, 3)
    normals = np.tile([0.0, 0.0, 1.0], (len(pos), 1))
    # rows go +y, columns +x: (+y) × (+x) = -z, so wind the other way
    faces = _grid_faces(k + 1, k + 1)[:, ::-1]
    tex = 0.5 * (pos[:, :2] + 1.0) if uv else None
    return Mesh(pos, normals, faces, "plane", uv=tex)


def _bernstein(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cubic Bernstein basis and its derivative at t : (s,); each (s, 4)."""
    s = 1.0 - t
    b = np.stack([s**3, 3 * t * s**2, 3 * t**2 * s, t**3], -1)
    db = np.stack([-3 * s**2, 3 * s**2 - 6 * t * s, 6 * t * s - 3 * t**2, 3 * t**2], -1)
    return b, db


def _patch_points(ctrl: np.ndarray, u: np.ndarray, v: np.ndarray):
    """Positions and (du × dv) on the grid u × v of bicubic patches.

    ctrl : (p, 4, 4, 3); u, v : (s,) parameters. Returns two (p, s, s, 3) arrays."""
    bu, dbu = _bernstein(u)
    bv, dbv = _bernstein(v)
    pos = np.einsum("ai,bj,pijk->pabk", bu, bv, ctrl)
    du = np.einsum("ai,bj,pijk->pabk", dbu, bv, ctrl)
    dv = np.einsum("ai,bj,pijk->pabk", bu, dbv, ctrl)
    return pos, np.cross(du, dv)


#: Newell's patches are wound so that du × dv points into the teapot; their normal is -(du × dv)
_TEAPOT_SIGN = -1.0


def teapot(tessellation: int | None = None, *, uv: bool = False) -> Mesh:
    """The Utah teapot from Newell's 32 bicubic Bézier patches.

    tessellation : samples per patch edge (default 12): each patch becomes a
    (tessellation + 1)² grid. Seams between patches of the same part (body, lid, handle,
    spout) are welded and their normals averaged; at the lid's and the bottom's pole, where a
    whole row of control points meets in one point and a patch derivative vanishes, the normal
    is the limit taken just inside the patch. Spout and handle are separate open parts pushed
    into the body, as in the original, so the teapot is not watertight.

    The model is turned y up (spout toward +x, lid toward +y) and fitted to [-1, 1]³.
    uv : each patch's own (u, v) as texture coordinates (the welded vertices split again where
    patches meet with different (u, v); see the module docstring)
    """

    t = _check_resolution("teapot", tessellation)
    cp = np.array(data.vertices(), dtype=np.float64)
    idx = np.array(data.patches(), dtype=np.int64)
    ctrl = cp[idx].reshape(-1, 4, 4, 3)
    s = np.linspace(0.0, 1.0, t + 1)
    pos, nrm = _patch_points(ctrl, s, s)
    nrm = _TEAPOT_SIGN * nrm
    # degenerate normals (a derivative vanishes at a pole): take the normal a little inside
    length = np.linalg.norm(nrm, axis=-1)
    bad = np.argwhere(length < 1e-9)
    if len(bad):
        eps = 1e-4
        for p, a, b in bad:
            ua = np.array([min(max(s[a], eps), 1 - eps)])
            vb = np.array([min(max(s[b], eps), 1 - eps)])
            _, n = _patch_points(ctrl[p : p + 1], ua, vb)
            nrm[p, a, b] = _TEAPOT_SIGN * n[0, 0, 0]
    nrm = nrm / np.linalg.norm(nrm, axis=-1, keepdims=True)
    n_patch = len(ctrl)
    per = (t + 1) ** 2
    faces = np.concatenate([_grid_faces(t + 1, t + 1, offset=p * per) for p in range(n_patch)])
    if _TEAPOT_SIGN < 0:
        faces = faces[:, ::-1]
    group_of = np.zeros(n_patch, np.int64)
    names = []
    for name, rows in data.GROUPS:
        if name not in names:
            names.append(name)
        group_of[list(rows)] = names.index(name)
    keys = np.repeat(group_of, per)
    su, sv = np.meshgrid(s, s, indexing="ij")
    patch_uv = np.tile(np.column_stack([su.ravel(), sv.ravel()]), (n_patch, 1))
    corner_uv = patch_uv[faces]
    kept: list = []
    pos, nrm, faces = _weld(pos.reshape(-1, 3), nrm.reshape(-1, 3), faces, keys, kept=kept)
    tex = None
    if uv:
        src, faces, tex = split_by_uv(faces, corner_uv[kept[0]])
        pos, nrm = pos[src], nrm[src]
    # Newell's z up -> y up: (x, y, z) -> (x, z, -y), a proper rotation (keeps winding)
    rot = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    pos = pos @ rot.T
    nrm = nrm @ rot.T
    lo, hi = pos.min(axis=0), pos.max(axis=0)
    pos = (pos - 0.5 * (lo + hi)) / float(np.max(0.5 * (hi - lo)))
    return Mesh(pos, nrm, faces, "teapot", uv=tex)


_BUILDERS = {
    "sphere": sphere,
    "icosphere": icosphere,
    "torus": torus,
    "cube": lambda resolution=None, uv=False: cube(uv=uv),
    "plane": plane,
    "teapot": teapot,
}


# -- files ---------------------------------------------------------------------------------


def load_mesh(path) -> Mesh:
    """Read a triangle mesh with trimesh (OBJ, STL, PLY, OFF, GLB, ...).

    Scenes (GLB, multi-object OBJ) are flattened with their node transforms. Faces with more
    than three corners are triangulated by trimesh. Vertex normals in the file are kept
    (renormalised); a file without them gets vertices welded by position and smooth
    area-weighted normals. Vertices no triangle uses are dropped.

    The file is read once (:func:`read_mesh_file`) and trimesh parses those bytes; every
    other file trimesh would open (an OBJ's ``mtllib``, a glTF's buffers) is served by
    :class:`CheckedResolver`, so no library opens a file the checked open has not. An OBJ's
    ``mtllib`` libraries are resolved by :func:`obj_material_names` (inside the OBJ's folder,
    ``.mtl`` names only; the others are named in a :class:`Notice` and not opened).

    A missing, unreadable or empty file, one that is too large or unpacks to too much, or one
    holding no triangles (a point cloud, a drawing), raises an :class:`ExplorerError` naming
    the file and the reason.
    """
    path = os.fspath(path)
    shown = path
    data = read_mesh_file(path)
    import logging

    import trimesh

    logging.getLogger("trimesh").setLevel(logging.ERROR)
    ext = os.path.splitext(path)[1].lower() or "(no suffix)"
    libraries, used_names = (), ()
    if ext == ".obj":
        libraries, used_names, refused = obj_material_names(path, data)
        for message in refused:
            warnings.warn(message, Notice, stacklevel=2)
    file_type = trimesh.util.split_extension(path, special=["tar.gz", "tar.bz2"]).lower()
    resolver = CheckedResolver(path, library_names(libraries) if ext == ".obj" else None)
    try:
        loaded = trimesh.load(
            io.BytesIO(data), file_type=file_type, resolver=resolver, process=False
        )
    except OSError as exc:
        raise ExplorerError(f"mesh file '{shown}' cannot be read: {exc.strerror or exc}") from exc
    except Exception as exc:  # noqa: BLE001 - every parser failure is the file's fault
        if isinstance(exc, NotImplementedError) or "not supported" in str(exc):
            raise ExplorerError(
                f"mesh file '{shown}': unsupported format {ext}; use one of "
                f"{', '.join(MESH_SUFFIXES)}"
            ) from exc
        raise ExplorerError(
            f"mesh file '{shown}' is not a valid {ext} file or is damaged "
            f"({type(exc).__name__}: {exc})"
        ) from exc
    parts = triangle_parts(loaded)
    if not parts:
        kind = type(loaded).__name__
        what = {"PointCloud": "points only", "Path2D": "lines only", "Path3D": "lines only"}
        reason = what.get(kind, f"no triangles (is it a valid {ext} file?)")
        raise ExplorerError(
            f"mesh file '{shown}' holds {reason}: a mesh needs triangles (or polygons)"
        )
    say_unread_materials(shown, parts, ext == ".obj")
    group_names: list[str] = []
    keys = []
    positions, normals, faces, has_normals = [], [], [], True
    base = 0
    for m, matrix in parts:
        name = material_name(m) if libraries else None
        if name is not None and name not in group_names:
            group_names.append(name)
        keys.append(np.full(len(m.vertices), -1 if name is None else group_names.index(name)))
        p = np.asarray(m.vertices, np.float64)
        f = np.asarray(m.faces, np.int64)
        n = None
        if "vertex_normals" in m._cache and len(m._cache["vertex_normals"]) == len(p):
            n = np.asarray(m._cache["vertex_normals"], np.float64)
        if matrix is not None:
            linear = matrix[:3, :3]
            p = p @ linear.T + matrix[:3, 3]
            if n is not None:
                n = n @ np.linalg.inv(linear)  # normals take the inverse transpose
            if np.linalg.det(linear) < 0:  # a mirroring transform turns the winding over
                f = f[:, ::-1]
        positions.append(p)
        faces.append(f + base)
        base += len(p)
        if n is None:
            has_normals = False
            n = np.zeros_like(p)
        normals.append(n)
    pos = np.vstack(positions)
    faces = np.vstack(faces)
    keys = np.concatenate(keys)
    tex = file_uv([part_uv(m) for m, _ in parts], shown)
    if (keys < 0).any() and group_names:  # faces before any usemtl, or an unknown material
        group_names.append("")
        keys[keys < 0] = len(group_names) - 1
    if not np.isfinite(pos).all():
        raise ExplorerError(f"mesh file '{shown}' has vertices that are not finite numbers")
    if has_normals:
        nrm = _unit_rows(np.nan_to_num(np.vstack(normals)))
        missing = np.linalg.norm(nrm, axis=1) == 0
        if missing.any():
            nrm[missing] = area_weighted_normals(pos, faces)[missing]
    else:
        pos, nrm, faces, keys, tex = _welded(pos, faces, keys, tex)
    if not has_area(pos, faces).any():
        raise ExplorerError(f"mesh file '{shown}' holds only degenerate (zero-area) triangles")
    used = used_vertices(pos, faces)
    if tex is not None:
        tex = tex[used]
    pos, nrm, faces = drop_unused(pos, nrm, faces)
    groups = None
    if group_names:  # in the file's order (trimesh's parts come in another)
        rank = [used_names.index(g) if g in used_names else len(used_names) for g in group_names]
        order = np.argsort(rank, kind="stable")
        keys = np.argsort(order)[keys]  # old index -> new index
        group_names = [group_names[i] for i in order]
        groups = MaterialGroups(tuple(group_names), keys[used], libraries, used_names)
    elif libraries:  # no usemtl matched a material trimesh found: one group, named nothing
        groups = MaterialGroups(("",), np.zeros(len(pos), np.int32), libraries, used_names)
    return Mesh(pos, nrm, faces, os.path.basename(path), groups, tex)


# -- lookup --------------------------------------------------------------------------------


def _welded(pos, faces, keys, tex):
    """A file without normals: vertices welded by position (and group) to 12 decimals of the
    mesh's frame (any scale), smooth normals, then split again where their (u, v) differ.
    Returns ``(positions, normals, faces, keys, uv)``."""
    centre, scale = frame_of(pos)
    Q = pos / scale - centre / scale
    corner_uv = None if tex is None else tex[faces]
    kept: list = []
    _, _, faces, src = _weld(Q, np.zeros_like(pos), faces, keys, 12, sources=True, kept=kept)
    pos, keys = pos[src], keys[src]
    nrm = area_weighted_normals(pos, faces)
    if corner_uv is not None:
        src, faces, tex = split_by_uv(faces, corner_uv[kept[0]])
        pos, nrm, keys = pos[src], nrm[src], keys[src]
    return pos, nrm, faces, keys, tex


def get_mesh(spec, resolution: int | None = None, *, uv: bool = False) -> Mesh:
    """A built-in mesh by name (with its ``resolution`` option, see :data:`RESOLUTION`) or a
    mesh file by path. ``resolution`` is ignored by ``cube`` and by files. ``uv``: a built-in
    mesh with its texture coordinates (a file has the ones it holds, or none).

    An unknown name that does not look like a path raises an :class:`ExplorerError` with a
    did-you-mean and the list of built-in names.
    """
    if isinstance(spec, Mesh):
        return spec
    if spec is None:
        spec = DEFAULT_MESH
    if not isinstance(spec, (str, os.PathLike)):
        raise ExplorerError(f"a mesh must be a built-in name or a file path, got {spec!r}")
    text = os.fspath(spec)
    if text in _BUILDERS:
        return _BUILDERS[text](resolution, uv=uv)
    if _looks_like_file(text):
        return load_mesh(os.path.expanduser(text))

    raise ExplorerError(
        f"unknown mesh '{text}'{suggest(text, BUILTIN_MESHES)}; built-in meshes: "
        f"{', '.join(BUILTIN_MESHES)}, or a mesh file ({', '.join(MESH_SUFFIXES)})"
    )


def _looks_like_file(text: str) -> bool:
    return os.path.exists(text) or "/" in text or os.sep in text or "." in os.path.basename(text)
