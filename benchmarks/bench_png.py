"""The PNG codec: VTK's writer and reader (the codec before issue 34) beside Pillow's (the one of
explorer/render/images.py), on one window-sized frame.

    python benchmarks/bench_png.py                     # 1100x720 (the window's size), 15 repeats
    python benchmarks/bench_png.py --size 1920x1080 --repeat 31

The frame is a real off-screen render (gold on the teapot, the default background), so the
compressor sees what it sees in use. Prints the median wall time of each in milliseconds (the
two codecs' calls alternate, so both see the same load; one untimed round first) and the file
size; both decoders must give the frame back exactly (they read a file in the page cache).
"""

from __future__ import annotations

import argparse
import io
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

import common  # noqa: F401 - the compiled tier (benchmarks/common.py)
import numpy as np

# VTK's codec, which the package used before, lives with the tests as their independent oracle
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from helpers.vtkpng import encode as vtk_encode  # noqa: E402
from helpers.vtkpng import read as vtk_decode  # noqa: E402


def pillow_decode(path: str) -> np.ndarray:
    from explorer.render.images import read_png

    return read_png(path)


def frame(size: tuple[int, int]) -> np.ndarray:
    from explorer.core.presets import find_preset
    from explorer.core.scene import Scene
    from explorer.geometry.meshes import get_mesh
    from explorer.render.offscreen import render_image

    scene = Scene(material=find_preset("gold"))
    return render_image(scene, get_mesh("teapot", 24), size)


def medians_ms(fns, repeat: int) -> list[float]:
    """Median wall time in ms of each of ``fns`` over ``repeat`` rounds, the calls of a round
    one after the other (A B A B ...: both see the same load), after one untimed round."""
    for fn in fns:
        fn()
    times: list[list[float]] = [[] for _ in fns]
    for _ in range(repeat):
        for fn, out in zip(fns, times, strict=True):
            t0 = time.perf_counter()
            fn()
            out.append(time.perf_counter() - t0)
    return [1000.0 * statistics.median(t) for t in times]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", default="1100x720", help="frame size WxH (default %(default)s)")
    ap.add_argument("--repeat", type=int, default=15, help="timed calls each (default 15)")
    args = ap.parse_args(argv)
    from explorer.render.images import encode_png, parse_size

    size = parse_size(args.size)
    img = frame(size)
    assert img.shape == (size[1], size[0], 3) and img.dtype == np.uint8
    vtk_png, pil_png = vtk_encode(img), encode_png(img)
    tmp = tempfile.mkdtemp(prefix="bench_png_")
    files = {}
    for name, data in (("VTK", vtk_png), ("Pillow", pil_png)):
        files[name] = os.path.join(tmp, f"{name}.png")
        with open(files[name], "wb") as fh:
            fh.write(data)
        for decode in (vtk_decode, pillow_decode):
            assert np.array_equal(decode(files[name]), img), f"{name} file, {decode.__name__}"
    from PIL import Image
    from vtkmodules.vtkCommonCore import vtkVersion

    with Image.open(io.BytesIO(pil_png)) as im:
        kind = f"{im.mode}, {im.info.get('dpi', 'no dpi')}"
    print(f"frame {size[0]}x{size[1]} RGB 8-bit (a teapot render); median of {args.repeat} calls")
    print(f"VTK {vtkVersion.GetVTKVersion()}, Pillow {Image.__version__}; Pillow's file: {kind}")
    print("| codec | encode ms | decode ms | file bytes |")
    print("|---|---:|---:|---:|")
    rows = (
        ("VTK (vtkPNGWriter / Reader)", vtk_encode, vtk_decode, "VTK", vtk_png),
        ("Pillow (explorer.render.images)", encode_png, pillow_decode, "Pillow", pil_png),
    )
    enc = medians_ms([lambda f=r[1]: f(img) for r in rows], args.repeat)
    dec = medians_ms([lambda f=r[2], k=r[3]: f(files[k]) for r in rows], args.repeat)
    for (name, *_, data), e, d in zip(rows, enc, dec, strict=True):
        print(f"| {name} | {e:.1f} | {d:.1f} | {len(data):,} |")
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    shutil.rmtree(tmp)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
