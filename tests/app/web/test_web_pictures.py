"""The page's picture path (explorer.app.web.pictures) against a stand-in for trame-vtk's image
publisher, with a real off-screen window and no browser: what is sent, when, and in which
codec (the browser's pixels themselves: test_web_pixels)."""

from __future__ import annotations

import asyncio
import io
import time

import numpy as np
import pytest

from explorer.app.web import pictures as P

pytest.importorskip("vtkmodules")


class Publisher:
    """What :class:`~explorer.app.web.pictures.Pictures` uses of trame-vtk's publisher."""

    def __init__(self, window):
        self.window = window
        self.tracking_views = {"1": {"enabled": True, "mtime": 0, "quality": 100}}
        self.views_in_animations: list[str] = []
        self.sent: list[dict] = []
        self.decode = True
        self.attachments: dict[str, bytes] = {}

    def get_view(self, v_id):
        return self.window

    def get_global_id(self, view):
        return 1

    def addAttachment(self, data: bytes) -> str:  # noqa: N802 (wslink's name)
        key = f"wslink_bin{len(self.attachments)}"
        self.attachments[key] = data
        return key

    def publish(self, topic: str, reply: dict) -> None:
        assert topic == "viewport.image.push.subscription"
        self.sent.append(dict(reply, data=self.attachments[reply["image"]]))


@pytest.fixture
def path():
    import pyvista as pv

    from explorer.render.vtk import plotter

    pl = plotter((96, 64), (0.2, 0.3, 0.4))
    pl.add_mesh(pv.Sphere(), color=(0.9, 0.4, 0.1))
    loop = asyncio.new_event_loop()
    pub = Publisher(pl.render_window)
    pics = P.Pictures(pub, loop, lambda fn, where: fn)
    yield pub, pics, loop
    pics.close()
    loop.close()
    pl.close()


def settle(loop, pub, count: int, timeout: float = 10.0) -> None:
    """Run ``loop`` until ``pub`` has sent ``count`` pictures (or ``timeout`` s)."""
    end = time.monotonic() + timeout
    while len(pub.sent) < count and time.monotonic() < end:
        loop.run_until_complete(asyncio.sleep(0.02))


def pixels(data: bytes) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(data)).convert("RGB"))


def test_a_picture_is_a_baseline_444_jpeg_then_the_still_frame_losslessly(path):
    pub, pics, loop = path
    pub.push_render("1")
    assert pub.decode is False  # bytes, no base64 round trip
    assert len(pub.sent) == 1  # sent at once, not after VTK's encoder thread
    jpeg = pub.sent[0]["data"]
    assert jpeg[:2] == b"\xff\xd8"
    assert b"\xff\xc0" in jpeg and b"\xff\xc2" not in jpeg  # baseline, not progressive
    sof = jpeg.index(b"\xff\xc0")
    assert [jpeg[sof + 11 + 3 * i] for i in range(3)] == [0x11] * 3  # 4:4:4: no subsampling
    frame = pics.last["1"][1]
    assert frame.shape == (64, 96, 3)
    assert np.abs(pixels(jpeg).astype(int) - frame).max() <= 1
    settle(loop, pub, 2)
    assert len(pub.sent) == 2
    png = pub.sent[1]["data"]
    assert png[:4] == b"\x89PNG"
    assert (pixels(png) == frame).all()  # the still view: the frame itself
    assert pub.sent[1]["mtime"] == pub.sent[0]["mtime"]


def test_a_newer_picture_takes_the_place_of_the_still_one(path):
    pub, pics, loop = path
    pub.push_render("1")
    pub.push_render("1")  # before the first one's still time
    settle(loop, pub, 3, timeout=3 * P.STILL_S + 2)
    kinds = [r["data"][:2] for r in pub.sent]
    assert kinds == [b"\xff\xd8", b"\xff\xd8", b"\x89P"]  # one PNG: the last picture's
    assert pub.sent[2]["mtime"] == pub.sent[1]["mtime"]


