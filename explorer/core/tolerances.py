"""Every epsilon and tolerance the project uses, in one place, each with its reason.

Engine epsilons are applied to *normalised* coordinates: before shading, the engine moves the
scene so the mesh's bounding-box centre is the origin and divides by its largest half-extent
(see :func:`explorer.geometry.frame.frame_of`), so "small" below means small relative to the mesh.
"""

from __future__ import annotations

# --- engine policies (float64 and float32 paths alike) -------------------------------------

#: A normal shorter than this is treated as absent: the vertex gets emission and ambient only
#: (no diffuse, no specular). Unit-length normals are 1; mesh writers emit 0 for "unknown".
#: The kernels test the normals after :data:`NORMAL_RANGE` scaling, so in practice only an
#: all-zero normal is absent: a normal of length 1e-20 is a valid direction.
NORMAL_EPS = 1e-12

#: Before shading, a vertex normal whose largest component |c| lies outside this range is scaled
#: by an exact power of two (:func:`explorer.geometry.frame.scale_normals`; directions unchanged,
#: bit for bit) to bring |c| into [0.5, 1). Inside it, the squared length (at least 1e-12, at most
#: 3e12) is far from float32's underflow (1e-38) and overflow (3e38) and far above NORMAL_EPS²,
#: so any finite non-zero normal (1e-300 or 1e300 long) shades as its direction. Normals already
#: in range (unit ones) are passed on unchanged, without a copy.
NORMAL_RANGE = (1e-6, 1e6)

#: A light (or the eye) closer to a vertex than this (in normalised units) is "at" the vertex:
#: the direction to it is undefined, so the engine uses the vertex normal (fully facing).
#: Its distance is 0 too, so a light at a vertex is attenuated by 1 / max(kc, floor) on both
#: tiers. (The true distance there is the rounding of the frame, about 1e-16, and differs
#: between the numpy tier, which divides by the scale, and the kernels, which multiply by its
#: reciprocal: times a coefficient of 1e30 that noise made the weight 1e-14 on one tier and 1e6
#: on the other, a light on a vertex lighting it fully or not at all.)
POINT_EPS = 1e-12

#: Blinn's halfway vector H = normalize(L + V) is undefined when L = -V. Below this squared
#: length of L + V the engine takes N·H = 0 (no highlight; with shininess 0, 0**0 = 1 applies).
HALFWAY_EPS2 = 1e-24

#: A specular lobe base (R·V or N·H) below this is 0 on both tiers: the square root of float64's
#: smallest normal number. The float64 kernels raise base² to n/2, and a smaller base's square
#: is subnormal (imprecise) or 0, which left a base of 1e-200 with shininess 0.001 dark where
#: the numpy tier gave 0.63. Such a base is rounding noise (dot products of unit vectors are
#: exact to about 1e-16; float32 and OpenGL hold it as 0 anyway), and it matters only for a
#: shininess far below 1 (for n >= 1, base**n < 1e-154).
LOBE_BASE_MIN = 1.4916681462400413e-154

#: Floor of the attenuation denominator kc + kl·d + kq·d². All-zero attenuation is rejected when
#: a scene is loaded; with kc = 0 a light exactly at a vertex would divide by zero, so the
#: attenuation factor is capped at 1 / ATTENUATION_FLOOR (and colours stay finite).
ATTENUATION_FLOOR = 1e-6
#: The same floor applies to a constant attenuation folded into the colours: 1/max(kc, floor).
#: So the factor never exceeds 1e6, never becomes inf (1/1e-320 would) or NaN (inf·0 with a
#: zero colour channel), and stays finite in float32 (1/1e-39 would not).

#: The attenuation coefficients the kernels receive, kc, kl·s and kq·s² (s the frame's scale),
#: are each capped at this: kq·s² overflows for a huge mesh (and so would inf·0 for a light on
#: a vertex), and float32 holds only up to 3.4e38. A capped coefficient still gives a weight of
#: at most 1/ATTENUATION_CAP wherever it matters (1e-30; colours are at most 1e6 per light), and
#: the weight stays monotone in the distance and in each coefficient.
ATTENUATION_CAP = 1e30

#: Far-light policy. A positional light farther than this from the mesh's centre (in normalised
#: units, i.e. mesh half-extents) is shaded as a directional light toward it: the engine and the
#: reference put it at exactly this distance along its direction, with the constant attenuation
#: 1 / max(kc + kl·D + kq·D², floor) at its true distance D (the denominator evaluated from the
#: frame-unit coefficients with 0·inf taken as 0, capped at ATTENUATION_CAP; D may be inf).
#: Beyond 1e12 the direction varies across the mesh by less than 2e-12 (below every colour
#: tolerance), while d² stays far from overflow in float32 (1e24) and float64: without it, a
#: light at 4e154 (float64) or 1e19 (float32) gave d² = inf and NaN colours, and one at 1e200
#: lit nothing.
FAR_LIGHT = 1e12

