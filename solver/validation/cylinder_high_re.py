"""A cylinder in a wide tunnel above Re 100: drag, lift and shedding frequency against published
two-dimensional simulations, at several resolutions, as speed against error.

The tunnel is the Strouhal case's (solver/validation/strouhal.py): 20 d wide (blockage 1/20)
with free-slip walls, 28 d long, uniform inflow U = `SPEED` (the window's wind), the pressure
outlet with the window's sponge and absorbing layer, the cylinder 8 d behind the inlet and
0.25 cells above the centre line, a transverse kick behind it so the street forms within tens of
d / U. The collision is the recursive-regularised operator with the third-order equilibrium
(solver/regularised.py), the one the window runs at these Reynolds numbers.

Measured, once the shedding period is steady (after at least three windows of `PERIODS`
periods, the last two agree within `TOL`; or at `MAX_CONVECTIVE_TIMES` d / U): C_D = F_x / (rho U^2 d / 2) averaged over
the last window, C_L' = half the peak-to-peak lift over it (the amplitude) and its rms about the
mean, and St = f d / U from the lift's upward zero crossings. Forces: momentum exchange.

Two cases:
* `cylinder-re200`: targets from two-dimensional simulations, REFERENCES below (sources in
  docs/science/collision-operators.md, 'High-Reynolds accuracy'): St within 3 %, C_D within 5 %.
* `cylinder-re1000`: no target the search reached from a two-dimensional simulation; the case
  reports the values and their change with resolution (the convergence a teacher can quote).

`feelflow validate --case cylinder-re200` runs d = 10, 20 and 40 (`RESOLUTIONS`) and prints
error against cost; `--resolution N` runs one. The runs are long (hours on two CPU cores at
d = 40): `pytest -m slow` and the validation command, never the default test run.
"""
from __future__ import annotations

import math
import time

import numpy as np

from feelflow.solver.config import FlowConfig
from feelflow.solver.lattice import equilibrium
from feelflow.solver.validation.base import CaseResult, Check, SolverFactory, Stopwatch
from feelflow.solver.validation.strouhal import LENGTH, UPSTREAM, WIDTH, shedding_period

SPEED = 0.05
RESOLUTIONS = (10, 20, 40)
DEFAULT_RESOLUTION = None          # None: the whole ladder RESOLUTIONS
QUICK_RESOLUTION = 6
PERIODS = 5
TOL = 0.005
#: lift samples per shedding period (about 100 d steps at U 0.05): a sample every d steps
SAMPLES_PER_D = 1
MAX_CONVECTIVE_TIMES = 400.0
QUICK_CONVECTIVE_TIMES = 20.0

#: Re -> published two-dimensional values (None: none found) and their source
REFERENCES = {
    200: {"strouhal": 0.196, "cd_mean": 1.34, "cl_rms": 0.49,
          "source": "2D simulations: St 0.196, C_D 1.34, C_L rms 0.49 at Re 200 (Henderson 1995; "
                    "Williamson 1996; Norberg 2003; docs/science/collision-operators.md)"},
    1000: None,
}
ST_REL = 0.03
CD_REL = 0.05


def config(re: float, d: int, speed: float = SPEED, width: float = WIDTH, length: float = LENGTH) -> FlowConfig:
    """The tunnel `length` x `width` diameters (the case's own by default; a lesson's to measure it)."""
    return FlowConfig(nx=int(round(length * d)), ny=int(round(width * d)), nu=speed * d / re, collision="rr",
                      dtype="float32",
                      x_boundary="tunnel", y_boundary="free_slip", inflow_speed=speed, inflow_ramp_steps=0,
                      initial_velocity=(speed, 0.0), sponge_cells=min(32, 2 * d), sponge_absorb=0.1)


