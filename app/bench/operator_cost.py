"""`feelflow bench operators [--quick] [--rounds N] [--backend B] [--json PATH]`: what each
collision operator costs per step, on the numpy, the compiled cpu and the gl backend (or only
those named with --backend), in the window's tunnel.

The tunnel scene of `feelflow bench solver` (app/bench/solver_speed.py: inlet, pressure outlet with
its sponge, a cylinder moved every 10 steps, the reference force every step) at the window's
default grid 256 x 128, float32, with each operator of solver/operator_choice.py and the others:
TRT, BGK, recursive-regularised BGK (rr), rr with a Smagorinsky constant 0.1, and entropic KBC
with and without it (numpy and cpu only: solver/kbc.py). Operators run in
alternating rounds; the table gives median steps per second and, per backend, the cost of a
step relative to TRT's measured in the same run (the chooser's "cheapest" is read from it).
"""
from __future__ import annotations

import statistics
import time

from feelflow.app.bench.solver_speed import SceneRun, machine, scene_config

OPERATORS = (("trt", 0.0), ("bgk", 0.0), ("rr", 0.0), ("rr", 0.1), ("kbc", 0.0), ("kbc", 0.1))
GRID = (256, 128)


def label(collision: str, smagorinsky: float) -> str:
    return collision + (f" + Smagorinsky {smagorinsky:g}" if smagorinsky else "")


def measure(backend: str, collision: str, smagorinsky: float, steps: int, grid=GRID) -> float:
    """Steps per second of the tunnel scene with this operator, after a 220-step warm-up."""
    from dataclasses import replace

    from feelflow.app.headless import make_solver

    cfg = replace(scene_config("tunnel", *grid), collision=collision, smagorinsky=smagorinsky,
                  inflow_ramp_steps=0, initial_velocity=(0.05, 0.0)).validate()
    solver = make_solver(backend, cfg)
    try:
        run = SceneRun("tunnel", solver)
        run.advance(220)
        t0 = time.perf_counter()
        run.advance(steps)
        return steps / (time.perf_counter() - t0)
    finally:
        solver.close()


def main(args) -> int:
    import json

    quick = bool(getattr(args, "quick", False))
    rounds = getattr(args, "rounds", None) or (1 if quick else 3)
    steps = {"numpy": 60 if quick else 300, "cpu": 300 if quick else 1500, "gl": 200 if quick else 1000}
    only = getattr(args, "backend", None)
    if only:   # --backend: only these backends (each with its own TRT for the ratios)
        steps = {b: n for b, n in steps.items() if b in only}
    from feelflow.solver.backend import COMPARISON_COLLISIONS

    def runs_on(backend, op):
        return backend in COMPARISON_COLLISIONS.get(op[0], (backend,))

    rates = {(b, op): [] for b in steps for op in OPERATORS if runs_on(b, op)}
    for _ in range(rounds):
        for backend in steps:
            for op in OPERATORS:
                if runs_on(backend, op):
                    rates[(backend, op)].append(measure(backend, *op, steps[backend]))
    rows = []
    for backend in steps:
        base = statistics.median(rates[(backend, OPERATORS[0])])
        for op in (op for op in OPERATORS if runs_on(backend, op)):
            rate = statistics.median(rates[(backend, op)])
            rows.append({"backend": backend, "operator": label(*op), "steps_per_s": rate,
                         "mlups": rate * GRID[0] * GRID[1] / 1e6, "cost_vs_trt": base / rate})
    m = machine()
    print(f"Collision operators, tunnel {GRID[0]} x {GRID[1]} float32 with a moving cylinder, median of {rounds} "
          f"round(s), on {m['cpu']} ({m['cores']} logical CPUs)\n")
    print("| backend | operator | steps/s | MLUPS | cost per step / TRT's |")
    print("| --- | --- | --- | --- | --- |")
    for r in rows:
        print(f"| {r['backend']} | {r['operator']} | {r['steps_per_s']:.0f} | {r['mlups']:.2f} | {r['cost_vs_trt']:.2f} |")
    if getattr(args, "json", None):
        from pathlib import Path

        from feelflow.app import files

        files.write_json_atomic(Path(args.json), {"machine": m, "grid": GRID, "rounds": rounds, "rows": rows})
    return 0
