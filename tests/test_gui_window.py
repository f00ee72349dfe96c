"""The window, for real: a Qt window with OpenGL under Xvfb (`xvfb-run -a python -m pytest
tests/test_gui_window.py`), the numpy solver on a small grid. Each control must change what it
should: the body (mask), the readouts, the plot."""
from __future__ import annotations

import math
import os
import subprocess
import sys

import numpy as np
import pytest

from gui_fixtures import GRID, solid_mask, wheel   # the `window` fixture comes from gui_fixtures too (conftest)

pytestmark = pytest.mark.gui


def test_window_opens_runs_and_shows_a_live_field(window, qtbot):
    from feelflow.app.gui.selftest import field_is_alive

    assert "llvmpipe" in window.viewport.renderer() or window.viewport.renderer() != "no GL"
    qtbot.waitUntil(lambda: window.sim.solver.time > 300, timeout=30000)   # the wind ramps up
    ok, why = field_is_alive(window)
    assert ok, why
    assert window.viewport.frames > 0


def test_shape_size_and_angle_controls_change_the_mask(window, qtbot):
    panel, sim = window.panel, window.sim
    before = solid_mask(sim)
    panel.shape.setCurrentIndex(panel.shape.findData("plate"))
    assert sim.params.shape == "plate" and sim.shape.kind == "plate"
    plate = solid_mask(sim)
    assert not np.array_equal(before, plate)
    panel.size.setValue(20)
    assert sim.shape.length == 20
    assert solid_mask(sim).sum() > plate.sum()
    tall = solid_mask(sim)
    panel.angle.setValue(90)
    qtbot.waitUntil(lambda: abs(sim.angle - math.pi / 2) < 1e-9, timeout=5000)
    flat = solid_mask(sim)
    ys, xs = np.nonzero(flat)
    ty, tx = np.nonzero(tall)
    assert np.ptp(xs) > np.ptp(tx) and np.ptp(ys) < np.ptp(ty)   # lying along the flow now


def test_wind_and_viscosity_change_re_and_ma(window):
    panel, sim = window.panel, window.sim
    panel.wind.setValue(0.08)
    assert sim.params.wind == pytest.approx(0.08)
    window.loop.readouts.refresh()
    assert panel.reynolds.text() == f"Re = {0.08 * 12 / sim.params.nu:.0f}"
    assert "Ma = 0.139" in panel.mach.text()
    panel.viscosity.setValue(0.04)
    window.loop.readouts.refresh()
    assert sim.config.nu == pytest.approx(0.04)
    assert panel.reynolds.text() == f"Re = {0.08 * 12 / 0.04:.0f}"


def test_grid_and_wall_controls_rebuild_the_solver(window):
    panel, sim = window.panel, window.sim
    panel.wall.setCurrentIndex(panel.wall.findData("free_slip"))
    assert sim.config.y_boundary == "free_slip"
    panel.grid.setCurrentIndex(panel.grid.findData("192x96"))
    assert (sim.config.nx, sim.config.ny) == (192, 96)
    assert sim.solver.distributions().shape == (9, 96, 192)


def test_force_model_selector_drives_plot_and_readouts(window, qtbot):
    panel, sim, plot = window.panel, window.sim, window.plot
    panel.model.setCurrentIndex(panel.model.findData("pressure"))
    n0 = len(sim.history)
    qtbot.waitUntil(lambda: len(sim.history) > n0 + 5, timeout=10000)
    window.loop.readouts.refresh()
    assert set(sim.solver.forces()) == {"pressure"}
    _, drag, _ = sim.history.drag_lift("pressure")
    assert np.isfinite(drag[-3:]).all()
    assert {k[0] for k in plot.time_views.curves} == {"pressure"}
    assert panel.drag.text() != "\u2013"
    panel.compare_all.setChecked(True)
    qtbot.waitUntil(lambda: len(sim.history.forces) == 3 and len(sim.history) > n0 + 10, timeout=10000)
    plot.refresh(force=True)
    assert {k[0] for k in plot.time_views.curves} == {"momentum_exchange", "macroscopic", "pressure"}