#: Far-viewer policy, as :data:`FAR_LIGHT` for lights: an eye farther than this from the mesh's
#: centre (normalised units) is put at exactly this distance along its direction
#: (:meth:`explorer.core.scene.Viewer.framed`), on both tiers. V then varies across the mesh by
#: less than 2e-12 from the true directions. Without it an eye at 1e8 seen from a mesh of size
#: 1e-300 was at 1e308 in the frame: inf in float32 (wrong highlights, 0.9 off the numpy tier),
#: and in float64 eye - P of infinite length, V taken as 0 (0.5 off the far viewer it is).
FAR_VIEWER = FAR_LIGHT

#: The smallest specular exponent the kernels receive for a positive shininess: twice the
#: smallest subnormal number of the pass's precision (float64 1e-323, float32 2.8e-45). The
#: float64 kernels raise base² to n/2, and half of 5e-324 rounds to 0 (and float32 holds no
#: 5e-324 at all): 0**0 = 1 then lit a vertex whose lobe base is 0 (R·V <= 0), where OpenGL's
#: 0**n = 0 for n > 0 leaves it dark. Any exponent this small gives base**n = 1 for base > 0
#: and 0 for base 0, as the given one does (:func:`explorer.shading.shader.kernel_shininess`).
MIN_KERNEL_SHININESS = {"float64": 2 * 5e-324, "float32": 2 * 1.401298464324817e-45}

#: Smallest scale of the normalised frame (explorer.geometry.frame.frame_of): float64's smallest
#: normal number. A mesh whose extent is subnormal (below 2.2e-308) would otherwise get a scale
#: whose reciprocal overflows to inf (the float64 redo of ambiguous lanes multiplies by it: NaN
#: colours); with this floor its normalised coordinates are merely smaller than 1.
MIN_FRAME_SCALE = 2.2250738585072014e-308

# --- rays (explorer.geometry.rays) ----------------------------------------------------------

#: Shadow rays: a hit nearer than this (normalised units) is the ray's own surface, not an
#: occluder; a hit within this of the light is the light's own position. Only front sides
#: occlude, so no larger bias is needed against "shadow acne".
RAY_T_EPS = 1e-9

#: Shadow rays: a ray-triangle determinant below this (it is -D·(e1 × e2)) is a back side or a
#: ray parallel to the triangle: no hit.
DET_EPS = 1e-15

#: Shadow rays are cast from the vertices where N·L > -SHADOW_NDL_MARGIN: N·L is rounded, and a
#: ray more than needed is harmless where one fewer would leave a lit vertex unshadowed.
SHADOW_NDL_MARGIN = 1e-6

#: Per-pixel reference: a pixel's ray meeting a triangle at a parameter at most this times the
#: scene's size in the mesh's normalised frame (max(largest absolute coordinate of the rays'
#: origins there, 1): the rays are cast in that frame) is ignored; the rays start at the camera,
#: so this only drops hits at the camera itself. Any determinant other than 0 counts (both
#: sides are seen, as VTK draws them).
PIXEL_RAY_T_MIN = 1e-9

#: Per-pixel reference: an interpolated normal shorter than this (the corners' normals cancel
#: out) is left zero rather than normalised (no lighting from a direction that is noise).
SURFACE_NORMAL_MIN = 1e-12

#: BVH (explorer.geometry.bvh): every node's box is grown by this times the mesh's size
#: (max(largest absolute coordinate, 1)) on each side. The box test then errs only toward
#: visiting a node: a ray that the Möller-Trumbore test finds hitting a triangle always enters
#: the boxes above it despite rounding, so the BVH reports exactly the hits of testing every
#: triangle.
BVH_BOX_PAD = 1e-9

#: Shadow rays toward one light (explorer.geometry.occluders): a triangle is left out of the
#: casts when the light is in front of it by more than this times the longest ray (sine of the
#: angle between the triangle's plane and the light), and it is no sliver (|e1 × e2| >= this
#: times |e1|·|e2|). Then every ray toward the light meets its plane from behind with a
#: determinant below -OCCLUDER_MARGIN² |e1| |e2|, a thousand times the determinant's rounding,
#: or beyond the light: it cannot block one (the module docstring has the argument).
OCCLUDER_MARGIN = 1e-6

