"""`feelflow bench motion [--backend B] [--grid NXxNY] [--rounds R] [--quick]`: what moving the
body costs per step, on every backend (numpy, cpu, gl; one that cannot run here is named and
skipped).

The window's tunnel (app/model/simulation.py default_base_config: float32, outlet sponge with its
absorbing layer, quiet inlet) at 256 x 128, a cylinder D = 16 and the momentum exchange every
step: held still in a stream of 0.04, or towed at -0.04 through fluid at rest and placed before
every step (solver/motion.py MotionRunner, the path the window, `feelflow run` and the
validation cases share). Held and towed alternate in `rounds` rounds on the same solver kind;
reported: milliseconds per step of each (medians), the move's cost per step (the median of the
per-round differences towed - held: the raster, links, refill and upload of a move, and the
per-step call a towed body needs) and the median of the per-round ratios towed / held, with the
load average. Figures from a shared machine are indicative; the ratio is measured in the same run.
"""
from __future__ import annotations

import dataclasses
import os
import statistics
import time

from feelflow.app.errors import UserError

GRID = (256, 128)
DIAMETER = 16.0
SPEED = 0.04
BACKENDS = ("numpy", "cpu", "gl")


def _run(backend: str, towed: bool, grid, steps: int, warmup: int) -> float:
    """Seconds per step of `steps` steps after `warmup`."""
    from feelflow.app.headless import make_solver
    from feelflow.app.model.simulation import default_base_config
    from feelflow.shapes.cylinder import Cylinder
    from feelflow.solver.motion import MotionRunner, MotionScript, Phase

    nx, ny = grid
    wind = 0.0 if towed else SPEED
    cfg = dataclasses.replace(default_base_config(grid), nu=0.02, inflow_speed=wind, initial_velocity=(wind, 0.0))
    solver = make_solver(backend, cfg.validate())
    try:
        solver.enable_force_models(["momentum_exchange"])
        body = Cylinder(x=nx * (0.7 if towed else 0.3), y=ny * 0.5, diameter=DIAMETER)
        script = MotionScript([Phase(warmup + steps + 10, (-SPEED, 0.0))] if towed else [])
        runner = MotionRunner(solver, body, script)
        runner.advance(warmup)
        solver.finish()
        t0 = time.perf_counter()
        for _ in range(steps // 10):     # the window's frames: 10 steps each
            runner.advance(10)
        solver.finish()
        return (time.perf_counter() - t0) / (steps // 10 * 10)
    finally:
        solver.close()


def measure(backend: str, grid=GRID, steps: int = 1000, rounds: int = 3, warmup: int = 50) -> dict:
    held, towed, ratios = [], [], []
    for _ in range(rounds):
        h = _run(backend, False, grid, steps, warmup)
        t = _run(backend, True, grid, steps, warmup)
        held.append(h)
        towed.append(t)
        ratios.append(t / h)
    return {"backend": backend, "grid": f"{grid[0]}x{grid[1]}", "steps": steps, "rounds": rounds,
            "held_ms_per_step": round(1e3 * statistics.median(held), 3),
            "towed_ms_per_step": round(1e3 * statistics.median(towed), 3),
            "move_ms_per_step": round(1e3 * statistics.median(t - h for t, h in zip(towed, held)), 3),
            "towed_over_held": round(statistics.median(ratios), 3),
            "load_average": round(os.getloadavg()[0], 2)}


def main(args) -> int:
    import json

    from feelflow.app.bench.solver_speed import machine
    from feelflow.app.files import save_text

    backends = args.backend or list(BACKENDS)
    grids = [tuple(int(v) for v in g.lower().split("x")) for g in (args.grid or ["256x128"])]
    quick = bool(getattr(args, "quick", False))
    rounds = args.rounds or (1 if quick else 3)
    steps = 100 if quick else 1000
    rows = []
    for backend in backends:
        if backend not in BACKENDS:
            raise UserError(f"--backend: must be one of {', '.join(BACKENDS)}, got {backend!r}")
    for grid in grids:
        for backend in backends:
            try:
                r = measure(backend, grid, steps, rounds, warmup=20 if quick else 50)
            except UserError as exc:
                if args.backend:       # asked for by name: say why it cannot run, and stop
                    raise
                print(f"{backend:6s}: skipped, {exc}", flush=True)
                continue
            rows.append(r)
            print(f"{r['backend']:6s} {r['grid']:>9s}: held {r['held_ms_per_step']:.3f} ms/step, towed "
                  f"{r['towed_ms_per_step']:.3f} ms/step, a move {r['move_ms_per_step']:.3f} ms/step, towed / held "
                  f"{r['towed_over_held']:.2f} (load average {r['load_average']})", flush=True)
    if args.json:
        save_text(args.json, json.dumps({"machine": machine(), "runs": rows}, indent=1) + "\n", "--json")
    return 0