def test_dragging_moves_the_body_and_hold_still_freezes_it(window, qtbot):
    from feelflow.app.gui.selftest import send_mouse

    sim, vp = window.sim, window.viewport
    start = sim.pos
    a = vp.to_widget(*start)
    b = vp.to_widget(start[0] + 30, start[1] + 5)
    send_mouse(vp, "press", a)
    send_mouse(vp, "move", b)
    assert sim.target == pytest.approx((start[0] + 30, start[1] + 5), abs=0.5)
    qtbot.waitUntil(lambda: sim.pos[0] - start[0] > 4, timeout=20000)   # follows through the spring
    assert sim.pos[1] > start[1]
    send_mouse(vp, "release", b)
    assert sim.target is None
    window.panel.hold_still.setChecked(True)
    still, t = sim.pos, sim.solver.time
    send_mouse(vp, "press", vp.to_widget(*still))
    send_mouse(vp, "move", vp.to_widget(still[0] - 30, still[1]))
    qtbot.waitUntil(lambda: sim.solver.time > t + 50, timeout=20000)
    send_mouse(vp, "release", vp.to_widget(still[0] - 30, still[1]))
    assert sim.pos == still


def test_wheel_rotates_the_body(window, qtbot):
    sim = window.sim
    wheel(window, 5)
    assert sim.angle_target == pytest.approx(math.radians(10))
    qtbot.waitUntil(lambda: sim.angle > math.radians(1), timeout=10000)


def _polygon_window(window):
    panel = window.panel
    panel.shape.setCurrentIndex(panel.shape.findData("polygon"))
    assert window.sim.params.shape == "polygon" and window.sim.polygon is not None
    return window.sim


def test_polygon_edit_undo_redo_and_invalid_refused(window, monkeypatch):
    from PySide6.QtWidgets import QMessageBox

    sim = _polygon_window(window)
    first = list(sim.polygon)
    moved = [(x * 1.5, y) for x, y in first]
    assert window.bodies.edit_polygon(moved)
    assert sim.shape.vertices == tuple(moved)
    window.undo.undo()
    assert list(sim.polygon) == first and sim.shape.vertices == tuple(first)
    window.undo.redo()
    assert sim.shape.vertices == tuple(moved)
    warnings = []
    monkeypatch.setattr(QMessageBox, "warning", lambda *a, **k: warnings.append(a[2]))
    bow_tie = [(-5, -5), (5, 5), (5, -5), (-5, 5)]
    assert not window.bodies.edit_polygon(bow_tie)
    assert warnings and "kept" in warnings[0]
    assert sim.shape.vertices == tuple(moved)     # previous shape kept
    assert window.undo.count() == 1


def test_vertex_handles_move_add_delete_and_undo(window, qtbot):
    from PySide6.QtCore import Qt

    from feelflow.app.gui.selftest import send_mouse

    sim = _polygon_window(window)
    window.panel.edit.setChecked(True)
    assert window.viewport.editing and sim.hold_still
    vp = window.viewport
    before = list(sim.polygon)
    wx, wy = vp.body_to_world([before[2]])[0]
    a = vp.to_widget(wx, wy)
    b = vp.to_widget(wx + 4, wy + 3)
    send_mouse(vp, "press", a)
    send_mouse(vp, "move", b)
    send_mouse(vp, "release", b)
    assert sim.polygon[2] != before[2] and len(sim.polygon) == len(before)
    send_mouse(vp, "press", b, Qt.RightButton)          # delete the vertex
    assert len(sim.polygon) == len(before) - 1
    from PySide6.QtTest import QTest

    window.activateWindow()
    vp.setFocus()
    qtbot.waitUntil(vp.hasFocus, timeout=5000)
    QTest.keyClick(vp, Qt.Key_Z, Qt.ControlModifier)     # Ctrl+Z twice: back to the start
    QTest.keyClick(vp, Qt.Key_Z, Qt.ControlModifier)
    assert [tuple(v) for v in sim.polygon] == [tuple(v) for v in before]
    QTest.keyClick(vp, Qt.Key_Z, Qt.ControlModifier | Qt.ShiftModifier)   # Ctrl+Shift+Z redoes the move
    assert sim.polygon[2] != before[2] and len(sim.polygon) == len(before)


