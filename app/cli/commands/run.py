"""`feelflow run SCENE.toml`: run a scene headless, write the body's forces as CSV.

Columns: `step,x,y,vx,vy` then `fx_<model>,fy_<model>` per force model, lattice units, one row
per output interval: `step` = steps done, (x, y) the body position then, (vx, vy) its velocity
during the last step, forces averaged over the interval. The file is written atomically.
"""
from __future__ import annotations

import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from feelflow.app.errors import UserError


def add_arguments(parser):
    parser.add_argument("scene", metavar="SCENE.toml", help="the scene file (keys: docs/reference/scenes.md)")
    parser.add_argument("--backend", default=None, metavar="numpy|cpu|gl|auto",
                        help="solver backend (default: the scene's run.backend, else auto); auto: the "
                             "fastest here, timed briefly on the scene's grid and remembered")
    parser.add_argument("--steps", default=None, metavar="N", help="number of steps (default: the scene's)")
    parser.add_argument("--out", default="forces.csv", metavar="PATH", help="CSV file to write (default: forces.csv)")
    parser.add_argument("--record", default=None, metavar="FILE.ffsession",
                        help="also record the run as a session file (docs/reference/session-format.md)")
    parser.add_argument("--si", default=None, metavar="FLUID:SIZE_M[:SPAN_M]",
                        help="add SI columns to the CSV for a physical flow with the scene's Reynolds number: "
                             "FLUID air, water or oil, the body's size (its reference length) and span in metres "
                             "(default span 0.1), for example water:0.01")
    parser.add_argument("--force", action="store_true",
                        help="replace --out / --record if they exist (never the scene itself; "
                             "without --force an existing file is refused before the run starts)")


def positive_int_option(name: str, text):
    """An option that must be a positive integer; UserError (one line) otherwise."""
    from feelflow.app.errors import shown

    try:
        if len(str(text).strip()) > 18:
            raise ValueError("too many digits")
        value = int(text)
    except (TypeError, ValueError):
        raise UserError(f"{name}: must be a positive integer of at most 18 digits, got {shown(text)!r}") from None
    if value < 1:
        raise UserError(f"{name}: must be a positive integer, got {value}")
    return value


def _fmt(v: float) -> str:
    return f"{v:.10g}"


def main(args) -> int:
    from feelflow.app.headless import make_solver, resolve_backend
    from feelflow.app.model.scene import load_scene

    from feelflow.app.files import check_output, save_csv
    from feelflow.app.inputs import check_memory, check_work
    from feelflow.app.model.scene import check_path_inside

    scene = load_scene(args.scene)
    backend = args.backend if args.backend is not None else scene.backend
    from feelflow.solver.backend import BACKENDS
    if backend not in BACKENDS and backend != "auto":   # before the run and its outputs
        raise UserError(f"--backend: must be one of {', '.join(sorted(BACKENDS))} or auto, got {backend!r}")
    si = None
    if getattr(args, "si", None):
        from feelflow.app.model.display_units import DisplayUnits, parse_si
        from feelflow.solver.units import FLUIDS, PhysicalUnits

        try:
            choice = parse_si(args.si)
            si = DisplayUnits(PhysicalUnits(FLUIDS[choice.fluid], choice.size_m, choice.span_m,
                                            scene.reference_length, scene.reference_speed, scene.config.nu))
        except ValueError as exc:
            raise UserError(str(exc).splitlines()[0]) from None
    steps = positive_int_option("--steps", args.steps) if args.steps is not None else scene.steps
    if args.steps is not None:   # the command line's steps: the same bounds as the scene's
        check_work(scene.config.nx, scene.config.ny, steps, "--steps", "--steps")
        check_path_inside(f"{args.scene} with --steps {steps}", scene.body, scene.motion, steps,
                          scene.config.nx, scene.config.ny)
    # every output is checked before the run: never an input, never twice, never a device
    out = check_output(args.out, "--out", inputs=[args.scene], force=args.force)
    if args.record:
        check_output(args.record, "--record", inputs=[args.scene], others=[args.out], force=args.force)
    check_memory(scene.config.nx, scene.config.ny, args.scene, "grid.nx, grid.ny")
    warn_outside_stable_region(scene, args.scene)

    backend = resolve_backend(backend, scene.config)
    solver = make_solver(backend, scene.config)
    recorder = None
    if args.record:
        from feelflow.app.inputs import read_bytes
        from feelflow.app.sessions import record_headless

        toml_text = read_bytes(args.scene, "scene file").decode("utf-8")
        solver, recorder = record_headless(solver, scene, scene_toml=toml_text)
        if si is not None:   # the units chosen, for a replay in the window (session-format.md, "units")
            from feelflow.app.model.display_units import choice_to_dict

            recorder.units = choice_to_dict(choice)
    try:
        # a blow-up is detected and reported in one line, not as floating-point warnings
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            header, rows, wall, diverged = run_scene(scene, solver, steps)
    finally:
        solver.close()

    if si is not None:   # SI columns beside the lattice ones (app/model/display_units.py)
        from feelflow.app.model.display_units import si_columns

        header, rows = si_columns(header, rows, si)
    csv_error = None
    try:
        save_csv(out, header, rows, "--out")
    except UserError as exc:   # the rows went to a rescue file; the session is still saved
        csv_error = exc
    if recorder is not None:
        from feelflow.app.sessions import SessionError

        try:
            recorder.save(args.record)
        except SessionError as exc:
            forces = "the forces too could not be written" if csv_error else f"the forces are in {out}"
            raise UserError(f"--record: {exc}; {forces}") from None
    if csv_error is not None:
        raise csv_error
    if diverged is not None:
        print(f"feelflow: the simulation diverged within steps {diverged[0]}..{diverged[1]} ({diverged[2]}); "
              f"the {len(rows)} rows before it are in {out}. Lower the speeds or raise the viscosity "
              f"or the resolution.", file=sys.stderr)
        return 1
    cells = scene.config.nx * scene.config.ny
    mlups = cells * steps / wall / 1e6 if wall > 0 else float("nan")
    print(f"{out}: {len(rows)} rows, {steps} steps on {backend} ({scene.config.nx} x {scene.config.ny}, "
          f"Re {scene.reynolds:.4g} with L = {scene.reference_length:g} cells, U = {scene.reference_speed:g}, "
          f"Ma {scene.mach:.3f}); {wall:.1f} s, {mlups:.1f} MLUPS"
          + (f"; SI columns for {si.describe()}" if si is not None else ""))
    if recorder is not None and recorder.full is not None:
        # the run went on to its end (every row is in --out); the session holds its first part
        print(f"feelflow: --record: {recorder.full} in {args.record}; the run went on to step {steps} "
              f"and all its forces are in {out}", file=sys.stderr)
        return 1
    return 0


