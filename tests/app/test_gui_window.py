"""The explorer in a real X window (Xvfb), driven by xdotool like a person would.

One run of ``phong-explorer gui`` on a private Xvfb server: drag the kd slider, drag the light
handle, rotate the camera, switch the preset with its button, show and hide the difference view
(its button, then key d), open the help with a key, quit
with ``q``. After each step the test polls the app's state file (written atomically after each
frame) and the window's pixels (``xwd``), never sleeping a fixed time: the pixel where the vertex
facing the camera lands must lie within the colours the engine gives the triangles around that
vertex, computed here from the reported scene.

Needs ``Xvfb``, ``xdotool`` and ``xwd`` (``apt-get install -y xvfb xdotool x11-apps``); skipped
with the reason when one is missing.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import explorer
from explorer.app import window as gui
from explorer.geometry import meshes as M
from explorer.shading.display import to_bytes

pytestmark = pytest.mark.gui

TOOLS = ("Xvfb", "xdotool", "xwd")
MISSING = [t for t in TOOLS if shutil.which(t) is None]
if sys.platform in ("darwin", "win32") or MISSING:
    pytest.skip(
        f"needs {', '.join(MISSING) or 'X11'} for the real-window test "
        "(apt-get install -y xvfb xdotool x11-apps)",
        allow_module_level=True,
    )

MESH = "sphere"
#: how long one step may take (generous: the first frame may compile the engine's kernels)
STEP_TIMEOUT = 20.0
START_TIMEOUT = 120.0


@pytest.fixture
def display():
    """A private Xvfb server; its display name (":N") chosen by the server itself."""
    r, w = os.pipe()
    proc = subprocess.Popen(
        ["Xvfb", "-displayfd", str(w), "-screen", "0", "1280x900x24", "-nolisten", "tcp"],
        pass_fds=(w,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    os.close(w)
    try:
        with os.fdopen(r) as f:
            number = f.readline().strip()
        if not number:
            pytest.fail("Xvfb did not start")
        yield f":{number}"
    finally:
        proc.terminate()
        proc.wait(timeout=10)


class Window:
    """The app under test: its process, its X window and its state file."""

    def __init__(self, display, tmp: Path):
        self.env = {k: v for k, v in os.environ.items() if k != "VTK_DEFAULT_OPENGL_WINDOW"}
        self.env.update(DISPLAY=display, PHONG_EXPLORER_MATERIALS=str(tmp / "presets"))
        self.state_file = tmp / "state.json"
        self.log = tmp / "app.log"
        cmd = [
            sys.executable, "-m", "explorer.cli", "gui", "--mesh", MESH,
            "--state-file", str(self.state_file), "--exit-after", "90",
            "--screenshot-dir", str(tmp),
        ]  # fmt: skip
        with open(self.log, "wb") as out:  # a file, not a pipe: a full pipe would block it
            self.proc = subprocess.Popen(cmd, env=self.env, stdout=out, stderr=out)
        self.wid = None
        self.pointer = None

    def xdotool(self, *args, timeout=STEP_TIMEOUT) -> str:
        r = subprocess.run(
            ["xdotool", *map(str, args)], env=self.env, capture_output=True, text=True,
            timeout=timeout, check=True,
        )  # fmt: skip
        return r.stdout

    def find(self) -> None:
        out = self.xdotool(
            "search", "--sync", "--onlyvisible", "--name", gui.G.TITLE, timeout=START_TIMEOUT
        )
        self.wid = out.split()[0]

    def state(self) -> dict | None:
        try:
            return json.loads(self.state_file.read_text())
        except (OSError, ValueError):
            return None

    def wait(self, what: str, pred, timeout=STEP_TIMEOUT) -> dict:
        """Poll the state until ``pred(state)`` holds."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if self.proc.poll() is not None:
                pytest.fail(f"the app exited ({self.proc.returncode}) waiting for {what}:\n"
                            + self.log.read_text(errors="replace"))  # fmt: skip
            s = self.state()
            if s is not None and pred(s):
                return s
            time.sleep(0.05)
        pytest.fail(f"timed out waiting for {what}; last state: {self.state()}")

    def pixels(self) -> np.ndarray:
        """The window's pixels, (h, w, 3) uint8, read from the X server."""
        raw = subprocess.run(
            ["xwd", "-id", self.wid, "-silent"], env=self.env, capture_output=True,
            timeout=STEP_TIMEOUT, check=True,
        ).stdout  # fmt: skip
        return read_xwd(raw)

    def move(self, x, y) -> list:
        """xdotool words moving the pointer to window pixel (x, y). ``--sync`` waits until the
        pointer arrives, so it is left out when the pointer is there already (it would wait
        for a motion that never comes)."""
        x, y = int(x), int(y)
        sync = ["--sync"] if self.pointer != (x, y) else []
        self.pointer = (x, y)
        return ["mousemove", "--window", self.wid, *sync, x, y, "sleep", 0.05]

    def drag(self, a, b, steps=4) -> None:
        (x0, y0), (x1, y1) = a, b
        args = [*self.move(x0, y0), "mousedown", 1, "sleep", 0.05]
        for t in np.linspace(0.0, 1.0, steps + 1)[1:]:
            args += self.move(round(x0 + t * (x1 - x0)), round(y0 + t * (y1 - y0)))
        args += ["mouseup", 1]
        self.xdotool(*args)

    def click(self, at) -> None:
        self.xdotool(*self.move(*at), "click", 1)

    def key(self, name: str) -> None:
        # no window manager: the key goes to the window under the pointer
        self.xdotool(*self.move(20, 20), "key", name)

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(timeout=10)