def test_screenshot_shows_the_body_where_it_is(window, qtbot, tmp_path):
    from PySide6.QtGui import QImage

    from feelflow.app.gui.overlay import BODY_FILL

    sim = window.sim
    window.panel.hold_still.setChecked(True)
    window.panel.arrows.setChecked(False)      # the arrows start at the body centre
    sim.pos = (40.0, 30.0)
    window.sim.set_shape()
    window.viewport.update()
    path = tmp_path / "shot.png"
    window.exports.save_screenshot(str(path))
    image = QImage(str(path))
    origin = window.viewport.mapTo(window, window.viewport.rect().topLeft())
    centre = window.viewport.to_widget(*sim.pos)
    colour = image.pixelColor(int(centre.x()) + origin.x(), int(centre.y()) + origin.y())
    assert (colour.red(), colour.green(), colour.blue()) == (BODY_FILL.red(), BODY_FILL.green(), BODY_FILL.blue())
    far = window.viewport.to_widget(110.0, 10.0)
    colour = image.pixelColor(int(far.x()) + origin.x(), int(far.y()) + origin.y())
    assert (colour.red(), colour.green(), colour.blue()) != (BODY_FILL.red(), BODY_FILL.green(), BODY_FILL.blue())


def test_nan_pauses_says_so_and_resets(window, qtbot, monkeypatch):
    from PySide6.QtWidgets import QMessageBox

    asked = []
    monkeypatch.setattr(QMessageBox, "question", lambda *a, **k: asked.append(a[2]) or QMessageBox.Reset)
    f = window.sim.solver.distributions()
    f[:, 10:20, 60:70] = np.nan
    window.sim.solver.solver.set_distributions(f)
    qtbot.waitUntil(lambda: bool(asked), timeout=10000)
    assert "unstable" in asked[0]
    qtbot.waitUntil(lambda: window.sim.solver.time > 5, timeout=10000)
    assert np.isfinite(window.sim.field_rgba()).all()
    assert not window.loop.paused


def test_space_pauses_and_r_resets(window, qtbot):
    from PySide6.QtCore import Qt
    from PySide6.QtTest import QTest

    def focused():   # ask again while waiting: a window left by an earlier test may take the activation first
        if not window.viewport.hasFocus():
            window.raise_()
            window.activateWindow()
            window.viewport.setFocus()
        return window.viewport.hasFocus()

    qtbot.waitUntil(focused, timeout=10000)
    QTest.keyClick(window.viewport, Qt.Key_Space)
    assert window.loop.paused
    t = window.sim.solver.time
    qtbot.wait(200)
    assert window.sim.solver.time == t
    QTest.keyClick(window.viewport, Qt.Key_R)
    assert window.sim.solver.time == 0 and len(window.sim.history) == 0
    QTest.keyClick(window.viewport, Qt.Key_Space)
    assert not window.loop.paused


