"""The compiled cpu backend against the numpy reference, same scene, N steps.

Both implement docs/algorithm.md; the cpu backend's kernel computes in float64 from float32
storage where numpy computes in float32, so fields must agree to float32 rounding (1e-5
relative) and every force model to 1e-4 relative: the tolerances of the gl backend's test
(tests/test_gl_vs_numpy.py). Relative = max |cpu - numpy| / max |numpy| over the grid: of f, of
rho - 1, of each velocity component against the top speed. With float64 storage both must
agree far closer (1e-10).
"""
from __future__ import annotations

import numpy as np
import pytest

from feelflow.shapes import Cylinder, FlatPlate
from feelflow.solver.backend import create_solver
from feelflow.solver.config import FlowConfig
from feelflow.solver.forces import MODELS

FIELD_TOL = {"float32": 1e-5, "float64": 1e-10}
FORCE_TOL = {"float32": 1e-4, "float64": 1e-9}
STEPS = 60
#: numba compiles one kernel per (operator, equilibrium, absorbing layer, body force, precision),
#: about 30 s each on a fresh 2-core machine. The default run checks the variants the window runs
#: (TRT, compressible, float32, with and without the absorbing layer); the others run with -m slow.
SLOW = pytest.mark.slow


def _rel(a, b):
    """max |a - b| / max |b| (the absolute difference where b is identically zero)."""
    diff, scale = float(np.abs(a - b).max()), float(np.abs(b).max())
    return diff / scale if scale > 0 else diff


def _run_pair(cfg, steps=STEPS, motion=None, models=(), per_call=1):
    """numpy and cpu on cfg for `steps` calls of step(per_call), `motion(solver, k)` before each."""
    solvers = [create_solver(b, cfg) for b in ("numpy", "cpu")]
    forces = [[], []]
    for s in solvers:
        if models:
            s.enable_force_models(models)
    for k in range(steps):
        for j, s in enumerate(solvers):
            if motion is not None:
                motion(s, k)
            s.step(per_call)
            torques = s.torques()
            forces[j].append({name: (*f, torques[name]) for name, f in s.forces().items()})
    return solvers, forces


def _check_fields(solvers):
    tol = FIELD_TOL[solvers[0].config.dtype]
    ref, cpu = (s.macroscopic() for s in solvers)
    rho = _rel(cpu[0] - 1, ref[0] - 1)
    speed = float(np.hypot(ref[1], ref[2]).max())
    u = max(float(np.abs(cpu[1] - ref[1]).max()), float(np.abs(cpu[2] - ref[2]).max())) / speed
    f = _rel(solvers[1].distributions(), solvers[0].distributions())
    print(f"\n  fields: rho-1 {rho:.1e}, u {u:.1e}, f {f:.1e}", end="")
    assert rho < tol and u < tol and f < tol


def _check_forces(forces, models, dtype="float32"):
    for name in models:
        ref = np.array([f[name] for f in forces[0]])
        cpu = np.array([f[name] for f in forces[1]])
        assert np.abs(ref[:, :2]).max() > 0, name  # the comparison must compare something
        err = _rel(cpu[:, :2], ref[:, :2])
        if ref.shape[1] == 3:  # and the torque (identically zero where a model has none)
            torque = _rel(cpu[:, 2], ref[:, 2])
            print(f"\n  torque {name}: {torque:.1e}", end="")
            err = max(err, torque)
        print(f"\n  force {name}: {err:.1e}", end="")
        assert err < FORCE_TOL[dtype], name


@pytest.mark.parametrize("collision", [pytest.param("bgk", marks=SLOW), pytest.param("trt", marks=SLOW)])
def test_periodic_box_with_body_force(collision):
    cfg = FlowConfig(nx=47, ny=32, dtype="float32", collision=collision, x_boundary="periodic",
                     y_boundary="periodic", body_force=(1e-5, -2e-6), initial_velocity=(0.03, 0.01))
    solvers, _ = _run_pair(cfg)
    rng = np.random.default_rng(3)  # then a disturbed state, so that streaming matters
    from feelflow.solver.lattice import equilibrium
    f = equilibrium(1 + 1e-3 * rng.standard_normal((32, 47)), 0.02 * rng.standard_normal((32, 47)),
                    0.02 * rng.standard_normal((32, 47)))
    for s in solvers:
        s.set_distributions(f)
        s.step(STEPS)
    _check_fields(solvers)


