"""The seed report's runs: its scenes run on a backend with all four force models, stored as JSON.

Each part (PARTS) is a set of scene runs; `run_part` runs one, `save_part` stores it in
`seed-report/<part>.json` and `load_parts` reads them back, so the analysis, plots and text
(app/reports/seed.py) can be rebuilt without running the flow again.
"""
from __future__ import annotations

import json
import math
import os
import platform
import time
from pathlib import Path

from feelflow.app.errors import UserError
from feelflow.app.files import write_text_atomic
from feelflow.app.machine import cpu_name

MODELS = ("momentum_exchange", "momentum_exchange_classic", "macroscopic", "pressure")
REFERENCE = "momentum_exchange"
PROTOCOL = (("d16", "seed_protocol_d16.toml"), ("d24", "seed_protocol_d24.toml"), ("d32", "seed_protocol_d32.toml"))
SHAPES = (("plate", "shapes_drag_plate.toml"), ("wedge upstream (<)", "shapes_drag_wedge_upstream.toml"),
          ("wedge downstream (>)", "shapes_drag_wedge_downstream.toml"), ("cylinder", "shapes_drag_cylinder.toml"))
LIFT = "lift_airfoil_half.toml"
SWEEP = "drag_vs_speed.toml"
#: inflow speeds of the drag-vs-speed sweep (lattice units); steps scale as 1 / U. The top speed
#: keeps the cell Reynolds number U / nu at 11: at nu = 0.005, U = 0.07 and 0.09 diverged (TRT,
#: tau = 0.515, the plate's sharp edges), measured with this report on the numpy backend.
SWEEP_SPEEDS = (0.025, 0.03, 0.037, 0.045, 0.055)
PHASE_NAMES = ("stopped", "with the stream", "stopped again", "against the stream")
#: --quick: steps per protocol phase, steps of every other run, inflow ramp
QUICK = {"phase_steps": 40, "steps": 80, "ramp": 20}


def load_scene_with(path: Path, *, phase_steps=None, steps=None, inflow_speed=None, ramp=None, interval=None):
    """A scene file with some keys replaced, validated like any scene (app/model/scene.py)."""
    from feelflow.app.inputs import load_toml
    from feelflow.app.model.scene import scene_from_dict

    if not Path(path).exists():
        raise UserError(f"{path}: no such scene file (the report needs the scenes shipped in scenes/)")
    data = load_toml(path, "scene file")   # the input policy: regular file, bounds (app/inputs.py)
    if phase_steps is not None:
        for phase in data.get("motion", []):
            phase["steps"] = phase_steps
    if steps is not None and "run" in data:
        data["run"]["steps"] = steps
    if inflow_speed is not None:
        data.setdefault("flow", {})["inflow_speed"] = inflow_speed
    if interval is not None:
        data.setdefault("output", {})["interval"] = interval
    if ramp is not None:   # a shortened ramp; with the quiet inlet, which refuses short ramps, none
        flow = data.setdefault("flow", {})
        flow["inflow_ramp_steps"] = 0 if flow.get("inlet_nonreflecting", 0) else min(ramp, flow.get("inflow_ramp_steps", ramp))
    return scene_from_dict(data, str(path))


def run_scene(scene, backend: str, log=print) -> dict:
    """Run a scene; per output interval: step, body x and vx, mean force per model."""
    from feelflow.app.headless import make_solver
    from feelflow.solver.motion import MotionRunner

    solver = make_solver(backend, scene.config)
    rows = {"step": [], "x": [], "vx": [], "forces": {m: [] for m in scene.force_models}}
    diverged = None
    start = time.perf_counter()
    try:
        solver.enable_force_models(scene.force_models)
        runner = MotionRunner(solver, scene.body, scene.motion)
        while runner.t < scene.steps:
            n = min(scene.output_interval, scene.steps - runner.t)
            vx = scene.motion.velocity_at(runner.t + n - 1)[0]
            forces = runner.advance(n)
            values = [c for m in scene.force_models for c in forces[m]]
            if not all(math.isfinite(v) for v in values):
                diverged = runner.t
                break
            rows["step"].append(runner.t)
            rows["x"].append(runner.position[0])
            rows["vx"].append(vx)
            for m in scene.force_models:
                rows["forces"][m].append(list(forces[m]))
    finally:
        solver.close()
    wall = time.perf_counter() - start
    done = rows["step"][-1] if rows["step"] else 0
    rows.update(source=scene.source, nx=scene.config.nx, ny=scene.config.ny, nu=scene.config.nu,
                inflow_speed=scene.config.inflow_speed, reynolds=scene.reynolds, body=scene.body.to_dict(),
                reference_length=scene.reference_length, steps=scene.steps, diverged_at=diverged,
                phases=[p.steps for p in scene.motion.phases], wall_s=wall,
                mlups=scene.config.nx * scene.config.ny * done / wall / 1e6 if wall > 0 else float("nan"))
    log(f"  {Path(scene.source).name}: {done} steps, {scene.config.nx} x {scene.config.ny}, "
        f"Re {scene.reynolds:.3g}, {wall:.0f} s ({rows['mlups']:.1f} MLUPS)"
        + (f", DIVERGED at step {diverged}" if diverged is not None else ""))
    return rows


