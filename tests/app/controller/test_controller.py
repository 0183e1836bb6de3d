"""The controller's flows with no GUI toolkit (explorer.app.controller): open, save, export,
undo across flows, the difference scheduling with a fake worker, compare, and one update per
change, through fake ports that record what the controller asked of its front end."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from helpers.controllers import SIZE, FakeView, icosphere_controller

from explorer.app import model as M
from explorer.app.controller import ports as P
from explorer.app.difference import Result
from explorer.core.errors import ExplorerError
from explorer.geometry import meshes as G


@pytest.fixture(scope="module")
def mesh():
    return G.get_mesh("icosphere", 2)


@pytest.fixture
def ctl(mesh, tmp_path, monkeypatch):
    c = icosphere_controller(mesh, FakeView(mesh.n_vertices), tmp_path, monkeypatch, 2)
    front, view, worker = c.ports.dialogs, c.ports.view, c.ports.worker
    c.start()
    c.front, c.view, c.worker = front, view, worker
    return c


def kd(c) -> float:
    return c.state.material.scalars()[1]


def test_the_fakes_implement_the_ports(ctl):
    assert isinstance(ctl.front, P.Dialogs) and isinstance(ctl.front, P.Messages)
    assert isinstance(ctl.front, P.Choices) and isinstance(ctl.front, P.Progress)
    assert isinstance(ctl.view, P.View) and isinstance(ctl.worker, P.Worker)
    assert ctl.front.presets and "icosphere" in ctl.front.meshes
    assert ctl.state.camera is not None  # framed for the view port's aspect


def test_a_slider_run_is_one_step_and_one_update_each(ctl):
    before = ctl.state
    shown, frames = len(ctl.view.shown), ctl.view.frames
    for v in (0.7, 0.6, 0.5):
        assert ctl.set_value("kd", v)
    ctl.release()
    assert kd(ctl) == pytest.approx(0.5)
    assert len(ctl.view.shown) - shown == 3 and ctl.view.frames - frames == 3
    assert ctl.front.history == ("kd", None)
    ctl.undo()
    assert ctl.state == before and ctl.front.history[0] is None
    ctl.redo()
    assert kd(ctl) == pytest.approx(0.5)


def test_the_viewer_made_infinite_keeps_the_cameras_perspective_when_the_mesh_is_framed(ctl):
    """local_viewer off: the engine's viewer is infinitely far along the view, but a mesh
    framed anew keeps the perspective camera (the infinite viewer alone would frame it with a
    parallel one), and turning it on puts the viewer back at the camera."""
    assert not ctl.state.camera.parallel and ctl.state.scene.viewer.local
    assert ctl.set_value("local_viewer", False, merge=False)
    assert ctl.state.scene.viewer.to_viewer is not None and not ctl.state.camera.parallel
    assert ctl.files.choose_mesh("cube")
    assert not ctl.state.camera.parallel and not ctl.state.scene.viewer.local
    ctl.undo()
    ctl.undo()
    assert ctl.state.local_viewer and ctl.state.scene.viewer.local


def test_a_refused_value_is_said_and_the_controls_show_the_state(ctl):
    assert not ctl.set_value("kd", 7.0)
    assert ctl.errors and "kd" in ctl.errors[-1]
    assert ctl.front.messages[-1][0] == "error"
    assert ctl.view.shown[-1] == (None, ctl.state)  # the controls show the state again
    with pytest.raises(ExplorerError, match="no control"):
        ctl.set_value("glossiness", 1.0)


def test_an_edit_that_works_takes_the_last_error_away(ctl):
    """A refused value is said until an edit works: then the message goes (an empty message,
    which the front ends show as none and do not log); later edits say nothing more."""
    assert not ctl.set_value("kd", 7.0)
    assert ctl.front.messages[-1][0] == "error"
    assert ctl.set_value("kd", 0.4)
    assert ctl.front.messages[-1] == ("info", "")
    n = len(ctl.front.messages)
    assert ctl.set_value("kd", 0.5)
    assert len(ctl.front.messages) == n  # nothing more to take away
    ctl.errors.clear()


def test_open_save_and_undo_across_flows(ctl, tmp_path):
    ctl.set_value("kd", 0.3)
    ctl.release()
    path = tmp_path / "s.yaml"
    assert ctl.files.save_session_as(path) == path and path.is_file()
    assert ctl.front.recent == [str(path)]
    ctl.set_value("kd", 0.7)
    ctl.release()
    ctl.files.open_file(path)
    assert kd(ctl) == pytest.approx(0.3) and ctl.session_path == path
    assert any("opened session" in t for _, t in ctl.front.messages)
    ctl.undo()
    assert kd(ctl) == pytest.approx(0.7)
    ctl.undo()
    assert kd(ctl) == pytest.approx(0.3)
    # saving over a file asks first: no leaves it as it was
    stamp = path.stat().st_mtime_ns
    ctl.front.answers["yes"].append(False)
    assert ctl.files.save_session_as(path) is None and path.stat().st_mtime_ns == stamp
    # a name from the dialog; giving up writes nothing
    ctl.front.answers["path"].append(None)
    assert ctl.files.save_session_as() is None
    with pytest.raises(ExplorerError, match="no such file"):
        ctl.files.open_file(tmp_path / "missing.yaml")


def test_open_a_mesh_file_and_a_preset(ctl, tmp_path):
    obj = tmp_path / "tri.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n")
    ctl.files.open_file(obj)
    assert ctl.state.mesh == str(obj) and str(obj) in ctl.front.meshes
    assert ctl.view.shown[-1][1].mesh == str(obj)
    name = next(p.name for p in ctl.presets if p.name != ctl.state.preset)
    ctl.pick_preset(name)
    assert ctl.state.preset == name
    ctl.undo()
    ctl.undo()
    assert ctl.state.mesh == "icosphere"


def test_save_preset_and_export(ctl, tmp_path):
    ctl.set_value("kd", 0.25)
    ctl.front.answers["text"].append("mine")
    written = ctl.files.save_preset_as()
    assert written.name == "mine.yaml" and ctl.state.preset == "mine" and not ctl.state.edited
    out = ctl.files.export_material(tmp_path / "m.mtl")
    assert out.is_file() and "Kd" in out.read_text()
    png = ctl.files.export_render(tmp_path / "v.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    ctl.front.answers["yes"].append(False)  # asked before replacing: no
    assert ctl.files.export_render(tmp_path / "v.png") is None
    with pytest.raises(ExplorerError, match="must end in"):
        ctl.files.export_render(tmp_path / "v.jpg")
    shot = ctl.files.screenshot()
    assert shot.parent == tmp_path and shot.suffix == ".png"


def result_for(job) -> Result:
    return Result(job, np.zeros((SIZE[1], SIZE[0], 3), np.uint8), None, "advice")


def test_difference_is_asked_once_per_change_and_stale_results_are_dropped(ctl):
    ctl.toggle_difference()
    assert len(ctl.worker.jobs) == 1
    first = ctl.worker.jobs[-1]
    ctl.set_value("kd", 0.4)
    assert len(ctl.worker.jobs) == 2  # one request per change
    ctl.camera_moved(ctl.state.camera)  # a frame, same camera and size: nothing asked
    assert len(ctl.worker.jobs) == 2
    ctl.on_difference(result_for(first))  # stale: for the state before
    assert ctl.difference is None
    assert all(r is None for r, on in ctl.view.differences if on)
    frames = ctl.view.frames
    latest = result_for(ctl.worker.jobs[-1])
    ctl.on_difference(latest)
    assert ctl.difference is latest and ctl.view.differences[-1] == (latest, True)
    assert ctl.view.frames == frames + 1
    # a drag waits for its end; the end asks once
    ctl.view.drag = True
    ctl.set_value("kd", 0.45)
    ctl.set_value("kd", 0.5)
    assert len(ctl.worker.jobs) == 2
    assert ctl.view.differences[-1] == (None, True)  # the live view, not the old map
    ctl.view.drag = False
    ctl.end_drag()
    assert len(ctl.worker.jobs) == 3
    # a resized view asks again at its next frame
    ctl.view.px = (80, 60)
    ctl.camera_moved(ctl.state.camera)
    assert len(ctl.worker.jobs) == 4 and ctl.worker.jobs[-1].size == (80, 60)
    ctl.toggle_difference()
    assert ctl.worker.cancels >= 1 and ctl.view.differences[-1] == (None, False)


def test_a_failed_difference_is_said_and_turns_the_view_off(ctl):
    ctl.toggle_difference()
    job = ctl.worker.jobs[-1]
    ctl.on_difference(Result(job, error=ValueError("no room")))
    assert not ctl.state.difference
    assert ctl.errors[-1] == "difference view: ValueError: no room"


def test_compare_swap_and_undo(ctl):
    name = next(p.name for p in ctl.presets if p.name != ctl.state.preset)
    ctl.toggle_compare()
    assert ctl.state.compare is not None
    ctl.act(M.set_compare_preset, name, next(p.material for p in ctl.presets if p.name == name))
    a, b = ctl.state.preset, ctl.state.compare_preset
    ctl.swap_sides()
    assert (ctl.state.preset, ctl.state.compare_preset) == (b, a)
    ctl.undo()
    assert (ctl.state.preset, ctl.state.compare_preset) == (a, b)
    ctl.toggle_compare()
    assert ctl.state.compare is None


def test_turntable_through_the_progress_port(ctl, tmp_path):
    out = tmp_path / "spin.gif"
    job = ctl.files.export_turntable(out, 2, size=(24, 20))
    assert job.stage == "written" and out.is_file() and job.dialog == "handle"
    assert "wrote" in ctl.front.messages[-1][1]


def test_the_controller_runs_without_any_gui_toolkit(tmp_path):
    code = (
        "import sys, numpy as np; from explorer.app import controller; "
        "from explorer.app.start import first_state; "
        "print(sorted({m.split('.')[0] for m in sys.modules} & "
        "{'PySide6', 'pyvistaqt', 'trame', 'qtpy'}))"
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"


@pytest.mark.parametrize("kind", ["fifo", "device link", "folder"])
def test_the_last_session_never_replaces_what_is_not_a_kept_session(ctl, tmp_path, kind, caplog):
    """Anything but a regular file at the last-session path (a FIFO, a link to a device, a
    folder) is left as it is when the explorer closes, with a warning; a kept session is
    replaced."""
    import logging

    path = tmp_path / "special.yaml"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "device link":
        path.symlink_to("/dev/null")
    else:
        path.mkdir()
    before = os.lstat(path)
    ctl.last_session = path
    with caplog.at_level(logging.WARNING):
        ctl.files.keep_last_session()
    after = os.lstat(path)
    assert (after.st_mode, after.st_ino) == (before.st_mode, before.st_ino)
    assert "could not keep the last session" in caplog.text
    kept = tmp_path / "kept.yaml"
    kept.write_text("old")
    ctl.last_session = kept
    ctl.files.keep_last_session()
    assert "scene" in kept.read_text()


def test_a_last_session_path_the_system_refuses_is_a_warning_on_stop(ctl, tmp_path, caplog):
    """A last-session name too long for the file system (``OSError`` 36) raised out of the
    window's close and the web server's stop; it is one warning, and nothing is written."""
    import logging

    ctl.last_session = tmp_path / ("x" * 300 + ".yaml")
    with caplog.at_level(logging.WARNING):
        ctl.files.keep_last_session()
    assert "could not keep the last session" in caplog.text
    assert "File name too long" in caplog.text
    assert list(tmp_path.iterdir()) == []