def test_no_still_picture_for_a_view_no_page_shows(path, monkeypatch):
    """The still PNG is neither encoded nor sent for a view no page shows any more: its last
    page removed its observer (the publisher stops tracking it) or turned it off, during the
    still time. Before, the PNG was encoded in the worker thread and published to nobody."""
    pub, pics, loop = path
    made = []
    encode = P.encode
    monkeypatch.setattr(
        P, "encode", lambda px, lossless: made.append(lossless) or encode(px, lossless)
    )
    pub.push_render("1")
    pub.tracking_views["1"]["enabled"] = False  # (viewport.image.push.enabled, off)
    loop.run_until_complete(asyncio.sleep(P.STILL_S + 0.3))
    pub.tracking_views["1"]["enabled"] = True
    pub.push_render("1")
    del pub.tracking_views["1"]  # (viewport.image.push.observer.remove, its last observer)
    loop.run_until_complete(asyncio.sleep(P.STILL_S + 0.3))
    assert [r["data"][:2] for r in pub.sent] == [b"\xff\xd8", b"\xff\xd8"]  # two JPEGs only
    assert made == [False, False]  # no PNG encoded


def test_a_camera_drag_sends_what_was_asked_at_its_next_tick(path):
    pub, pics, loop = path
    pub.views_in_animations.append("1")
    pub.push_render("1", True)  # a tick with nothing asked: nothing
    assert pub.sent == []
    pub.push_render("1")  # a mouse event asks: held for the tick
    assert pub.sent == []
    pub.push_render("1", True)
    assert len(pub.sent) == 1
    pub.push_render("1", True)  # nothing asked since
    assert len(pub.sent) == 1


def test_a_resize_is_drawn_at_the_new_size(path):
    pub, pics, loop = path
    pub.tracking_views["1"]["originalSize"] = [80, 50]
    pub.push_render("1")
    assert pub.sent[0]["size"] == [80, 50]
    assert pixels(pub.sent[0]["data"]).shape == (50, 80, 3)


def test_the_read_back_is_the_frame_vtks_image_filter_reads(path):
    """``read_back`` (the window's back buffer through ``GetPixelData``) gives the pixels
    ``vtkWindowToImageFilter`` gives (VTK's web application's way), rows top to bottom, at
    the window's size and at an odd one after a resize."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter

    pub, pics, loop = path
    window = pub.window
    window.GetRenderers().GetFirstRenderer().ResetCamera()  # (the sphere and its background)
    for size in (None, (81, 47)):
        if size is not None:
            window.SetSize(*size)
        window.Render()
        w2i = vtkWindowToImageFilter()
        w2i.SetInput(window)
        w2i.ReadFrontBufferOff()
        w2i.ShouldRerenderOff()
        w2i.Update()
        w, h, _ = w2i.GetOutput().GetDimensions()
        filtered = vtk_to_numpy(w2i.GetOutput().GetPointData().GetScalars())
        expected = filtered.reshape(h, w, -1)[::-1, :, :3]
        got = P.read_back(window)
        assert got.shape == (h, w, 3) and got.flags.c_contiguous
        assert (got == expected).all()
        assert len(np.unique(got.reshape(-1, 3), axis=0)) == 2  # (the sphere, the background)


def test_the_publishers_api_relied_on_is_there():
    """What Pictures takes over of trame-vtk's publisher: its attributes, and that its RPCs
    (``viewport.image.push``, the observers, the drag's ticks) reach the picture through the
    instance's ``push_render`` and ``still_render`` (replaced per instance)."""
    import inspect

    from trame_vtk.modules.vtk.protocols import publish_image_delivery as D

    pub = D.vtkWebPublishImageDelivery(decode=True)
    for name in ("tracking_views", "views_in_animations", "decode"):
        assert hasattr(pub, name), name
    called = (
        "push_render",
        "still_render",
        "publish",
        "addAttachment",
        "get_view",
        "get_global_id",
    )
    for name in called:
        assert callable(getattr(pub, name)), name
    src = inspect.getsource(D.vtkWebPublishImageDelivery)
    assert src.count("self.push_render(") >= 4  # image_push, the observers, animate
    assert "self.still_render(" in src
