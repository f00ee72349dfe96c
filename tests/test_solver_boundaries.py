"""Domain boundaries on every backend: inflow ramp and profile, free-slip walls, tunnel ends.

Inlet: moving-wall half-way bounce-back (Ladd 1994); outlet: anti-bounce-back pressure outlet
(Krueger et al. 2017, sec. 5.3.5); walls: half-way bounce-back or specular reflection.
"""
from __future__ import annotations


import numpy as np
import pytest
from conftest import make_solver
from solver_backends import BACKENDS

from feelflow.solver.config import FlowConfig
from feelflow.solver.inflow import INLET_DIRECTIONS, inflow_velocity, inlet_wall_profile, profile, ramp
from feelflow.solver.lattice import equilibrium
from feelflow.solver.relaxation import relaxation_rates


def test_ramp_is_smooth_from_zero_to_one():
    T = 400
    assert ramp(0, T) == 0.0 and ramp(T, T) == 1.0 and ramp(10 * T, T) == 1.0
    assert ramp(T // 2, T) == pytest.approx(0.5)
    assert ramp(1, T) < 1e-4          # zero slope at the start: no pressure shock
    assert ramp(T - 1, T) > 1 - 1e-4  # and at the end
    assert all(ramp(t, T) <= ramp(t + 1, T) for t in range(T))
    assert ramp(0, 0) == 1.0


def test_parabolic_profile_peak_and_mean():
    """4 U s (H - s) / H^2 at s = iy + 1/2: discrete mean 2U/3 (1 + 1/(2 H^2)); peak U at the
    centre when H is even (s = H/2 falls between two nodes, so the nodes get U (1 - 1/H^2))."""
    H, U = 20, 0.04
    p = profile(H, U, "parabolic")
    assert p.mean() == pytest.approx(2 * U / 3 * (1 + 1 / (2 * H * H)), rel=1e-12)
    assert p.max() == pytest.approx(U * (1 - 1 / H ** 2), rel=1e-12)
    assert np.allclose(p, p[::-1])
    assert np.all(profile(H, U, "uniform") == U)
    cfg = FlowConfig(nx=40, ny=H, inflow_speed=U, inflow_profile="parabolic", inflow_ramp_steps=100)
    assert np.allclose(inflow_velocity(cfg, 50), 0.5 * p)


def test_sponge_raises_viscosity_towards_the_outlet():
    cfg = FlowConfig(nx=100, ny=10, nu=0.02, collision="bgk", sponge_cells=20, sponge_strength=10.0)
    op, _ = relaxation_rates(cfg)
    nu = (1 / op - 0.5) / 3
    assert np.allclose(nu[:80], 0.02)
    assert nu[-1] == pytest.approx(0.2)           # A nu at the last column (s = 1)
    assert nu[80] == pytest.approx(0.02 * (1 + 9 / 400))  # s = 1/L at the first sponge column
    assert np.all(np.diff(nu[79:]) > 0)


def test_inlet_links_take_the_inflow_at_their_midpoints():
    """Link i of row iy meets the inlet at (-1/2, iy - c_iy / 2): the row's height for i = 1, the
    rows' common edge below (i = 5) or above (i = 8); the corner links of a parabolic profile
    meet the walls, where it is zero."""
    H, U = 20, 0.04
    links = inlet_wall_profile(H, U, "parabolic")
    assert INLET_DIRECTIONS == (1, 5, 8) and links.shape == (3, H)
    edges = 4 * U * np.arange(H + 1) * (H - np.arange(H + 1)) / H ** 2  # at s = 0 .. H
    assert np.allclose(links[0], profile(H, U, "parabolic"), rtol=1e-14)
    assert np.allclose(links[1], edges[:-1], rtol=1e-14) and links[1][0] == 0.0
    assert np.allclose(links[2], edges[1:], rtol=1e-14) and links[2][-1] == 0.0
    assert np.all(inlet_wall_profile(H, U, "uniform") == U)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("walls", ["free_slip", "periodic"])
def test_uniform_stream_through_the_tunnel_is_a_fixed_point(backend, walls, request):
    """f = f^eq(RHO0, U) everywhere is reproduced exactly by every rule: the inlet's moving-wall
    term, the outlet's anti-bounce-back, specular walls and their corners."""
    U = 0.05
    cfg = FlowConfig(nx=32, ny=12, nu=0.02, x_boundary="tunnel", y_boundary=walls, inflow_speed=U,
                     inflow_ramp_steps=0, initial_velocity=(U, 0.0))
    s = make_solver(backend, cfg, request)
    s.step(100)
    rho, ux, uy = s.macroscopic()
    tol = 1e-13 if backend == "numpy" else 1e-6
    assert np.abs(rho - 1).max() < tol
    assert np.abs(ux - U).max() < tol and np.abs(uy).max() < tol


@pytest.mark.parametrize("backend", BACKENDS)
def test_free_slip_walls_keep_a_periodic_stream_uniform(backend, request):
    cfg = FlowConfig(nx=16, ny=12, nu=0.02, x_boundary="periodic", y_boundary="free_slip",
                     initial_velocity=(0.04, 0.0))
    s = make_solver(backend, cfg, request)
    s.step(50)
    rho, ux, uy = s.macroscopic()
    tol = 1e-13 if backend == "numpy" else 1e-6
    assert np.abs(rho - 1).max() < tol and np.abs(ux - 0.04).max() < tol and np.abs(uy).max() < tol


@pytest.mark.parametrize("backend", BACKENDS)
def test_channel_with_parabolic_inflow_balances_mass_and_stays_parabolic(backend, request):
    """No-slip channel fed with the Poiseuille profile: at steady state the mass flux out equals
    the flux in, the total mass stops changing, and the profile mid-channel is the parabola
    (to the inlet's O(rho - RHO0) error: it imposes momentum RHO0 u_in)."""
    ny, U = 16, 0.05
    cfg = FlowConfig(nx=96, ny=ny, nu=0.05, x_boundary="tunnel", y_boundary="no_slip", inflow_speed=U,
                     inflow_profile="parabolic", inflow_ramp_steps=200)
    s = make_solver(backend, cfg, request)
    s.step(4000)
    m1 = s.total_mass()
    s.step(500)
    m2 = s.total_mass()
    rho, ux, _ = s.macroscopic()
    flux_in, flux_out = (rho * ux)[:, 0].sum(), (rho * ux)[:, -1].sum()
    assert flux_out == pytest.approx(flux_in, rel=2e-3)
    assert abs(m2 - m1) / m1 < 1e-3  # a zero-gradient outlet gained ~3e-2 here (density drift)
    sy = np.arange(ny) + 0.5
    exact = 4 * U * sy * (ny - sy) / ny ** 2
    mid = ux[:, 48]
    assert np.abs(mid - exact).max() < 0.03 * U
    assert np.abs(rho - 1).max() < 0.03


@pytest.mark.parametrize("backend", BACKENDS)
def test_parabolic_inlet_keeps_the_poiseuille_flow_at_the_inlet(backend, request):
    """The Poiseuille flow is the exact steady state of a straight channel fed with its own
    profile, at the inlet too: each inlet link must take the inflow at its own midpoint
    (solver.inflow.inlet_wall_profile). With the row's velocity for the diagonal links the inlet
    shears the flow: u_y reached 4.9 % and the u_x error 2.8 % of U in the first columns here,
    against 0.13 % and 0.55 % (the density's rise towards the inlet, 0.45 %, at a mass flux of
    RHO0 u_in) with the midpoints. U is small so that this compressibility error stays small."""
    ny, U = 16, 0.01
    cfg = FlowConfig(nx=96, ny=ny, nu=0.05, x_boundary="tunnel", y_boundary="no_slip", inflow_speed=U,
                     inflow_profile="parabolic", inflow_ramp_steps=200)
    s = make_solver(backend, cfg, request)
    s.step(4000)
    _, ux, uy = s.macroscopic()
    sy = np.arange(ny) + 0.5
    exact = 4 * U * sy * (ny - sy) / ny ** 2
    inlet = slice(0, 5)
    assert np.abs(uy[:, inlet]).max() < 0.005 * U
    assert np.abs(ux[:, inlet] - exact[:, None]).max() < 0.01 * U


@pytest.mark.parametrize("backend", BACKENDS)
def test_incompressible_equilibrium_removes_the_inlet_compressibility_error(backend, request):
    """The same channel as above. The pressure gradient that drives Poiseuille flow makes the
    density rise towards the inlet; with the compressible equilibrium u = j / rho then falls
    below the profile where rho > RHO0 (0.55 % of U in the first columns here), while He & Luo's
    incompressible equilibrium (u = j / RHO0, velocity terms times RHO0) has the profile as its
    exact steady state whatever the density: 0.20 % (what is left is the outlet's disturbance)."""
    ny, U = 16, 0.01
    sy = np.arange(ny) + 0.5
    exact = 4 * U * sy * (ny - sy) / ny ** 2
    err = {}
    for eq in ("compressible", "incompressible"):
        cfg = FlowConfig(nx=96, ny=ny, nu=0.05, x_boundary="tunnel", y_boundary="no_slip", inflow_speed=U,
                         inflow_profile="parabolic", inflow_ramp_steps=200, equilibrium=eq)
        s = make_solver(backend, cfg, request)
        s.step(4000)
        _, ux, _ = s.macroscopic()
        err[eq] = float(np.abs(ux[:, :5] - exact[:, None]).max()) / U
    print(f"\n{backend}: u_x error in the first 5 columns {err['compressible']:.2%} (compressible), "
          f"{err['incompressible']:.2%} (incompressible)")
    assert err["incompressible"] < 0.0025
    assert err["incompressible"] < 0.5 * err["compressible"]


@pytest.mark.parametrize("backend", BACKENDS)
def test_absorbing_sponge_lets_sound_out_and_leaves_a_stream_alone(backend, request):
    """A sound pulse in a closed-open tunnel (velocity inlet at rest, pressure outlet) rings: the
    outlet reflects it with its sign flipped and the inlet reflects it again, so only viscosity
    damps it. With the sponge's absorbing layer (Kam et al. 2006) the pulse leaves: after four
    crossings its rms density fluctuation is far below the ringing tunnel's. A uniform stream at
    RHO0 is untouched by it (its density fluctuation is zero)."""
    nx, ny = 200, 8
    x = np.arange(nx)
    bump = 1.0 + 1e-3 * np.exp(-((x - 60) / 6.0) ** 2)
    rms = {}
    for absorb in (0.0, 0.3):
        cfg = FlowConfig(nx=nx, ny=ny, nu=0.01, y_boundary="periodic", inflow_speed=0.0,
                         inflow_ramp_steps=0, sponge_cells=50, sponge_absorb=absorb)
        s = make_solver(backend, cfg, request)
        rho = np.repeat(bump[None, :], ny, axis=0)
        s.set_distributions(equilibrium(rho, np.zeros_like(rho), np.zeros_like(rho)))
        s.step(int(4 * nx / np.sqrt(1 / 3)))
        rho, _, _ = s.macroscopic()
        rms[absorb] = float(np.sqrt(np.mean((rho[:, : nx - 50] - 1.0) ** 2)))
        s.close()
    print(f"\n{backend}: rms density fluctuation after four crossings {rms[0.0]:.3e} (ringing), "
          f"{rms[0.3]:.3e} (absorbing layer)")
    assert rms[0.3] < 0.1 * rms[0.0]
    U = 0.05
    cfg = FlowConfig(nx=32, ny=12, nu=0.02, y_boundary="periodic", inflow_speed=U, inflow_ramp_steps=0,
                     initial_velocity=(U, 0.0), sponge_cells=10, sponge_absorb=0.3)
    s = make_solver(backend, cfg, request)
    f0 = s.distributions()
    s.step(50)
    assert np.allclose(s.distributions(), f0, rtol=0, atol=1e-6)
    s.close()


def test_absorbing_sponge_stops_the_tunnel_sloshing_after_a_ramp(request):
    """The window's default tunnel (256 x 128, sponge 32) with the inflow ramped up over 1000
    steps and the bare velocity inlet (the quiet inlet is tested in test_quiet_tunnel.py):
    without the absorbing layer the tunnel's quarter-wave mode swings the mean velocity
    by tens of percent of U for thousands of steps; with it (app.simulation.default_base_config)
    the mean is steady within 2 % from step 3000 on."""
    from dataclasses import replace

    from feelflow.app.model.simulation import default_base_config

    swing = {}
    for absorb in (0.0, 0.1):
        cfg = replace(default_base_config((256, 128)), inflow_speed=0.05, inflow_ramp_steps=1000,
                      sponge_absorb=absorb, inlet_nonreflecting=0.0).validate()
        s = make_solver("numpy", cfg, request)
        s.step(3000)
        means = []
        for _ in range(25):
            s.step(200)
            means.append(s.macroscopic()[1][:, : 256 - 32].mean() / 0.05)
        swing[absorb] = max(means) - min(means)
        s.close()
    print(f"\nswing of the mean u / U after the ramp: {swing[0.0]:.3f} without, {swing[0.1]:.4f} with the layer")
    assert swing[0.0] > 0.2 and swing[0.1] < 0.02
    assert default_base_config((256, 128)).sponge_absorb == 0.1
