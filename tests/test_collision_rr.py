"""The recursive-regularised collision (solver/regularised.py, shaders/collide_rr.glsl) tested
against physics and against itself across the numpy and gl backends (explicitly these two: a
backend without the operator refuses it with a ConfigError).

- a decaying shear wave u_x = A sin(k y) loses amplitude as exp(-nu k^2 t) (the Navier-Stokes
  solution): the operator has BGK's viscosity nu = (tau - 1/2) / 3;
- the Smagorinsky eddy viscosity adds C^2 |S| to it (the closure's own formula), nothing at C -> 0;
- gl equals numpy to float32 rounding in a tunnel with the sponge, its absorbing layer and a
  moving, spinning body (the moving-wall and refill terms), and in a forced periodic box;
- at U / nu = 50 the hard case TRT cannot hold (the shaken cylinder) stays bounded with rr.
"""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from conftest import make_solver

from feelflow.shapes import Cylinder
from feelflow.solver.config import ConfigError, FlowConfig
from feelflow.solver.lattice import equilibrium
from feelflow.solver.validation import stability

BACKENDS = ["numpy", pytest.param("gl", marks=pytest.mark.gl)]


def test_smagorinsky_needs_the_rr_operator():
    with pytest.raises(ConfigError, match="smagorinsky"):
        FlowConfig(nx=16, ny=16, collision="trt", smagorinsky=0.1).validate()
    with pytest.raises(ConfigError, match="smagorinsky"):
        FlowConfig(nx=16, ny=16, collision="rr", smagorinsky=-0.1).validate()
    FlowConfig(nx=16, ny=16, collision="rr", smagorinsky=0.1).validate()


def _shear_wave_decay(backend, request, nu, smagorinsky=0.0, ny=64, steps=400, amp=0.02, settle=200):
    """Measured nu_eff from the decay of u_x = amp sin(2 pi y / ny) over `steps`, after `settle`
    steps in which the start from equilibrium (no non-equilibrium part) has relaxed."""
    cfg = FlowConfig(nx=8, ny=ny, nu=nu, collision="rr", smagorinsky=smagorinsky, dtype="float64",
                     x_boundary="periodic", y_boundary="periodic", inflow_speed=0.0).validate()
    s = make_solver(backend, cfg, request)
    k = 2 * math.pi / ny
    y = np.arange(ny, dtype=float)[:, None] * np.ones((1, 8))
    s.set_distributions(equilibrium(np.ones_like(y), amp * np.sin(k * y), np.zeros_like(y)))
    proj = np.sin(k * y)

    def amplitude():
        return float((s.macroscopic()[1] * proj).sum() / (proj * proj).sum())

    s.step(settle)
    a0 = amplitude()
    s.step(steps)
    a1 = amplitude()
    s.close()
    return -math.log(a1 / a0) / (k * k * steps)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("nu", [0.02, 0.002])
def test_shear_wave_decays_at_the_viscosity(backend, nu, request):
    nu_eff = _shear_wave_decay(backend, request, nu)
    print(f"\n  nu {nu}: measured {nu_eff:.6f}", end="")
    assert nu_eff == pytest.approx(nu, rel=0.01)


def test_smagorinsky_eddy_viscosity_is_c_squared_times_the_strain(request):
    """nu_t = C^2 |du/dy| (dx = 1) on u_x = A sin(k y): its projection on the mode adds
    C^2 A k <|cos|^3> / <cos^2> = C^2 A k 8 / (3 pi) to the decay's viscosity."""
    nu, amp, c = 0.002, 0.02, 0.15
    plain = _shear_wave_decay("numpy", request, nu, 0.0, amp=amp)
    tiny = _shear_wave_decay("numpy", request, nu, 0.001, amp=amp)
    les = _shear_wave_decay("numpy", request, nu, c, amp=amp)
    predicted = c * c * amp * (2 * math.pi / 64) * 8 / (3 * math.pi)
    print(f"\n  nu_eff: C=0 {plain:.7f}, C=0.001 {tiny:.7f}, C={c} {les:.7f}; nu_t predicted {predicted:.2e}", end="")
    assert les - plain == pytest.approx(predicted, rel=0.1)
    assert tiny == pytest.approx(plain, rel=1e-3)


def _rel(a, b):
    return float(np.abs(a - b).max() / np.abs(b).max())


