"""Schaefer-Turek 2D-1: steady flow past a cylinder at Re = 20; C_D, C_L and dp.

Targets: at 20 cells per diameter C_D within 1 % of 5.5795 and dp within 2 %; at 40
cells C_D within 0.3 %, C_L within 10 %, dp within 1 % (of the refined reference values of
John 2004). Runs from the developed channel flow until C_D, C_L and dp, averaged over a
block of steps, change by less than `TOL` from one block to the next: a convergence criterion,
not a fixed step count. A block is one acoustic round trip along the channel (2 nx / c_s steps),
so that the sound waves of the start, reflected between inlet and outlet, average out.
"""
from __future__ import annotations

import math

from feelflow.solver import units
from feelflow.solver.validation.base import CaseResult, Check, SolverFactory, Stopwatch
from feelflow.solver.validation.schaefer_turek import (REF_2D1, U_MAX, Geometry, check_resolution,  # noqa: F401 (validate's hook)
                                             reference_dp_coefficient)

NAME = "schaefer-turek-2d1"
DEFAULT_RESOLUTION = 20
QUICK_RESOLUTION = 10
RE = 20.0
TOL = 1e-5
SAMPLES = 8  # dp samples per block
SOURCE = "Schaefer & Turek 1996; refined values John 2004"


def targets(d: int) -> dict[str, float]:
    """Relative tolerances of the issue's targets at this resolution (None: not checked)."""
    if d >= 40:
        return {"cd": 0.003, "cl": 0.10, "dp": 0.01}
    if d >= 20:
        return {"cd": 0.01, "dp": 0.02}
    return {}


def run(make_solver: SolverFactory, resolution: int | None = None, quick: bool = False,
        backend: str = "numpy", max_convective_times: float = 400.0, u_max: float = U_MAX,
        refine: bool = False) -> CaseResult:
    """`u_max`: peak inflow speed in lattice units (the validation keeps U_MAX; `feelflow bench
    accuracy` varies it to measure the time step's share of the error). `refine`: the cylinder
    in a patch of twice the resolution (`Geometry.refined_patch`, numpy only)."""
    d = resolution or (QUICK_RESOLUTION if quick else DEFAULT_RESOLUTION)
    geo = Geometry(d, RE, u_max=u_max)
    block = int(math.ceil(2 * geo.nx / units.CS))
    sub = int(math.ceil(block / SAMPLES))
    block = sub * SAMPLES
    max_steps = int(max_convective_times * d / geo.u_mean)
    solver = geo.start(make_solver, refine=refine)
    operator = solver.config.collision.upper()   # the case's TRT, or `feelflow validate --collision`
    watch = Stopwatch()
    converged = False
    try:
        prev = None
        while watch.steps < max_steps:
            fx = fy = dp = 0.0
            for _ in range(SAMPLES):
                watch.step(solver, sub)
                f = solver.forces()["momentum_exchange"]
                fx, fy = fx + f[0] / SAMPLES, fy + f[1] / SAMPLES
                dp += geo.pressure_difference(solver) / SAMPLES
            cd, cl = geo.coefficients((fx, fy))
            now = (cd, cl, dp)
            if prev is not None and (abs(cd - prev[0]) < TOL * abs(cd) and abs(cl - prev[1]) < TOL * abs(cd)
                                     and abs(dp - prev[2]) < TOL * abs(dp)):
                converged = True
                break
            prev = now
    finally:
        solver.close()
    dp_ref = reference_dp_coefficient()
    result = CaseResult(NAME, backend, d, quantities={
        "cd": cd, "cl": cl, "dp": dp * REF_2D1["u_mean"] ** 2,  # in the benchmark's units
        "cd_rel_error": cd / REF_2D1["cd"] - 1, "cl_rel_error": cl / REF_2D1["cl"] - 1,
        "dp_rel_error": dp / dp_ref - 1, "converged": float(converged),
        "re": RE, "u_max_lattice": geo.u_max, "tau": geo.config().tau})
    for quantity, rel in targets(d).items():
        result.checks.append(Check(f"{quantity}_rel_error", -rel, rel, SOURCE))
    result.checks.append(Check("converged", 1.0, 1.0, f"steady within {TOL:g} per {block} steps"))
    result.notes = f"U_m = {geo.u_max} (Ma {geo.u_max * 3 ** 0.5:.3f}), {operator}, {geo.nx} x {geo.ny}"
    if refine:
        result.quantities["cells_per_d_at_body"] = 2.0 * d
        result.notes += f", refined patch {geo.refined_patch()} at {2 * d} cells per diameter"
    return watch.fill(result)