#: the report's parts, each run and stored on its own (seed-report/data-<part>.json)
PARTS = ("protocol", "shapes", "sweep", "lift")


def run_part(part: str, scenes_dir: Path, backend: str, quick: bool, phase_steps, log=print,
             keys=None) -> dict:
    """Run one part's experiments (for the protocol: the diameters in `keys`, default all);
    JSON-ready raw series plus how they were run."""
    q = QUICK if quick else {}
    over = {"ramp": q.get("ramp"), "interval": 10 if quick else None}
    runs: dict = {}
    t0 = time.perf_counter()
    if part == "protocol":
        for key, name in PROTOCOL:
            if keys and key not in keys:
                continue
            scene = load_scene_with(scenes_dir / name, phase_steps=q.get("phase_steps", phase_steps), **over)
            runs[key] = run_scene(scene, backend, log)
    elif part == "shapes":
        for key, name in SHAPES:
            runs[key] = run_scene(load_scene_with(scenes_dir / name, steps=q.get("steps"), **over), backend, log)
    elif part == "sweep":
        base = load_scene_with(scenes_dir / SWEEP)
        for u in SWEEP_SPEEDS:
            steps = q.get("steps") or int(round(base.steps * base.config.inflow_speed / u))
            runs[f"{u:g}"] = run_scene(load_scene_with(scenes_dir / SWEEP, inflow_speed=u, steps=steps, **over),
                                       backend, log)
    elif part == "lift":
        runs["half_airfoil"] = run_scene(load_scene_with(scenes_dir / LIFT, steps=q.get("steps"), **over), backend, log)
    else:
        raise ValueError(f"unknown part {part!r}")
    return {"part": part, "backend": backend, "quick": quick,
            "phase_steps": phase_steps if part == "protocol" else None, "machine": machine(),
            "wall_s": time.perf_counter() - t0, "runs": runs}


def save_part(folder: Path, data: dict) -> None:
    """Store a part; the protocol one file per diameter (data-protocol-d16.json ...), so that
    diameters can be run (or rerun) by separate processes."""
    folder.mkdir(parents=True, exist_ok=True)
    if data["part"] == "protocol":
        for key, run in data["runs"].items():
            one = dict(data, runs={key: run}, wall_s=run["wall_s"])
            write_text_atomic(folder / f"data-protocol-{key}.json", json.dumps(one, separators=(",", ":")))
        return
    write_text_atomic(folder / f"data-{data['part']}.json", json.dumps(data, separators=(",", ":")))


def _read_json(path: Path) -> dict:
    """A stored series, through the one bounded reader (app/inputs.py)."""
    from feelflow.app.inputs import load_json

    try:
        return load_json(path, "stored series", 256 << 20, allow_nan=True, max_items=10 ** 8)
    except UserError as exc:
        raise UserError(f"{exc}; run that part again") from None


def load_parts(folder: Path) -> dict:
    """part -> stored data, for the parts that have been run (protocol diameters merged; each
    protocol run keeps how it was run in `provenance`)."""
    parts = {}
    for part in PARTS:
        if part == "protocol":
            runs, provenance = {}, {}
            for key, _ in PROTOCOL:
                path = folder / f"data-protocol-{key}.json"
                if path.exists():
                    one = _read_json(path)
                    runs[key] = one["runs"][key]
                    provenance[key] = one
            if runs:
                first = next(iter(provenance.values()))
                parts[part] = dict(first, runs=runs, provenance=provenance,
                                   wall_s=sum(p["wall_s"] for p in provenance.values()))
            continue
        path = folder / f"data-{part}.json"
        if path.exists():
            parts[part] = _read_json(path)
    return parts


def machine() -> str:
    return f"{cpu_name()}, {os.cpu_count()} cores, {platform.system()} {platform.release()}"
