"""The rotation handle on the body, in the real window (Xvfb, numpy solver, small grid): it shows
when the pointer comes near the body, dragging its knob turns the body by the pointer's angle
(the solid mask follows), Shift snaps to 15 degrees, one drag is one undo step, and it is refused
while a replay shows or a motion script or a haptic device drives the body. The mouse wheel and
the panel's angle box turn the body undoably too: a burst of notches or of edits is one undo step,
and undo gives back the very angle it took away; both are refused while a motion script drives
the body."""
from __future__ import annotations

import math

import numpy as np
import pytest

from gui_fixtures import solid_mask, wheel   # the `window` fixture comes from gui_fixtures too (conftest)

pytestmark = pytest.mark.gui


def knob_after_hover(window):
    """Bring the pointer over the body (the handle appears), then onto the knob; the knob's
    centre and the reference point, widget pixels."""
    from feelflow.app.gui.selftest import send_mouse

    vp, sim = window.viewport, window.sim
    send_mouse(vp, "hover", vp.to_widget(*sim.pos))
    assert vp.handle_shown()
    centre, knob, _ = vp.handle_geometry()
    send_mouse(vp, "hover", knob)
    return centre, knob


def drag_handle(window, degrees: float, moves: int = 12, modifiers=None):
    """Press on the knob and carry it `degrees` counter-clockwise about the reference point."""
    from PySide6.QtCore import QPointF, Qt

    from feelflow.app.gui.selftest import send_mouse

    vp = window.viewport
    modifiers = Qt.NoModifier if modifiers is None else modifiers
    centre, knob = knob_after_hover(window)
    r = math.hypot(knob.x() - centre.x(), knob.y() - centre.y())
    a0 = math.atan2(centre.y() - knob.y(), knob.x() - centre.x())   # widget y is down
    send_mouse(vp, "press", knob)
    assert vp.turn is not None, "the press did not take the handle"
    at = knob
    for k in range(1, moves + 1):
        a = a0 + math.radians(degrees) * k / moves
        at = QPointF(centre.x() + r * math.cos(a), centre.y() - r * math.sin(a))
        send_mouse(vp, "move", at, modifiers=modifiers)
    send_mouse(vp, "release", at, modifiers=modifiers)


def plate(window):
    panel = window.panel
    panel.shape.setCurrentIndex(panel.shape.findData("plate"))
    assert window.sim.shape.kind == "plate" and window.sim.angle == 0.0
    return window.sim


def test_dragging_the_handle_turns_the_body_and_one_undo_turns_it_back(window, qtbot):
    sim = plate(window)
    upright, steps = solid_mask(sim), window.undo.count()
    drag_handle(window, 90)
    assert math.degrees(sim.angle_target) == pytest.approx(90, abs=0.5)
    assert window.undo.count() == steps + 1                        # twelve moves, one undo step
    assert window.panel.angle.value() == 90
    qtbot.waitUntil(lambda: sim.angle == sim.angle_target, timeout=30000)   # it swings there, like the wheel
    lying = solid_mask(sim)
    ys, xs = np.nonzero(lying)
    uy, ux = np.nonzero(upright)
    assert np.ptp(xs) > np.ptp(ux) and np.ptp(ys) < np.ptp(uy)      # along the flow now
    window.undo.undo()
    assert sim.angle_target == pytest.approx(0.0, abs=1e-9) and window.panel.angle.value() == 0
    qtbot.waitUntil(lambda: sim.angle == sim.angle_target, timeout=30000)
    np.testing.assert_array_equal(solid_mask(sim), upright)


def test_shift_snaps_to_15_degrees_and_paused_turns_at_once(window):
    from PySide6.QtCore import Qt

    sim = plate(window)
    window.loop.set_paused(True)
    upright, steps = solid_mask(sim), window.undo.count()
    drag_handle(window, 50, modifiers=Qt.ShiftModifier)
    assert sim.angle == pytest.approx(math.radians(45), abs=1e-12)    # 50 snaps to 45, at once while paused
    assert window.panel.angle.value() == 45 and sim.params.angle_deg == 45
    assert not np.array_equal(solid_mask(sim), upright)
    drag_handle(window, 50)                                        # without Shift: where the pointer is
    assert math.degrees(sim.angle) == pytest.approx(95, abs=0.5)
    assert window.undo.count() == steps + 2
    window.undo.undo()
    assert sim.angle == pytest.approx(math.radians(45), abs=1e-12)
    window.undo.undo()
    assert sim.angle == 0.0 and window.panel.angle.value() == 0
    np.testing.assert_array_equal(solid_mask(sim), upright)
    window.undo.redo()
    assert sim.angle == pytest.approx(math.radians(45), abs=1e-12)


