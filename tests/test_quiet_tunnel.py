"""The inlet's absorbing layer (FlowConfig.inlet_sponge_cells, solver/sponge.py): sound leaves the
tunnel through the velocity inlet, and the mean flow is left as it was.

Parametrised over the numpy and gl backends explicitly: a backend without the layer refuses it
with a ConfigError. docs/science/quiet-tunnel.md.
"""
from __future__ import annotations

import numpy as np
import pytest
from conftest import make_solver
from solver_backends import BACKENDS

from feelflow.solver.config import ConfigError, FlowConfig
from feelflow.solver.lattice import equilibrium
from feelflow.solver.sponge import absorb_keep, density_keep

CS = 1.0 / np.sqrt(3.0)


def test_rows_of_the_inlet_layer():
    """keep = 1 - a s_in^2 in the first L_in columns (velocity only), the outlet's layer on both."""
    cfg = FlowConfig(nx=64, ny=8, sponge_cells=10, sponge_absorb=0.2, inlet_sponge_cells=8).validate()
    keep, keep_rho = absorb_keep(cfg), density_keep(cfg)
    assert keep[0] == pytest.approx(0.8) and keep[7] == pytest.approx(1 - 0.2 / 64)
    assert np.all(keep[8:54] == 1.0) and keep[-1] == pytest.approx(0.8)
    assert np.all(keep_rho[:54] == 1.0) and keep_rho[-1] == pytest.approx(0.8)
    with pytest.raises(ConfigError, match="inlet_sponge_cells"):
        FlowConfig(nx=64, ny=8, inlet_sponge_cells=16).validate()


@pytest.mark.parametrize("backend", BACKENDS)
def test_inlet_layer_takes_energy_out_of_a_reflected_sound_pulse(backend, request):
    """A density pulse in a tunnel at rest splits into two halves; the right one leaves through
    the outlet's absorbing layer. The left one is reflected by the bare velocity inlet (a wall
    for sound) and comes back; the inlet's layer damps the velocity of what passes through it,
    so less comes back. Measured when the reflection is back in the middle of the tunnel: a
    velocity-only layer is a weak absorber of plane waves (docs/science/quiet-tunnel.md gives
    the measured fractions), so the test asks for a clear reduction, not for silence."""
    nx, ny, x0, L_out = 300, 8, 100, 50
    x = np.arange(nx)
    bump = 1.0 + 1e-3 * np.exp(-((x - x0) / 6.0) ** 2)
    steps = int((x0 + 60) / CS)   # the left half: to the inlet and 60 cells back
    rms = {}
    for inlet in (0, 30):
        cfg = FlowConfig(nx=nx, ny=ny, nu=0.01, y_boundary="periodic", inflow_speed=0.0, inflow_ramp_steps=0,
                         sponge_cells=L_out, sponge_absorb=0.3, inlet_sponge_cells=inlet)
        s = make_solver(backend, cfg, request)
        rho = np.repeat(bump[None, :], ny, axis=0)
        s.set_distributions(equilibrium(rho, np.zeros_like(rho), np.zeros_like(rho)))
        s.step(steps)
        rho, _, _ = s.macroscopic()
        rms[inlet] = float(np.sqrt(np.mean((rho[:, 30:nx - L_out] - 1.0) ** 2)))
        s.close()
    print(f"\n{backend}: rms density fluctuation after the reflection {rms[0]:.3e} (bare inlet), "
          f"{rms[30]:.3e} (inlet layer)")
    assert rms[30] < 0.9 * rms[0]


@pytest.mark.parametrize("backend", BACKENDS)
def test_inlet_layer_keeps_the_mean_pressure_rise_and_the_flow(backend, request):
    """A channel with no-slip walls needs a pressure rise towards the inlet to drive the flow; the
    inlet layer relaxes the velocity only, so that rise stays and the mass flux through the
    channel is the inflow's: the steady mean density and velocity away from the layer agree with
    the bare inlet's to a fraction of the layer's strength."""
    out = {}
    for inlet in (0, 12):
        cfg = FlowConfig(nx=96, ny=24, nu=0.05, inflow_speed=0.04, inflow_ramp_steps=0, initial_velocity=(0.04, 0.0),
                         sponge_cells=16, sponge_absorb=0.2, inlet_sponge_cells=inlet)
        s = make_solver(backend, cfg, request)
        s.step(3000)
        rho, ux, _ = s.macroscopic()
        out[inlet] = (rho[:, 20:70].mean() - 1.0, ux[:, 20:70].mean())
        s.close()
    (drho0, u0), (drho1, u1) = out[0], out[12]
    print(f"\n{backend}: mean rho - 1 {drho0:.3e} / {drho1:.3e}, mean u {u0:.5f} / {u1:.5f} (bare / layer)")
    assert drho0 > 1e-4                      # the rise is there to keep
    assert abs(drho1 - drho0) < 0.02 * drho0
    assert abs(u1 - u0) < 1e-3 * u0


def test_window_lessons_scenes_and_stability_case_use_the_inlet_layer():
    """Wherever a tunnel with an outlet sponge runs (the window, the lessons, the example and seed
    scenes, the stability validation case), the inlet lets sound out as the window's does."""
    from pathlib import Path

    from feelflow.app.model.scene import load_scene
    from feelflow.app.model.simulation import INLET_LAYER, default_base_config
    from feelflow.solver.validation import stability

    window = default_base_config((256, 128))
    assert window.inlet_sponge_cells == INLET_LAYER > 0 and window.sponge_absorb > 0
    assert (stability.INLET_CELLS, stability.SPONGE_ABSORB) == (INLET_LAYER, window.sponge_absorb)
    root = Path(__file__).resolve().parents[1] / "scenes"
    paths = sorted(root.glob("*.toml")) + sorted((root / "presets").glob("*.toml"))
    with_sponge = [p for p in paths if load_scene(p).config.sponge_cells > 0]
    assert len(with_sponge) >= 20
    for p in with_sponge:
        cfg = load_scene(p).config
        assert (cfg.inlet_sponge_cells, cfg.sponge_absorb) == (INLET_LAYER, window.sponge_absorb), p.name
