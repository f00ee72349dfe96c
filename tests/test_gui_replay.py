"""Replaying a recorded session in the real window (Xvfb, numpy solver, small grid): the
viewport and the plot show the replayed flow, body and forces, input is refused while it runs,
and Stop replay (Esc) returns to the live tunnel as it was."""
from __future__ import annotations

import dataclasses
import subprocess
import sys

import numpy as np
import pytest

pytestmark = pytest.mark.gui


def record_in_window(window, qtbot, path, monkeypatch):
    """File > Record session: drag the body, change the wind, stop and save to `path`."""
    from PySide6.QtWidgets import QFileDialog

    from feelflow.app.gui.selftest import send_mouse

    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (str(path), ""))
    vp, sim = window.viewport, window.sim
    window.actions.record.trigger()
    t0 = sim.solver.time
    send_mouse(vp, "press", vp.to_widget(*sim.pos))
    send_mouse(vp, "move", vp.to_widget(sim.pos[0] + 15, sim.pos[1] + 4))
    qtbot.waitUntil(lambda: sim.solver.time > t0 + 80, timeout=20000)
    send_mouse(vp, "release", vp.to_widget(*sim.pos))
    window.panel.wind.setValue(0.06)
    t1 = sim.solver.time
    qtbot.waitUntil(lambda: sim.solver.time > t1 + 40, timeout=20000)
    window.actions.record.trigger()
    assert path.exists()


def replayed_values(history, models):
    return np.column_stack([np.asarray(history.forces[m], float) for m in models])


def test_replay_in_the_window_and_stop_returns_to_the_live_tunnel(window, qtbot, tmp_path, monkeypatch):
    from PySide6.QtCore import Qt
    from PySide6.QtTest import QTest
    from PySide6.QtWidgets import QFileDialog

    from feelflow.app.gui.selftest import send_mouse
    from feelflow.app.sessions import load_session

    path = tmp_path / "lesson.ffsession"
    record_in_window(window, qtbot, path, monkeypatch)
    session = load_session(path)
    assert np.ptp(session.inputs["pose"][:, 0]) > 1.0   # the body really moved while recording

    live = window.sim
    window.panel.size.setValue(14)                       # the live scene moves on after recording
    before = (dataclasses.replace(live.params), live.shape, live.shape.to_dict(), live.config, live.pos)
    history_before = list(live.history.time)
    monkeypatch.setattr(QFileDialog, "getOpenFileName", lambda *a, **k: (str(path), ""))
    window.actions.replay.trigger()
    replay = window.replays.replay
    assert replay is not None and window.viewport.sim is replay and window.plot.sim is replay
    assert window.viewport.locked and window.actions.replay_toolbar.isVisible()

    # while it runs: progress in the status bar, the body at the recorded pose of the last row
    seen = []

    def poses_follow_the_recording():
        k = replay.player.row_index      # the row the flow is in (in parts) or last completed
        if k >= 0 and replay.shape is not None:
            seen.append(((replay.shape.x, replay.shape.y), tuple(session.forces["body"][k][:2])))
        return len(seen) >= 3
    qtbot.waitUntil(poses_follow_the_recording, timeout=20000)
    assert all(a == b for a, b in seen), seen[:3]
    assert window.replays.label.text().startswith("Replaying lesson.ffsession: step ")
    assert f"/ {session.steps}" in window.replays.label.text()
    t_live = live.solver.time

    # input is refused: the mouse, the panel, the reset key
    vp = window.viewport
    send_mouse(vp, "press", vp.to_widget(*replay.pos))
    send_mouse(vp, "move", vp.to_widget(replay.pos[0] + 10, replay.pos[1]))
    send_mouse(vp, "release", vp.to_widget(replay.pos[0] + 10, replay.pos[1]))
    assert "the mouse does not move the body" in window.statusBar().currentMessage()
    assert live.target is None
    window.panel.wind.setValue(0.03)
    assert "Replaying lesson.ffsession" in window.statusBar().currentMessage()
    assert window.panel.wind.value() == pytest.approx(before[0].wind) and live.params.wind == before[0].wind
    window.panel.shape.setCurrentIndex(window.panel.shape.findData("plate"))
    assert live.shape is before[1] and window.panel.shape.currentData() == before[0].shape
    window.flow.reset()
    assert live.solver.time == t_live                     # the live flow waits, untouched

    # the end: paused on the last frame, with a message; the plot holds the replayed forces
    qtbot.waitUntil(lambda: replay.done, timeout=30000)
    assert replay.step == session.steps
    assert "finished" in window.replays.label.text() and window.actions.pause.isChecked()
    assert (replay.shape.x, replay.shape.y) == tuple(session.forces["body"][-1][:2])
    h = replay.history
    assert h.time == [int(t) for t in session.forces["step"]]
    values = replayed_values(h, session.models)
    assert np.nanmax(np.abs(values)) > 0
    # numpy: bit for bit, except rows longer than a replay frame's budget, run in parts (their
    # forces are averaged over the parts: equal up to rounding)
    np.testing.assert_allclose(values, session.forces["values"], rtol=1e-12, atol=1e-15)
    curve = window.plot.time_views.curves[(session.models[0], "drag")]
    window.loop.readouts.refresh()
    x, y = curve.getData()
    np.testing.assert_array_equal(x, h.time)                        # the plot shows the replay
    assert np.isfinite(y).all()
    frames = window.viewport.frames
    qtbot.waitUntil(lambda: window.viewport.frames > frames, timeout=5000)

    # Esc: back to the live tunnel, parameters, shape, grid and history as they were
    window.activateWindow()
    vp.setFocus()
    qtbot.waitUntil(vp.hasFocus, timeout=5000)
    QTest.keyClick(vp, Qt.Key_Escape)
    assert window.replays.replay is None and window.viewport.sim is live and window.plot.sim is live
    assert not window.viewport.locked and not window.actions.replay_toolbar.isVisible()
    p, shape, shape_dict, config, pos = before
    assert live.params == p and live.shape is shape and live.shape.to_dict() == shape_dict
    assert live.config == config and live.pos == pos
    assert live.history.time[:len(history_before)] == history_before
    assert window.panel.size.value() == 14 and window.panel.wind.value() == pytest.approx(p.wind)
    assert live.solver.time == t_live
    qtbot.waitUntil(lambda: live.solver.time > t_live + 10, timeout=20000)   # and it runs on
    assert window.viewport.field_texture is not None


