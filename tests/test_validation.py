"""Physics validation (solver/validation/): quick versions in the default run, full ones `slow`.

Each case measures against physics (analytic solutions, convergence order, published
benchmarks, Galilean invariance, conservation); the targets are the published ones (docs/science/validation.md).
"""
import pytest

from feelflow.solver.validation import CASES, case_module
from conftest import make_solver

BACKENDS = ["numpy", pytest.param("gl", marks=pytest.mark.gl)]


def factory(backend, request):
    return lambda config: make_solver(backend, config, request)


@pytest.mark.parametrize("backend", BACKENDS)
def test_poiseuille_converges_with_order_two(backend, request):
    r = case_module("poiseuille").run(factory(backend, request), quick=True, backend=backend)
    assert r.quantities["steady"] == 1.0
    assert 1.8 <= r.quantities["order"] <= 2.2, r.quantities


@pytest.mark.parametrize("backend", BACKENDS)
def test_taylor_green_decay_gives_viscosity(backend, request):
    r = case_module("taylor-green").run(factory(backend, request), quick=True, backend=backend)
    assert abs(r.quantities["nu_rel_error"]) < 0.01, r.quantities


@pytest.mark.parametrize("backend", BACKENDS)
def test_galilean_invariance_of_the_force(backend, request):
    r = case_module("galilean").run(factory(backend, request), quick=True, backend=backend)
    assert abs(r.quantities["towed_vs_fixed"]) < 0.03, r.quantities
    assert r.quantities["comoving_vs_fixed"] < 0.02, r.quantities


@pytest.mark.parametrize("backend", BACKENDS)
def test_mass_drift_of_a_moving_body_is_small(backend, request):
    r = case_module("mass").run(factory(backend, request), quick=True, backend=backend)
    assert abs(r.quantities["mass_drift"]) < 1e-3, r.quantities


def test_surface_value_extrapolates_a_quadratic_exactly():
    import numpy as np

    from feelflow.solver.validation.schaefer_turek import surface_value

    y, x = np.mgrid[0:6, 0:10].astype(float)
    field = 1 + 0.1 * x + 0.02 * x ** 2 + 0.3 * y
    solid = x >= 6
    assert surface_value(field, solid, (5.6, 2.5), -1) == pytest.approx(1 + 0.56 + 0.02 * 5.6 ** 2 + 0.75)


def test_every_case_result_has_the_reported_fields(request):
    r = case_module("taylor-green").run(factory("numpy", request), resolution=16)
    d = r.to_dict()
    for key in ("name", "backend", "resolution", "quantities", "steps", "wall_seconds", "mlups", "passed"):
        assert key in d
    assert d["steps"] > 0 and d["wall_seconds"] > 0


#: published targets a full case misses, with what it measures (docs/science/validation.md)
KNOWN_MISSES = {
    "schaefer-turek-2d2": "at 40 cells per diameter on cpu C_D,max is 3.25056 (target 3.22 .. 3.24) and C_L,max "
                          "0.986747 (target 0.99 .. 1.01); St 0.300601 is inside 0.295 .. 0.305 (feelflow validate "
                          "--case schaefer-turek-2d2 --backend cpu: 67500 steps, 278 s on a loaded 2-core machine; "
                          "numpy gives the same six digits in 3160 s; 60 cells on gl meet the targets, "
                          "docs/science/validation.md)",
}

#: full cases run by another slow test with more checks: the stability scan (725 s on cpu, 2 cores)
#: runs once, in tests/test_stability.py test_full_scan_supports_the_window_limit, which also
#: holds the window's stability constant against what it measures
RUN_ELSEWHERE = {"stability"}


@pytest.mark.slow
@pytest.mark.timeout(3600)   # a full case runs for minutes on cpu (2D-2: 326 s under load, one numba thread)
@pytest.mark.parametrize("name", [pytest.param(name, marks=pytest.mark.xfail(strict=True, reason=KNOWN_MISSES[name]))
                                  if name in KNOWN_MISSES else name for name in CASES
                                  if not getattr(case_module(name), "NAMED_ONLY", False) and name not in RUN_ELSEWHERE])