@pytest.mark.parametrize("y_boundary", ["no_slip", "free_slip", "periodic"])
@pytest.mark.parametrize("collision", [pytest.param("bgk", marks=SLOW), "trt"])
def test_tunnel_walls_inlet_outlet_sponge(y_boundary, collision):
    cfg = FlowConfig(nx=61, ny=32, dtype="float32", collision=collision, y_boundary=y_boundary,
                     inflow_profile="parabolic" if y_boundary == "no_slip" else "uniform",
                     inflow_ramp_steps=20, sponge_cells=8)
    solvers, _ = _run_pair(cfg)
    _check_fields(solvers)


def test_periodic_channel_free_slip_walls():
    cfg = FlowConfig(nx=48, ny=32, dtype="float32", x_boundary="periodic", y_boundary="free_slip",
                     initial_velocity=(0.03, 0.02))
    solvers, _ = _run_pair(cfg)
    _check_fields(solvers)


@pytest.mark.parametrize("dtype", ["float32", pytest.param("float64", marks=SLOW)])
@pytest.mark.parametrize("collision", [pytest.param("bgk", marks=SLOW), "trt"])
def test_moving_rotating_cylinder_every_force_model(collision, dtype):
    """Moved every step (cover/uncover refill, impulses), moving-wall term with rotation."""
    cfg = FlowConfig(nx=63, ny=32, dtype=dtype, collision=collision, inflow_ramp_steps=20)

    def move(s, k):
        s.set_body(Cylinder(8.3, x=20.4 + 0.05 * k, y=15.7 + 0.02 * k), velocity=(0.05, 0.02), omega=0.002)

    solvers, forces = _run_pair(cfg, motion=move, models=list(MODELS))
    _check_fields(solvers)
    _check_forces(forces, MODELS, dtype)


def test_body_at_the_periodic_seam():
    """A body touching the periodic seam: its links' nodes pull across it (the boundary-node
    pass's own periodic neighbours)."""
    cfg = FlowConfig(nx=48, ny=32, dtype="float32", x_boundary="periodic", y_boundary="periodic",
                     initial_velocity=(0.03, 0.0))

    def place(s, k):
        if k == 0:
            s.set_body(Cylinder(8.0, x=4.3, y=16.2), velocity=(0.01, 0.0))

    solvers, forces = _run_pair(cfg, motion=place, models=["momentum_exchange"])
    _check_fields(solvers)
    _check_forces(forces, ["momentum_exchange"])


def test_thin_plate_and_body_removed():
    """A plate thinner than a cell (cut links between fluid nodes), then no body at all: the
    boundary-node list shrinks back to the domain's edges."""
    cfg = FlowConfig(nx=64, ny=32, dtype="float32", inflow_ramp_steps=20)

    def place(s, k):
        if k == 0:
            s.set_body(FlatPlate(10.0, 0.4, x=24.3, y=16.2, angle=1.2))
        if k == 40:
            s.set_body(None)

    solvers, forces = _run_pair(cfg, motion=place, models=["momentum_exchange"])
    _check_fields(solvers)
    _check_forces([f[:40] for f in forces], ["momentum_exchange"])


@pytest.mark.parametrize("collision", [pytest.param("bgk", marks=SLOW), pytest.param("trt", marks=SLOW)])
def test_incompressible_absorbing_sponge_moving_cylinder(collision):
    """He & Luo's equilibrium, the sponge's absorbing layer and a cylinder moved every step."""
    cfg = FlowConfig(nx=64, ny=32, dtype="float32", collision=collision, inflow_profile="parabolic",
                     inflow_ramp_steps=20, sponge_cells=12, sponge_absorb=0.3, equilibrium="incompressible")

    def move(s, k):
        s.set_body(Cylinder(8.3, x=20.4 + 0.05 * k, y=15.7 + 0.02 * k), velocity=(0.05, 0.02), omega=0.002)

    solvers, forces = _run_pair(cfg, motion=move, models=list(MODELS))
    _check_fields(solvers)
    _check_forces(forces, MODELS)


def test_compressible_absorbing_sponge():
    cfg = FlowConfig(nx=61, ny=32, dtype="float32", collision="trt", inflow_profile="parabolic",
                     inflow_ramp_steps=20, sponge_cells=12, sponge_absorb=0.3)
    solvers, _ = _run_pair(cfg)
    _check_fields(solvers)


def test_divergence_is_reported():
    """A state that is not finite raises SolverDiverged, as numpy's does."""
    from feelflow.solver.backend import SolverDiverged

    cfg = FlowConfig(nx=32, ny=16, dtype="float32", x_boundary="periodic", y_boundary="periodic")
    s = create_solver("cpu", cfg)
    f = s.distributions()
    f[1, 5, 7] = np.nan
    s.set_distributions(f)
    with pytest.raises(SolverDiverged):
        s.step(1)