def measure(make_solver: SolverFactory, re: float, d: int, max_convective_times: float = MAX_CONVECTIVE_TIMES,
            speed: float = SPEED, progress=None, width: float = WIDTH, length: float = LENGTH,
            upstream: float = UPSTREAM):
    """Run one resolution; returns (quantities, stopwatch, solver config that ran)."""
    from feelflow.shapes import Cylinder

    cfg = config(re, d, speed, width, length).validate()
    x0, y0 = upstream * d, 0.5 * cfg.ny - 0.5 + 0.25
    solver = make_solver(cfg)
    ran = solver.config
    watch = Stopwatch()
    ux = np.full((cfg.ny, cfg.nx), speed)
    uy = np.zeros_like(ux)
    uy[:, int(x0):int(x0 + 3 * d)] = 0.2 * speed   # the kick that starts the street
    solver.set_distributions(equilibrium(np.ones_like(ux), ux, uy, order=3))
    solver.set_body(Cylinder(float(d), x0, y0))
    solver.enable_force_models(["momentum_exchange"])
    scale = 0.5 * speed ** 2 * d
    t, cd, cl = [], [], []
    max_steps = int(max_convective_times * d / speed)
    sample = max(1, SAMPLES_PER_D * d)
    guess = d / (0.2 * speed)                      # a period, for the window lengths only
    window = max(8, int(PERIODS * guess / sample))
    period, converged = math.nan, False
    try:
        while watch.steps < max_steps:
            watch.step(solver, sample)
            fx, fy = solver.forces()["momentum_exchange"][:2]
            t.append(float(solver.time))
            cd.append(fx / scale)
            cl.append(fy / scale)
            if not (math.isfinite(cd[-1]) and math.isfinite(cl[-1])):
                break
            if len(cl) >= 3 * window and len(cl) % (window // 2) == 0:
                a = shedding_period(t[-2 * window:-window], cl[-2 * window:-window])
                b = shedding_period(t[-window:], cl[-window:])
                if len(a) >= PERIODS - 2 and len(b) >= PERIODS - 2:
                    pa, pb = float(np.mean(a)), float(np.mean(b))
                    period = pb
                    if progress:
                        progress(f"d {d}: step {watch.steps}, period {pb:.1f} (previous window {pa:.1f})")
                    if abs(pa - pb) < TOL * pb:
                        converged = True
                        break
    finally:
        solver.close()
    last_cl = np.asarray(cl[-window:]) if cl else np.zeros(1)
    last_cd = np.asarray(cd[-window:]) if cd else np.zeros(1)
    if not math.isfinite(period) and len(cl) > window:   # short (quick) runs: the last window's crossings
        p = shedding_period(t[-window:], cl[-window:])
        period = float(np.mean(p)) if p else math.nan
    q = {"strouhal": d / (period * speed) if math.isfinite(period) else 0.0,
         "cd_mean": float(last_cd.mean()),
         "cl_amplitude": 0.5 * float(last_cl.max() - last_cl.min()),
         "cl_rms": float(last_cl.std()),
         "converged": float(converged)}
    return q, watch, ran


def checks(re: float) -> list[Check]:
    ref = REFERENCES.get(int(re))
    if ref is None:
        return [Check("converged", 1.0, 1.0, f"period steady within {TOL:g} over {PERIODS} periods")]
    return [Check("strouhal", ref["strouhal"] * (1 - ST_REL), ref["strouhal"] * (1 + ST_REL), ref["source"]),
            Check("cd_mean", ref["cd_mean"] * (1 - CD_REL), ref["cd_mean"] * (1 + CD_REL), ref["source"]),
            Check("converged", 1.0, 1.0, f"period steady within {TOL:g} over {PERIODS} periods")]


def run_ladder(name: str, re: float, make_solver: SolverFactory, resolution: int | None = None,
               quick: bool = False, backend: str = "numpy") -> CaseResult:
    """The case at `resolution`, or at every one of RESOLUTIONS; the result carries the finest
    run's quantities and, in details['ladder'], every run's values, errors and cost."""
    sizes = [QUICK_RESOLUTION] if quick else ([resolution] if resolution else list(RESOLUTIONS))
    ref = REFERENCES.get(int(re))
    ladder = []
    total = Stopwatch()
    ran = None
    for d in sizes:
        t0 = time.perf_counter()
        q, watch, ran = measure(make_solver, re, d, QUICK_CONVECTIVE_TIMES if quick else MAX_CONVECTIVE_TIMES,
                                progress=lambda line: print("   ", line, flush=True))
        row = {"d": d, **q, "steps": watch.steps, "node_updates": watch.node_updates,
               "wall_seconds": round(watch.seconds, 2), "case_seconds": round(time.perf_counter() - t0, 2),
               "mlups": round(watch.node_updates / watch.seconds / 1e6, 3) if watch.seconds else None}
        if ref is not None:
            for key in ("strouhal", "cd_mean", "cl_rms"):
                row[f"{key}_error"] = q[key] / ref[key] - 1.0
        ladder.append(row)
        total.seconds += watch.seconds
        total.steps += watch.steps
        total.node_updates += watch.node_updates
    finest = ladder[-1]
    quantities = {k: finest[k] for k in ("strouhal", "cd_mean", "cl_amplitude", "cl_rms", "converged")}
    quantities.update({"re": re, "u_lattice": SPEED, "tau": ran.tau, "blockage": 1.0 / WIDTH})
    result = CaseResult(name, backend, finest["d"], quantities=quantities, checks=checks(re))
    result.details = {"ladder": ladder, "reference": ref}
    cfg = config(re, finest["d"])
    result.notes = (f"{cfg.nx} x {cfg.ny} at d = {finest['d']}, U = {SPEED}, free-slip walls 20 d apart, "
                    f"{ran.collision}" + (f" (Smagorinsky C {ran.smagorinsky:g})" if ran.smagorinsky else ""))
    return total.fill(result)


def format_details(result: CaseResult) -> str:
    """Speed against error: one row per resolution (error against the reference where there is one,
    else the change from the previous resolution), with the cost of the run."""
    ladder = result.details.get("ladder") if result.details else None
    if not ladder:
        return ""
    ref = result.details.get("reference")
    lines = [f"{result.name}: speed against error ({result.backend})", "",
             "| d | St | C_D | C_L' (amplitude) | C_L rms | error St / C_D / C_L rms | converged | steps | "
             "node updates | wall s | MLUPS |", "| --- " * 11 + "|"]
    prev = None
    for row in ladder:
        if ref is not None:
            err = " / ".join(f"{100 * row[k + '_error']:+.1f} %" for k in ("strouhal", "cd_mean", "cl_rms"))
        elif prev is not None:
            err = "change from d {}: {}".format(prev["d"], " / ".join(
                f"{100 * (row[k] / prev[k] - 1):+.1f} %" if prev[k] else "n/a" for k in ("strouhal", "cd_mean", "cl_rms")))
        else:
            err = "(no published 2D value)"
        lines.append(f"| {row['d']} | {row['strouhal']:.4f} | {row['cd_mean']:.4f} | {row['cl_amplitude']:.4f} | "
                     f"{row['cl_rms']:.4f} | {err} | {'yes' if row['converged'] else 'no'} | {row['steps']} | "
                     f"{row['node_updates']:.3g} | {row['wall_seconds']:.0f} | {row['mlups']} |")
        prev = row
    return "\n".join(lines)