def test_full_case_meets_its_targets(name, request):
    """Every full case (`feelflow validate --case NAME --backend cpu`) on the compiled cpu backend,
    which computes the numpy reference's numbers to float32 rounding (tests/test_cpu_vs_numpy.py)
    in a fraction of its time (2D-2: 326 s; 2683 s on numpy, both on a loaded 2-core machine)."""
    r = case_module(name).run(factory("cpu", request), backend="cpu")
    assert r.passed, r.to_dict()


@pytest.mark.slow
@pytest.mark.timeout(1800)   # (a few minutes on cpu; numba compiles the regularised operator's kernel first)
def test_cylinder_at_re200_sheds_at_the_published_strouhal_at_10_cells(request):
    """The high-Reynolds case at its coarsest rung (the whole ladder d = 10, 20, 40 takes hours:
    `feelflow validate --case cylinder-re200`): St within its 3 % target; C_D is measured 7.8 %
    high at 10 cells (docs/science/collision-operators.md), outside its 5 % target there, so only
    its sign and size are held here. On the compiled cpu backend (equal to numpy; on numpy it
    took 391 s on a loaded 2-core machine)."""
    r = case_module("cylinder-re200").run(factory("cpu", request), resolution=10, backend="cpu")
    q = r.quantities
    assert q["converged"] == 1.0 and r.check_results()["strouhal"], r.to_dict()
    assert 0.0 < q["cd_mean"] / 1.34 - 1.0 < 0.10, q


def test_cylinder_re200_targets_are_the_published_values_within_their_tolerances():
    """The Re 200 case's checks: St within 3 % and C_D within 5 % of the published 2D values
    (held without running the case, which takes minutes; the case itself is `slow`)."""
    from feelflow.solver.validation import cylinder_high_re as high_re

    ref = high_re.REFERENCES[200]
    checks = {c.quantity: c for c in high_re.checks(200.0)}
    for key, rel in (("strouhal", high_re.ST_REL), ("cd_mean", high_re.CD_REL)):
        assert checks[key].holds(ref[key] * (1 + 0.99 * rel)) and checks[key].holds(ref[key] * (1 - 0.99 * rel))
        assert not checks[key].holds(ref[key] * (1 + 1.01 * rel)) and not checks[key].holds(ref[key] * (1 - 1.01 * rel))
    assert [c.quantity for c in high_re.checks(1000.0)] == ["converged"]


@pytest.mark.slow
@pytest.mark.timeout(3600)
def test_schaefer_turek_2d1_at_40_cells(request):
    """2D-1 at 40 cells per diameter: eight times the node updates of the 20-cell full case, so
    it runs on the compiled cpu backend (equal to numpy, tests/test_cpu_vs_numpy.py); on numpy it
    ran past 600 s on a loaded 2-core machine."""
    r = case_module("schaefer-turek-2d1").run(factory("cpu", request), resolution=40, backend="cpu")
    assert r.passed, r.to_dict()


def test_schaefer_turek_2d1_coarse_converges_near_the_benchmark(request):
    """At 10 cells per diameter (no issue target there) the steady state is reached by the
    convergence criterion and C_D, dp lie within a few percent of the refined reference values
    (benchmarks.md: interpolated bounce-back LBM codes get C_D within ~1 % at 24 cells)."""
    r = case_module("schaefer-turek-2d1").run(factory("numpy", request), quick=True)
    assert r.quantities["converged"] == 1.0
    assert abs(r.quantities["cd_rel_error"]) < 0.03, r.quantities
    assert abs(r.quantities["dp_rel_error"]) < 0.05, r.quantities
    # the lift, 2 per mille of the drag, is the sensitive one: -19 % here while the inlet's
    # diagonal links took the row's velocity (docs/science/validation.md, Schaefer-Turek 2D-1)
    assert abs(r.quantities["cl_rel_error"]) < 0.05, r.quantities


