"""The recursive-regularised collision (solver/regularised.py, shaders/collide_rr.glsl) tested
against physics and against itself across the numpy and gl backends (explicitly these two: a
backend without the operator refuses it with a ConfigError).

- a decaying shear wave u_x = A sin(k y) loses amplitude as exp(-nu k^2 t) (the Navier-Stokes
  solution): the operator has BGK's viscosity nu = (tau - 1/2) / 3;
- the Smagorinsky eddy viscosity adds C^2 |S| to it (the closure's own formula), nothing at C -> 0;
- gl equals numpy to float32 rounding in a tunnel with the sponge, its absorbing layer and a
  moving, spinning body (the moving-wall and refill terms), and in a forced periodic box;
- at U / nu = 50 the hard case TRT cannot hold (the shaken cylinder) stays bounded with rr;
- what makes rr rr, on every backend: one collision of a uniform non-equilibrium state equals the
  Hermite definition written independently here (third-order equilibrium rho ux^2 uy, rho ux uy^2
  and the recursive non-equilibrium a_xxy, a_xyy); a shear wave advected at U = 0.15 decays at
  the viscosity (Galilean invariance, which the third-order equilibrium buys); the linear
  stability limit of the uniform flow is the published one (Coreixas et al. 2017).
  Deleting the third-order equilibrium fails all three; deleting the recursive terms fails the first.
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

from solver_backends import BACKENDS as ALL_BACKENDS

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


# --- what is specific to rr: the third-order Hermite terms, on every backend -------------------

def _hermite_rr(f, nu, third_order_equilibrium=True, recursive=True):
    """One recursive-regularised collision of the populations f (9,), written from the Hermite
    tensors (Malaspinas 2015 eqs. 11, 31; Coreixas et al. 2017 sec. III), independently of
    solver/regularised.py: H^(n) as full tensors, f^eq to third order, n^reg from a^(2)neq and
    a^(3)neq_abc = u_a a_bc + u_b a_ac + u_c a_ab. The flags drop the rr-specific terms (to show
    the test sees them)."""
    from feelflow.solver.lattice import C, W

    c = C.astype(float)
    cs2 = 1.0 / 3.0
    d = np.eye(2)
    h2 = np.einsum("ia,ib->iab", c, c) - cs2 * d
    h3 = (np.einsum("ia,ib,ic->iabc", c, c, c) - cs2 * (np.einsum("ia,bc->iabc", c, d)
          + np.einsum("ib,ac->iabc", c, d) + np.einsum("ic,ab->iabc", c, d)))
    rho = f.sum()
    u = c.T @ f / rho
    a2eq = rho * np.einsum("a,b->ab", u, u)
    a3eq = rho * np.einsum("a,b,c->abc", u, u, u) * third_order_equilibrium
    feq = W * (rho + c @ (rho * u) / cs2 + np.einsum("iab,ab->i", h2, a2eq) / (2 * cs2 ** 2)
               + np.einsum("iabc,abc->i", h3, a3eq) / (6 * cs2 ** 3))
    a2 = np.einsum("iab,i->ab", h2, f - feq)
    a3 = np.einsum("a,bc->abc", u, a2) + np.einsum("b,ac->abc", u, a2) + np.einsum("c,ab->abc", u, a2)
    a3 = a3 * recursive
    nreg = W * (np.einsum("iab,ab->i", h2, a2) / (2 * cs2 ** 2) + np.einsum("iabc,abc->i", h3, a3) / (6 * cs2 ** 3))
    omega = 1.0 / (3.0 * nu + 0.5)
    return feq + (1.0 - omega) * nreg


@pytest.mark.parametrize("backend", ALL_BACKENDS)
def test_one_collision_is_the_third_order_hermite_definition(backend, request):
    """A uniform state in a periodic box streams onto itself, so one step is one collision: every
    node must hold _hermite_rr(f). The state moves fast (u = (0.09, -0.07)) and is far from
    equilibrium, so dropping the third-order equilibrium or the recursive terms moves f* by over
    a hundred times the tolerance (asserted)."""
    from feelflow.solver.lattice import W

    nu, tol = 0.01, 2e-6
    rng = np.random.default_rng(7)
    f0 = equilibrium(np.array(1.02), np.array(0.09), np.array(-0.07)) + 0.05 * W * rng.standard_normal(9)
    expected = _hermite_rr(f0, nu)
    cfg = FlowConfig(nx=8, ny=8, nu=nu, collision="rr", dtype="float32", x_boundary="periodic",
                     y_boundary="periodic", inflow_speed=0.0).validate()
    s = make_solver(backend, cfg, request)
    s.set_distributions(np.broadcast_to(f0[:, None, None], (9, 8, 8)).copy())
    s.step(1)
    got = s.distributions().astype(np.float64)
    s.close()
    scale = np.abs(expected).max()
    err = float(np.abs(got - expected[:, None, None]).max() / scale)
    without_eq3 = float(np.abs(_hermite_rr(f0, nu, third_order_equilibrium=False) - expected).max() / scale)
    without_rec = float(np.abs(_hermite_rr(f0, nu, recursive=False) - expected).max() / scale)
    print(f"\n  {backend}: max |f* - Hermite| / max f* = {err:.1e}; without the third-order "
          f"equilibrium {without_eq3:.1e}, without the recursive terms {without_rec:.1e}", end="")
    assert min(without_eq3, without_rec) > 100 * tol
    assert err < tol


def _advected_shear_wave(backend, request, speed, nu=0.01, n=32, steps=600, settle=100, amp=0.005):
    """nu_eff of u_y = amp sin(k x) carried along x at `speed` through a periodic box: the
    modulus of the mode's complex amplitude decays as exp(-nu k^2 t) whatever the speed
    (Galilean invariance of the Navier-Stokes equations)."""
    cfg = FlowConfig(nx=n, ny=8, nu=nu, collision="rr", dtype="float64", x_boundary="periodic",
                     y_boundary="periodic", inflow_speed=0.0).validate()
    s = make_solver(backend, cfg, request)
    k = 2 * math.pi / n
    x = np.ones((8, 1)) * np.arange(n, dtype=float)[None, :]
    s.set_distributions(equilibrium(np.ones_like(x), np.full_like(x, speed), amp * np.sin(k * x), order=3))
    mode = np.exp(-1j * k * x)

    def amplitude():
        return abs(complex((s.macroscopic()[2] * mode).sum()))

    s.step(settle)
    a0 = amplitude()
    s.step(steps)
    a1 = amplitude()
    s.close()
    return -math.log(a1 / a0) / (k * k * steps)


@pytest.mark.parametrize("backend", ALL_BACKENDS)
def test_a_shear_wave_advected_fast_decays_at_the_viscosity(backend, request):
    """At U = 0.15 (Ma 0.26) D2Q9's second-order equilibrium misses rho ux^2 uy in the momentum
    flux's divergence and the wave decays at about nu (1 - 3 U^2 / (...)); the third-order
    equilibrium restores nu (measured: docs/science/collision-operators.md)."""
    nu = 0.01
    rest = _advected_shear_wave(backend, request, 0.0, nu)
    fast = _advected_shear_wave(backend, request, 0.15, nu)
    print(f"\n  {backend}: nu_eff at rest {rest:.6f}, at U 0.15 {fast:.6f} (nu {nu})", end="")
    assert rest == pytest.approx(nu, rel=0.01)
    assert fast == pytest.approx(nu, rel=0.01)


def test_linear_stability_limit_is_the_third_order_one():
    """The fastest uniform flow (along the diagonal, the weakest direction) in which no disturbance
    grows, from the Jacobian of the numpy reference operator (solver/validation/linear_stability.py):
    0.272 at nu 0.001 with the third-order equilibrium, 0.172 with the second-order one
    (Coreixas et al. 2017, Fig. 5 region for D2Q9 rr with the full equilibrium)."""
    from feelflow.solver.validation.linear_stability import max_stable_speed

    u = max_stable_speed("rr", 0.001, 45.0, tol=4e-3, k_points=32)
    print(f"\n  rr nu 0.001, 45 deg: max stable |u| {u:.3f}", end="")
    assert 0.25 < u < 0.30
