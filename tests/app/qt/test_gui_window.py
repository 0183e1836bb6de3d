"""The explorer in a real X window (Xvfb), driven by xdotool like a person would.

``phong-explorer gui`` on a private Xvfb server: drag the kd slider, undo with Ctrl+Z, redo
with Ctrl+Shift+Z, quit with ``q`` in the view (the window keeps the session), reopen it with
``gui --last`` and check it is the same, then open the ``--state-file`` as a session too.
After each step the test polls the app's state file (written atomically after each frame) and
the window's pixels (``xwd``), never sleeping a fixed time: the pixel where the vertex facing
the camera lands must lie within the colours the engine gives the triangles around that vertex,
computed here from the reported scene.

Needs ``Xvfb``, ``xdotool`` and ``xwd`` (``apt-get install -y xvfb xdotool x11-apps``) and the
Qt xcb libraries; skipped with the reason when a tool is missing.
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
from explorer.app import session as S
from explorer.app import start as gui
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
    proc, name = gui.start_xvfb()
    yield name
    proc.terminate()
    proc.wait(timeout=10)


class Window:
    """The app under test: its process, its X window and its state file."""

    def __init__(self, display, tmp: Path, *extra, name="state.json"):
        self.env = {k: v for k, v in os.environ.items() if k != "VTK_DEFAULT_OPENGL_WINDOW"}
        self.env.update(DISPLAY=display, PHONG_EXPLORER_MATERIALS=str(tmp / "presets"),
                        QT_QPA_PLATFORM="xcb",
                        PHONG_EXPLORER_LAST_SESSION=str(tmp / "last.yaml"))  # fmt: skip
        self.state_file = tmp / name
        self.log = tmp / f"{name}.log"
        cmd = [
            sys.executable, "-m", "explorer.cli", "gui", *(extra or ("--mesh", MESH)),
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
            "search", "--sync", "--onlyvisible", "--name", gui.TITLE, timeout=START_TIMEOUT
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
        # no window manager: X's focus follows the pointer (PointerRoot), so the key goes, as
        # a real key press (XTEST), to the window under the pointer, which is moved inside it
        s = self.state()
        x, y, w, h = s["window"]["view_box"] if s else (10, 30, 10, 10)
        self.xdotool(*self.move(x + 10, y + h - 10), "key", name)

    def focus_view(self) -> None:
        """A click in the view (no drag: the camera stays) gives it the keyboard."""
        x, y, w, h = self.state()["window"]["view_box"]
        self.click((x + 10, y + h - 10))

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
        assert s["window"]["n_vertices"] == mesh.n_vertices
        scene = explorer.load_scene(s["scene"])
        colours = to_bytes(explorer.shade(scene, mesh.positions, mesh.normals)).astype(int)
        i = s["window"]["probe"]["vertex"]
        x, y = s["window"]["probe"]["px"]
        around = np.unique(mesh.faces[(mesh.faces == i).any(axis=1)])
        lo = colours[around].min(axis=0) - 2
        hi = colours[around].max(axis=0) + 2
        pixel = win.pixels()[y, x].astype(int)
        if (pixel >= lo).all() and (pixel <= hi).all() and win.state() == s:
            return s
        if time.monotonic() > end:
            pytest.fail(f"pixel ({x}, {y}) is {pixel}, the engine says {lo + 2}..{hi - 2}")
        time.sleep(0.05)


def kd(s) -> float:
    return max(s["scene"]["material"]["diffuse"])


@pytest.mark.slow  # a real X window driven with xdotool, waiting for each frame
def test_real_window(display, tmp_path):
    mesh = M.get_mesh(MESH, gui.MESH_CHOICES[MESH], uv=True)  # as the start loads it
    win = Window(display, tmp_path)
    try:
        win.find()
        s = win.wait("the first frame", lambda s: s["window"]["frame"] >= 1,
                     timeout=START_TIMEOUT)  # fmt: skip
        assert s["mesh"] == MESH and s["preset"] == gui.DEFAULT_PRESET
        assert not s["window"]["errors"]
        check_probe(win, mesh)

        # drag the kd slider's knob 60 pixels to the left: one undo step
        start = kd(s)
        x, y, w, h = s["window"]["widgets"]["kd_slider"]
        knob = x + 8 + start * (w - 16)  # the knob's centre (the groove is inset by the knob)
        win.drag((knob, y + h // 2), (knob - 60, y + h // 2))
        s = win.wait("kd to follow the drag",
                     lambda s: not s["window"]["dragging"] and kd(s) < start - 0.1)  # fmt: skip
        dragged = kd(s)
        check_probe(win, mesh)

        win.key("ctrl+z")
        s = win.wait("undo", lambda s: kd(s) == pytest.approx(start, abs=1e-9))
        assert not s["window"]["can_undo"] and s["window"]["can_redo"]
        check_probe(win, mesh)
        win.key("ctrl+shift+z")
        s = win.wait("redo", lambda s: kd(s) == pytest.approx(dragged, abs=1e-9))
        kept = s

        # q in the view quits; the window keeps the session
        win.focus_view()
        win.key("q")
        assert win.proc.wait(timeout=STEP_TIMEOUT) == 0
        log = win.log.read_text(errors="replace")
        assert "exit-after" not in log and "Traceback" not in log, log
    finally:
        win.close()

    # gui --last reopens it exactly
    again = Window(display, tmp_path, "--last", name="again.json")
    try:
        again.find()
        s = again.wait("the first frame", lambda s: s["window"]["frame"] >= 1,
                       timeout=START_TIMEOUT)  # fmt: skip
        assert s["scene"]["material"] == kept["scene"]["material"]
        assert s["scene"]["lights"] == kept["scene"]["lights"] and s["mesh"] == MESH
        assert s["camera"]["position"] == pytest.approx(kept["camera"]["position"])
        check_probe(again, mesh)
        again.focus_view()
        again.key("ctrl+q")
        assert again.proc.wait(timeout=STEP_TIMEOUT) == 0
    finally:
        again.close()
    state, _ = S.load_session(tmp_path / "state.json")  # the --state-file is a session too
    assert state.scene.material.diffuse == tuple(kept["scene"]["material"]["diffuse"])