@pytest.mark.parametrize("smagorinsky", [pytest.param(0.0, marks=SLOW), pytest.param(0.1, marks=SLOW)])
def test_regularised_operator_moving_body(smagorinsky):
    """The compiled recursive-regularised operator (with and without the Smagorinsky viscosity)
    in a tunnel with a sponge and a moving body, against numpy's."""
    cfg = FlowConfig(nx=61, ny=32, dtype="float32", collision="rr", smagorinsky=smagorinsky, nu=0.002,
                     inflow_speed=0.05, sponge_cells=8)
    solvers, forces = _run_pair(cfg, steps=30, motion=lambda s, k: s.set_body(
        Cylinder(x=20 + 0.1 * k, y=16.3, diameter=8), velocity=(0.1, 0.0)), models=("momentum_exchange",))
    _check_fields(solvers)
    _check_forces(forces, ("momentum_exchange",))


@pytest.mark.parametrize("smagorinsky", [0.0, 0.15])
def test_regularised_node_equals_the_reference_collider(smagorinsky):
    """The compiled kernel's rr node, run as plain Python (no compile), against
    solver/regularised.py on disturbed nodes with a body force and the absorbing layer, float64:
    catches a wrong Hermite coefficient without paying for the kernel's compile (the kernel
    itself runs against numpy in the slow tier above)."""
    from feelflow.solver.cpu_kernels import _collide_rr, constants
    from feelflow.solver.lattice import W, equilibrium
    from feelflow.solver.regularised import RegularisedCollider, smagorinsky_factor

    rng = np.random.default_rng(5)
    ny, nx = 3, 4
    f = equilibrium(1 + 1e-2 * rng.standard_normal((ny, nx)), 0.05 * rng.standard_normal((ny, nx)),
                    0.05 * rng.standard_normal((ny, nx)))
    g = f - W[:, None, None] + 1e-3 * rng.standard_normal((9, ny, nx))  # off equilibrium
    omega = np.array([1.9, 1.7, 1.5, 1.2])
    keep = np.array([1.0, 1.0, 0.8, 0.5])
    target = np.array([0.04, 0.05, 0.06])
    force = (2e-5, -1e-5)
    ref = g.copy()
    RegularisedCollider(ny, nx, np.float64, omega, force, keep=keep, smagorinsky=smagorinsky)(ref, target)
    K = constants("float64")
    for y in range(ny):
        for x in range(nx):
            out = _collide_rr.py_func(*g[:, y, x], omega[x], keep[x], target[y], False, True, *force, True,
                                      smagorinsky_factor(smagorinsky), K)
            assert np.allclose(out[:9], ref[:, y, x], rtol=0, atol=1e-13), (y, x)


@pytest.mark.parametrize("smagorinsky", [pytest.param(0.0, marks=SLOW), pytest.param(0.1, marks=SLOW)])
def test_kbc_operator_moving_body(smagorinsky):
    """The compiled entropic KBC operator (with and without the Smagorinsky viscosity) in a
    tunnel with a sponge and a moving body, against numpy's (solver/kbc.py)."""
    cfg = FlowConfig(nx=61, ny=32, dtype="float32", collision="kbc", smagorinsky=smagorinsky, nu=0.002,
                     inflow_speed=0.05, sponge_cells=8)
    solvers, forces = _run_pair(cfg, steps=30, motion=lambda s, k: s.set_body(
        Cylinder(x=20 + 0.1 * k, y=16.3, diameter=8), velocity=(0.1, 0.0)), models=("momentum_exchange",))
    _check_fields(solvers)
    _check_forces(forces, ("momentum_exchange",))


@pytest.mark.parametrize("smagorinsky", [0.0, 0.15])
def test_kbc_node_equals_the_reference_collider(smagorinsky):
    """The compiled kernel's KBC node, run as plain Python (no compile), against solver/kbc.py
    on disturbed nodes with a body force and the absorbing layer, float64: the entropic gamma,
    the shear split and the third-order equilibrium each move the result by far more than the
    tolerance (the kernel itself runs against numpy in the slow tier above)."""
    from feelflow.solver.cpu_kernels import _kbc_node
    from feelflow.solver.kbc import KBCCollider
    from feelflow.solver.lattice import W, equilibrium
    from feelflow.solver.regularised import smagorinsky_factor

    rng = np.random.default_rng(7)
    ny, nx = 3, 4
    f = equilibrium(1 + 1e-2 * rng.standard_normal((ny, nx)), 0.05 * rng.standard_normal((ny, nx)),
                    0.05 * rng.standard_normal((ny, nx)))
    g = f - W[:, None, None] + 1e-3 * rng.standard_normal((9, ny, nx))  # off equilibrium
    omega = np.array([1.9, 1.7, 1.5, 1.2])
    keep = np.array([1.0, 1.0, 0.8, 0.5])
    target = np.array([0.04, 0.05, 0.06])
    force = (2e-5, -1e-5)
    ref = g.copy()
    KBCCollider(ny, nx, np.float64, omega, force, keep=keep, smagorinsky=smagorinsky)(ref, target)
    for y in range(ny):
        for x in range(nx):
            out = np.empty((9, 1))
            _kbc_node.py_func(g[:, y, x][:, None].copy(), out, 0, omega[x], keep[x], target[y], False, True,
                              *force, True, smagorinsky_factor(smagorinsky))
            assert np.allclose(out[:, 0], ref[:, y, x], rtol=0, atol=1e-13), (y, x)


