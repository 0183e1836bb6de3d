"""Reading animations back in tests."""

from __future__ import annotations

import gc
import warnings

import imageio.v3 as iio
import numpy as np


def read_frames(path) -> np.ndarray:
    """Every frame of a GIF or MP4, (n, h, w, 3|4) uint8. imageio-ffmpeg's MP4 reader leaves its
    ffmpeg pipes to the garbage collector (a ResourceWarning, an error in the suite; the writer,
    which the package uses, closes them): that one warning is ignored here, and the collector
    runs before the filter is restored."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "unclosed file <_io.Buffered", ResourceWarning)
        frames = iio.imread(path, index=None)
        gc.collect()
    return frames
