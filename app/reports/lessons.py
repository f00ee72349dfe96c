"""`feelflow report lessons`: every lesson of the Presets menu run headless as the window runs it
(app.simulation.Simulation, one force sample per frame of `FRAME` steps), and what a class sees
of its forces: how steady drag and lift are at the end, and for the wind sweep the drag at each
speed and the exponent the plot's log-log view fits (app/model/plot_series.py, settled samples only).

`compare=True` also runs each lesson *plain*: without the sponge's absorbing layer, with the
wind blowing everywhere from the first step and the sweep's wind changed at once, the old way of
running them; the difference is what those choices buy (docs/science/validation.md
'Calm tunnels'). Qt-free (the fit is app.model.power_law's).
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

#: steps per force sample, as the window's frames (about 10 steps each at 256 x 128)
FRAME = 10
#: the end of a lesson whose steadiness is reported (the second half of a sweep's last hold)
TAIL_STEPS = 1000


def plain_scene(scene):
    """The scene without the absorbing layer and the quiet inlet, the wind everywhere from the
    first step."""
    cfg = scene.config
    cfg = dataclasses.replace(cfg, sponge_absorb=0.0, inlet_nonreflecting=0.0, inflow_ramp_steps=0,
                              initial_velocity=(cfg.inflow_speed, 0.0))
    return dataclasses.replace(scene, config=cfg)


def run_lesson(key: str, backend: str = "numpy", plain: bool = False, make_ctx=None) -> dict:
    """Run lesson `key` (app.presets.PRESETS) for its length: the sweep's holds, else the
    scene's `steps`. Returns a JSON-ready dict (see `format_table`)."""
    from feelflow.app.model.power_law import fit_power_law
    from feelflow.app.model.presets import PRESETS
    from feelflow.app.model.scene import load_scene
    from feelflow.app.model.simulation import Simulation
    from feelflow.solver.backend import needs_gl_context

    lesson = PRESETS[key]
    scene = load_scene(lesson.path)
    if plain:
        scene = plain_scene(scene)
    sim = Simulation(backend=backend, ctx=make_ctx() if needs_gl_context(backend) else None)
    try:
        sim.load_scene(scene)
        sim.hold_still = lesson.hold_still and sim.runner is None
        if plain:
            sim.sweep_slew_steps = 0
        if lesson.wind_sweep:
            sim.start_sweep(lesson.wind_sweep, lesson.hold_steps)
            steps = sim.sweep_end()
            first = sim.sweep.start
        else:
            steps = scene.steps
        start = time.perf_counter()
        while sim.solver.time < steps:
            sim.advance(FRAME)
        wall = time.perf_counter() - start
        h = sim.history
        t, drag, lift = h.drag_lift(sim.params.force_model)
        wind = np.hypot(*np.asarray(h.wind, float).reshape(-1, 2).T)
        settled = np.asarray(h.settled, bool)
    finally:
        sim.solver.close()
    tail = t > t[-1] - TAIL_STEPS
    scale = abs(drag[tail].mean())
    out = {"lesson": key, "title": lesson.title, "plain": plain, "backend": backend, "steps": int(steps),
           "wall_s": round(wall, 2), "model": sim.params.force_model,
           "tail_steps": TAIL_STEPS, "drag_mean": float(drag[tail].mean()),
           "drag_std_rel": float(drag[tail].std() / scale), "lift_mean": float(lift[tail].mean()),
           "lift_std_rel": float(lift[tail].std() / scale)}
    if lesson.wind_sweep:
        rows = []
        for k, u in enumerate(lesson.wind_sweep):
            hold = (t > first + k * lesson.hold_steps) & (t <= first + (k + 1) * lesson.hold_steps)
            second = hold & (t > first + (k + 0.5) * lesson.hold_steps)
            d = drag[second]
            rows.append({"wind": u, "drag_second_half": float(d.mean()),
                         "std_rel_second_half": float(d.std() / abs(d.mean())),
                         "drag_settled": float(drag[hold & settled].mean()) if (hold & settled).any() else float("nan"),
                         "settled_samples": int((hold & settled).sum())})
        out["sweep"] = rows
        out["exponent_settled"] = fit_power_law(wind[settled], drag[settled])[2]
        out["exponent_all_samples"] = fit_power_law(wind, drag)[2]
    return out


def format_table(runs: list[dict]) -> str:
    """Markdown: one row per lesson run, then the sweep's rows."""
    lines = [f"| lesson | run | steps | wall s | drag std / drag (last {TAIL_STEPS} steps) | lift / drag | lift std / drag |"
             " fitted exponent (settled / all samples) |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in runs:
        fit = ""
        if "sweep" in r:
            fit = f"{table_number(r['exponent_settled'])} / {table_number(r['exponent_all_samples'])}"
        lines.append(f"| {r['lesson']} | {'plain' if r['plain'] else 'as shipped'} | {r['steps']} | {r['wall_s']:.1f} "
                     f"| {r['drag_std_rel']:.4f} | {r['lift_mean'] / abs(r['drag_mean']):+.4f} "
                     f"| {r['lift_std_rel']:.4f} | {fit} |")
    sweeps = [r for r in runs if "sweep" in r]
    if sweeps:
        lines += ["", "| lesson | run | wind | drag, settled samples | drag, 2nd half of the hold | "
                  "std / mean, 2nd half | settled samples |", "| --- | --- | --- | --- | --- | --- | --- |"]
        for r in sweeps:
            for row in r["sweep"]:
                lines.append(f"| {r['lesson']} | {'plain' if r['plain'] else 'as shipped'} | {row['wind']:g} "
                             f"| {table_number(row['drag_settled'], '.5g')} | {row['drag_second_half']:.5g} "
                             f"| {row['std_rel_second_half']:.4f} | {row['settled_samples']} |")
    return "\n".join(lines)


def table_number(x, fmt=".3f") -> str:
    """A table cell for a number that may be missing: "-" for None or not finite (the reports'
    tables, here and in app/scene_report.py)."""
    return "-" if x is None or not np.isfinite(x) else format(x, fmt)
