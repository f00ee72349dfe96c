"""The seed report's measurements from the stored runs: phase and tail means, swings, the
acoustic period, running means and power-law fits of drag against speed."""
from __future__ import annotations

import math

import numpy as np

from feelflow.app.reports.seed_runs import MODELS
from feelflow.solver.lattice import CS2


def fmt(v, digits=3) -> str:
    """A number to `digits` significant digits, "n/a" for None or non-finite."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "n/a"
    return f"{v:.{digits}g}"


def ratio(a: float, b: float) -> float:
    return a / b if b else math.nan


def force_series(run: dict, model: str) -> np.ndarray:
    return np.asarray(run["forces"][model], dtype=np.float64).reshape(-1, 2)


def acoustic_period(run: dict) -> float:
    """Period of the tunnel's quarter-wave acoustic mode, 4 nx / c_s steps (README, 'Solver'):
    the inlet and the outlet both reflect sound, and every start, stop and ramp rings it."""
    return 4.0 * run["nx"] / math.sqrt(CS2)


def tail_mean(run: dict, model: str, start: int, end: int) -> np.ndarray:
    """Mean force at the end of [start, end]: over the longest whole number of acoustic periods
    that fits in its last half (a ringing mode then averages out), else over the last half;
    nan for a run that diverged (its rows stop early and end in the blow-up)."""
    if run.get("diverged_at") is not None:
        return np.array([math.nan, math.nan])
    steps = np.asarray(run["step"])
    half = (end - start) // 2
    period = acoustic_period(run)
    length = int(round(math.floor(half / period) * period)) if half >= period else half
    sel = (steps > end - length) & (steps <= end)
    f = force_series(run, model)
    if not sel.any():
        return np.array([math.nan, math.nan])
    return f[sel].mean(axis=0)


def tail_swing(run: dict, model: str, start: int, end: int) -> float:
    """Standard deviation of F_x over the last half of [start, end] (rows are already means over
    the output interval): how much the force swings around the mean reported."""
    steps = np.asarray(run["step"])
    sel = (steps > start + (end - start) // 2) & (steps <= end)
    return float(np.std(force_series(run, model)[sel, 0])) if sel.sum() > 1 else math.nan


def phase_means(run: dict, model: str) -> list[np.ndarray]:
    bounds = np.concatenate([[0], np.cumsum(run["phases"])])
    return [tail_mean(run, model, int(bounds[k]), int(bounds[k + 1])) for k in range(len(run["phases"]))]


#: the protocol plots show a running mean over this many steps: the impulsive starts and stops
#: ring the tunnel's acoustic modes, whose force swings exceed the drag at U = 0.01
PLOT_SMOOTH_STEPS = 1000


def running_mean(run: dict, model: str, steps: int):
    """(step, F_x) averaged over `steps` steps (centred, whole windows only)."""
    step = np.asarray(run["step"], dtype=np.float64)
    fx = force_series(run, model)[:, 0]
    if len(step) < 2:
        return step, fx
    k = max(1, int(round(steps / (step[1] - step[0]))))
    if k <= 1 or len(fx) < k:
        return step, fx
    kernel = np.ones(k) / k
    return np.convolve(step, kernel, mode="valid"), np.convolve(fx, kernel, mode="valid")


def power_fit(x, y) -> tuple[float, float]:
    """(n, a) of y = a x^n, least squares in log-log over the finite points (diverged runs are
    nan); nan where fewer than two remain or any is <= 0."""
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    keep = np.isfinite(y)
    x, y = x[keep], y[keep]
    if len(x) < 2 or np.any(y <= 0):
        return math.nan, math.nan
    n, loga = np.polyfit(np.log(x), np.log(y), 1)
    return float(n), float(math.exp(loga))


def analyse(parts: dict) -> dict:
    """The numbers the report states, per part present, per model."""
    out: dict = {}
    if "protocol" in parts:
        runs = parts["protocol"]["runs"]
        out["protocol"], out["area"] = {}, {}
        for m in MODELS:
            per_d = {}
            for key, run in runs.items():
                f = [float(p[0]) for p in phase_means(run, m)]
                bounds = np.concatenate([[0], np.cumsum(run["phases"])])
                swing = tail_swing(run, m, int(bounds[2]), int(bounds[3]))
                per_d[key] = {"phases": f, "zero_rel_frac": ratio(f[1], f[2]), "swing": swing,
                              "against_over_stopped": ratio(f[3], f[2]),
                              "reynolds": run["reynolds"], "diameter": run["reference_length"]}
            out["protocol"][m] = per_d
            d = [v["diameter"] for v in per_d.values()]
            stopped = [v["phases"][2] for v in per_d.values()]
            out["area"][m] = {"diameters": d, "drag": stopped, "exponent": power_fit(d, stopped)[0]}
    if "sweep" in parts:
        runs = list(parts["sweep"]["runs"].values())
        out["sweep"] = {}
        for m in MODELS:
            speeds = [r["inflow_speed"] for r in runs]
            drags = [float(tail_mean(r, m, 0, r["steps"])[0]) for r in runs]
            n, a = power_fit(speeds, drags)
            out["sweep"][m] = {"speeds": speeds, "drag": drags, "exponent": n, "prefactor": a,
                               "reynolds": [r["reynolds"] for r in runs]}
    if "shapes" in parts:
        out["shapes"] = {}
        for m in MODELS:
            shapes = {}
            for key, run in parts["shapes"]["runs"].items():
                fx = float(tail_mean(run, m, 0, run["steps"])[0])
                u, w = run["inflow_speed"], run["reference_length"]
                shapes[key] = {"drag": fx, "cd": ratio(2 * fx, u * u * w), "reynolds": run["reynolds"]}
            out["shapes"][m] = shapes
    if "lift" in parts:
        run = parts["lift"]["runs"]["half_airfoil"]
        out["lift"] = {}
        for m in MODELS:
            fx, fy = (float(c) for c in tail_mean(run, m, 0, run["steps"]))
            u, chord = run["inflow_speed"], run["body"].get("chord", run["reference_length"])
            out["lift"][m] = {"fx": fx, "fy": fy, "cl_chord": ratio(2 * fy, u * u * chord),
                              "reynolds_chord": u * chord / run["nu"]}
    return out
