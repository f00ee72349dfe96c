"""The window chooses its collision operator (solver/operator_choice.py) and says which and why
in one line of the status bar; the lessons that need the high-Reynolds operator load and run.
A real Qt window under Xvfb, the numpy solver (`xvfb-run -a python -m pytest -m gui ...`)."""
from __future__ import annotations


import pytest

pytestmark = pytest.mark.gui


def test_the_status_bar_names_the_operator_and_follows_the_viscosity(window, qtbot):
    panel, sim = window.panel, window.sim
    panel.viscosity.setValue(0.02)
    qtbot.waitUntil(lambda: window.status["operator"].text().startswith("TRT"), timeout=20000)
    assert sim.config.collision == "trt" and "cheapest" in window.status["operator"].text()
    panel.wind.setValue(0.05)
    panel.viscosity.setValue(0.001)   # U / nu = 50: beyond TRT's region, inside rr's for a 20-cell body
    assert sim.config.collision == "rr" and sim.params.nu == pytest.approx(0.001)
    qtbot.waitUntil(lambda: window.status["operator"].text().startswith("regularised BGK"), timeout=20000)
    assert "\n" not in window.status["operator"].text()
    t = sim.solver.time
    qtbot.waitUntil(lambda: sim.solver.time > t + 20, timeout=30000)   # the rebuilt solver runs


@pytest.mark.parametrize("key", ["wake_re40_400", "plate_re1000", "airfoil_stall"])
def test_high_reynolds_lessons_load_and_run(window, qtbot, key):
    from feelflow.app.model.presets import PRESETS
    from feelflow.app.model.scene import load_scene

    assert window.lessons.apply(key)
    scene = load_scene(PRESETS[key].path)
    sim = window.sim
    assert sim.config.nu == pytest.approx(scene.config.nu) and sim.guard_note is None   # nothing raised
    qtbot.waitUntil(lambda: sim.solver.time > 30, timeout=30000)
    if key == "wake_re40_400":
        assert sim.sweep is not None and sim.config.collision == "trt"   # Re 40 first: TRT holds it
    else:
        assert sim.config.collision == "rr"