def test_the_handle_is_refused_while_a_replay_shows(window, qtbot, tmp_path, monkeypatch):
    from PySide6.QtCore import QPointF
    from test_gui_replay import record_in_window

    from feelflow.app.gui.selftest import send_mouse

    path = tmp_path / "turn.ffsession"
    record_in_window(window, qtbot, path, monkeypatch)
    live, vp = window.sim, window.viewport
    angle, steps = live.angle_target, window.undo.count()
    assert window.replays.start(str(path))
    replay = window.replays.replay
    send_mouse(vp, "hover", vp.to_widget(*replay.pos))
    assert not vp.handle_shown()                                   # no handle on a replayed body
    centre, knob, _ = vp.handle_geometry()
    replay_angle = replay.angle
    send_mouse(vp, "press", knob)
    quarter = QPointF(centre.x() - (knob.y() - centre.y()), centre.y() + (knob.x() - centre.x()))
    send_mouse(vp, "move", quarter)
    send_mouse(vp, "release", knob)
    assert vp.turn is None
    assert "the mouse does not move the body" in window.statusBar().currentMessage()
    assert not window.bodies.turn_body(45.0)
    assert live.angle_target == angle and window.undo.count() == steps
    assert replay.angle == replay_angle


def test_the_handle_is_refused_while_a_script_or_a_device_drives_the_body(window, qtbot):
    from feelflow.app.gui.selftest import send_mouse

    vp = window.viewport
    assert window.lessons.apply("seed_protocol")
    sim = window.sim
    assert sim.runner is not None
    angle = sim.angle_target
    _, knob = knob_after_hover(window)
    send_mouse(vp, "press", knob)
    send_mouse(vp, "release", knob)
    assert vp.turn is None and sim.angle_target == angle
    assert "A motion script drives the body" in window.statusBar().currentMessage()

    window.flow.reset()                                            # the script ends: the mouse turns it again
    panel = window.panel
    panel.input.setCurrentIndex(panel.input.findData("sim://diyhid"))
    assert window.inputs.device is not None
    _, knob = knob_after_hover(window)
    send_mouse(vp, "press", knob)
    send_mouse(vp, "release", knob)
    assert vp.turn is None and sim.angle_target == angle
    assert "The haptic device drives the body" in window.statusBar().currentMessage()

    panel.input.setCurrentIndex(panel.input.findData("mouse"))
    assert window.inputs.device is None and vp.turn_blocker() is None
    _, knob = knob_after_hover(window)
    send_mouse(vp, "press", knob)
    assert vp.turn is not None
    send_mouse(vp, "release", knob)


def at_57_degrees(window):
    """A plate set to 57 degrees in the angle box: radians -> degrees -> radians of 57 is not 57's
    radians in floating point, so an undo that went through degrees would miss it by one ulp."""
    sim = plate(window)
    window.panel.angle.setValue(57)
    assert sim.angle == sim.angle_target == math.radians(57) and sim.params.angle_deg == 57
    assert math.radians(math.degrees(sim.angle_target)) != sim.angle_target
    return sim


def test_a_wheel_turn_is_one_undo_step_back_to_the_exact_angle(window, qtbot):
    sim = at_57_degrees(window)
    mask, steps = solid_mask(sim), window.undo.count()
    wheel(window, 1)
    assert math.degrees(sim.angle_target) == pytest.approx(59)
    assert window.undo.count() == steps + 1 and window.panel.angle.value() == 59
    qtbot.waitUntil(lambda: sim.angle == sim.angle_target, timeout=30000)   # running: it swings there
    window.undo.undo()
    assert sim.angle_target == math.radians(57) and sim.params.angle_deg == 57
    assert window.panel.angle.value() == 57
    qtbot.waitUntil(lambda: sim.angle == sim.angle_target, timeout=30000)
    np.testing.assert_array_equal(solid_mask(sim), mask)
    window.undo.redo()
    assert math.degrees(sim.angle_target) == pytest.approx(59)


def test_a_burst_of_wheel_notches_is_one_undo_step(window, qtbot):
    from feelflow.app.gui.turn_handle import BURST_S

    sim = at_57_degrees(window)
    window.loop.set_paused(True)                                   # paused: each notch turns it at once
    mask, steps = solid_mask(sim), window.undo.count()
    for _ in range(5):
        wheel(window, 1)
    assert sim.angle == pytest.approx(math.radians(67), abs=1e-12) and sim.params.angle_deg == 67
    assert window.undo.count() == steps + 1
    window.undo.undo()
    assert sim.angle == sim.angle_target == math.radians(57) and sim.params.angle_deg == 57
    np.testing.assert_array_equal(solid_mask(sim), mask)
    window.undo.redo()
    assert sim.params.angle_deg == 67
    qtbot.wait(int(BURST_S * 1000) + 300)                           # a pause: the next notch is a new step
    wheel(window, 1)
    assert window.undo.count() == steps + 2
    wheel(window, -1)                                              # back where this burst began: no step
    assert window.undo.count() == steps + 1 and sim.params.angle_deg == 67


