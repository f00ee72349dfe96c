"""The seed's experiments, reproduced on FeelFlow, with all four force models side by side
(issue 3; SEED-NOTES 'Experiments'): runs the scenes in `scenes/`, measures, plots (pyqtgraph,
offscreen) and writes a Markdown report.

Experiments (scene files): the stop/with/stop/against protocol for cylinders of 16, 24, 32
cells (`seed_protocol_d*.toml`); drag per shape at equal frontal width (`shapes_drag_*.toml`);
lift on the half airfoil (`lift_airfoil_half.toml`); drag on a plate at five speeds
(`drag_vs_speed.toml`, swept here over `SWEEP_SPEEDS`). Means are taken over the last half of
each phase (or of the run), so the start-up transient is left out.

The measured numbers are stored in `report-seed/data.json` next to the report, so the text and
plots can be rebuilt (`--replot`) without running the flow again.
"""
from __future__ import annotations

import json
import math
import os
import platform
import time
from pathlib import Path

import numpy as np

from feelflow.app.errors import UserError
from feelflow.app.files import write_text_atomic
from feelflow.app.machine import cpu_name
from feelflow.solver.lattice import CS2

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
COLOURS = {"momentum_exchange": (0, 90, 200), "momentum_exchange_classic": (200, 60, 0),
           "macroscopic": (0, 150, 60), "pressure": (150, 0, 150)}


# --- running -----------------------------------------------------------------------------
def load_scene_with(path: Path, *, phase_steps=None, steps=None, inflow_speed=None, ramp=None, interval=None):
    """A scene file with some keys replaced, validated like any scene (app/scene.py)."""
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
    if ramp is not None:
        data.setdefault("flow", {})["inflow_ramp_steps"] = min(ramp, data.get("flow", {}).get("inflow_ramp_steps", ramp))
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


#: the report's parts, each run and stored on its own (report-seed/data-<part>.json)
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
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise UserError(f"{path}: not valid JSON ({exc.msg}); run that part again") from None


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


# --- measuring -----------------------------------------------------------------------------
def _forces(run: dict, model: str) -> np.ndarray:
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
    f = _forces(run, model)
    if not sel.any():
        return np.array([math.nan, math.nan])
    return f[sel].mean(axis=0)


