"""Texture images: read safely, and looked up as OpenGL looks them up.

:func:`read_texture` reads a map's image (PNG or JPEG, decoded by Pillow) through the checked open
(:func:`explorer.core.files.read_checked`: a FIFO or device is refused without blocking, at most
``MAX_TEXTURE_FILE_BYTES`` bytes are read) and refuses an image of more than
``MAX_TEXTURE_PIXELS`` pixels from its header, before decoding. Every refusal is one
:class:`TextureError` line naming the file, the map key and what is wrong.

The image's rows go to OpenGL bottom row first (``glTexImage2D``'s first row is v = 0), so
(u, v) = (0, 0) is the image's lower-left corner, as in OBJ and OpenGL (:func:`gl_rows`).
:func:`sample_nearest` is the texel ``GL_NEAREST`` picks with ``GL_REPEAT`` (or
``GL_CLAMP_TO_EDGE`` for a ``-clamp on`` map): the reference the tests hold the drawing to.
"""

from __future__ import annotations

import functools
import io
import os
import re
import warnings

import numpy as np

from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError
from explorer.core.files import NO_SUCH_FILE, UnreadableFile, read_checked
from explorer.core.texture import TextureMap

#: image formats read (Pillow's names)
FORMATS = ("PNG", "JPEG")


class TextureError(ExplorerError):
    """A texture image that cannot be used: the message names the file, the map and why."""


def read_texture(tmap: TextureMap | str, key: str = "diffuse_map") -> np.ndarray:
    """The image of ``tmap`` as (height, width, 4) uint8 RGBA, rows top first (as stored).

    key : the material key the map is (for the message)
    A missing file, one that is not a regular file, is larger than ``MAX_TEXTURE_FILE_BYTES``,
    is no PNG or JPEG, is truncated or damaged, or has more than ``MAX_TEXTURE_PIXELS`` pixels
    raises a :class:`TextureError`.
    """
    name = tmap.file if isinstance(tmap, TextureMap) else os.fspath(tmap)
    where = f"{key} '{name}'"
    try:
        data = read_checked(name, cap=tol.MAX_TEXTURE_FILE_BYTES, what=f"{key} image")
    except UnreadableFile as exc:
        reason = "does not exist" if exc.reason == NO_SUCH_FILE else exc.reason
        raise TextureError(f"{where}: {reason}") from None
    if not data:
        raise TextureError(f"{where}: the file is empty, not a PNG or JPEG image")
    from PIL import Image, UnidentifiedImageError

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            image = Image.open(io.BytesIO(data), formats=list(FORMATS))
            w, h = image.size
            if w * h > tol.MAX_TEXTURE_PIXELS:
                raise TextureError(
                    f"{where}: {w}x{h} is {w * h} pixels, more than the limit of "
                    f"{tol.MAX_TEXTURE_PIXELS} (4096x4096); use a smaller image"
                )
            image.load()
            rgba = np.asarray(image.convert("RGBA"), dtype=np.uint8)
    except TextureError:
        raise
    except UnidentifiedImageError:
        raise TextureError(f"{where}: not a PNG or JPEG image") from None
    except (Image.DecompressionBombError, Image.DecompressionBombWarning) as exc:
        # Pillow's own guard, at open (more than ~89 M pixels, far above the cap): the header
        # declares a size too large, which is no damage (it said "damaged or truncated")
        n = re.search(r"\((\d+) pixels\)", str(exc))
        size = f"{n.group(1)} pixels" if n else "its size"
        raise TextureError(
            f"{where}: {size}, more than the limit of {tol.MAX_TEXTURE_PIXELS} (4096x4096); "
            "use a smaller image"
        ) from None
    except (OSError, ValueError, SyntaxError) as exc:
        raise TextureError(f"{where}: a damaged or truncated image ({exc})") from None
    return np.ascontiguousarray(rgba)


def gl_rows(image: np.ndarray) -> np.ndarray:
    """The image's rows bottom first: OpenGL's order (row 0 is v = 0)."""
    return np.ascontiguousarray(image[::-1])


def sample_nearest(image: np.ndarray, st, *, clamp: bool = False) -> np.ndarray:
    """The texels ``GL_NEAREST`` gives at texture coordinates ``st`` (k, 2): ``GL_REPEAT``
    (or ``GL_CLAMP_TO_EDGE`` when ``clamp``). image : (h, w, c) rows top first.
    Returns (k, c) of the image's dtype."""
    rows = gl_rows(image)
    j, i = texel_index(rows.shape[:2], st, clamp=clamp)
    return rows[j, i]


def texel_index(shape, st, *, clamp: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """``(j, i)`` (k,) int64 each: the row (bottom first, OpenGL's order: :func:`gl_rows`) and
    column of the texel ``GL_NEAREST`` picks at ``st`` (k, 2) in an image of ``shape`` (h, w),
    repeated (``GL_REPEAT``) or clamped to the edge (``clamp``)."""
    h, w = (int(n) for n in shape[:2])
    st = np.asarray(st, np.float64)
    s, t = st[:, 0], st[:, 1]
    if not clamp:
        s, t = s - np.floor(s), t - np.floor(t)
    i = np.clip(np.floor(s * w), 0, w - 1).astype(np.int64)
    j = np.clip(np.floor(t * h), 0, h - 1).astype(np.int64)
    return j, i


def file_stamp(file) -> tuple | None:
    """``(modification time in ns, size, inode)`` of ``file``, what a kept image or thumbnail
    of it is kept by (a changed or replaced file is read again); None where it cannot be
    stat'ed (:func:`read_texture` then says what is wrong)."""
    try:
        st = os.stat(file)
    except OSError:
        return None
    return st.st_mtime_ns, st.st_size, st.st_ino


#: a map's thumbnail in the panels: its longer side (pixels)
THUMBNAIL_SIZE = 48


def thumbnail(file: str, key: str = "diffuse_map", size: int = THUMBNAIL_SIZE) -> np.ndarray:
    """Image ``file`` as at most ``size`` pixels on its longer side, (h, w, 3) uint8 RGB, rows
    top first, with the image's mean colour: a larger image shrunk, each pixel the mean of the
    texels it covers (Pillow's box filter); a smaller one grown by a whole factor, each texel a
    square block.
    Made once per file (name and :func:`file_stamp`) and kept; a bad file raises
    :func:`read_texture`'s :class:`TextureError`."""
    return _thumbnail(os.fspath(file), key, size, file_stamp(file))


@functools.lru_cache(maxsize=64)
def _thumbnail(file: str, key: str, size: int, stamp) -> np.ndarray:
    from PIL import Image

    image = Image.fromarray(read_texture(file, key)).convert("RGB")
    w, h = image.size
    if max(w, h) > size:
        scale = size / max(w, h)
        image = image.resize((max(1, round(w * scale)), max(1, round(h * scale))), Image.BOX)
    elif max(w, h) * 2 <= size:
        k = size // max(w, h)
        image = image.resize((w * k, h * k), Image.NEAREST)
    out = np.ascontiguousarray(np.asarray(image, np.uint8))
    out.setflags(write=False)
    return out