@pytest.mark.slow
@pytest.mark.timeout(1800)   # two full 2D-1 runs (D 20 and 30): 175 s on cpu under a load average of 3.5
def test_schaefer_turek_2d1_drag_converges_at_second_order_with_tau_held(request):
    """D = 20 -> 30 with U_m D held (tau 0.65, `feelflow bench accuracy --axis tau`): every error
    of a second-order scheme falls like D^-2. C_D's observed order was 1.23 while the inlet's
    diagonal links took the row's velocity, a first-order error (docs/science/validation.md, Schaefer-Turek
    2D-1 section)."""
    import math

    from feelflow.app.bench.accuracy import TAU_FIXED

    st = case_module("schaefer-turek-2d1")
    points = TAU_FIXED[:2]  # (20, 0.075), (30, 0.05)
    errors = [abs(st.run(factory("cpu", request), resolution=d, u_max=u, backend="cpu")
                  .quantities["cd_rel_error"]) for d, u in points]
    order = math.log(errors[0] / errors[1]) / math.log(points[1][0] / points[0][0])
    assert order > 1.8, (errors, order)


@pytest.mark.parametrize("d", [16, 15, 25, 0, -10, 20.0, True])
def test_schaefer_turek_refuses_a_channel_that_is_not_whole_cells_high(d):
    """4.1 D must be a whole number of cells (walls half-way between nodes): a resolution that
    is not a multiple of 10 would change the blockage D / H, so it is refused, naming why."""
    from feelflow.solver.validation.schaefer_turek import Geometry

    with pytest.raises(ValueError, match="multiple of 10"):
        Geometry(d, 20.0)


@pytest.mark.parametrize("d", [10, 20, 40, 80])
def test_schaefer_turek_lengths_keep_the_benchmark_ratios(d):
    """Channel 4.1 D high between the half-way walls (-1/2 and ny - 1/2) and 22 D long, cylinder
    2 D from the bottom wall and from the inlet (x = -1/2), 2.1 D from the top wall."""
    from feelflow.solver.validation.schaefer_turek import Geometry

    g = Geometry(d, 100.0)
    assert 10 * g.ny == 41 * d and g.nx == 22 * d
    cx, cy = g.centre
    assert (cx + 0.5, cy + 0.5) == (2 * d, 2 * d) and (g.ny - 0.5) - cy == pytest.approx(2.1 * d)


def test_the_oscillating_cylinder_check_tells_a_shifted_or_scaled_force_from_the_paper():
    """Duetsch et al.'s fig. 10 (digitised): the case's deviation is nil for the reference
    itself and outside its bounds for the force of a tenth of a period late or 15 % too strong,
    or for an inertia force alone (the added mass of potential flow, -rho pi D^2/4 dU/dt), so the
    bounds are tighter than those errors (the case itself, minutes, is `slow`)."""
    import math

    import numpy as np

    from feelflow.solver.validation import oscillating_cylinder as osc

    ref = np.asarray(osc.REFERENCE)
    phase = np.linspace(-0.2, 1.2, 561)
    curve = np.interp(phase % 1.0, ref[:, 0], ref[:, 1])
    assert max(osc.compare(phase, curve)[1:]) < 0.005   # (the sampled curve's own interpolation)
    late = np.interp((phase - 0.1) % 1.0, ref[:, 0], ref[:, 1])
    inertia = -math.pi ** 2 / (2 * osc.KC) * np.sin(2 * math.pi * phase)   # F / (rho U_m^2 D), U = -U_m cos
    for wrong in (late, 1.15 * curve, inertia):
        _, rms, worst = osc.compare(phase, wrong)
        assert rms > osc.RMS_MAX or worst > osc.WORST_MAX
