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


def test_the_local_guard_raises_the_viscosity_in_the_window_and_says_so(window, qtbot):
    """A fast vortex let into the running tunnel (|u| about 0.3): within a check (64 steps) the
    local guard (solver/local_guard.py) raises the viscosity, the panel shows it and the status
    bar says why in one sentence; the flow runs on, finite."""
    from feelflow.solver import local_guard
    from feelflow.solver.lattice import equilibrium

    sim = window.sim
    nx, ny = sim.config.nx, sim.config.ny
    y, x = np.mgrid[0:ny, 0:nx].astype(float)
    dx, dy = x - 0.7 * nx, y - 0.5 * ny
    r = np.sqrt(dx * dx + dy * dy) + 1e-9
    swirl = 0.25 * 1.5852 * 4.0 / r * (1 - np.exp(-(r / 4.0) ** 2))
    ux, uy = sim.params.wind - swirl * dy / r, swirl * dx / r
    nu0 = sim.params.nu
    assert not local_guard.check(sim.config.collision, nu0, float(np.hypot(ux, uy).max())).inside
    sim.solver.solver.set_distributions(equilibrium(np.ones_like(ux), ux, uy))
    qtbot.waitUntil(lambda: sim.params.nu > nu0, timeout=60000)
    qtbot.waitUntil(lambda: window.statusBar().currentMessage().startswith("Viscosity raised to"), timeout=10000)
    message = window.statusBar().currentMessage()
    assert "where it is fastest" in message and "\n" not in message, message
    assert window.panel.viscosity.value() == pytest.approx(sim.params.nu)
    t = sim.solver.time
    qtbot.waitUntil(lambda: sim.solver.time > t + 500, timeout=60000)
    assert np.isfinite(sim.field_rgba()).all()
