"""Vortex shedding behind a cylinder at Re = 100 in a wide tunnel: the Strouhal number.

Williamson (1996, Annu. Rev. Fluid Mech. 28, 477; the universal St-Re curve) gives St = f d / U
= 0.164 - 0.166 at Re 100 for an unconfined cylinder; the target is that interval widened by
3 % on both sides. The tunnel is 20 d wide (blockage 1/20) with free-slip walls (no wall boundary
layers that would add confinement), uniform inflow U = `SPEED`, the pressure outlet with the
window's sponge and absorbing layer, the cylinder 8 d behind the inlet and 0.25 cells above
the centre line, and a tunnel 28 d long. The flow starts uniform with a transverse kick behind the
cylinder, so the street forms within tens of d / U instead of growing from rounding.

The shedding frequency is read from the lift (momentum exchange) once its oscillation is
established: upward zero crossings of C_L - mean, interpolated, over the second half of the run;
the run lasts until two consecutive windows of `PERIODS` periods give the same period within
`TOL`, or `MAX_CONVECTIVE_TIMES` d / U. The case runs the recursive-regularised operator, the
one the window adds for high Reynolds numbers (`feelflow validate --case strouhal-re100
[--collision trt]` runs another).
"""
from __future__ import annotations

import math

import numpy as np

from feelflow.solver.config import FlowConfig
from feelflow.solver.lattice import equilibrium
from feelflow.solver.validation.base import CaseResult, Check, SolverFactory, Stopwatch

NAME = "strouhal-re100"
DEFAULT_RESOLUTION = 10   # 280 x 200 nodes; 20 cells take eight times the node updates
QUICK_RESOLUTION = 10
RE = 100.0
SPEED = 0.05               # the window's wind
WIDTH = 20                 # tunnel width in diameters (blockage 1/20)
LENGTH = 28                # tunnel length in diameters
UPSTREAM = 8               # inlet to cylinder centre, diameters
ST_RANGE = (0.164, 0.166)  # Williamson 1996 at Re 100
REL = 0.03
PERIODS = 6
TOL = 0.005
SAMPLE = 10                # steps per lift sample
MAX_CONVECTIVE_TIMES = 400.0
SOURCE = "Williamson 1996 (St 0.164 - 0.166 at Re 100), +-3 %"


def config(d: int) -> FlowConfig:
    return FlowConfig(nx=LENGTH * d, ny=WIDTH * d, nu=SPEED * d / RE, collision="rr", dtype="float32",
                      x_boundary="tunnel",
                      y_boundary="free_slip", inflow_speed=SPEED, inflow_ramp_steps=0,
                      initial_velocity=(SPEED, 0.0), sponge_cells=min(32, 2 * d), sponge_absorb=0.1)


def shedding_period(t, cl) -> list[float]:
    """Periods between successive upward zero crossings of cl - mean (linear interpolation)."""
    c = np.asarray(cl) - float(np.mean(cl))
    up = np.nonzero((c[:-1] < 0) & (c[1:] >= 0))[0]
    times = [t[i] + (t[i + 1] - t[i]) * (-c[i]) / (c[i + 1] - c[i]) for i in up]
    return list(np.diff(times))


def run(make_solver: SolverFactory, resolution: int | None = None, quick: bool = False,
        backend: str = "numpy") -> CaseResult:
    from feelflow.shapes import Cylinder

    d = resolution or (QUICK_RESOLUTION if quick else DEFAULT_RESOLUTION)
    cfg = config(d).validate()
    x0, y0 = UPSTREAM * d, 0.5 * cfg.ny - 0.5 + 0.25
    solver = make_solver(cfg)
    ran = solver.config          # the operator that ran (feelflow validate --collision may change it)
    watch = Stopwatch()
    ux = np.full((cfg.ny, cfg.nx), SPEED)
    uy = np.zeros_like(ux)
    uy[:, int(x0):int(x0 + 3 * d)] = 0.2 * SPEED   # the kick that starts the street
    solver.set_distributions(equilibrium(np.ones_like(ux), ux, uy))
    solver.set_body(Cylinder(float(d), x0, y0))
    solver.enable_force_models(["momentum_exchange"])
    scale = 0.5 * SPEED ** 2 * d
    t, cl = [], []
    max_steps = int(MAX_CONVECTIVE_TIMES * d / SPEED)
    guess = d / (0.165 * SPEED)                    # a period, for the window lengths only
    window = int(PERIODS * guess / SAMPLE)
    period = math.nan
    converged = False
    try:
        while watch.steps < max_steps:
            watch.step(solver, SAMPLE)
            t.append(float(solver.time))
            cl.append(solver.forces()["momentum_exchange"][1] / scale)
            if len(cl) >= 4 * window and len(cl) % (window // 2) == 0:
                a = shedding_period(t[-2 * window:-window], cl[-2 * window:-window])
                b = shedding_period(t[-window:], cl[-window:])
                if len(a) >= PERIODS - 2 and len(b) >= PERIODS - 2:
                    pa, pb = float(np.mean(a)), float(np.mean(b))
                    if abs(pa - pb) < TOL * pb:
                        period, converged = pb, True
                        break
                    period = pb
    finally:
        solver.close()
    st = d / (period * SPEED) if math.isfinite(period) else 0.0
    last = np.asarray(cl[-window:]) if cl else np.zeros(1)
    result = CaseResult(NAME, backend, d, quantities={
        "strouhal": st, "cl_amplitude": 0.5 * float(last.max() - last.min()), "converged": float(converged),
        "re": RE, "u_lattice": SPEED, "tau": ran.tau, "blockage": 1.0 / WIDTH})
    result.checks.append(Check("strouhal", ST_RANGE[0] * (1 - REL), ST_RANGE[1] * (1 + REL), SOURCE))
    result.checks.append(Check("converged", 1.0, 1.0, f"period steady within {TOL:g} over {PERIODS} periods"))
    result.notes = (f"{cfg.nx} x {cfg.ny}, d = {d}, U = {SPEED}, free-slip walls 20 d apart, "
                    f"{ran.collision}" + (f" (Smagorinsky C {ran.smagorinsky:g})" if ran.smagorinsky else ""))
    return watch.fill(result)