def test_a_bad_session_file_is_one_line_and_changes_nothing(window, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QMessageBox

    warnings = []
    monkeypatch.setattr(QMessageBox, "warning", lambda *a, **k: warnings.append((a[1], a[2])))
    bad = tmp_path / "broken.ffsession"
    bad.write_bytes(b"this is not a zip archive")
    live = window.sim
    assert not window.replays.start(str(bad))
    assert len(warnings) == 1
    title, text = warnings[0]
    assert title == "Could not replay the session" and "not a FeelFlow session file" in text and "\n" not in text
    assert window.replays.replay is None and window.viewport.sim is live and not window.viewport.locked
    assert not window.replays.label.isVisible()


@pytest.mark.gl
def test_gl_window_replays_in_its_own_context(qtbot, tmp_path, monkeypatch):
    """The gl backend: the replay runs in the viewport's own GL context and the viewport draws
    the replay's field texture, then the live one again."""
    from PySide6.QtCore import QSettings

    from feelflow.app.gui.main_window import MainWindow
    from feelflow.app.sessions import load_session
    from feelflow.app.model.simulation import Params
    from gui_fixtures import GRID

    w = MainWindow(backend="gl", settings=QSettings(str(tmp_path / "s.ini"), QSettings.IniFormat),
                   params=Params(grid=GRID, size=12))
    qtbot.addWidget(w)
    w.resize(1100, 700)
    w.show()
    qtbot.waitUntil(lambda: w.sim is not None and w.sim.solver.time > 20, timeout=30000)
    path = tmp_path / "gl.ffsession"
    record_in_window(w, qtbot, path, monkeypatch)
    session = load_session(path)
    live_texture = w.sim.solver.field_texture()
    assert w.replays.start(str(path))
    replay = w.replays.replay
    assert replay.solver.name == "gl" and replay.solver.gl_context is w.viewport.ctx
    split_ends = []   # the session steps at which a row run in parts (longer than a frame) ended
    driver, step_part = replay.solver, replay.solver.step_part

    def counting_step_part(k, row_steps):
        done = step_part(k, row_steps)
        if done:
            split_ends.append(driver.clock)
        return done
    driver.step_part = counting_step_part   # before the first frame: replays.start only queued it
    qtbot.waitUntil(lambda: replay.done, timeout=30000)
    assert w.viewport.field_texture is replay.solver.field_texture()
    values = replayed_values(replay.history, session.models)
    recorded = np.asarray(session.forces["values"])
    split = np.isin(np.asarray(session.forces["step"]), split_ends)
    # same backend, same machine: bit for bit, except rows run in parts, whose forces the gl
    # step pass sums over each part in float32 (lbm_step.glsl LINK_SUMS): equal to that rounding,
    # which is relative to the size of the summed link terms (the force's scale), not to a
    # component that happens to be small (a lift near zero)
    np.testing.assert_allclose(values[~split], recorded[~split], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(values[split], recorded[split], rtol=1e-6, atol=1e-6 * np.abs(recorded).max())
    print(f"\n  rows run in parts: {int(split.sum())} of {split.size}", end="")
    w.replays.stop()
    assert w.viewport.field_texture is live_texture
    t = w.sim.solver.time
    qtbot.waitUntil(lambda: w.sim.solver.time > t + 10, timeout=20000)
    w.loop.timer.stop()
    w.loop.slow_timer.stop()


def test_a_haptic_device_is_paused_and_refused_during_a_replay(window, qtbot, tmp_path, monkeypatch):
    """With the simulated DIY board as input: the replay fades its force out (loop 'paused'),
    a device move is refused in the status bar and leaves the replayed body alone; Stop hands
    the body back to the device."""
    path = tmp_path / "dev.ffsession"
    record_in_window(window, qtbot, path, monkeypatch)
    panel = window.panel
    panel.input.setCurrentIndex(panel.input.findData("sim://diyhid"))
    dev = window.inputs.device
    qtbot.waitUntil(lambda: dev.target() is not None and dev.loop.status().samples > 5, timeout=20000)
    assert window.replays.start(str(path))
    qtbot.waitUntil(lambda: dev.loop.status().state == "paused", timeout=5000)
    x, y = dev.target()
    monkeypatch.setattr(dev, "target", lambda: (x + 10.0, y))   # the student pushes the handle
    qtbot.waitUntil(lambda: "the device does not move the body" in window.statusBar().currentMessage(),
                    timeout=5000)
    replay = window.replays.replay
    qtbot.waitUntil(lambda: replay.done, timeout=30000)
    assert window.sim.target is None or window.sim.target != (x + 10.0, y)
    window.replays.stop()
    qtbot.waitUntil(lambda: dev.loop.status().state != "paused", timeout=5000)
    qtbot.waitUntil(lambda: window.sim.target == (x + 10.0, y), timeout=5000)   # live again


def test_an_impossible_event_mid_replay_is_one_line_and_back_to_live(window, qtbot, tmp_path, monkeypatch):
    """A file that loads but asks for the impossible later (the body across the inlet): the
    replay stops with a one-line dialog and the live tunnel is back."""
    from PySide6.QtWidgets import QMessageBox

    from feelflow.app.sessions import load_session, save_session

    path = tmp_path / "lesson.ffsession"
    record_in_window(window, qtbot, path, monkeypatch)
    s = load_session(path)
    k = len(s.inputs["step"]) // 2
    s.inputs["pose"][k, 0] = 1.0          # on the grid, so it loads; across the inlet, so it cannot run
    save_session(s, tmp_path / "edge.ffsession")
    warnings = []
    monkeypatch.setattr(QMessageBox, "warning", lambda *a, **k: warnings.append(a[2]))
    assert window.replays.start(str(tmp_path / "edge.ffsession"))
    qtbot.waitUntil(lambda: window.replays.replay is None, timeout=30000)
    assert len(warnings) == 1 and "cannot be replayed" in warnings[0] and "\n" not in warnings[0]
    assert window.viewport.sim is window.sim and not window.viewport.locked
    t = window.sim.solver.time
    qtbot.waitUntil(lambda: window.sim.solver.time > t + 10, timeout=20000)


def test_the_replay_line_is_not_drawn_under_a_passing_message(window, qtbot, tmp_path, monkeypatch):
    """The startup hint ("Drag the body...") is a passing status message; the replay's progress
    line must not be shown under it (both were drawn on top of each other)."""
    path = tmp_path / "lesson.ffsession"
    record_in_window(window, qtbot, path, monkeypatch)
    window.statusBar().showMessage("Drag the body to move it.", 20000)
    assert window.replays.start(str(path))
    assert window.replays.label.isVisible()
    assert window.statusBar().currentMessage() == ""
    window.replays.stop()


def test_selftest_measures_a_cli_recorded_replay_rows_whole_and_in_parts(tmp_path):
    """`feelflow --selftest gui SESSION` on a session recorded by `feelflow run --record` (a force
    row per 50 steps): the replay runs with rows whole, then in parts, and prints both rates."""
    session = tmp_path / "cli.ffsession"
    r = subprocess.run([sys.executable, "-m", "feelflow.app", "run", "scenes/default.toml", "--steps", "3000", "--backend", "numpy",
                        "--out", str(tmp_path / "f.csv"), "--record", str(session)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    r = subprocess.run([sys.executable, "-m", "feelflow.app", "--selftest", "--seconds", "4", "gui", str(session)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    lines = {kind: line for line in r.stdout.splitlines() for kind in ("rows whole", "long rows in parts")
             if f"replay, {kind}:" in line}
    assert len(lines) == 2, r.stdout
    per_frame = {k: float(v.split("(")[1].split(" steps/frame")[0]) for k, v in lines.items()}
    assert per_frame["long rows in parts"] <= per_frame["rows whole"]


def test_a_recording_stops_at_the_session_bound_says_so_and_saves_a_file_that_opens(
        window, qtbot, tmp_path, monkeypatch):
    """The bound made small (app/sessions/bounds.py MAX_ROWS): the recording stops, the status
    bar and the Record action say so, the tunnel runs on, and choosing Record saves what was
    recorded, which the loader (same bound) opens."""
    from PySide6.QtWidgets import QFileDialog

    from feelflow.app.gui.selftest import send_mouse
    from feelflow.app.sessions import bounds, load_session

    monkeypatch.setattr(bounds, "MAX_ROWS", 30)
    path = tmp_path / "full.ffsession"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (str(path), ""))
    vp, sim = window.viewport, window.sim
    window.actions.record.trigger()
    rec = sim.solver.recorder
    send_mouse(vp, "press", vp.to_widget(*sim.pos))
    send_mouse(vp, "move", vp.to_widget(sim.pos[0] + 15, sim.pos[1] + 4))   # a row of each kind a step
    qtbot.waitUntil(lambda: rec.full is not None and "full" in window.actions.record.text(), timeout=20000)
    assert "stopped" in window.statusBar().currentMessage() and "Record session" in window.statusBar().currentMessage()
    assert window.actions.record.isChecked()
    t = sim.solver.time
    qtbot.waitUntil(lambda: sim.solver.time > t + 20, timeout=20000)   # the tunnel runs on
    send_mouse(vp, "release", vp.to_widget(*sim.pos))
    window.actions.record.trigger()
    assert window.actions.record.text() == "Record session" and not window.actions.record.isChecked()
    s = load_session(path)
    assert max(s.manifest["counts"][k] for k in ("inputs", "parameters", "forces")) == 30