# Normal cones of the BVH's nodes (explorer.geometry.occluders: a child whose triangles all
# face a light is left out of its shadow rays' boxes whole):
#: a normal cone's bound on ``h`` must beat the threshold by this times ``|L - c| + r``: the
#: axis is stored in float32 (its dot and cross products with ``L - c`` off by up to 3e-7 of
#: ``|L - c|``); the rounding of the float64 bound is a few ulps of those (the sine comes from
#: a cross product, not from ``1 - cos²``)
CONE_SLACK = 1e-6
#: an inner node's cone angle is its children's widened by this (as a cosine) per level: the
#: angle between two unit vectors from their dot product ``g`` near 1 is off by up to
#: ``sqrt(2 ulp)`` ≈ 1.5e-8
CONE_WIDEN = 1e-7
#: the stored cosine ``κ`` of a cone's angle is lowered and its sine raised by this: both are
#: stored in float32 (off by up to 3e-8 near 1)
CONE_ROUND = 1e-7

# --- float32 fast path ----------------------------------------------------------------------

#: A float32 dot product of unit vectors is within about 1e-6 of the float64 one after the
#: engine's recentring (a few ulps of 2**-24 per term, plus the normalisations). A vertex where
#: a decision flips on the sign of such a dot (N·L > 0 for the specular step, N·V < 0 for
#: two-sided, the spot cone test x >= cos(cutoff), the clamp of N·H or R·V at 0 that decides
#: 0**n) lies within AMBIGUOUS_DOT of the threshold is recomputed in float64, so float32 never
#: switches a highlight or a cone edge on or off where float64 does not. 10x margin over the
#: error bound; such vertices are a measure-zero set in practice.
AMBIGUOUS_DOT = 1e-5

#: Likewise for |L + V|² near HALFWAY_EPS2 and distances near POINT_EPS (in normalised units).
AMBIGUOUS_LEN2 = 1e-9

#: A light or eye within this distance (normalised units) of a vertex is redone in float64:
#: float32 positions are accurate to ~1e-7 there, so "at the vertex" is decided in float64.
AMBIGUOUS_DIST = 1e-5

#: Light culling (explorer.shading.kernels.bounds): a chunk's bounding sphere and normal cone are
#: widened by this (relative, in float64) so that their own rounding can never leave a vertex
#: outside them; a chunk is skipped for a light only when every vertex faces away from it (or
#: lies outside its cone) by AMBIGUOUS_DOT or more, far beyond float32's rounding of N·L.
CULL_GUARD = 1e-12

#: The fast path must stay within this of the float64 path everywhere (one 8-bit level).
FLOAT32_MAX_ABS_ERROR = 1.0 / 255.0

# --- tests ----------------------------------------------------------------------------------

#: Engine (float64) against the independent OpenGL 2.1 oracle in the tests.
ORACLE_ABS_TOL = 1e-5
#: Planned result against the full equation (explorer.shading.equation; both float64).
PLAN_ABS_TOL = 1e-9
#: Colours after rotating/translating the whole scene (float64; the rotation itself rounds).
INVARIANCE_ABS_TOL = 1e-6
#: float32 colours reached by two routes (a fresh pass, or cached sums brought up to date by a
#: lobe re-run or a recompose) agree to this times max(1, shininess): the routes run different
#: compiled loops, and a last-bit difference in a lobe's base (2**-24 relative) grows n-fold
#: through base**n. A stale cache entry is orders of magnitude larger.
FLOAT32_ROUTE_ABS_TOL = 1e-6
#: Stored float64 colours of every preset (tests/golden/preset_colors.npz) against the engine's
#: colours now. The kernels compile with fast-math flags (reassociation, contraction, approximate
#: functions), so another CPU (vector width), numba or LLVM version may round differently: a few
#: ulps of 1, grown at most n-fold through base**n (shininess n <= 1000), orders of magnitude
#: below this. A change of 0.001 in one coefficient of a preset moves its colours by about 1e-3,
#: far above it; one 8-bit level is 4e-3.
GOLDEN_COLOR_ABS_TOL = 1e-9

#: Largest difference between a material's ambient and X3D's ``ambientIntensity × diffuseColor``
#: reported as exact: the least-squares ``ambientIntensity`` of an ambient that is a multiple of
#: the diffuse colour reproduces it to a few ulps (about 1e-16), far below one 8-bit level.
X3D_AMBIENT_TOLERANCE = 1e-9

# --- caps on what a small input may make the program allocate ------------------------------

