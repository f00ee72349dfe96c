"""The inflow after a scene's ramp, with the quiet inlet and with the bare velocity inlet:
`python -m feelflow.app.reports.ramps SCENE.toml ... [--backend numpy|gl]`.

For each scene: the mean velocity through the column 5 cells from the inlet over the inflow
speed, sampled every 50 steps from 500 to 5000 steps after the ramp's end (min - max, and
mean), once as the scene is with the quiet inlet and once with the bare velocity inlet (the
outlet's absorbing layer kept in both). The quiet inlet lets sound out as a swing of the inflow
(solver/quiet_inlet.py), so the swing is larger with it; what matters is the mean, which should
stay 1. docs/science/quiet-tunnel.md 'Ramps' holds the figures. Qt-free.
"""
from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np

#: the column watched (cells from the inlet), the sampling interval, the window after the ramp
PROBE_COLUMN = 5
EVERY = 50
WINDOW = (500, 5000)


def inflow_after_ramp(path: Path, backend: str = "numpy", quiet_rate: float | None = None) -> dict:
    """Run the scene at `path` with its boundaries, `inlet_nonreflecting` set to `quiet_rate`
    (None: as the scene has it) up to WINDOW[1] steps after its ramp; a JSON-ready dict."""
    from feelflow.app.headless import make_solver
    from feelflow.app.model.scene import load_scene
    from feelflow.solver.motion import MotionRunner

    scene = load_scene(path)
    cfg = scene.config if quiet_rate is None else dataclasses.replace(scene.config, inlet_nonreflecting=quiet_rate)
    start, end = cfg.inflow_ramp_steps + WINDOW[0], cfg.inflow_ramp_steps + WINDOW[1]
    solver = make_solver(backend, cfg)
    ratios = []
    try:
        runner = MotionRunner(solver, scene.body, scene.motion)
        while runner.t < end:
            runner.advance(min(EVERY, end - runner.t))
            if runner.t > start:
                _, ux, _ = solver.macroscopic()
                ratios.append(float(np.nanmean(ux[:, PROBE_COLUMN])) / cfg.inflow_speed)
    finally:
        solver.close()
    r = np.asarray(ratios)
    period = 4.0 * cfg.nx * np.sqrt(3.0)   # the quarter-wave mode's period, 4 nx / c_s
    return {"scene": path.name, "grid": f"{cfg.nx}x{cfg.ny}", "ramp": cfg.inflow_ramp_steps,
            "ramp_over_period": round(cfg.inflow_ramp_steps / period, 2), "quiet": cfg.inlet_nonreflecting,
            "from": start, "to": end, "min": float(r.min()), "max": float(r.max()), "mean": float(r.mean())}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m feelflow.app.reports.ramps", description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="+", type=Path)
    parser.add_argument("--backend", default="numpy", choices=("numpy", "gl"))
    parser.add_argument("--rate", type=float, default=1e-3, help="the quiet inlet's rate (default 0.001)")
    args = parser.parse_args(argv)
    print("| scene | grid | ramp (steps, / quarter-wave period) | steps | quiet inlet: u / U min - max (mean) "
          "| bare inlet: u / U min - max (mean) |\n| --- | --- | --- | --- | --- | --- |", flush=True)
    for path in args.scenes:
        cells = []
        for rate in (args.rate, 0.0):
            try:
                r = inflow_after_ramp(path, args.backend, rate)
            except Exception as exc:   # a refused configuration is a row, not the end of the report
                cells.append(f"refused: {str(exc).splitlines()[0][:120]}")
                continue
            cells.append(f"{r['min']:.3f} - {r['max']:.3f} ({r['mean']:.3f})")
        print(f"| {r['scene']} | {r['grid']} | {r['ramp']} ({r['ramp_over_period']}) | {r['from']} - {r['to']} "
              f"| {cells[0]} | {cells[1]} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
