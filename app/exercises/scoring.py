"""Scoring one shape: the exercise's tunnel on the numpy reference backend in float64, the
momentum-exchange force sampled every `sample_interval` steps, averaged as below, turned into
the objective's score.

Averaging (docs/reference/exercise-format.md, [scene]): the force coefficients
C_D = 2 F_x / (rho_0 U^2 L), C_L = 2 F_y / (rho_0 U^2 L) (L = scene.reference_length, U the
inflow speed; app/model/readouts.py, the definition the window shows) are sampled as means over `sample_interval` steps; the score uses
the last `average_steps` steps of the run (the window).
- Steady flow: the mean over the window; *settled* when the means of the window's two halves
  differ by at most `settle_tolerance` |C_D| in C_D and in C_L.
- Unsteady flow (C_L swings by more than 2 settle_tolerance |C_D| peak to peak, as behind a
  body that sheds vortices): the mean over the whole shedding periods in the window, from the
  first to the last upward crossing of C_L through its mean (Strouhal-type averaging over whole
  periods, so a half period does not bias the mean); *settled* when at least two whole periods
  fit and the first and the last period's means agree within `settle_tolerance` |C_D|.
- A run that diverges (NaN), or does not settle, scores "not settled", never a number.
Deterministic: float64 numpy on one machine gives the same digits on every run (no threads
race in numpy's element-wise kernels; the CLI and the window call this same function).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from feelflow.app.model import readouts

FORCE_MODEL = "momentum_exchange"
#: solvers a score may be computed with, both float64: numpy (the reference) and the compiled
#: cpu backend, which gives the same scores (within 1e-12 relative: tests/test_exercise_uncertainty.py)
#: in less CPU time; the window and `feelflow exercise score|check` use the faster of the two
#: (grading.resolve_backend)
BACKENDS = ("numpy", "cpu")
SCORED, NOT_SETTLED, BROKEN = "scored", "not settled", "broken"


class Cancelled(Exception):
    """The user stopped a scoring run."""


@dataclass
class Result:
    """One shape's verdict: `status` is SCORED (score is a number), NOT_SETTLED or BROKEN (the
    reason says why; score, C_D, C_L are None)."""

    status: str
    score: float | None = None
    cd: float | None = None
    cl: float | None = None
    steps: int = 0
    seconds: float = 0.0
    reason: str = ""
    averaging: str = ""
    hit: bool | None = None          # target objectives: within the tolerance
    scale: int = 1
    cpu_seconds: float = 0.0         # the process's CPU time for the run (what a quiet core needs)

    @property
    def ok(self) -> bool:
        return self.status == SCORED

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in ("status", "score", "cd", "cl", "steps", "seconds", "reason",
                                              "averaging", "hit", "scale", "cpu_seconds")}


@dataclass
class Averaged:
    cd: float
    cl: float
    settled: bool
    how: str
    periods: int = 0
    extra: dict = field(default_factory=dict)


def upward_crossings(signal: np.ndarray) -> list[int]:
    """Indices where `signal` (mean removed) rises through zero, with hysteresis of a quarter of
    its half peak-to-peak so that sampling noise near zero does not count as a period."""
    x = signal - signal.mean()
    h = 0.25 * 0.5 * (x.max() - x.min())
    out, below = [], False
    for i, v in enumerate(x):
        if v < -h:
            below = True
        elif below and v >= 0.0:
            out.append(i)
            below = False
    return out


def average(cd: np.ndarray, cl: np.ndarray, tolerance: float) -> Averaged:
    """The window's mean coefficients and whether they settled (module docstring)."""
    cd = np.asarray(cd, dtype=np.float64)
    cl = np.asarray(cl, dtype=np.float64)
    if cd.size < 4 or not (np.all(np.isfinite(cd)) and np.all(np.isfinite(cl))):
        return Averaged(math.nan, math.nan, False, "the flow diverged (NaN)")
    scale = max(abs(float(cd.mean())), 1e-6)
    swing = float(cl.max() - cl.min())
    if swing > 2.0 * tolerance * scale:
        ups = upward_crossings(cl)
        if len(ups) >= 3:
            a, b = ups[0], ups[-1]
            periods = len(ups) - 1
            first = slice(ups[0], ups[1])
            last = slice(ups[-2], ups[-1])
            drift = max(abs(cd[first].mean() - cd[last].mean()), abs(cl[first].mean() - cl[last].mean()))
            settled = drift <= tolerance * scale
            how = (f"unsteady: mean over {periods} whole shedding periods (C_L swings {swing:.3g} peak to peak)")
            if not settled:
                how += f"; first and last period differ by {drift / scale:.2%} of C_D"
            return Averaged(float(cd[a:b].mean()), float(cl[a:b].mean()), settled, how, periods)
        drift = abs(cd[: cd.size // 2].mean() - cd[cd.size // 2:].mean())
        return Averaged(float(cd.mean()), float(cl.mean()), False,
                        f"C_L changes by {swing:.3g} in the averaging window without two whole periods "
                        f"(C_D halves differ by {drift / scale:.2%})")
    half = cd.size // 2
    drift = max(abs(cd[:half].mean() - cd[half:].mean()), abs(cl[:half].mean() - cl[half:].mean()))
    settled = drift <= tolerance * scale
    how = f"steady: mean over the window (halves agree within {drift / scale:.3%} of C_D)"
    if not settled:
        how = f"still changing: the window's halves differ by {drift / scale:.2%} of C_D"
    return Averaged(float(cd.mean()), float(cl.mean()), settled, how)


def objective_score(objective, cd: float, cl: float) -> tuple[float, bool | None]:
    """(score, hit) for the objective (hit only for target objectives)."""
    kind = objective.kind
    if kind == "least_cd":
        return cd, None
    if kind == "largest_cl":
        return cl, None
    if kind == "largest_ld":
        return cl / cd, None
    value = cd if kind == "target_cd" else cl
    miss = abs(value - objective.target)
    return miss, miss <= objective.tolerance


def score_shape(exercise, shape, scale: int = 1, progress=None, cancelled=None, backend: str = "numpy") -> Result:
    """Score `shape` (already checked against the constraints) at `scale` times the exercise's
    resolution, on the float64 solver `backend` (BACKENDS). `progress(done_fraction)` is called after every sample; `cancelled()` returning
    True stops the run (raises Cancelled)."""
    from feelflow.app.exercises.constraints import posed
    from feelflow.solver.backend import SolverDiverged, create_solver

    s = exercise.scene.scaled(scale)
    body = posed(exercise, shape, scale)
    start, cpu0 = time.perf_counter(), time.process_time()
    if backend not in BACKENDS:
        raise ValueError(f"backend: scores are computed on {' or '.join(BACKENDS)}, not {backend!r}")
    solver = create_solver(backend, s.flow_config())
    cd, cl = [], []
    try:
        solver.enable_force_models([FORCE_MODEL])
        solver.set_body(body)
        n = s.steps // s.sample_interval
        reference = readouts.ReferenceLength(s.reference_length, readouts.EXERCISE_LENGTH)
        with np.errstate(all="ignore"):
            for k in range(n):
                if cancelled is not None and cancelled():
                    raise Cancelled()
                try:
                    solver.step(s.sample_interval)
                except SolverDiverged:
                    return Result(NOT_SETTLED, steps=solver.time, seconds=time.perf_counter() - start,
                                  reason="the flow diverged (NaN)", scale=scale)
                fx, fy = solver.forces()[FORCE_MODEL]
                if not (math.isfinite(fx) and math.isfinite(fy)):
                    return Result(NOT_SETTLED, steps=solver.time, seconds=time.perf_counter() - start,
                                  reason="the flow diverged (NaN)", scale=scale)
                c_d, c_l = readouts.coefficients(fx, fy, s.inflow_speed, reference, min_speed=0.0)   # flow along +x
                cd.append(c_d)
                cl.append(c_l)
                if progress is not None:
                    progress((k + 1) / n)
    finally:
        solver.close()
    seconds = time.perf_counter() - start
    cpu = time.process_time() - cpu0
    window = s.average_steps // s.sample_interval
    avg = average(np.array(cd[-window:]), np.array(cl[-window:]), s.settle_tolerance)
    if not avg.settled:
        return Result(NOT_SETTLED, steps=s.steps, seconds=seconds, reason=avg.how, averaging=avg.how, scale=scale,
                      cpu_seconds=cpu)
    score, hit = objective_score(exercise.objective, avg.cd, avg.cl)
    return Result(SCORED, score=score, cd=avg.cd, cl=avg.cl, steps=s.steps, seconds=seconds,
                  averaging=avg.how, hit=hit, scale=scale, cpu_seconds=cpu)