def warn_outside_stable_region(scene, name) -> bool:
    """One line on stderr when the scene lies outside the measured stable region,
    U sqrt(d) / nu <= K (solver/stability_limit.py); the scene is run as written (the window, by
    contrast, raises the viscosity). U is the scene's reference speed (the inflow, or the fastest
    motion phase in fluid at rest), d the body's larger bounding-box side (the scan's d: cylinder
    diameter, plate or wedge length)."""
    from feelflow.solver.stability_limit import measured_cell_reynolds

    cfg = scene.config
    speed = abs(scene.reference_speed)
    x0, y0, x1, y1 = scene.body.bounding_box()
    size = max(x1 - x0, y1 - y0)
    limit = measured_cell_reynolds(cfg.collision, size, speed)
    if speed / cfg.nu <= limit:
        return False
    print(f"feelflow: warning: {name}: U / nu = {speed / cfg.nu:.3g} is above {limit:.3g}, the measured stable "
          f"cell Reynolds number for a {size:.3g}-cell body ({cfg.collision}, "
          f"solver/stability_limit.py); the run may diverge (nu >= {speed / limit:.4g} keeps it inside)",
          file=sys.stderr)
    return True


def warn_outside_local_region(scene, solver, step: int) -> bool:
    """One line on stderr the first time the flow's fastest node leaves the operator's stable
    region (the local guard, solver/local_guard.py, from the physical-range check's max |u|); the
    scene runs as written (the window, by contrast, raises the viscosity)."""
    from feelflow.solver import local_guard
    from feelflow.solver.operator_choice import NAMES

    if solver.max_speed_at is None:
        return False
    cfg = scene.config
    verdict = local_guard.check(cfg.collision, cfg.nu, solver.max_speed_seen)
    if verdict.inside:
        return False
    print(f"feelflow: warning: step {step}: {verdict.line(NAMES.get(cfg.collision, cfg.collision))} "
          f"The scene runs as written.", file=sys.stderr)
    return True


def run_scene(scene, solver, steps: int):
    """Step `scene` in `solver` along its motion script for `steps` steps.

    Returns (header, rows, wall seconds, None or (first, last step of the interval in which the
    flow diverged, why)); the rows stop at the last interval whose flow was physical."""
    from feelflow.solver import backend as backends
    from feelflow.solver.motion import MotionRunner

    diverged_error = getattr(backends, "SolverDiverged", ())
    solver.enable_force_models(scene.force_models)
    runner = MotionRunner(solver, scene.body, scene.motion)
    from feelflow.app.sessions.format import force_columns

    header = force_columns(scene.force_models)   # ... fx_m, fy_m per model, then torque_m per model
    rows = []
    warned = False
    start = time.perf_counter()
    while runner.t < steps:
        t0 = runner.t
        n = min(scene.output_interval, steps - t0)
        velocity = scene.motion.velocity_at(t0 + n - 1)
        try:
            forces = runner.advance(n)   # checks the flow's physical range (Solver.check_physical)
        except diverged_error as exc:
            detail = str(exc).split(": ", 1)[-1].split(" (lower")[0]
            return header, rows, time.perf_counter() - start, (t0, t0 + n, detail)
        values = [v for m in scene.force_models for v in forces[m]]
        if not all(math.isfinite(v) for v in values) or not math.isfinite(solver.total_mass()):
            return header, rows, time.perf_counter() - start, (t0, t0 + n, "NaN")
        values += [runner.last_torques.get(m, math.nan) for m in scene.force_models]
        if not warned:
            warned = warn_outside_local_region(scene, solver, runner.t)
        x, y = runner.position
        rows.append([runner.t] + [_fmt(v) for v in (x, y, *velocity, *values)])
    return header, rows, time.perf_counter() - start, None