def test_quiet_inlet_matches_the_reference():
    """The quiet inlet (compiled in the boundary pass): a tunnel with it, a sponge and a moving
    body agrees with numpy to float32 rounding."""
    cfg = FlowConfig(nx=61, ny=32, dtype="float32", nu=0.01, inflow_speed=0.05, inflow_ramp_steps=0,
                     initial_velocity=(0.05, 0.0), inlet_nonreflecting=0.01, sponge_cells=8, sponge_absorb=0.1)
    solvers, forces = _run_pair(cfg, steps=STEPS, motion=lambda s, k: s.set_body(
        Cylinder(x=20 + 0.1 * k, y=16.3, diameter=8), velocity=(0.1, 0.0)), models=("momentum_exchange",))
    _check_fields(solvers)
    _check_forces(forces, ("momentum_exchange",))


@pytest.mark.parametrize("per_call", [2, 3, 8])
def test_several_steps_in_one_call(per_call):
    """n steps in one call run the AA pattern between a first and a last step in the solver's
    natural layout, and every boundary rule reads the state through the layout of its step:
    no-slip walls, the sponge's absorbing layer, the quiet inlet and a cylinder moved and spun
    between calls, with both momentum exchanges summed in the kernel, even and odd n."""
    cfg = FlowConfig(nx=61, ny=32, dtype="float32", nu=0.01, inflow_speed=0.05, inflow_ramp_steps=0,
                     initial_velocity=(0.05, 0.0), inlet_nonreflecting=0.01, sponge_cells=8, sponge_absorb=0.1)
    models = ["momentum_exchange", "momentum_exchange_classic"]

    def move(s, k):
        s.set_body(Cylinder(8.3, x=20.4 + 0.15 * k, y=15.7 + 0.05 * k), velocity=(0.05, 0.02), omega=0.002)

    solvers, forces = _run_pair(cfg, steps=24 // per_call + 1, motion=move, models=models, per_call=per_call)
    _check_fields(solvers)
    _check_forces(forces, models)


def test_several_steps_in_one_call_free_slip_and_the_seam():
    """As above with free-slip walls (mirrored neighbours) and a body across the periodic seam."""
    cfg = FlowConfig(nx=48, ny=32, dtype="float32", x_boundary="periodic", y_boundary="free_slip",
                     initial_velocity=(0.03, 0.01))

    def place(s, k):
        s.set_body(Cylinder(8.0, x=4.3 + 0.1 * k, y=16.2), velocity=(0.02, 0.0))

    solvers, forces = _run_pair(cfg, steps=6, motion=place, models=["momentum_exchange"], per_call=5)
    _check_fields(solvers)
    _check_forces(forces, ["momentum_exchange"])


def test_a_second_process_loads_the_compiled_kernels_from_the_disk_cache():
    """numba compiles a kernel variant in tens of seconds; with cache=True a later process (the
    next start of the window, the next CLI run) must load it from the on-disk cache, not compile
    it again (solver/cpu_kernels.py make_kernel says what breaks that)."""
    import subprocess
    import sys

    code = ("from feelflow.solver.backend import create_solver\n"
            "from feelflow.solver.config import FlowConfig\n"
            "s = create_solver('cpu', FlowConfig(nx=48, ny=24, dtype='float32', collision='trt', "
            "sponge_cells=8, sponge_absorb=0.1))\n"
            "s.step(2)\n"
            "d = s._advance\n"
            "print(d.stats.cache_hits.total(), d.stats.cache_misses.total())\n")
    runs = [subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
            for _ in range(2)]
    for r in runs:
        assert r.returncode == 0, r.stderr
    hits, misses = map(int, runs[1].stdout.split())
    assert misses == 0 and hits >= 1, runs[1].stdout
