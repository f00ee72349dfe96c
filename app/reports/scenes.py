"""`feelflow report scenes`: the example scenes in `scenes/` that have an outlet sponge, run
headless as `feelflow run` runs them, and how calm their tunnel is: the mean velocity through a
column near the inlet against the inflow speed once the inflow ramp is over (the tunnel's
quarter-wave sound mode swings it; Kam, Leung & Chew 2006 and Xu & Sagaut 2013 for the
absorbing layer that lets the sound out, docs/science/algorithm.md step 3), and the drag's scatter
over the second half of the run.

`compare=True` also runs each scene without the sponge's absorbing layer (`sponge_absorb = 0`)
and with the bare velocity inlet (`inlet_nonreflecting = 0`), the old way of running them
(docs/science/validation.md 'Calm tunnels'). Qt-free.
"""
from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numpy as np

#: the example scenes a class opens with File > Open or `feelflow run` (the seed report's scenes
#: keep their own set-up: their figures in docs/science/seed-report.md were measured with it)
SCENES = ("default", "plate", "half_airfoil", "wedge_upstream", "wedge_downstream", "seed_experiment")
#: the column whose mean velocity is watched (cells from the inlet)
PROBE_COLUMN = 5
#: steps after the end of the inflow ramp before the swing is measured
SETTLE_AFTER_RAMP = 500


def run_scene_calm(path, backend: str = "numpy", without_layer: bool = False, steps: int | None = None) -> dict:
    """Run the scene at `path` for its `steps` (or `steps`); returns a JSON-ready dict."""
    from feelflow.app.headless import make_solver
    from feelflow.app.model.scene import load_scene
    from feelflow.solver.motion import MotionRunner

    scene = load_scene(path)
    cfg = scene.config
    if without_layer:
        cfg = dataclasses.replace(cfg, sponge_absorb=0.0, inlet_nonreflecting=0.0)
    steps = int(steps or scene.steps)
    solver = make_solver(backend, cfg)
    t, mean_u, drag = [], [], []
    try:
        solver.enable_force_models(["momentum_exchange"])
        runner = MotionRunner(solver, scene.body, scene.motion)
        start = time.perf_counter()
        while runner.t < steps:
            forces = runner.advance(min(scene.output_interval, steps - runner.t))
            _, ux, _ = solver.macroscopic()
            column = ux[:, PROBE_COLUMN]
            t.append(runner.t)
            mean_u.append(float(np.mean(column[np.isfinite(column)])))
            drag.append(forces["momentum_exchange"][0])
        wall = time.perf_counter() - start
    finally:
        solver.close()
    t, mean_u, drag = map(np.asarray, (t, mean_u, drag))
    u_in = cfg.inflow_speed
    late = t > min(cfg.inflow_ramp_steps + SETTLE_AFTER_RAMP, steps // 2)
    second = t > steps / 2
    relative = mean_u[late] / u_in
    return {"scene": Path(path).stem, "layer": cfg.sponge_absorb, "backend": backend, "steps": steps,
            "grid": f"{cfg.nx}x{cfg.ny}", "wall_s": round(wall, 2),
            "from_step": int(t[late][0]), "mean_u_min": float(relative.min()),
            "mean_u_max": float(relative.max()), "drag_mean_second_half": float(drag[second].mean()),
            "drag_std_rel_second_half": _relative(drag[second].std(), drag[second].mean())}


def _relative(spread: float, mean: float) -> float:
    """spread / |mean|, NaN when the mean is zero to rounding (a body at rest in fluid at rest)."""
    return float(spread / abs(mean)) if abs(mean) > 1e-12 else float("nan")


def format_table(runs: list[dict]) -> str:
    """Markdown: one row per run."""
    from feelflow.app.reports.lessons import table_number

    lines = ["| scene | grid | absorbing layer | steps | wall s | inlet column mean u / U after the ramp (min - max) "
             "| drag, 2nd half | drag std / mean, 2nd half |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in runs:
        lines.append(f"| {r['scene']} | {r['grid']} | {r['layer']:g} | {r['steps']} | {r['wall_s']:.1f} "
                     f"| {r['mean_u_min']:.3f} - {r['mean_u_max']:.3f} (from step {r['from_step']}) "
                     f"| {r['drag_mean_second_half']:.5g} | {table_number(r['drag_std_rel_second_half'])} |")
    return "\n".join(lines)
