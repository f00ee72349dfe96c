"""The force plot's ranges in the real window (Xvfb, numpy solver, small grid): the time view's
force axis shows the settled forces, not the impulsive start's pulse, until the user zooms; the
log-log view frames its points even when there is only one speed."""
from __future__ import annotations


import numpy as np
import pytest

# the `window` fixture comes from tests/gui_fixtures.py (conftest)

pytestmark = pytest.mark.gui


def test_time_view_force_axis_leaves_out_the_start_pulse(window, qtbot):
    from feelflow.app.model.readouts import start_pulse_steps

    sim, plot = window.sim, window.plot
    settle = start_pulse_steps(sim.params.size)
    qtbot.waitUntil(lambda: sim.solver.time > 4 * settle, timeout=30000)
    plot.refresh(force=True)
    t, drag, lift = sim.history.drag_lift(sim.params.force_model)
    early, late = t < settle, t >= settle
    assert np.nanmax(np.abs(drag[early])) > 3 * np.nanmax(np.abs(drag[late]))   # there is a pulse to leave out
    lo, hi = plot.plot.getViewBox().viewRange()[1]
    for v in (0.0, np.nanmin(drag[late]), np.nanmax(drag[late]), np.nanmin(lift[late]), np.nanmax(lift[late])):
        assert lo <= v <= hi
    assert hi < np.nanmax(drag[early])                        # the pulse runs off the top...
    shown = plot.time_views.curves[(sim.params.force_model, "drag")].getData()[1]
    assert np.nanmax(shown) == pytest.approx(np.nanmax(drag))   # ...but its data is all there


def test_the_users_zoom_is_kept_until_auto_range(window, qtbot):
    from PySide6.QtCore import QPoint, QPointF, Qt
    from PySide6.QtGui import QWheelEvent
    from PySide6.QtWidgets import QApplication

    plot = window.plot
    qtbot.waitUntil(lambda: len(window.sim.history) > 20, timeout=20000)
    plot.refresh(force=True)
    view = plot.plot
    centre = QPointF(view.viewport().width() / 2, view.viewport().height() / 2)
    ev = QWheelEvent(centre, view.viewport().mapToGlobal(centre), QPoint(), QPoint(0, 120 * 3), Qt.NoButton,
                     Qt.NoModifier, Qt.NoScrollPhase, False)
    QApplication.sendEvent(view.viewport(), ev)
    zoomed = view.getViewBox().viewRange()[1]
    assert not plot.ranges.follow
    plot.refresh(force=True)
    assert view.getViewBox().viewRange()[1] == pytest.approx(zoomed)
    view.getViewBox().enableAutoRange()                    # what pyqtgraph's "A" button does
    plot.refresh(force=True)
    assert plot.ranges.follow


def test_a_zoom_of_the_force_axis_alone_is_kept(window, qtbot):
    """A wheel over the left axis zooms y only (pyqtgraph keeps x on auto-range): still the
    user's view, not the "A" button's."""
    plot = window.plot
    qtbot.waitUntil(lambda: len(window.sim.history) > 20, timeout=20000)
    plot.refresh(force=True)
    box = plot.plot.getViewBox()
    box.scaleBy(y=0.5)                                     # what ViewBox.wheelEvent(axis=1) does
    box.sigRangeChangedManually.emit([False, True])
    zoomed = box.viewRange()[1]
    assert box.autoRangeEnabled()[0] and not plot.ranges.follow
    plot.refresh(force=True)
    assert box.viewRange()[1] == pytest.approx(zoomed) and not plot.ranges.follow


def test_log_log_view_frames_a_single_speed(window, qtbot):
    plot, sim = window.plot, window.sim
    qtbot.waitUntil(lambda: len(sim.history) > 30, timeout=20000)
    plot.view.setCurrentIndex(plot.view.findData("speed"))      # from the time view, as a lesson does
    plot.refresh(force=True)
    if not any(sim.history.settled):                           # nothing steady yet: no points, and says why
        assert plot.speed_view.fit_text().startswith("fit: hold a speed")
    qtbot.waitUntil(lambda: sum(sim.history.settled) > 5, timeout=60000)   # History.SETTLE_STEPS
    plot.refresh(force=True)
    us, fs = plot.speed_view.scatter.getData()                            # in log mode: log10 of the data
    assert len(us) == 1 and plot.speed_view.fitted_exponent is None       # one wind speed so far: one point
    (x0, x1), (y0, y1) = plot.plot.getViewBox().viewRange()   # log10 of the axes' ends
    u, f = us[0], fs[0]
    assert x0 < u < x1 and x1 - x0 < 2                         # a factor < 100 around it, not 1e-300..1e300
    assert y0 < f < y1 and y1 - y0 < 2
    for axis in ("bottom", "left"):                            # the tick labels follow (no 10^-300)
        a0, a1 = plot.plot.getAxis(axis).range
        assert a1 - a0 < 2, (axis, a0, a1)


def test_the_window_fits_a_1024_pixel_wide_screen(window, qtbot):
    """A classroom projector is often 1024 pixels wide: the window, with the log-log view and
    its fit shown, must fit it without clipping the C_D / C_L readout."""
    plot = window.plot
    plot.view.setCurrentIndex(plot.view.findData("speed"))
    qtbot.waitUntil(lambda: len(window.sim.history) > 30, timeout=20000)
    plot.refresh(force=True)
    assert plot.speed_view.fit_text().startswith("fit")
    window.resize(1024, 700)
    qtbot.waitUntil(lambda: window.width() <= 1024, timeout=5000)
    qtbot.wait(100)
    assert plot.readout_box.value_label.width() >= plot.readout_box.value_label.sizeHint().width()
    assert plot.readout_box.reference_label.width() >= plot.readout_box.reference_label.sizeHint().width()


def test_the_torque_view_shows_the_torque_that_resists_a_turn(window, qtbot):
    """The torque view plots the force history's torque of the model shown; the body turned
    counter-clockwise by the window's turn feels it clockwise (negative) while it turns."""
    plot, sim = window.plot, window.sim
    qtbot.waitUntil(lambda: len(sim.history) > 5, timeout=20000)
    plot.view.setCurrentIndex(plot.view.findData("torque"))
    assert plot.axis_labels()[1].startswith("torque")
    n0 = len(sim.history)
    sim.turn_to(sim.params.angle_deg + 60.0)
    qtbot.waitUntil(lambda: len(sim.history) > n0 + 10, timeout=20000)
    plot.refresh(force=True)
    t, torque = sim.history.torque(sim.params.force_model)
    shown_t, shown = plot.time_views.curves[(sim.params.force_model, "torque")].getData()
    assert np.allclose(shown[-5:], torque[-5:], equal_nan=True)
    turning = torque[n0:n0 + 10]
    assert np.isfinite(turning).all() and np.median(turning) < 0
