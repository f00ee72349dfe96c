"""Taylor-Green vortex decay: the measured decay rate must give the set viscosity within 1 %.

u = -U0 cos(k x) sin(k y) e^{-2 nu k^2 t}, v = U0 sin(k x) cos(k y) e^{-2 nu k^2 t},
p = -rho U0^2 / 4 (cos 2kx + cos 2ky) e^{-4 nu k^2 t}, k = 2 pi / N on an N x N periodic lattice
(Taylor & Green 1937; Krueger et al. 2017, sec. 4.5). The velocity amplitude is the projection
of the field on the initial mode; nu follows from a least-squares fit of its logarithm.
"""
from __future__ import annotations

import math

import numpy as np

from feelflow.solver.config import FlowConfig
from feelflow.solver.lattice import CS2, RHO0, equilibrium
from feelflow.solver.validation.base import CaseResult, Check, SolverFactory, Stopwatch

NAME = "taylor-green"
DEFAULT_RESOLUTION = 64  # N x N nodes, one vortex period
QUICK_RESOLUTION = 32
NU = 0.05
U0 = 0.01
REL_TOL = 0.01


def initial_fields(n: int, u0: float = U0):
    """(rho, ux, uy) of the Taylor-Green vortex at t = 0 on an n x n grid, arrays [iy, ix]."""
    k = 2 * math.pi / n
    y, x = np.mgrid[0:n, 0:n].astype(np.float64)
    ux = -u0 * np.cos(k * x) * np.sin(k * y)
    uy = u0 * np.sin(k * x) * np.cos(k * y)
    p = -RHO0 * u0 * u0 / 4 * (np.cos(2 * k * x) + np.cos(2 * k * y))
    return RHO0 + p / CS2, ux, uy


def run(make_solver: SolverFactory, resolution: int | None = None, quick: bool = False,
        backend: str = "numpy", nu: float = NU) -> CaseResult:
    n = resolution or (QUICK_RESOLUTION if quick else DEFAULT_RESOLUTION)
    k = 2 * math.pi / n
    rate = 2 * nu * k * k  # velocity amplitude decay rate
    config = FlowConfig(nx=n, ny=n, nu=nu, x_boundary="periodic", y_boundary="periodic",
                        inflow_speed=0.0, inflow_ramp_steps=0)
    solver = make_solver(config)
    watch = Stopwatch()
    try:
        rho, ux, uy = initial_fields(n)
        solver.set_distributions(equilibrium(rho, ux, uy))
        mode_x, mode_y = ux / U0, uy / U0
        norm = float((mode_x ** 2 + mode_y ** 2).sum())
        total = int(math.ceil(math.log(4.0) / rate))  # until the amplitude fell to 1/4
        samples = 40
        every = max(1, total // samples)
        times, amps = [], []
        while watch.steps < total:
            watch.step(solver, every)
            _, vx, vy = solver.macroscopic()
            times.append(solver.time)
            amps.append(float((vx * mode_x + vy * mode_y).sum()) / norm)
        times = np.array(times, dtype=float)
        amps = np.array(amps)
        # skip the first tenth: the equilibrium start lacks the non-equilibrium stress
        use = times >= 0.1 * total
        slope = np.polyfit(times[use], np.log(amps[use]), 1)[0]
        nu_measured = -slope / (2 * k * k)
    finally:
        solver.close()
    result = CaseResult(NAME, backend, n, quantities={
        "nu_set": nu, "nu_measured": nu_measured, "nu_rel_error": nu_measured / nu - 1.0})
    result.checks.append(Check("nu_rel_error", -REL_TOL, REL_TOL, "target: decay rate gives nu within 1 %"))
    return watch.fill(result)