@pytest.mark.gl
@pytest.mark.parametrize("smagorinsky", [0.0, 0.15])
def test_gl_equals_numpy_in_a_tunnel_with_a_moving_body(smagorinsky, request):
    cfg = FlowConfig(nx=64, ny=32, nu=0.002, dtype="float32", collision="rr", smagorinsky=smagorinsky,
                     inflow_speed=0.05, initial_velocity=(0.05, 0.0), inflow_ramp_steps=0, sponge_cells=16,
                     sponge_absorb=0.1).validate()
    solvers = [make_solver(b, cfg, request) for b in ("numpy", "gl")]
    for s in solvers:
        s.set_body(Cylinder(8, 20, 16), velocity=(0.01, -0.005), omega=0.002)
        s.step(60)
    ref, gl = (s.distributions() for s in solvers)
    (_, ux0, uy0), (_, ux1, uy1) = (s.macroscopic() for s in solvers)
    print(f"\n  f {_rel(gl, ref):.1e}, ux {_rel(ux1, ux0):.1e}", end="")
    assert _rel(gl, ref) < 1e-5
    assert max(float(np.abs(ux1 - ux0).max()), float(np.abs(uy1 - uy0).max())) / float(np.abs(ux0).max()) < 1e-5


@pytest.mark.gl
def test_gl_equals_numpy_with_a_body_force(request):
    cfg = FlowConfig(nx=48, ny=32, nu=0.004, dtype="float32", collision="rr", smagorinsky=0.1,
                     x_boundary="periodic", y_boundary="periodic", body_force=(1e-5, -2e-6)).validate()
    rng = np.random.default_rng(3)
    f = equilibrium(1 + 1e-3 * rng.standard_normal((32, 48)), 0.02 * rng.standard_normal((32, 48)),
                    0.02 * rng.standard_normal((32, 48)))
    solvers = [make_solver(b, cfg, request) for b in ("numpy", "gl")]
    for s in solvers:
        s.set_distributions(f)
        s.step(60)
    assert _rel(solvers[1].distributions(), solvers[0].distributions()) < 1e-5


def test_rr_holds_where_trt_runs_away(request):
    """The shaken cylinder at U / nu = 50 (d = 20, U = 0.05): TRT fails within 6 d / U, rr lasts."""
    u, nu = 0.05, 0.001
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        trt = stability.run_point(lambda c: make_solver("numpy", c, request), "cylinder_shaken", "trt", u, nu)
        rr = stability.run_point(lambda c: make_solver("numpy", c, request), "cylinder_shaken", "rr", u, nu)
    assert not trt.stable, trt.to_dict()
    assert rr.stable and rr.max_u < stability.U_BOUND, rr.to_dict()


def test_shedding_period_reads_the_period_of_a_sampled_sine():
    """The Strouhal case's frequency reader (solver/validation/strouhal.py) on a known signal:
    period 123.4 steps, sampled every 10, with an offset."""
    from feelflow.solver.validation.strouhal import shedding_period

    t = np.arange(0, 3000, 10.0)
    periods = shedding_period(t, 0.3 + np.sin(2 * math.pi * t / 123.4 + 0.4))
    assert len(periods) >= 20
    assert float(np.mean(periods)) == pytest.approx(123.4, rel=1e-3)


def test_the_chooser_takes_trt_where_it_holds_rr_beyond_and_keeps_a_named_one():
    from feelflow.solver.operator_choice import choose
    from feelflow.solver.stability_limit import inside

    low = choose(0.05, 0.02, 20)                  # U / nu = 2.5: inside TRT's measured region
    assert low.collision == "trt" and inside(0.05, 0.02, "trt", 20) and "cheapest" in low.reason
    high = choose(0.05, 0.001, 20)                # U / nu = 50: beyond TRT's, inside rr's
    assert high.collision == "rr" and not inside(0.05, 0.001, "trt", 20) and inside(0.05, 0.001, "rr", 20)
    assert choose(0.05, 0.001, 20, named="trt").collision == "trt"   # a scene's own choice stays
    assert choose(0.05, 0.0001, 20).collision == "rr"                  # beyond both: the most stable
    for c in (low, high):
        assert "\n" not in c.reason and c.reason.startswith(("TRT", "regularised BGK"))
