"""Pictures as arrays and files: sizes, and the one PNG codec for every picture the package
writes or reads (Pillow's; the page's still pictures written by :func:`encode_png` ``fast``,
the standard library's zlib behind one fixed row filter)."""

from __future__ import annotations

import io
import os
import re
import struct
import zlib

import numpy as np

from explorer.core.errors import ExplorerError
from explorer.core.files import read_checked
from explorer.core.tolerances import MAX_PICTURE_PIXELS, MAX_PNG_FILE_BYTES

#: default image size (width, height)
DEFAULT_SIZE = (400, 400)
#: smallest and largest accepted image side in pixels
SIZE_RANGE = (16, 8192)


# -- sizes and files -----------------------------------------------------------------------


def check_size(size) -> tuple[int, int]:
    """(width, height) as ints in :data:`SIZE_RANGE`, or an :class:`ExplorerError`."""
    lo, hi = SIZE_RANGE
    try:
        w, h = (int(v) for v in size)
        ok = all(float(v) == int(v) for v in size)
    except (TypeError, ValueError):
        ok = False
    if not ok or not (lo <= w <= hi and lo <= h <= hi):
        raise ExplorerError(
            f"image size must be two whole numbers of pixels, each in [{lo}, {hi}], got {size!r}"
        )
    check_picture_pixels(w, h, "image size")
    return w, h


def check_picture_pixels(width: int, height: int, what: str) -> None:
    """An :class:`ExplorerError` naming ``what`` when a ``width`` x ``height`` picture is more
    than :data:`~explorer.core.tolerances.MAX_PICTURE_PIXELS`; call it before allocating."""
    if width * height > MAX_PICTURE_PIXELS:
        raise ExplorerError(
            f"{what}: {width}x{height} is {width * height} pixels, more than the limit of "
            f"{MAX_PICTURE_PIXELS} (8192x8192); use a smaller size"
        )


_SIZE_RE = re.compile(r"^\s*(\d+)\s*[xX×]\s*(\d+)\s*$")


def parse_size(text: str) -> tuple[int, int]:
    """``"400x300"`` -> (400, 300) (width x height), checked against :data:`SIZE_RANGE`."""
    m = _SIZE_RE.match(str(text))
    if not m:
        raise ExplorerError(f"size must look like WIDTHxHEIGHT, e.g. 400x400, got {text!r}")
    return check_size((int(m.group(1)), int(m.group(2))))


#: zlib level of the PNG files written (lossless at every level): 5, VTK's writer's, which the
#: package used before; Pillow's default 6 took 1.6-1.9 times as long for files 4 % smaller on
#: a 1100x720 render (benchmarks/bench_png.py)
PNG_COMPRESS_LEVEL = 5
#: zlib level of a ``fast`` PNG (:func:`encode_png`): the fastest
PNG_FAST_LEVEL = 1


def _picture(image) -> np.ndarray:
    img = np.asarray(image)
    if img.dtype != np.uint8 or img.ndim != 3 or img.shape[2] not in (3, 4):
        raise ValueError(f"image must be (h, w, 3|4) uint8, got {img.shape} {img.dtype}")
    return np.ascontiguousarray(img)


def encode_png(image, *, fast: bool = False) -> bytes:
    """PNG file contents of an (h, w, 3|4) uint8 image: 8-bit RGB or RGBA, rows top to bottom,
    no other chunks (Pillow's PNG writer; ``benchmarks/bench_png.py`` times it beside VTK's).

    fast : every row filtered by PNG's filter 2 (Up: the byte above subtracted) and deflated at
        :data:`PNG_FAST_LEVEL`, by numpy and the standard library's zlib: the page's still
        pictures (:mod:`explorer.app.web.pictures`). Pillow tries PNG's five filters on every
        row and keeps the best; on an 800x600 frame of the explorer that took about as long as
        the deflate itself (7.9 ms against 3.7 for this, the same size within 5 %), and
        Chromium decodes the one-filter file in 1.8 ms against 3.4 (docs/web_bench.md).
    """
    img = _picture(image)
    if fast:
        return _png_up(img)
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(img).save(buf, format="PNG", compress_level=PNG_COMPRESS_LEVEL)  # RGB(A)
    return buf.getvalue()


