"""The window's stability guard, for real (Qt window under Xvfb, numpy solver): the student's
lowest viscosity at the highest wind gives a finite running flow and one plain sentence in the
status bar saying the viscosity was raised (app.simulation.stable_params)."""
from __future__ import annotations


import numpy as np
import pytest

pytestmark = pytest.mark.gui


def test_lowest_viscosity_at_highest_wind_runs_finite_and_says_so(window, qtbot):
    from feelflow.solver.stability_limit import inside, min_stable_viscosity

    panel, sim = window.panel, window.sim
    panel.wind.setValue(panel.wind.maximum())
    panel.viscosity.setValue(panel.viscosity.minimum())
    u = panel.wind.maximum()
    assert sim.params.wind == pytest.approx(u)          # the wind the student chose stays
    nu = sim.params.nu
    assert nu > panel.viscosity.minimum() and inside(u, nu, sim.config.collision, sim.params.size)
    assert nu == pytest.approx(min_stable_viscosity(u, sim.config.collision, sim.params.size), abs=1e-4)
    assert sim.config.nu == nu and panel.viscosity.value() == pytest.approx(nu)   # the panel shows it
    message = window.statusBar().currentMessage()
    assert message.startswith(f"Viscosity raised to {nu:.4f}") and message.count(". ") == 0, message
    t = sim.solver.time
    qtbot.waitUntil(lambda: sim.solver.time > t + 2000, timeout=90000)
    assert not window.loop.paused
    rgba = sim.field_rgba()
    assert np.isfinite(rgba).all()
    assert np.hypot(rgba[..., 1], rgba[..., 2]).max() < 0.3
