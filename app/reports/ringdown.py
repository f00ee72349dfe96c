"""`feelflow report ringdown`: how long the tunnel's sound rings in the force after a body moves.

Two kinds of case, each run with the boundaries it had before the quiet inlet ("before": a bare
velocity inlet; the seed scenes also without the outlet's absorbing layer) and with the quiet
tunnel's ("after", solver/quiet_inlet.py, solver/sponge.py; docs/science/quiet-tunnel.md):
- window: the window's default tunnel (app/model/simulation.py default_base_config, 256 x 128,
  wind everywhere from the first step), a cylinder D = 20 at Re = 40 (steady) where the window
  puts a body, held still HOLD_STEPS, moved against the stream at MOVE_SPEED for MOVE_STEPS,
  then still again for AFTER_STEPS. The drag is averaged over blocks of BLOCK steps; reported:
  the standard deviation of those means between steps 1000 and 3000 after the stop, and over
  the last 2000 steps before the move, each over the settled drag (the mean 1000 - 3000 steps
  after the stop).
- seed dNN: the seed's protocol (scenes/seed_protocol_dNN.toml, U = 0.01), the swing as the
  seed report measures it (app/reports/seed_analysis.py tail_swing: the drag's standard
  deviation over the second half of the 'stopped again' phase, 100-step means) over that
  phase's mean drag; the fourth phase is not run.
A standing sound wave between reflecting ends shows as a swing of the drag (Xu & Sagaut,
J. Comput. Phys. 245 (2013) 14). Qt-free.
"""
from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numpy as np

#: the window case: grid, cylinder diameter, Reynolds number, wind (lattice units)
WINDOW_GRID = (256, 128)
DIAMETER = 20.0
REYNOLDS = 40.0
WIND = 0.05
HOLD_STEPS = 6000
MOVE_SPEED = 0.02
MOVE_STEPS = 200
AFTER_STEPS = 3000
#: steps per drag mean; the window after the stop in which the swing is measured
BLOCK = 10
AFTER_WINDOW = (1000, 3000)
BEFORE_WINDOW = 2000
#: --quick: (hold, move, after, after window, before window) and seed phase steps: a smoke test
QUICK = (300, 20, 300, (100, 300), 200)
QUICK_PHASE_STEPS = 60
#: the seed protocol's scenes and their "before" boundaries (as the scenes were)
SEED_DIAMETERS = ("d16", "d24", "d32")
SEED_BEFORE = {"sponge_absorb": 0.0, "inlet_nonreflecting": 0.0}
#: the window's "before": its outlet sponge and absorbing layer, the bare velocity inlet
WINDOW_BEFORE = {"inlet_nonreflecting": 0.0}


def window_case(hold: int = HOLD_STEPS, move: int = MOVE_STEPS, after: int = AFTER_STEPS):
    """(FlowConfig, cylinder, MotionScript) of the window case, with the window's current
    boundaries (the quiet tunnel)."""
    from feelflow.app.model.simulation import default_base_config
    from feelflow.shapes.cylinder import Cylinder
    from feelflow.solver.motion import MotionScript, Phase

    nx, ny = WINDOW_GRID
    cfg = dataclasses.replace(default_base_config(WINDOW_GRID), nu=WIND * DIAMETER / REYNOLDS,
                              inflow_speed=WIND, initial_velocity=(WIND, 0.0)).validate()
    body = Cylinder(x=nx * 0.3, y=ny * 0.5, diameter=DIAMETER)
    script = MotionScript([Phase(hold), Phase(move, (-MOVE_SPEED, 0.0)), Phase(after)])
    return cfg, body, script


def _drag_series(solver, body, script, steps: int, block: int) -> np.ndarray:
    """Drag (momentum exchange, x) averaged over blocks of `block` steps, `steps` in all."""
    from feelflow.solver.motion import MotionRunner

    solver.enable_force_models(["momentum_exchange"])
    runner = MotionRunner(solver, body, script)
    out = []
    while runner.t < steps:
        out.append(runner.advance(min(block, steps - runner.t))["momentum_exchange"][0])
    return np.asarray(out)


def run_window(backend: str, before: bool, quick: bool = False) -> dict:
    """The window case (module docstring); a JSON-ready dict."""
    from feelflow.app.headless import make_solver

    hold, move, after_steps, window, before_window = (QUICK if quick else
                                                      (HOLD_STEPS, MOVE_STEPS, AFTER_STEPS, AFTER_WINDOW, BEFORE_WINDOW))
    cfg, body, script = window_case(hold, move, after_steps)
    if before:
        cfg = dataclasses.replace(cfg, **WINDOW_BEFORE).validate()
    stop = hold + move
    steps = stop + after_steps
    solver = make_solver(backend, cfg)
    start = time.perf_counter()
    try:
        drag = _drag_series(solver, body, script, steps, BLOCK)
    finally:
        solver.close()
    t = (np.arange(len(drag)) + 1) * BLOCK  # step at each block's end
    after = (t > stop + window[0]) & (t <= stop + window[1])
    still = (t > hold - before_window) & (t <= hold)
    settled = float(drag[after].mean())
    return {"case": "window", "backend": backend, "boundaries": "before" if before else "after",
            "grid": f"{cfg.nx}x{cfg.ny}", "quiet_inlet": cfg.inlet_nonreflecting, "absorb": cfg.sponge_absorb,
            "wall_s": round(time.perf_counter() - start, 1), "settled_drag": settled,
            "swing_after_stop": float(drag[after].std() / abs(settled)),
            "swing_before_move": float(drag[still].std() / abs(settled))}