def test_a_burst_of_wheel_notches_across_180_degrees_is_one_undo_step(window):
    sim = plate(window)
    window.loop.set_paused(True)
    window.panel.angle.setValue(177)
    steps = window.undo.count()
    for _ in range(3):
        wheel(window, 1)                                           # 179, 181 (shown as -179), -177
    assert sim.params.angle_deg == -177 and window.undo.count() == steps + 1
    window.undo.undo()
    assert sim.angle == math.radians(177) and sim.params.angle_deg == 177


def test_edits_of_the_angle_box_are_one_undo_step(window, qtbot):
    from PySide6.QtCore import Qt

    from feelflow.app.gui.turn_handle import BURST_S

    sim = at_57_degrees(window)
    qtbot.wait(int(BURST_S * 1000) + 300)                           # the 57 is a step of its own
    mask, steps = solid_mask(sim), window.undo.count()
    box = window.panel.angle
    for _ in range(3):
        box.stepBy(1)                                              # the arrows: 5 degrees a step
    assert sim.angle == math.radians(72) and window.undo.count() == steps + 1
    box.selectAll()
    qtbot.keyClicks(box, "-48")                                    # typed: "-", "-4", "-48", each applied
    qtbot.keyClick(box, Qt.Key_Return)
    assert sim.angle == math.radians(-48) and sim.params.angle_deg == -48
    assert window.undo.count() == steps + 1                        # arrows and typing in one burst
    window.undo.undo()
    assert sim.angle == sim.angle_target == math.radians(57) and box.value() == 57
    np.testing.assert_array_equal(solid_mask(sim), mask)
    window.undo.redo()
    assert sim.angle == math.radians(-48) and box.value() == -48


def test_the_wheel_is_refused_while_a_replay_shows(window, qtbot, tmp_path, monkeypatch):
    from test_gui_replay import record_in_window

    path = tmp_path / "wheel.ffsession"
    record_in_window(window, qtbot, path, monkeypatch)
    live = window.sim
    angle, steps = live.angle_target, window.undo.count()
    assert window.replays.start(str(path))
    replay_angle = window.replays.replay.angle
    wheel(window, 3)
    assert "the mouse does not move the body" in window.statusBar().currentMessage()
    assert live.angle_target == angle and window.undo.count() == steps
    assert window.replays.replay.angle == replay_angle


def test_the_wheel_and_the_angle_box_are_refused_while_a_script_drives_the_body(window):
    """A motion script ignores the angle until it ends (then the body would swing to whatever was
    asked meanwhile): the wheel and the Angle box are refused like the handle, with no undo step."""
    assert window.lessons.apply("seed_protocol")
    sim = window.sim
    assert sim.runner is not None
    angle, steps, shown = sim.angle_target, window.undo.count(), window.panel.angle.value()
    wheel(window, 3)
    assert "A motion script drives the body: the mouse wheel" in window.statusBar().currentMessage()
    window.panel.angle.setValue(shown + 30)
    assert "the Angle box cannot rotate it" in window.statusBar().currentMessage()
    assert sim.angle_target == angle and window.undo.count() == steps
    assert window.panel.angle.value() == shown
    window.flow.reset()                      # the script ends: the wheel turns the body again
    wheel(window, 3)
    assert sim.angle_target != angle and window.undo.count() == steps + 1


def test_a_paused_wheel_burst_over_180_degrees_and_back_leaves_no_undo_step(window):
    sim = window.sim
    window.loop.set_paused(True)
    window.bodies.set_angle(179.0)
    steps = window.undo.count()
    wheel(window, 1)
    wheel(window, -1)
    assert sim.params.angle_deg == pytest.approx(179.0) and window.undo.count() == steps


def test_loading_a_lesson_clears_the_undo_history(window):
    """A lesson replaces the body and its pose: an undo must not turn the lesson's body to an
    angle asked for before it (during a motion script it would swing there when the script ends)."""
    wheel(window, 5)
    assert window.undo.count() > 0
    assert window.lessons.apply("seed_protocol")
    assert window.undo.count() == 0


def test_the_handle_shows_the_torque_that_resists_the_turn(window, qtbot):
    """While the handle turns the plate counter-clockwise, the fluid's torque pulls it back: the
    handle's torque arc (readouts.torque_arc of the model's torque) runs clockwise, and the
    overlay draws it (a frame grabbed while it shows)."""
    sim = plate(window)
    vp = window.viewport
    drag_handle(window, 60)
    arcs = []
    qtbot.waitUntil(lambda: (arcs.append(vp.torque_arc) or sim.body.rate > 0.002), timeout=20000)
    qtbot.waitUntil(lambda: (arcs.append(vp.torque_arc) or len(arcs) > 12), timeout=20000)
    turning = [a for a in arcs[-8:] if a is not None]
    assert turning and sum(a < 0 for a in turning) >= 0.75 * len(turning), turning
    vp.grab()   # the arc paints (with the handle shown or not) without error
