"""The local stability guard (solver/local_guard.py): the operator's region from the linear
stability analysis of the reference operators, and the window raising the viscosity where the
flow's fastest node leaves it, the same way on every grid."""
from __future__ import annotations

import math

import numpy as np
import pytest

from feelflow.solver import local_guard
from feelflow.solver.lattice import equilibrium


@pytest.mark.parametrize("collision, nu, weakest", [("trt", 0.004, 22.5), ("rr", 0.001, 45.0)])
def test_the_table_is_the_linear_analysis(collision, nu, weakest):
    """The tabulated limit is what solver/validation/linear_stability.py measures along the
    weakest direction (coarser k grid and bisection here, so within 0.01; `python -m
    feelflow.solver.local_guard` checks the whole table)."""
    from feelflow.solver.validation.linear_stability import max_stable_speed

    fresh = max_stable_speed(collision, nu, weakest, tol=4e-3, k_points=24)
    assert local_guard.speed_limit(collision, nu) == pytest.approx(fresh, abs=0.01)


def test_the_verdict_and_the_viscosity_that_brings_the_flow_back():
    inside = local_guard.check("trt", 0.01, 0.10)
    assert inside.inside and inside.nu_needed is None
    out = local_guard.check("trt", 0.004, 0.10)
    assert not out.inside and out.nu_needed > 0.004
    assert local_guard.MARGIN * local_guard.speed_limit("trt", out.nu_needed) == pytest.approx(0.10, rel=1e-9)
    assert local_guard.check("rr", 0.001, 0.2).inside            # rr keeps Ma 0.35 at nu 0.001
    assert not local_guard.check("rr", 0.001, 0.3).inside
    beyond = local_guard.check("rr", 0.001, 0.6)                  # no viscosity holds |u| 0.6
    assert beyond.nu_needed is None and "lower the wind" in beyond.line("regularised BGK")
    for v in (out, beyond):
        assert "\n" not in v.line("TRT")


def _vortex(ny, nx, x0, y0, peak, radius=4.0):
    """A Lamb-Oseen-like vortex of peak speed `peak` in a stream of 0.05."""
    y, x = np.mgrid[0:ny, 0:nx].astype(float)
    dx, dy = x - x0, y - y0
    r2 = dx * dx + dy * dy + 1e-12
    swirl = peak * 1.5852 * radius / np.sqrt(r2) * (1 - np.exp(-r2 / radius ** 2))   # max = peak at r ~ 1.12 R
    return 0.05 - swirl * dy / np.sqrt(r2), swirl * dx / np.sqrt(r2)


@pytest.mark.parametrize("grid", [(96, 48), (160, 80), (256, 128)])
def test_the_window_raises_the_viscosity_where_the_flow_leaves_the_region(grid):
    """A fast vortex (|u| 0.25 with the stream) let into the window's tunnel, TRT at nu 0.01
    (its region ends at 0.9 x 0.179 = 0.161): the guard raises the viscosity to what holds the vortex, says so in one
    line, and the flow stays finite; the same viscosity on every grid (the guard reads the local
    flow, not the grid)."""
    from feelflow.app.model.simulation import Params, Simulation

    nx, ny = grid
    sim = Simulation(Params(grid=grid, size=8.0, wind=0.05, nu=0.01))
    assert sim.config.collision == "trt"
    ux, uy = _vortex(ny, nx, 0.6 * nx, 0.5 * ny, 0.2)
    sim.solver.solver.set_distributions(equilibrium(np.ones_like(ux), ux, uy))
    sim.advance(1)
    nu = sim.params.nu
    print(f"\n  {grid}: nu 0.01 -> {nu}; {sim.guard_note}", end="")
    assert sim.guard_changed and sim.guard_note.startswith("Viscosity raised to") and "\n" not in sim.guard_note
    assert 0.02 < nu < 0.03             # |u| 0.247 (stream + vortex) needs 0.0243
    assert sim.config.nu == nu
    seen = sim.solver.max_speed_seen
    assert local_guard.check(sim.config.collision, nu, seen).inside
    sim.advance(40)
    rho, vx, vy = sim.solver.macroscopic()
    assert np.isfinite(rho).all() and float(np.hypot(vx, vy).max()) < 0.25
    test_the_window_raises_the_viscosity_where_the_flow_leaves_the_region.seen.append(nu)
    assert max(test_the_window_raises_the_viscosity_where_the_flow_leaves_the_region.seen) == pytest.approx(
        min(test_the_window_raises_the_viscosity_where_the_flow_leaves_the_region.seen), abs=2e-4)


test_the_window_raises_the_viscosity_where_the_flow_leaves_the_region.seen = []


def test_a_calm_flow_is_left_alone():
    from feelflow.app.model.simulation import Params, Simulation

    sim = Simulation(Params(grid=(96, 48), size=8.0, wind=0.05, nu=0.01))
    sim.advance(20)
    assert not sim.guard_changed and sim.params.nu == 0.01
