"""The quiet inlet (FlowConfig.inlet_nonreflecting, solver/quiet_inlet.py): sound leaves the
tunnel through the velocity inlet, and the mean flow is left as it was.

Parametrised over the numpy and gl backends explicitly: a backend without the quiet inlet
refuses it with a ConfigError. docs/science/quiet-tunnel.md.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from conftest import make_solver
from solver_backends import BACKENDS

from feelflow.solver.config import ConfigError, FlowConfig
from feelflow.solver.lattice import equilibrium
from feelflow.solver.quiet_inlet import shortest_ramp

CS = 1.0 / np.sqrt(3.0)


def test_rate_out_of_range_is_refused_by_name():
    for bad in (-1e-3, 0.5, float("nan")):
        with pytest.raises(ConfigError, match="inlet_nonreflecting"):
            FlowConfig(nx=64, ny=8, inlet_nonreflecting=bad).validate()


@pytest.mark.parametrize("backend", BACKENDS)
def test_quiet_inlet_lets_a_sound_pulse_out(backend, request):
    """A density pulse in a tunnel at rest splits into two halves; the right one leaves through
    the outlet's absorbing layer. The left one is reflected by the bare velocity inlet (a wall
    for sound: same sign, same amplitude) and comes back; through the quiet inlet it leaves.
    Measured when the reflection would be back in the middle of the tunnel."""
    nx, ny, x0, L_out = 300, 8, 100, 50
    x = np.arange(nx)
    bump = 1.0 + 1e-3 * np.exp(-((x - x0) / 6.0) ** 2)
    steps = int((x0 + 60) / CS)   # the left half: to the inlet and 60 cells back
    rms = {}
    for rate in (0.0, 1e-3):
        cfg = FlowConfig(nx=nx, ny=ny, nu=0.01, y_boundary="periodic", inflow_speed=0.0, inflow_ramp_steps=0,
                         sponge_cells=L_out, sponge_absorb=0.3, inlet_nonreflecting=rate)
        s = make_solver(backend, cfg, request)
        rho = np.repeat(bump[None, :], ny, axis=0)
        s.set_distributions(equilibrium(rho, np.zeros_like(rho), np.zeros_like(rho)))
        s.step(steps)
        rho, _, _ = s.macroscopic()
        rms[rate] = float(np.sqrt(np.mean((rho[:, : nx - L_out] - 1.0) ** 2)))
        s.close()
    print(f"\n{backend}: rms density fluctuation after the reflection {rms[0.0]:.3e} (bare inlet), "
          f"{rms[1e-3]:.3e} (quiet inlet)")
    assert rms[1e-3] < 0.1 * rms[0.0]


@pytest.mark.parametrize("backend", BACKENDS)
def test_quiet_inlet_leaves_a_uniform_stream_alone(backend, request):
    """A uniform stream at RHO0 has no density fluctuation at the inlet: nothing to correct."""
    U = 0.05
    cfg = FlowConfig(nx=32, ny=12, nu=0.02, y_boundary="periodic", inflow_speed=U, inflow_ramp_steps=0,
                     initial_velocity=(U, 0.0), sponge_cells=10, sponge_absorb=0.3, inlet_nonreflecting=1e-3)
    s = make_solver(backend, cfg, request)
    f0 = s.distributions()
    s.step(50)
    assert np.allclose(s.distributions(), f0, rtol=0, atol=1e-6)
    s.close()


@pytest.mark.parametrize("backend", BACKENDS)
def test_quiet_inlet_keeps_the_mean_pressure_rise_and_the_flow(backend, request):
    """A channel with no-slip walls needs a pressure rise towards the inlet to drive the flow. The
    quiet inlet's reference density follows that rise, so once it has (rate 0.005 here, e-folding
    in 200 steps) the mean density and velocity are the bare inlet's: the mean inflow stays u_in."""
    out = {}
    for rate in (0.0, 0.005):
        cfg = FlowConfig(nx=96, ny=24, nu=0.05, inflow_speed=0.04, inflow_ramp_steps=0, initial_velocity=(0.04, 0.0),
                         sponge_cells=16, sponge_absorb=0.2, inlet_nonreflecting=rate)
        s = make_solver(backend, cfg, request)
        s.step(3000)
        rho, ux, _ = s.macroscopic()
        out[rate] = (rho[:, 5:70].mean() - 1.0, ux[:, 5:70].mean())
        s.close()
    (drho0, u0), (drho1, u1) = out[0.0], out[0.005]
    print(f"\n{backend}: mean rho - 1 {drho0:.4e} / {drho1:.4e}, mean u {u0:.6f} / {u1:.6f} (bare / quiet)")
    assert drho0 > 1e-3                      # the rise is there to keep
    assert abs(drho1 - drho0) < 0.01 * drho0
    assert abs(u1 - u0) < 1e-3 * u0