def tail_swing(run: dict, model: str, start: int, end: int) -> float:
    """Standard deviation of F_x over the last half of [start, end] (rows are already means over
    the output interval): how much the force swings around the mean reported."""
    steps = np.asarray(run["step"])
    sel = (steps > start + (end - start) // 2) & (steps <= end)
    return float(np.std(_forces(run, model)[sel, 0])) if sel.sum() > 1 else math.nan


def phase_means(run: dict, model: str) -> list[np.ndarray]:
    bounds = np.concatenate([[0], np.cumsum(run["phases"])])
    return [tail_mean(run, model, int(bounds[k]), int(bounds[k + 1])) for k in range(len(run["phases"]))]


#: the protocol plots show a running mean over this many steps: the impulsive starts and stops
#: ring the tunnel's acoustic modes, whose force swings exceed the drag at U = 0.01
PLOT_SMOOTH_STEPS = 1000


def running_mean(run: dict, model: str, steps: int):
    """(step, F_x) averaged over `steps` steps (centred, whole windows only)."""
    step = np.asarray(run["step"], dtype=np.float64)
    fx = _forces(run, model)[:, 0]
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
                per_d[key] = {"phases": f, "zero_rel_frac": _ratio(f[1], f[2]), "swing": swing,
                              "against_over_stopped": _ratio(f[3], f[2]),
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
                shapes[key] = {"drag": fx, "cd": _ratio(2 * fx, u * u * w), "reynolds": run["reynolds"]}
            out["shapes"][m] = shapes
    if "lift" in parts:
        run = parts["lift"]["runs"]["half_airfoil"]
        out["lift"] = {}
        for m in MODELS:
            fx, fy = (float(c) for c in tail_mean(run, m, 0, run["steps"]))
            u, chord = run["inflow_speed"], run["body"].get("chord", run["reference_length"])
            out["lift"][m] = {"fx": fx, "fy": fy, "cl_chord": _ratio(2 * fy, u * u * chord),
                              "reynolds_chord": u * chord / run["nu"]}
    return out


# --- plotting ------------------------------------------------------------------------------
def _qt():
    if "QT_QPA_PLATFORM" not in os.environ and not os.environ.get("DISPLAY"):
        os.environ["QT_QPA_PLATFORM"] = "offscreen"
    import pyqtgraph as pg

    pg.mkQApp()
    pg.setConfigOptions(background="w", foreground="k", antialias=True)
    return pg


def _export(plot_widget, path: Path, width=900):
    """Write the plot as PNG atomically, then dispose of the widget (Qt objects left for the
    interpreter's shutdown can crash PySide6 there)."""
    from pyqtgraph.exporters import ImageExporter
    from pyqtgraph.Qt import QtWidgets

    from feelflow.app.files import atomic_path

    plot_widget.show()  # lay the plot out (title, axes) before rendering it
    QtWidgets.QApplication.processEvents()
    try:
        with atomic_path(path, suffix=".png") as tmp:
            exporter = ImageExporter(plot_widget.getPlotItem())
            exporter.parameters()["width"] = width
            exporter.export(str(tmp))
    finally:
        plot_widget.close()
        plot_widget.deleteLater()
        QtWidgets.QApplication.processEvents()


def _plot(pg, title, xlabel, ylabel, size=(900, 520)):
    w = pg.PlotWidget()
    w.resize(*size)
    w.setTitle(title, size="11pt")
    w.setLabel("bottom", xlabel)
    w.setLabel("left", ylabel)
    w.showGrid(x=True, y=True, alpha=0.3)
    w.addLegend(offset=(10, 10))
    return w


def make_plots(parts: dict, res: dict, folder: Path) -> list[str]:
    pg = _qt()
    folder.mkdir(parents=True, exist_ok=True)
    names = []
    dash = {"d16": pg.QtCore.Qt.PenStyle.SolidLine, "d24": pg.QtCore.Qt.PenStyle.DashLine,
            "d32": pg.QtCore.Qt.PenStyle.DotLine}
    dcol = {"d16": (0, 90, 200), "d24": (200, 60, 0), "d32": (0, 150, 60)}
    if "protocol" in parts:
        runs = parts["protocol"]["runs"]
        for m in MODELS:
            w = _plot(pg, f"{m}: F_x over the seed protocol (stop | with | stop | against), "
                          f"running mean over {PLOT_SMOOTH_STEPS} steps", "step", "F_x (lattice units per step)")
            curves = []
            for key, run in runs.items():
                steps, fx = running_mean(run, m, PLOT_SMOOTH_STEPS)
                curves.append(fx)
                w.plot(steps, fx, pen=pg.mkPen(dcol[key], width=2, style=dash[key]),
                       name=f"D = {run['reference_length']:g}")
            vals = np.concatenate(curves)
            if vals.size:  # the start of each moving phase is a spike: show the plateaus
                lo, hi = np.percentile(vals, [3, 97])
                pad = 0.15 * (hi - lo) + 1e-12
                w.setYRange(lo - pad, hi + pad)
            first = next(iter(runs.values()))
            for b in np.cumsum(first["phases"])[:-1]:
                w.addItem(pg.InfiniteLine(pos=float(b), angle=90,
                                          pen=pg.mkPen((120, 120, 120), style=pg.QtCore.Qt.PenStyle.DashLine)))
            name = f"protocol_{m}.png"
            _export(w, folder / name)
            names.append(name)
    if "sweep" in res:
        w = _plot(pg, "Plate drag against speed (log-log), fitted F ~ U^n", "inflow speed U (lattice units)",
                  "|F_x| (lattice units per step)")
        w.setLogMode(True, True)
        for m in MODELS:
            s = res["sweep"][m]
            x, y = np.asarray(s["speeds"]), np.abs(np.asarray(s["drag"]))
            ok = y > 0
            w.plot(x[ok], y[ok], pen=None, symbol="o", symbolBrush=COLOURS[m], symbolPen=COLOURS[m],
                   name=f"{m}: n = {_g(s['exponent'])}")
            if math.isfinite(s["exponent"]):
                xx = np.linspace(x.min(), x.max(), 20)
                w.plot(xx, s["prefactor"] * xx ** s["exponent"], pen=pg.mkPen(COLOURS[m], width=1))
        _export(w, folder / "drag_vs_speed.png")
        names.append("drag_vs_speed.png")
    if "shapes" in res:
        w = _plot(pg, "Drag coefficient per shape (same frontal width 24, Re 200)", "shape",
                  "C_D = 2 F_x / (rho U^2 W)")
        keys = list(res["shapes"][REFERENCE])
        for j, m in enumerate(MODELS):
            cds = [res["shapes"][m][k]["cd"] for k in keys]
            bars = pg.BarGraphItem(x=np.arange(len(keys)) + (j - 1.5) * 0.2, height=cds, width=0.18, brush=COLOURS[m])
            w.addItem(bars)
            w.plotItem.legend.addItem(bars, m)
        w.getAxis("bottom").setTicks([[(i, k) for i, k in enumerate(keys)]])
        _export(w, folder / "drag_per_shape.png")
        names.append("drag_per_shape.png")
    if "lift" in parts:
        w = _plot(pg, "Half airfoil, flat side down: lift F_y against time", "step", "F_y (lattice units per step)")
        run = parts["lift"]["runs"]["half_airfoil"]
        for m in MODELS:
            w.plot(run["step"], _forces(run, m)[:, 1], pen=pg.mkPen(COLOURS[m], width=2), name=m)
        _export(w, folder / "lift.png")
        names.append("lift.png")
    return names


# --- writing -------------------------------------------------------------------------------
def _g(v, digits=3) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "n/a"
    return f"{v:.{digits}g}"


def _provenance(data: dict) -> str:
    text = f"backend `{data['backend']}`, {data['wall_s'] / 60:.1f} min on {data['machine']}"
    if data.get("phase_steps"):
        text += f"; **shortened: {data['phase_steps']} steps per phase instead of the scenes' 15000**"
    if data.get("quick"):
        text += "; **--quick smoke run: the numbers are not physics**"
    if data.get("note"):
        text += f"; {data['note']}"
    return text


def _runs_table(parts: dict) -> list[str]:
    lines = ["| experiment | grid | Re | steps | wall s | MLUPS | note |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for part, data in parts.items():
        for key, r in data["runs"].items():
            note = f"diverged at step {r['diverged_at']}" if r["diverged_at"] is not None else ""
            name = f"{part} {key}" if part != "sweep" else f"sweep, plate U = {key}"
            lines.append(f"| {name} | {r['nx']} x {r['ny']} | {r['reynolds']:.3g} | {r['steps']} | {r['wall_s']:.0f} "
                         f"| {r['mlups']:.1f} | {note} |")
    return lines


def markdown(parts: dict, res: dict, plots_dir: str) -> str:
    L: list[str] = []
    add = L.append
    add("# The seed's experiments on FeelFlow: four force models side by side\n")
    add("Written by `feelflow report seed` (app/seed_report.py) from the scenes in `scenes/`; "
        "`feelflow report seed --replot` rebuilds this page from the stored series in `report-seed/`.\n")
    add("Models (docs/force-models.md): `momentum_exchange` (the reference: Galilean-invariant momentum exchange), "
        "`momentum_exchange_classic` (the seed's), `macroscopic` (drag equation with tabulated C_D, velocity sampled "
        "4 cells off the wall), `pressure` (seed eq. 24 with beta = rho_0/6, i.e. the lattice pressure; no shear). "
        "Forces in lattice units per step; means at the end of each phase or run, over the longest whole number "
        "of periods of the tunnel's acoustic mode (4 nx / c_s steps) within its last half (else the last half). "
        "Parts not run yet are left out.\n")
    for part in PARTS:
        if part == "protocol" and part in parts:
            for key, prov in parts[part]["provenance"].items():
                add(f"- protocol {key}: {_provenance(prov)}")
        elif part in parts:
            add(f"- {part}: {_provenance(parts[part])}")
    add("\n## Runs\n")
    L += _runs_table(parts)

    if "protocol" in res:
        add("\n## 1. The seed's protocol: stopped, with, stopped, against (U = 0.01)\n")
        add("Cylinders of diameter 16, 24, 32 in a uniform stream (0.01, 0), tunnel with free-slip walls. "
            "Relative speed per phase: 0.01, **0**, 0.01, 0.02. While the body moves with the stream it still "
            "pushes the slow fluid of its own wake until that wake has diffused (time scale D^2/nu, longer than a "
            "phase), so even the exact force is not yet zero there: compare each model with the reference. "
            "F(against)/F(stopped) = 2^n, n the drag exponent at this Re (n = 2 only for constant C_D).\n")
        add("At U = 0.01 the drag is small next to the force swings of the tunnel's acoustic modes, rung by every "
            "impulsive start and stop of the body: the column *swing* is the standard deviation of F_x (100-step "
            "means) over the last half of the second stopped phase. Differences smaller than it are noise. "
            "The clean Galilean check is `pytest tests/test_force_models_flow.py -s` (the same protocol in two "
            "frames in a periodic box, no tunnel acoustics; docs/force-models.md has its numbers). The classic form "
            "differs from the reference only by -u_w sum (f_out - f_in) over the body links and by the cover/uncover "
            "impulse; both stay small while the density stays at rho_0 (the tunnel's pressure outlet holds it there), "
            "and that test shows the classic form failing at an ambient density 5 % above rho_0.\n")
        add("| model | D | Re (stopped) | F stopped | swing | F with (rel. 0) | with / stopped | F against | against / stopped | implied n |")
        add("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
        for m in MODELS:
            for v in res["protocol"][m].values():
                f = v["phases"]
                ratio = v["against_over_stopped"]
                n = math.log(ratio, 2) if ratio and ratio > 0 and math.isfinite(ratio) else math.nan
                add(f"| {m} | {v['diameter']:g} | {v['reynolds']:.3g} | {_g(f[2])} | {_g(v['swing'], 2)} | {_g(f[1])} | {_g(v['zero_rel_frac'])} "
                    f"| {_g(f[3])} | {_g(ratio)} | {_g(n)} |")
        for m in MODELS:
            add(f"\n![F_x over the protocol, {m}]({plots_dir}/protocol_{m}.png)")
        add("\n## 2. Drag against frontal area (stopped cylinders, U = 0.01)\n")
        add("| model | F(D=16) | F(D=24) | F(D=32) | exponent m of F ~ D^m |\n| --- | --- | --- | --- | --- |")
        for m in MODELS:
            a = res["area"][m]
            add(f"| {m} | " + " | ".join(_g(x) for x in a["drag"]) + f" | {_g(a['exponent'])} |")
        add("\nm = 1 is drag proportional to frontal area at constant C_D. Here Re grows with D (Re = U D / nu), "
            "so C_D falls with D and m < 1 is the physics, not an error.")

    if "sweep" in res:
        sw = res["sweep"][REFERENCE]
        add(f"\n## 3. Drag against relative speed (plate of width 20, Re {sw['reynolds'][0]:.0f} - {sw['reynolds'][-1]:.0f})\n")
        add("| model | " + " | ".join(f"U = {u:g}" for u in sw["speeds"]) + " | fitted n (F ~ U^n) |")
        add("| --- |" + " --- |" * (len(sw["speeds"]) + 1))
        for m in MODELS:
            s = res["sweep"][m]
            add(f"| {m} | " + " | ".join(_g(x) for x in s["drag"]) + f" | {_g(s['exponent'])} |")
        add("\nThe macroscopic model is |u - V| (u - V) of its own contour-sampled velocity times constants: against "
            "the inflow speed its exponent only tells how that contour mean changes with Re, nothing about the drag.")
        add(f"\n![drag against speed]({plots_dir}/drag_vs_speed.png)")

    if "shapes" in res:
        add("\n## 4. Drag per shape (frontal width 24, U = 0.05, Re 200)\n")
        keys = list(res["shapes"][REFERENCE])
        add("| model | " + " | ".join(f"C_D {k}" for k in keys) + " | ordering (largest drag first) |")
        add("| --- |" + " --- |" * (len(keys) + 1))
        for m in MODELS:
            s = res["shapes"][m]
            order = " > ".join(sorted(keys, key=lambda k: -s[k]["drag"]))
            add(f"| {m} | " + " | ".join(_g(s[k]["cd"]) for k in keys) + f" | {order} |")
        add("\nThe macroscopic model's ordering is its C_D table's (docs/force-models.md), an input, not a result.")
        add(f"\n![drag per shape]({plots_dir}/drag_per_shape.png)")

    if "lift" in res:
        lf0 = res["lift"][REFERENCE]
        add(f"\n## 5. Lift on the half airfoil (flat side down, U = 0.05, Re {lf0['reynolds_chord']:.0f} on the chord)\n")
        add("| model | mean F_x | mean F_y | C_L (on the chord) | lift points |\n| --- | --- | --- | --- | --- |")
        for m in MODELS:
            lf = res["lift"][m]
            sign = "up" if lf["fy"] > 0 else ("down" if lf["fy"] < 0 else "nowhere")
            add(f"| {m} | {_g(lf['fx'])} | {_g(lf['fy'])} | {_g(lf['cl_chord'])} | {sign} |")
        add(f"\n![lift]({plots_dir}/lift.png)")

    add("\n## Each model, measured (the lesson)\n")
    for m in MODELS:
        add(f"- **{m}**: " + verdict(m, res))
    add("")
    return "\n".join(L)


def _ratio(a: float, b: float) -> float:
    return a / b if b else math.nan


def verdict(m: str, res: dict) -> str:
    """One measured summary per model; the thresholds are stated in the words."""
    parts = []
    if "protocol" in res:
        p = list(res["protocol"][m].values())
        ref = list(res["protocol"][REFERENCE].values())
        frac = [v["zero_rel_frac"] for v in p]
        text = (f"moving with the stream it reads {', '.join(_g(100 * f, 2) + ' %' for f in frac)} of its stopped drag "
                f"(D = 16, 24, 32; force swing {', '.join(_g(100 * _ratio(v['swing'], abs(v['phases'][2])), 2) + ' %' for v in p)})")
        if m != REFERENCE:
            text += f"; the reference reads {', '.join(_g(100 * r['zero_rel_frac'], 2) + ' %' for r in ref)}"
            if m == "momentum_exchange_classic":
                gap = max(_ratio(abs(a - b), abs(r["phases"][2])) for v, r in zip(p, ref) for a, b in zip(v["phases"], r["phases"]))
                text += f"; largest phase-mean difference from the reference: {_g(100 * gap, 2)} % of the stopped drag"
            else:
                text += ("; stopped drag / reference's: "
                         + ", ".join(_g(_ratio(v["phases"][2], r["phases"][2]), 2) for v, r in zip(p, ref)))
        parts.append(text)
        parts.append(f"counter-moving / stopped = {', '.join(_g(v['against_over_stopped']) for v in p)}")
        parts.append(f"drag ~ D^{_g(res['area'][m]['exponent'])} over the three cylinders")
    if "sweep" in res:
        s = res["sweep"][m]
        parts.append(f"drag ~ U^{_g(s['exponent'])} on the plate at Re {s['reynolds'][0]:.0f}-{s['reynolds'][-1]:.0f}")
    if "shapes" in res:
        ref_order = sorted(res["shapes"][REFERENCE], key=lambda k: -res["shapes"][REFERENCE][k]["drag"])
        order = sorted(res["shapes"][m], key=lambda k: -res["shapes"][m][k]["drag"])
        if m != REFERENCE:
            rel = [_ratio(res["shapes"][m][k]["drag"], res["shapes"][REFERENCE][k]["drag"]) for k in ref_order]
            parts.append("drag / reference drag: " + ", ".join(f"{k} {_g(r, 2)}" for k, r in zip(ref_order, rel)))
        parts.append("shape ordering " + (f"{' > '.join(order)}" if m == REFERENCE else
                                          "matches the reference" if order == ref_order else
                                          f"**differs from the reference** ({' > '.join(order)})"))
    if "lift" in res:
        fy = res["lift"][m]["fy"]
        parts.append("lift points " + ("up" if fy > 0 else "**down or nowhere**"))
    return "; ".join(parts) + "." if parts else "not measured yet."


def write_report(out_dir: Path) -> Path:
    """Analyse the stored parts, plot, write report-seed.md; returns its path."""
    folder = out_dir / "report-seed"
    parts = load_parts(folder)
    if not parts:
        raise UserError(f"{folder}: no stored experiment data; run `feelflow report seed` first")
    res = analyse(parts)
    make_plots(parts, res, folder)
    path = out_dir / "report-seed.md"
    write_text_atomic(path, markdown(parts, res, "report-seed"))
    return path
