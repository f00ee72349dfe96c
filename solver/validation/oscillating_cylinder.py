"""An in-line oscillating cylinder in fluid at rest, Re = 100, KC = 5: the in-line force over a
period against Duetsch, Durst, Becker & Lienhart (1998), J. Fluid Mech. 360, 249-271.

The cylinder (diameter D) moves as x(t) = -A sin(2 pi t / T) (the paper's motion), so its velocity
is -U_m cos(2 pi t / T) with U_m = 2 pi A / T; Keulegan-Carpenter number KC = U_m T / D = 2 pi A / D
= 5 and Re = U_m D / nu = 100. The reference is the paper's fig. 10, the in-line force
F_x / (rho U_m^2 D) over a period in the periodic state, as digitised at t/T = 0, 0.1, ..., 1 in
the validation data of cuIBM (Krishnan, Layton, Minar et al.: validation-data/osc_Re100_KC5_Dutsch.txt,
REFERENCE below; eleven points read off the published figure, so their own reading error, a few
hundredths, is part of any comparison).

The lattice: U_m = `SPEED` (Mach 0.07), a 12 D square; the fluid at rest is a tunnel with no
inflow (the quiet inlet at the left passes outgoing sound, the sponge with its absorbing layer at
the right takes it), free-slip walls at the top and bottom, the cylinder's mean position 0.45 of
the way along. A closed or periodic box rings: the sound the cylinder sends out at its start and
every half period comes back and swamps the force (a periodic 12 D box at D = 16: rms deviation
0.8 of the amplitude against this reference; probe, not kept). The body is placed every step by the
motion runner (solver/motion.py: the scene format's sinusoidal `[[motion]]`). The force is the
momentum exchange's, averaged over windows of T / 80 steps (the per-step force carries the cells'
covering and uncovering), each window's mean taken at its middle; the run lasts `PERIODS` periods
and the last one is compared.

The checks: the deviation from the digitised curve, rms over its eleven points and at its worst
point, each over the curve's peak |F|. The paper's reproductions (Guilmineau & Queutey 2002, Kim &
Choi 2006, Seo & Mittal 2011, ...) print their curves as figures only; no tabulated spread of
them was at hand, so the bounds here (`RMS_MAX`, `WORST_MAX` of the peak) are this case's own,
not a published spread: docs/science/force-models.md says what was measured.
"""
from __future__ import annotations

import math

import numpy as np

from feelflow.solver.config import FlowConfig
from feelflow.solver.validation.base import CaseResult, Check, SolverFactory, Stopwatch

NAME = "oscillating-cylinder"
DEFAULT_RESOLUTION = 16   # cells per diameter (192 x 192 nodes, 2000 steps a period)
QUICK_RESOLUTION = 16
RE = 100.0
KC = 5.0
SPEED = 0.04              # U_m, lattice units
BOX = 12                  # the square's side in diameters
PERIODS = 5
BINS_PER_PERIOD = 80      # the force is averaged over T / 80 steps
#: Duetsch et al. 1998 fig. 10 as digitised by cuIBM: (t / T, F_x / (rho U_m^2 D))
REFERENCE = ((0.0, 1.0018), (0.1, -0.0176), (0.2, -1.1072), (0.3, -1.6063), (0.3993, -1.6063), (0.5, -1.0580),
             (0.6, 0.0457), (0.7, 1.0931), (0.8, 1.5993), (0.8993, 1.6063), (1.0, 1.0018))
SOURCE = "Duetsch, Durst, Becker & Lienhart 1998 (J. Fluid Mech. 360), fig. 10, digitised by cuIBM"
RMS_MAX = 0.05            # of the peak |F|: this case's bound (module docstring)
WORST_MAX = 0.10


def config(d: int) -> FlowConfig:
    n = BOX * d
    return FlowConfig(nx=n, ny=n, nu=SPEED * d / RE, dtype="float32", x_boundary="tunnel", y_boundary="free_slip",
                      inflow_speed=0.0, inflow_ramp_steps=0, sponge_cells=32, sponge_absorb=0.1,
                      inlet_nonreflecting=0.001)


def period_steps(d: int) -> float:
    """T = KC D / U_m, in steps."""
    return KC * d / SPEED


def compare(phase, force):
    """(simulated values at the reference's phases, rms deviation, worst deviation), both over the
    reference's peak |F|; `phase` (t/T within the compared period) increasing."""
    ref = np.asarray(REFERENCE)
    sim = np.interp(ref[:, 0], phase, force)
    peak = float(np.abs(ref[:, 1]).max())
    dev = sim - ref[:, 1]
    return sim, float(np.sqrt(np.mean(dev ** 2))) / peak, float(np.abs(dev).max()) / peak


def run(make_solver: SolverFactory, resolution: int | None = None, quick: bool = False,
        backend: str = "numpy") -> CaseResult:
    from feelflow.shapes import Cylinder
    from feelflow.solver.motion import MotionRunner, MotionScript, Phase

    d = resolution or (QUICK_RESOLUTION if quick else DEFAULT_RESOLUTION)
    cfg = config(d).validate()
    period = period_steps(d)
    amplitude = KC * d / (2.0 * math.pi)
    window = max(1, int(round(period / BINS_PER_PERIOD)))
    bins = int(math.ceil((PERIODS * period + window) / window))
    solver = make_solver(cfg)
    solver.enable_force_models(["momentum_exchange"])
    runner = MotionRunner(solver, Cylinder(float(d), 0.45 * cfg.nx, 0.5 * cfg.ny - 0.5),
                          MotionScript([Phase(bins * window, amplitude=(-amplitude, 0.0), period=period)]))
    watch = Stopwatch()
    fx = np.empty(bins)
    try:   # the runner places the body every step; each call gives the mean force of its steps
        for j in range(bins):
            fx[j] = watch.timed(solver.nodes_per_step, window, runner.advance, window)["momentum_exchange"][0]
    finally:
        solver.close()
    force = fx / (SPEED ** 2 * d)            # F_x / (rho U_m^2 D), rho = 1
    t = (np.arange(bins) + 0.5) * window     # each window's middle (step k moves the pose from k to k + 1)
    start = (PERIODS - 1) * period
    sel = (t >= start - window) & (t <= start + period + window)
    sim, rms, worst = compare((t[sel] - start) / period, force[sel])
    result = CaseResult(NAME, backend, d, quantities={
        "rms_deviation": rms, "worst_deviation": worst, "re": RE, "kc": KC, "u_lattice": SPEED,
        "tau": solver.config.tau, "period_steps": period})
    result.details = {"phase": [p for p, _ in REFERENCE], "reference": [f for _, f in REFERENCE],
                      "simulated": [float(v) for v in sim]}
    result.checks.append(Check("rms_deviation", 0.0, RMS_MAX, SOURCE + " (this case's bound)"))
    result.checks.append(Check("worst_deviation", 0.0, WORST_MAX, SOURCE + " (this case's bound)"))
    result.notes = (f"{cfg.nx} x {cfg.ny}, D = {d}, U_m = {SPEED}, T = {period:g} steps, period {PERIODS} "
                    f"compared, force averaged over {window} steps; quiet inlet and absorbing sponge, free-slip walls")
    return watch.fill(result)
