"""`feelflow report towed`: the force on a body towed through fluid at rest against the same
body held still in a stream (Galilean invariance), and how noisy each step's force is.

The case: a cylinder D = 16 at Re = 40 (U = 0.04, nu = U D / Re), 320 x 128 lattice, float64,
the window's quiet tunnel (outlet sponge of 32 cells with its absorbing layer, quiet inlet
1e-3), forces of every model evaluated every step.
- held: the body rests at x = 0.3 nx in a stream U (wind everywhere from the first step).
- towed: no inflow; the body moves at -U from x = 0.85 nx, advanced every step
  (solver/motion.py's MotionRunner, the path every caller shares).
Over steps START..END each model's drag series is detrended with a cubic fit (the towed body's
wake is still developing, the held body's settles); reported: the mean drag, and the standard
deviation of the residual per step, of 5-step means and of 25-step means (a frame, a plot point,
a whole cell crossing at U = 0.04), each over the mean drag. Qt-free.
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

GRID = (320, 128)
DIAMETER = 16.0
REYNOLDS = 40.0
SPEED = 0.04
WINDOW = (3000, 5000)
#: --quick: steps window of a smoke test (not physics)
QUICK_WINDOW = (20, 70)
BLOCKS = (1, 5, 25)
MODELS = ("momentum_exchange", "pressure")


def case(towed: bool, dtype: str = "float64"):
    """(FlowConfig, Cylinder, MotionScript) of the held or towed case."""
    from feelflow.app.model.simulation import default_base_config
    from feelflow.shapes.cylinder import Cylinder
    from feelflow.solver.motion import MotionScript, Phase

    nx, ny = GRID
    base = default_base_config(GRID)
    wind = 0.0 if towed else SPEED
    cfg = dataclasses.replace(base, dtype=dtype, nu=SPEED * DIAMETER / REYNOLDS, inflow_speed=wind, y_boundary="free_slip",
                              initial_velocity=(wind, 0.0)).validate()
    x = nx * (0.85 if towed else 0.3)
    body = Cylinder(x=x, y=ny * 0.5, diameter=DIAMETER)
    script = MotionScript([Phase(WINDOW[1] + 10, (-SPEED, 0.0))] if towed else [])
    return cfg, body, script


def noise(series: np.ndarray, block: int) -> float:
    """Standard deviation of the block-means of `series` after a cubic detrend, over |mean|."""
    t = np.arange(series.size, dtype=np.float64)
    resid = series - np.polyval(np.polyfit(t, series, 3), t)
    n = resid.size // block
    means = resid[:n * block].reshape(n, block).mean(axis=1)
    return float(means.std() / abs(series.mean()))


def series(backend: str, towed: bool, window=WINDOW, refill: str | None = None, impulse: str | None = None,
           models=MODELS) -> dict[str, np.ndarray]:
    """Each model's (drag x) per step over `window`; `refill`, `impulse`: the body's schemes
    (solver/body.py) where not the default."""
    from feelflow.app.headless import make_solver
    from feelflow.solver.motion import MotionRunner

    cfg, body, script = case(towed)
    solver = make_solver(backend, cfg)
    try:
        if refill is not None or impulse is not None:
            solver.set_body_schemes(**{k: v for k, v in (("refill", refill), ("impulse", impulse)) if v})
        solver.enable_force_models(list(models))
        runner = MotionRunner(solver, body, script)
        if not towed:
            runner.advance(window[0])
        else:
            while runner.t < window[0]:
                runner.advance(min(500, window[0] - runner.t))
        out = {m: np.empty(window[1] - window[0]) for m in models}
        for k in range(window[1] - window[0]):
            forces = runner.advance(1)
            for m in models:
                out[m][k] = forces[m][0]
    finally:
        solver.close()
    return out


def run(backend: str, towed: bool, quick: bool = False, refill: str | None = None,
        impulse: str | None = None) -> dict:
    """One case (module docstring); a JSON-ready dict."""
    start = time.perf_counter()
    data = series(backend, towed, QUICK_WINDOW if quick else WINDOW, refill, impulse)
    out = {"case": "towed" if towed else "held", "backend": backend, "refill": refill or "default",
           "impulse": impulse or "default", "wall_s": round(time.perf_counter() - start, 1)}
    for m, s in data.items():
        out[m] = {"mean": float(s.mean()), **{f"noise_{b}": noise(s, b) for b in BLOCKS}}
    return out


def format_table(runs: list[dict]) -> str:
    """Markdown: one row per run; the towed rows also give their mean over the held one's."""
    held = {r["backend"]: r for r in runs if r["case"] == "held"}
    lines = ["| case | backend | refill | impulse | drag (momentum exchange) | vs held | noise per step / 5 / 25 "
             "| drag (pressure) | vs held | noise per step / 5 / 25 | wall s |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in runs:
        cells = []
        for m in MODELS:
            d = r[m]
            ref = held.get(r["backend"])
            rel = "-" if ref is None or r is ref else f"{100 * (d['mean'] / ref[m]['mean'] - 1):+.1f} %"
            cells += [f"{d['mean']:.5f}", rel, " / ".join(f"{100 * d[f'noise_{b}']:.1f}" for b in BLOCKS) + " %"]
        lines.append(f"| {r['case']} | {r['backend']} | {r['refill']} | {r['impulse']} | " + " | ".join(cells)
                     + f" | {r['wall_s']:.0f} |")
    return "\n".join(lines)