def _chunk(kind: bytes, data: bytes) -> bytes:
    """One PNG chunk: length, type, data, CRC-32 of type and data."""
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def _png_up(img: np.ndarray) -> bytes:
    """``img`` (h, w, 3|4) uint8, C-contiguous, as a PNG whose rows all use filter 2 (Up)."""
    h, w, c = img.shape
    rows = img.reshape(h, w * c)
    lines = np.empty((h, w * c + 1), np.uint8)  # each row: its filter byte, then its bytes
    lines[:, 0] = 2
    lines[0, 1:] = rows[0]  # (the first row's "above" is zeros)
    np.subtract(rows[1:], rows[:-1], out=lines[1:, 1:])  # modulo 256, as PNG's Up is
    header = struct.pack(">IIBBBBB", w, h, 8, 2 if c == 3 else 6, 0, 0, 0)  # 8-bit RGB / RGBA
    return b"".join(
        (
            b"\x89PNG\r\n\x1a\n",
            _chunk(b"IHDR", header),
            _chunk(b"IDAT", zlib.compress(lines, PNG_FAST_LEVEL)),
            _chunk(b"IEND", b""),
        )
    )


def decode_png(data: bytes, name: str = "PNG data") -> np.ndarray:
    """An (h, w, 3|4) uint8 image from PNG file contents: RGB and RGBA as they are, grey and
    palette pictures as RGB (RGBA when they have transparency). 16-bit pictures are refused
    (an :class:`ExplorerError` naming ``name``), as is anything that is not a PNG."""
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(io.BytesIO(data), formats=["PNG"]) as im:
            depth = data[24]  # IHDR's bit depth (Pillow keeps 8 of 16-bit RGB's bits)
            check_picture_pixels(*im.size, name)
            if depth <= 8 and im.mode not in ("RGB", "RGBA"):
                alpha = "A" in im.getbands() or "transparency" in im.info
                im = im.convert("RGBA" if alpha else "RGB")
            pixels = np.array(im, dtype=np.uint8) if depth <= 8 else None
    except UnidentifiedImageError:
        raise ExplorerError(f"{name}: not a readable PNG file (not PNG data)") from None
    except (OSError, SyntaxError) as exc:  # Pillow's errors for damaged data
        raise ExplorerError(f"{name}: not a readable PNG file ({exc})") from None
    if pixels is None:
        raise ExplorerError(f"{name}: a {depth}-bit PNG; only 8-bit pictures are read")
    return pixels


def read_png(path) -> np.ndarray:
    """An (h, w, 3|4) uint8 image from a PNG file (:func:`decode_png`), read through the
    checked open (a regular file of at most ``MAX_PNG_FILE_BYTES``)."""
    name = os.fspath(path)
    return decode_png(read_checked(name, cap=MAX_PNG_FILE_BYTES, what="PNG file"), name)


def side_by_side(left, right, gap: int = 0, fill=(0, 0, 0)) -> np.ndarray:
    """Two pictures (h1, w1, 3) and (h2, w2, 3) uint8 in one, ``gap`` columns of ``fill``
    between them, the shorter one padded at the bottom with ``fill``:
    (max(h1, h2), w1 + gap + w2, 3) uint8."""
    a, b = np.asarray(left, np.uint8), np.asarray(right, np.uint8)
    h = max(a.shape[0], b.shape[0])
    out = np.empty((h, a.shape[1] + int(gap) + b.shape[1], 3), np.uint8)
    out[:] = np.asarray(fill, np.uint8)
    out[: a.shape[0], : a.shape[1]] = a
    out[: b.shape[0], a.shape[1] + int(gap) :] = b
    return out