#: Largest mesh file read (bytes). The largest meshes worth shading per vertex are a few
#: million triangles, about 100 MiB as binary STL/PLY; a bigger file would take minutes and
#: gigabytes before any error, so it is refused before it is read.
MAX_MESH_FILE_BYTES = 256 << 20
#: Largest total a compressed mesh file (a zip, bz2 or gzip archive, which trimesh unpacks in
#: memory) may unpack to (bytes): a 2 MB zip can hold gigabytes of text. Zip members are
#: checked by their declared sizes before anything is unpacked (reading stops at the declared
#: size); bz2 and gzip streams are counted while unpacking and abandoned past the cap.
MAX_MESH_UNPACKED_BYTES = 256 << 20
#: Largest .mtl file read (bytes). A material library is text of a few lines per material; the
#: largest real ones (scenes of thousands of materials) are a few MiB, so anything larger is
#: refused before it is read.
MAX_MTL_FILE_BYTES = 16 << 20
#: Longest ``newmtl`` name read (characters). An imported material keeps its name in its
#: preset's description; a name of megabytes would make a preset file over the YAML reader's
#: 1 MiB cap, so import would write what validate and render then refuse. Real names are a
#: few dozen characters.
MAX_MTL_NAME_LENGTH = 256
#: How many ``mtllib`` libraries one OBJ may name: each is a file opened and read.
MAX_MTL_LIBRARIES = 64
#: Largest texture image file read (bytes): a PNG or JPEG of the largest size below is at most
#: a few tens of MiB; anything larger is refused before it is read.
MAX_TEXTURE_FILE_BYTES = 64 << 20
#: Most pixels a texture image may have (width × height), checked from the image's header
#: before it is decoded: 4096 × 4096, 64 MiB as RGBA bytes. A 100 KB PNG can declare
#: 50 000 × 50 000 pixels (10 GB decoded); OpenGL 2.1 drivers take 4096 or 8192 a side.
MAX_TEXTURE_PIXELS = 4096 * 4096

#: A bump map's tangent frame (:func:`explorer.render.pixelmaps.bumped_normals`): a triangle
#: whose (u, v) corners span an area below this (``|du1·dv2 - du2·dv1|``: corners sharing a
#: texture coordinate, or on one line of the image), or whose surface spans less than this per
#: unit of (u, v) squared (``|P_u × P_v|``: a degenerate triangle), has no frame; its pixels
#: keep their normal (dividing by either would make the tilt arbitrary).
BUMP_FRAME_EPS = 1e-12
#: Largest of the other files the product reads (bytes): the window's recent-files list, the
#: accuracy table (about 400 KB), ``/proc/cpuinfo`` for a benchmark's machine line (a few KB
#: per core). Read through the checked open, which never trusts a size (``/proc`` gives 0).
MAX_DATA_FILE_BYTES = 16 << 20
#: Most lights the window holds (a session, a scene opened in it, lights added there): eight
#: times OpenGL's GL_MAX_LIGHTS. Each light is a row in the light panel and a handle in the
#: view and is shaded every frame; a 20,000-light session took 40-50 s to open and to close
#: (and was kept as a last session over the 1 MiB the reader takes). ``render`` and the
#: library take more.
MAX_WINDOW_LIGHTS = 64
#: Most turntable frames one render writes: a full turn in 1-degree steps.
MAX_TURNTABLE_FRAMES = 360
#: Largest turntable, frames x width x height pixels, whose frames are held until the end: a
#: GIF (its encoder keeps every frame, one byte per pixel once in its palette) and the window's
#: turntable (it keeps the frames it renders, 3 bytes per pixel, to encode them in a thread).
#: 2**29 pixels: 512 MiB palettised, 1.5 GiB as RGB; 360 frames of 1200 x 1200, 36 of 3800 x 3800.
MAX_TURNTABLE_HELD_PIXELS = 1 << 29
#: Largest MP4 turntable of ``render --turntable``, frames x width x height pixels: its frames
#: are streamed to the encoder one at a time (memory: one frame), so this bounds the time only:
#: 2**32 pixels, 360 frames of 3400 x 3400, several minutes (360 x 2048² took 117 s).
MAX_TURNTABLE_PIXELS = 1 << 32
#: Largest picture (width x height pixels) a render or a whole sheet may have: 8192 x 8192,
#: 192 MiB as RGB bytes and several times that inside VTK while drawing. A sheet of large
#: tiles is checked before anything is allocated (beyond it VTK aborts with std::bad_alloc).
MAX_PICTURE_PIXELS = 8192 * 8192
#: Largest PNG file read (bytes): the largest picture as RGBA without any compression, plus
#: 1 MiB for its chunks' headers (a PNG of MAX_PICTURE_PIXELS is never larger).
MAX_PNG_FILE_BYTES = 4 * MAX_PICTURE_PIXELS + (1 << 20)
#: Largest file the web page downloads (bytes): files the product has just written into its
#: private folder (a session, a material, a PNG, a turntable: a GIF of MAX_TURNTABLE_HELD_PIXELS
#: is at most 512 MiB), read back through the checked open.
MAX_DOWNLOAD_BYTES = 1 << 30