def test_shape_save_and_load_round_trip(window, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QMessageBox

    sim = _polygon_window(window)
    window.bodies.edit_polygon([(x * 1.2, y * 0.8) for x, y in sim.polygon])
    verts = sim.shape.vertices
    path = tmp_path / "body.json"
    window.exports.save_shape(str(path))
    window.panel.shape.setCurrentIndex(window.panel.shape.findData("cylinder"))
    assert sim.shape.kind == "cylinder"
    assert window.exports.load_shape(str(path))
    assert sim.shape.kind == "polygon" and np.allclose(sim.shape.vertices, verts)
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    warnings = []
    monkeypatch.setattr(QMessageBox, "warning", lambda *a, **k: warnings.append(a[2]))
    assert not window.exports.load_shape(str(bad))
    assert warnings and np.allclose(sim.shape.vertices, verts)


def test_plot_exports_csv_and_png(window, qtbot, tmp_path):
    window.plot.refresh(force=True)
    window.plot.export_csv(tmp_path / "f.csv")
    lines = (tmp_path / "f.csv").read_text().splitlines()
    assert lines[0].startswith("step,body_vx") and "momentum_exchange_drag" in lines[0]
    assert len(lines) == len(window.sim.history) + 1
    window.plot.export_png(tmp_path / "f.png")
    assert (tmp_path / "f.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_settings_are_remembered(qtbot, tmp_path):
    from PySide6.QtCore import QSettings

    from feelflow.app.gui.main_window import MainWindow
    from feelflow.app.model.simulation import Params

    path = str(tmp_path / "settings.ini")
    w = MainWindow(backend="numpy", settings=QSettings(path, QSettings.IniFormat), params=Params(grid=GRID, size=12))
    qtbot.addWidget(w)
    w.show()
    qtbot.waitUntil(lambda: w.sim is not None, timeout=20000)
    w.panel.wind.setValue(0.07)
    w.panel.display.setCurrentIndex(w.panel.display.findData("vorticity"))
    w.panel.shape.setCurrentIndex(w.panel.shape.findData("polygon"))
    edited = [(x * 1.3, y) for x, y in w.sim.polygon]
    assert w.bodies.edit_polygon(edited)
    w.remember()
    w2 = MainWindow(backend="numpy", settings=QSettings(path, QSettings.IniFormat))
    qtbot.addWidget(w2)
    assert w2.params.wind == pytest.approx(0.07) and w2.loop.display.mode == "vorticity"
    assert w2.panel.wind.value() == pytest.approx(0.07) and w2.params.grid == GRID
    w.loop.timer.stop()
    w2.show()                                   # the custom polygon comes back too
    qtbot.waitUntil(lambda: w2.sim is not None, timeout=20000)
    assert w2.sim.params.shape == "polygon" and np.allclose(w2.sim.shape.vertices, edited)
    w2.loop.timer.stop()


def test_without_a_display_one_line_and_exit_2():
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    r = subprocess.run([sys.executable, "-m", "feelflow.app"], env=env, capture_output=True, text=True, timeout=60)
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1 and "display" in r.stderr and "Traceback" not in r.stderr


@pytest.mark.parametrize("key", ["drag_speed", "shape_matters", "lift", "vortex_street", "seed_protocol", "models"])
def test_each_lesson_preset_loads_its_scene_and_runs(window, qtbot, key):
    from feelflow.app.model.presets import PRESETS
    from feelflow.app.model.scene import load_scene

    assert window.lessons.apply(key)
    scene = load_scene(PRESETS[key].path)
    sim = window.sim
    assert (sim.config.nx, sim.config.ny) == (scene.config.nx, scene.config.ny)
    assert sim.shape.kind == scene.body.kind and sim.config.nu == pytest.approx(scene.config.nu)
    assert window.loop.display.mode == PRESETS[key].display
    qtbot.waitUntil(lambda: sim.solver.time > 30, timeout=20000)
    if key == "seed_protocol":
        assert sim.runner is not None and sim.script_phase()[2] == "stopped"
    if key == "drag_speed":
        assert sim.sweep is not None and sim.params.wind == pytest.approx(0.02)


def test_seed_protocol_moves_the_body_with_the_stream(window, qtbot):
    assert window.lessons.apply("seed_protocol")
    sim = window.sim
    x0 = sim.pos[0]
    sim.runner.t = 2500 - 5           # skip the first (stopped) phase: the script is a plain object
    qtbot.waitUntil(lambda: sim.pos[0] > x0 + 1, timeout=20000)
    assert sim.script_phase()[2] == "moving with the stream"


@pytest.mark.gl
def test_gl_backend_runs_in_the_widgets_own_context(qtbot, tmp_path):
    from PySide6.QtCore import QSettings

    from feelflow.app.gui.main_window import MainWindow
    from feelflow.app.gui.selftest import field_is_alive
    from feelflow.app.model.simulation import Params

    w = MainWindow(backend="gl", settings=QSettings(str(tmp_path / "s.ini"), QSettings.IniFormat),
                   params=Params(grid=GRID, size=12))
    qtbot.addWidget(w)
    w.show()
    qtbot.waitUntil(lambda: w.sim is not None and w.sim.solver.time > 20, timeout=30000)
    assert w.sim.solver.name == "gl" and w.sim.solver.gl_context is w.viewport.ctx
    assert w.viewport.field_texture is w.sim.solver.field_texture()
    ok, why = field_is_alive(w)
    assert ok, why
    w.loop.timer.stop()


def test_haptic_device_moves_the_body_feels_the_force_and_unplugging_falls_back_to_mouse(window, qtbot):
    panel = window.panel
    i = panel.input.findData("sim://diyhid")
    assert i > 0, [panel.input.itemData(k) for k in range(panel.input.count())]
    panel.input.setCurrentIndex(i)
    dev = window.inputs.device
    assert dev is not None and dev.url == "sim://diyhid"
    qtbot.waitUntil(lambda: window.sim.target is not None and dev.loop.status().samples > 5, timeout=20000)
    assert dev.loop.status().running
    assert dev.loop.status().running
    window.inputs.stop_device_force()      # Esc: the force goes to zero at once
    qtbot.waitUntil(lambda: dev.loop.status().state == "stopped" and dev.loop.status().force == (0.0, 0.0),
                    timeout=5000)
    dev.loop.simulate_unplug()             # the real disconnect path of the simulated board
    qtbot.waitUntil(lambda: window.inputs.device is None, timeout=10000)
    assert panel.input.currentData() == "mouse"
    assert "disconnected" in panel.input_note.text()


def test_recording_a_session_saves_inputs_parameters_and_forces(window, qtbot, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QFileDialog

    from feelflow.app.gui.selftest import send_mouse
    from feelflow.app.sessions import load_session

    path = tmp_path / "lesson.ffsession"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (str(path), ""))
    window.actions.record.trigger()
    assert window.sim.solver.recorder is not None
    t0 = window.sim.solver.time
    vp, sim = window.viewport, window.sim
    send_mouse(vp, "press", vp.to_widget(*sim.pos))
    send_mouse(vp, "move", vp.to_widget(sim.pos[0] + 20, sim.pos[1]))
    qtbot.waitUntil(lambda: sim.solver.time > t0 + 100, timeout=20000)
    send_mouse(vp, "release", vp.to_widget(sim.pos[0], sim.pos[1]))
    window.panel.wind.setValue(0.06)
    t1 = sim.solver.time
    qtbot.waitUntil(lambda: sim.solver.time > t1 + 50, timeout=20000)
    window.actions.record.trigger()
    assert window.sim.solver.recorder is None and path.exists()
    session = load_session(path)
    names = [p["name"] for p in session.parameters]
    assert "inflow_speed" in names
    assert len(session.inputs["step"]) > 0 and len(session.forces["step"]) > 0
    assert session.steps > 100


def test_a_backend_that_cannot_run_is_a_dialog_and_a_clean_close(qtbot, tmp_path, monkeypatch):
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QMessageBox

    from feelflow.app.gui.main_window import MainWindow

    shown = []
    monkeypatch.setattr(QMessageBox, "critical", lambda *a, **k: shown.append(a[2]))
    w = MainWindow(backend="no-such-backend", settings=QSettings(str(tmp_path / "s.ini"), QSettings.IniFormat))
    qtbot.addWidget(w)
    w.show()
    qtbot.waitUntil(lambda: bool(shown), timeout=20000)
    assert "cannot run here" in shown[0] and "unknown backend" in shown[0]
    assert w.sim is None and w.startup_error
    qtbot.waitUntil(lambda: not w.isVisible(), timeout=5000)


def test_the_outlet_zone_is_marked_where_the_sponge_begins(window, qtbot, tmp_path):
    """A dashed line at the first sponge column (and a label): the flow beyond it is the outlet's."""
    from PySide6.QtGui import QImage

    cfg = window.sim.config
    view = window.viewport
    x = view.outlet_zone_x()
    assert x == pytest.approx(view.to_widget(cfg.nx - cfg.sponge_cells - 0.5, 0.0).x())
    path = tmp_path / "shot.png"
    window.exports.save_screenshot(str(path))
    image = QImage(str(path))
    origin = view.mapTo(window, view.rect().topLeft())
    r = view.lattice_rect()
    rows = range(int(r.top()) + 2, int(r.bottom()) - 30)

    def brightness(px, py):
        c = image.pixelColor(int(px) + origin.x(), int(py) + origin.y())
        return c.red() + c.green() + c.blue()

    on_line = sum(abs(brightness(x, y) - brightness(x - 4, y)) > 40 for y in rows)
    off_line = sum(abs(brightness(x - 8, y) - brightness(x - 12, y)) > 40 for y in rows)
    assert on_line > 0.3 * len(rows) and off_line < 0.05 * len(rows), (on_line, off_line, len(rows))