def run_seed(key: str, backend: str, before: bool, scenes_dir: Path, phase_steps=None) -> dict:
    """The seed protocol at diameter `key` (module docstring) up to the end of its third phase."""
    from feelflow.app.headless import make_solver
    from feelflow.app.reports.seed_runs import load_scene_with

    scene = load_scene_with(Path(scenes_dir) / f"seed_protocol_{key}.toml", phase_steps=phase_steps)
    cfg = scene.config
    if before:
        cfg = dataclasses.replace(cfg, **SEED_BEFORE).validate()
    bounds = np.cumsum([p.steps for p in scene.motion.phases])
    solver = make_solver(backend, cfg)
    start = time.perf_counter()
    interval = scene.output_interval
    try:
        drag = _drag_series(solver, scene.body, scene.motion, int(bounds[2]), interval)
    finally:
        solver.close()
    t = (np.arange(len(drag)) + 1) * interval
    a, b = int(bounds[1]), int(bounds[2])
    tail = (t > a + (b - a) // 2) & (t <= b)
    mean = float(drag[tail].mean())
    return {"case": f"seed {key}", "backend": backend, "boundaries": "before" if before else "after",
            "grid": f"{cfg.nx}x{cfg.ny}", "quiet_inlet": cfg.inlet_nonreflecting, "absorb": cfg.sponge_absorb,
            "wall_s": round(time.perf_counter() - start, 1), "settled_drag": mean,
            "swing_after_stop": float(drag[tail].std() / abs(mean)), "swing_before_move": None,
            "phase_steps": int(b - a)}


def last_stop(script) -> int | None:
    """The step at which the script's last moving phase ends (None: it never moves)."""
    end, stop = 0, None
    for phase in script.phases:
        end += phase.steps
        if phase.velocity != (0.0, 0.0) or phase.oscillates:
            stop = end
    return stop


def load_moving_scene(path):
    """(scene, step of its last stop); UserError (one line) for a bad file or a body that never moves."""
    from feelflow.app.errors import UserError
    from feelflow.app.model.scene import load_scene

    scene = load_scene(path)
    stop = last_stop(scene.motion)
    if stop is None:
        raise UserError(f"{path}: the body never moves: nothing rings down after a stop")
    return scene, stop


def run_scene(path, backend: str, window=AFTER_WINDOW) -> dict:
    """A scene file as it stands (its own boundaries, body and motion): the drag swing between
    `window` steps after its last moving phase ends (10-step means, over their mean), as for
    the window case; the run goes on past the scene's own steps where it must."""
    from feelflow.app.headless import make_solver

    scene, stop = load_moving_scene(path)
    steps = stop + window[1]
    cfg = scene.config
    solver = make_solver(backend, cfg)
    start = time.perf_counter()
    try:
        drag = _drag_series(solver, scene.body, scene.motion, steps, BLOCK)
    finally:
        solver.close()
    t = (np.arange(len(drag)) + 1) * BLOCK
    after = (t > stop + window[0]) & (t <= stop + window[1])
    settled = float(drag[after].mean())
    return {"case": f"scene {Path(path).name}", "backend": backend, "boundaries": "scene",
            "grid": f"{cfg.nx}x{cfg.ny}", "quiet_inlet": cfg.inlet_nonreflecting, "absorb": cfg.sponge_absorb,
            "wall_s": round(time.perf_counter() - start, 1), "settled_drag": settled,
            "swing_after_stop": float(drag[after].std() / abs(settled)), "swing_before_move": None}


def format_table(runs: list[dict]) -> str:
    """Markdown: one row per run, before and after side by side in run order."""
    lines = ["| case | backend | boundaries | grid | quiet inlet rate | absorb | settled drag "
             "| swing after the stop / drag | swing before any move / drag | wall s |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in runs:
        before_move = "-" if r["swing_before_move"] is None else f"{100 * r['swing_before_move']:.2f} %"
        lines.append(f"| {r['case']} | {r['backend']} | {r['boundaries']} | {r['grid']} | {r['quiet_inlet']:g} "
                     f"| {r['absorb']:g} | {r['settled_drag']:.5g} | {100 * r['swing_after_stop']:.2f} % "
                     f"| {before_move} | {r['wall_s']:.0f} |")
    return "\n".join(lines)