def read_xwd(raw: bytes) -> np.ndarray:
    """An X window dump (TrueColor, 24 or 32 bits per pixel) as (h, w, 3) uint8 RGB."""
    header = np.frombuffer(raw[:100], ">u4")
    (size, _version, _format, _depth, width, height, _xoff, byte_order, _unit, _bit_order,
     _pad, bpp, bytes_per_line, _visual, red, green, blue, _bits, _entries, ncolors) = header[:20]  # fmt: skip  # noqa: E501
    if bpp not in (24, 32):
        raise ValueError(f"unsupported xwd: {bpp} bits per pixel")
    start = int(size) + 12 * int(ncolors)
    rows = np.frombuffer(raw[start : start + int(height) * int(bytes_per_line)], np.uint8)
    rows = rows.reshape(int(height), int(bytes_per_line))[:, : int(width) * int(bpp) // 8]
    px = rows.reshape(int(height), int(width), int(bpp) // 8).astype(np.uint32)
    if byte_order == 0:  # LSBFirst
        value = sum(px[:, :, i] << (8 * i) for i in range(px.shape[2]))
    else:
        value = sum(px[:, :, i] << (8 * (px.shape[2] - 1 - i)) for i in range(px.shape[2]))

    def channel(mask):
        mask = int(mask)
        shift = (mask & -mask).bit_length() - 1
        return ((value & mask) >> shift).astype(np.uint8)

    return np.stack([channel(red), channel(green), channel(blue)], axis=-1)


def check_probe(win: Window, mesh: M.Mesh) -> dict:
    """The pixel of the vertex facing the camera shows the engine's colour there: within the
    colours of the triangles around it (Gouraud), computed here from the reported scene.
    Polls state and pixels together until they agree; returns the state."""
    end = time.monotonic() + STEP_TIMEOUT
    while True:
        s = win.state()
        assert s["n_vertices"] == mesh.n_vertices
        scene = explorer.load_scene(s["scene"])
        colours = to_bytes(explorer.shade(scene, mesh.positions, mesh.normals)).astype(int)
        i = s["probe"]["vertex"]
        x, y = s["probe"]["px"]
        around = np.unique(mesh.faces[(mesh.faces == i).any(axis=1)])
        lo = colours[around].min(axis=0) - 2
        hi = colours[around].max(axis=0) + 2
        pixel = win.pixels()[y, x].astype(int)
        if (pixel >= lo).all() and (pixel <= hi).all() and win.state() == s:
            return s
        if time.monotonic() > end:
            pytest.fail(f"pixel ({x}, {y}) is {pixel}, the engine says {lo + 2}..{hi - 2}")
        time.sleep(0.05)


@pytest.mark.slow  # a real X window driven with xdotool, waiting for each frame
def test_real_window(display, tmp_path):
    mesh = M.get_mesh(MESH, gui.MESH_CHOICES[MESH])
    win = Window(display, tmp_path)
    try:
        win.find()
        s = win.wait("the first frame", lambda s: s["frame"] >= 1, timeout=START_TIMEOUT)
        assert s["mesh"] == MESH and s["preset"] == gui.DEFAULT_PRESET and not s["errors"]
        check_probe(win, mesh)

        # drag the kd slider's knob 80 pixels to the left
        kd = s["sliders"]["kd"]
        (x_lo, y), (x_hi, _) = kd["ends_px"]
        x0 = kd["knob_px"][0]
        x1 = x0 - 80
        want = (x1 - x_lo) / (x_hi - x_lo)
        win.drag((x0, y), (x1, y))
        s = win.wait(
            "kd to follow the drag",
            lambda s: not s["dragging"] and abs(s["material"]["kd"] - want) < 0.012,
        )
        assert s["sliders"]["kd"]["value"] == pytest.approx(s["material"]["kd"], abs=6e-4)
        check_probe(win, mesh)

        # drag the light's handle to the left and down
        before = s["light"]
        hx, hy = s["handle_px"]
        win.drag((hx, hy), (hx - 160, hy + 60))
        s = win.wait(
            "the light to move",
            lambda s: not s["dragging"] and abs(s["light"]["azimuth"] - before["azimuth"]) > 5.0,
        )
        for name in ("azimuth", "elevation", "distance"):  # handle and sliders agree
            assert s["sliders"][name]["value"] == pytest.approx(s["light"][name], abs=1e-6)
        check_probe(win, mesh)

        # rotate the camera: the viewer follows it
        eye = s["scene"]["viewer"]["eye"]
        win.drag((120, 560), (260, 540))
        s = win.wait(
            "the viewer to follow the camera", lambda s: s["scene"]["viewer"] != {"eye": eye}
        )
        assert s["scene"]["viewer"] == {"eye": s["camera"]["position"]}
        check_probe(win, mesh)

        # the next preset, with the button
        nxt = s["presets"][s["presets"].index(s["preset"]) + 1]
        win.click(s["buttons"]["preset_next"]["px"])
        s = win.wait(f"preset {nxt}", lambda s: s["preset"] == nxt)
        check_probe(win, mesh)

        # the difference view: its button (the map is made once the event loop is free), then
        # the key turns it off and the engine's colours are on the screen again
        win.click(s["buttons"]["difference"]["px"])
        s = win.wait("the heat map", lambda s: s["difference"]["shown"])
        assert s["difference"]["pixels"] > 1000 and "every pixel" in s["difference"]["advice"]
        win.key("d")
        s = win.wait("the live view", lambda s: not s["difference"]["on"])
        check_probe(win, mesh)

        win.key("h")
        s = win.wait("the help overlay", lambda s: s["help_visible"])
        assert not s["errors"]

        win.key("q")
        assert win.proc.wait(timeout=STEP_TIMEOUT) == 0
        log = win.log.read_text(errors="replace")
        assert "exit-after" not in log and "Traceback" not in log, log
    finally:
        win.close()
