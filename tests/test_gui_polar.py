"""The polar lesson in the real window (under Xvfb): the polar and the C_p views are drawn from
the flow, and the speed view shows the published 2D drag beside a cylinder's measured drag."""
from __future__ import annotations

import os

import numpy as np
import pytest

pytestmark = [pytest.mark.gui,
              pytest.mark.skipif(not os.environ.get("DISPLAY"), reason="needs an X display (run under xvfb-run -a)")]


def _data(item):
    """The item's data as given (not as a log-log view transforms it for display)."""
    x, y = item.xData, item.yData
    return (np.array([]), np.array([])) if x is None else (np.asarray(x), np.asarray(y))


def test_polar_lesson_builds_the_polar_and_cp_from_the_flow(window, qtbot):
    assert window.lessons.apply("polar")
    sim, plot = window.sim, window.plot
    assert plot.view.currentData() == "polar" and sim.shape.kind == "naca" and sim.hold_still
    sweep = sim.polar.sweep
    # short holds for the test (the lesson's settling is app/model/polar.py's, tested in test_polar.py)
    sweep.window_steps = sweep.min_steps = 150
    sweep.max_steps = 300
    qtbot.waitUntil(lambda: len(sweep.points) >= 2, timeout=120000)
    plot.refresh(force=True)
    alpha, cl = _data(plot.lift_views.items["cl"])
    _, cd = _data(plot.lift_views.items["cd"])
    assert list(alpha[:2]) == [p.alpha for p in sweep.points[:2]] and list(cl[:2]) == [p.cl for p in sweep.points[:2]]
    assert np.all(cd[:2] > 0.02) and cl[1] > cl[0]            # the drag is real; 2 degrees lift more than 0
    theory_a, theory_cl = _data(plot.lift_views.items["theory"])
    assert theory_a.max() >= 24 and np.allclose(theory_cl, 2 * np.pi * np.radians(theory_a))   # 0012: alpha_0 = 0
    assert sim.angle == pytest.approx(np.radians(-sweep.angle))   # turned to the next angle, nose up
    # the C_p view: the angle being held, sampled on the wall of the body in the flow
    plot.view.setCurrentIndex(plot.view.findData("cp"))
    qtbot.waitUntil(lambda: sim.polar.probe.steps > 50, timeout=30000)
    plot.refresh(force=True)
    x, cp_upper = _data(plot.lift_views.items["upper"])
    _, cp_lower = _data(plot.lift_views.items["lower"])
    assert len(x) > 20 and x.min() < 0.05 and x.max() > 0.95
    assert cp_upper.max() > 0.3 or cp_lower.max() > 0.3         # the stagnation point near the nose
    assert cp_upper.min() < -0.1                                # suction over the upper side
    assert plot.lift_views.plot.getPlotItem().getViewBox().yInverted()
    # the drag polar view
    plot.view.setCurrentIndex(plot.view.findData("drag_polar"))
    plot.refresh(force=True)
    cds, cls = _data(plot.lift_views.items["polar"])
    assert len(cds) >= 2 and list(cls[:2]) == [p.cl for p in sweep.points[:2]]


def test_cylinder_drag_against_speed_shows_the_published_curve(window, qtbot):
    assert window.lessons.apply("drag_speed")
    plot = window.plot
    assert plot.view.currentData() == "speed"
    speeds = np.array([0.02, 0.03])
    plot.lift_views.draw_published_drag(window.sim, speeds)
    us, fs = _data(plot.lift_views.items["published"])
    d, nu = window.sim.shape.diameter, window.sim.config.nu
    re = us * d / nu
    assert len(us) > 3 and re.min() >= 20 - 1e-9
    from feelflow.app.model.published import published_drag

    k = int(np.argmin(abs(re - 40)))
    assert fs[k] == pytest.approx(0.5 * published_drag(re[k])[0] * us[k] ** 2 * d)


def test_cylinder_readout_shows_the_measured_and_published_strouhal_number(window, qtbot):
    """A cylinder whose lift swings: the readout gives its St beside Williamson's at that Re
    (the history here is a swing at St 0.17 fed to the real plot; the vortex street lesson makes
    one in a few thousand steps)."""
    window.loop.set_paused(True)
    sim = window.sim
    assert sim.shape.kind == "cylinder"
    sim.history.clear()
    d, u = sim.shape.diameter, sim.params.wind
    for t in np.arange(0, 40000, 20.0):
        lift = 0.01 * np.sin(2 * np.pi * t * 0.17 * u / d)
        sim.history.add(t, (0.0, 0.0), (u, 0.0), {sim.params.force_model: (0.02, lift)})
    window.plot.refresh(force=True)
    text = window.plot.readout_box.reference_label.text()
    assert "St 0.170" in text
    if 49 <= sim.reynolds() <= 178:
        assert "Williamson 1989" in text