def test_window_lessons_scenes_and_stability_case_use_the_quiet_inlet():
    """Wherever a tunnel with an outlet sponge runs (the window, the lessons, the example and seed
    scenes, the stability validation case), the inlet lets sound out as the window's does."""
    from feelflow.app.model.scene import load_scene
    from feelflow.app.model.simulation import QUIET_INLET_RATE, default_base_config
    from feelflow.solver.validation import stability

    window = default_base_config((256, 128))
    assert window.inlet_nonreflecting == QUIET_INLET_RATE > 0 and window.sponge_absorb > 0
    assert (stability.QUIET_INLET_RATE, stability.SPONGE_ABSORB) == (QUIET_INLET_RATE, window.sponge_absorb)
    root = Path(__file__).resolve().parents[1] / "scenes"
    paths = sorted(root.glob("*.toml")) + sorted((root / "presets").glob("*.toml"))
    with_sponge = [p for p in paths if load_scene(p).config.sponge_cells > 0]
    assert len(with_sponge) >= 20
    quiet = []
    for p in with_sponge:
        cfg = load_scene(p).config
        assert cfg.sponge_absorb == window.sponge_absorb, p.name
        ramp_allows = cfg.inflow_ramp_steps == 0 or cfg.inflow_ramp_steps >= shortest_ramp(cfg.nx)
        assert cfg.inlet_nonreflecting == (QUIET_INLET_RATE if ramp_allows else 0.0), p.name
        quiet += [p.name] * ramp_allows
    assert len(quiet) >= 15   # the lessons and the seed scenes among them
    assert {"seed_protocol_d16.toml", "seed_protocol_d32.toml", "vortex_street.toml"} <= set(quiet)


def test_a_ramp_too_short_for_the_quiet_inlet_is_refused_by_name():
    """A ramp from rest shorter than half the tunnel's slowest sound period leaves that mode
    ringing; the quiet inlet would let it out as a swing of the inflow (docs/science/quiet-tunnel.md,
    'Ramps'), so the combination is refused with the shortest ramp it takes."""
    assert shortest_ramp(400) == 1386
    with pytest.raises(ConfigError, match=r"inlet_nonreflecting.*at least 1386 steps at nx = 400 \(got 1000\)"):
        FlowConfig(nx=400, ny=32, inlet_nonreflecting=1e-3, inflow_ramp_steps=1000).validate()
    for ramp in (0, 1386):
        FlowConfig(nx=400, ny=32, inlet_nonreflecting=1e-3, inflow_ramp_steps=ramp).validate()
    FlowConfig(nx=400, ny=32, inlet_nonreflecting=0.0, inflow_ramp_steps=1000).validate()


@pytest.mark.parametrize("backend", BACKENDS)
def test_quiet_inlet_holds_its_reference_while_the_inflow_ramps_up(backend, request):
    """The window's tunnel with the inflow ramped up from rest over 1000 steps: the inlet's
    density during the ramp is the ramp's sound, so the inlet is bare and the reference held
    until the ramp ends; afterwards the
    mean velocity is as steady as with the bare inlet and the absorbing layer (within 2 % of U
    from step 3000 on, tests/test_solver_boundaries.py). A reference that learnt the ramp's
    sound swung the mean by 3.6 % of U (docs/science/quiet-tunnel.md)."""
    from dataclasses import replace

    from feelflow.app.model.simulation import default_base_config

    cfg = replace(default_base_config((256, 128)), inflow_speed=0.05, inflow_ramp_steps=1000).validate()
    assert cfg.inlet_nonreflecting > 0
    s = make_solver(backend, cfg, request)
    s.step(3000)
    means = []
    for _ in range(25):
        s.step(200)
        means.append(s.macroscopic()[1][:, : 256 - 32].mean() / 0.05)
    s.close()
    print(f"\n{backend}: swing of the mean u / U after the ramp {max(means) - min(means):.4f}")
    assert max(means) - min(means) < 0.02 and abs(np.mean(means) - 1.0) < 0.02


@pytest.mark.parametrize("backend", BACKENDS)
def test_the_reference_is_state_that_can_be_read_and_set(backend, request):
    """The quiet inlet's reference is part of the flow's state beside the populations: a second
    solver given both continues bit for bit (float32 storage: the populations round-trip exactly);
    given the populations only, it does not. A flow
    without the quiet inlet has none and refuses one."""
    cfg = FlowConfig(nx=96, ny=24, nu=0.05, inflow_speed=0.04, inflow_ramp_steps=0, initial_velocity=(0.04, 0.0),
                     sponge_cells=16, sponge_absorb=0.2, inlet_nonreflecting=0.005, dtype="float32")
    a = make_solver(backend, cfg, request)
    a.step(300)
    f, ref = a.distributions(), a.inlet_reference()
    assert ref.shape == (24,) and np.abs(ref).max() > 1e-5
    b, c = make_solver(backend, cfg, request), make_solver(backend, cfg, request)
    for s in (b, c):
        s.set_distributions(f)
    assert np.abs(b.inlet_reference()).max() == 0.0     # set_distributions restarts it
    b.set_inlet_reference(ref)
    assert np.array_equal(b.inlet_reference(), ref)
    for s in (a, b, c):
        s.step(50)
    assert np.array_equal(a.distributions(), b.distributions())
    assert not np.array_equal(a.distributions(), c.distributions())
    plain = make_solver(backend, replace(cfg, inlet_nonreflecting=0.0), request)
    assert plain.inlet_reference() is None
    with pytest.raises(ValueError, match="no quiet inlet"):
        plain.set_inlet_reference(ref)
    with pytest.raises(ValueError, match="24 finite numbers"):
        a.set_inlet_reference(np.full(24, np.nan))
    for s in (a, b, c, plain):
        s.close()
