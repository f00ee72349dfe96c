"""`feelflow polar SCENE.toml --angles ...`: an angle-of-attack sweep of the scene's body.

Each angle is held until its forces settle (app/model/polar.py: the mean C_L and C_D of the
last window of samples and of the window before differ by less than --tolerance), then the next
one. Writes the polar as CSV (alpha_deg, cl, cd, cl_std, steps, settled; coefficients on the
chord) and as an image (C_L and C_D against alpha with the thin-airfoil line, C_L against C_D);
with --cp also C_p along the surface at every angle (CSV, and an image beside it).
`--scale 2` runs the scene at twice the resolution (grid, body, sponge, viscosity scaled so that
Re and the wind stay the same) to see what the resolution changes.
"""
from __future__ import annotations

import math
import sys
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

from feelflow.app.errors import UserError

#: most angles in one sweep, and the largest |angle|
MAX_ANGLES = 60
MAX_ANGLE = 90.0
MAX_SCALE = 4


def add_arguments(parser):
    parser.add_argument("scene", metavar="SCENE.toml", help="the scene file; its body is turned to each angle")
    parser.add_argument("--angles", required=True, metavar="LIST",
                        help="angles of attack in degrees (nose up is positive): a list '-4,0,4,8' or a range "
                             "'START:STOP:STEP' ('-4:16:2' includes 16)")
    parser.add_argument("--backend", default=None, metavar="numpy|cpu|gl|auto",
                        help="solver backend (default: the scene's run.backend, else auto: the fastest here)")
    parser.add_argument("--scale", default="1", metavar="N",
                        help="resolution factor 1 - 4 (default 1): grid, body and viscosity scaled, Re kept")
    parser.add_argument("--tolerance", default=0.01, type=float, metavar="DC",
                        help="an angle has settled when its window means of C_L and C_D drift by less than this "
                             "(default 0.01)")
    parser.add_argument("--out", default="polar.csv", metavar="PATH", help="polar CSV (default: polar.csv)")
    parser.add_argument("--plot", default=None, metavar="PATH.png",
                        help="polar image (default: the CSV's name with .png)")
    parser.add_argument("--cp", default=None, metavar="PATH.csv",
                        help="also write C_p along the surface at every angle (and an image beside it, .png)")
    parser.add_argument("--force", action="store_true", help="replace the outputs if they exist")


def parse_angles(text: str) -> tuple[float, ...]:
    """'-4,0,4' or 'START:STOP:STEP' (STOP included when on the step); UserError otherwise."""
    text = str(text).strip()
    try:
        if ":" in text:
            start, stop, step = (float(v) for v in text.split(":"))
            if step <= 0 or stop < start:
                raise ValueError
            count = int(math.floor((stop - start) / step + 1e-9)) + 1
            if count > MAX_ANGLES:
                raise UserError(f"--angles: {count} angles, at most {MAX_ANGLES}")
            angles = tuple(round(start + k * step, 9) for k in range(count))
        else:
            angles = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise UserError(f"--angles: must be a list like -4,0,4,8 or a range START:STOP:STEP, got {text[:40]!r}") from None
    if not angles or len(angles) > MAX_ANGLES:
        raise UserError(f"--angles: between 1 and {MAX_ANGLES} angles, got {len(angles)}")
    bad = [a for a in angles if not math.isfinite(a) or abs(a) > MAX_ANGLE]
    if bad:
        raise UserError(f"--angles: each angle must lie within +-{MAX_ANGLE:g} degrees, got {bad[0]:g}")
    return angles


#: shape keys that are lengths in cells (scaled with --scale); a NACA thickness is a fraction
_LENGTH_KEYS = {"cylinder": ("diameter",), "plate": ("length", "thickness"), "wedge": ("length",),
                "half_airfoil": ("chord", "thickness"), "naca": ("chord",), "polygon": ()}


def scaled(scene, factor: int):
    """(config, shape) of the scene at `factor` times its resolution, Re and the wind unchanged."""
    from feelflow.shapes import from_dict

    cfg, body = scene.config, scene.body
    if factor == 1:
        return cfg, body
    d = body.to_dict()
    d["x"], d["y"] = d["x"] * factor, d["y"] * factor
    for key in _LENGTH_KEYS.get(d["kind"], ()):
        d[key] = d[key] * factor
    if d["kind"] == "polygon":
        d["vertices"] = [[vx * factor, vy * factor] for vx, vy in d["vertices"]]
    cfg = replace(cfg, nx=cfg.nx * factor, ny=cfg.ny * factor, nu=cfg.nu * factor,
                  sponge_cells=cfg.sponge_cells * factor, inflow_ramp_steps=cfg.inflow_ramp_steps * factor)
    return cfg.validate(), from_dict(d)


def main(args) -> int:
    from feelflow.app.cli.commands.run import positive_int_option
    from feelflow.app.files import check_output, save_csv
    from feelflow.app.headless import make_solver, resolve_backend
    from feelflow.app.model.polar import (PolarSweep, chord_of, lift_slope, max_lift, max_lift_fit,
                                          naca_zero_lift_angle, run_sweep)
    from feelflow.app.model.scene import load_scene
    from feelflow.solver.backend import BACKENDS

    scene = load_scene(args.scene)
    angles = parse_angles(args.angles)
    factor = positive_int_option("--scale", args.scale)
    if factor > MAX_SCALE:
        raise UserError(f"--scale: at most {MAX_SCALE}, got {factor}")
    if not (math.isfinite(args.tolerance) and args.tolerance > 0):
        raise UserError(f"--tolerance: must be a positive number, got {args.tolerance}")
    backend = args.backend if args.backend is not None else scene.backend
    if backend not in BACKENDS and backend != "auto":
        raise UserError(f"--backend: must be one of {', '.join(sorted(BACKENDS))} or auto, got {backend!r}")
    out = Path(args.out)
    plot = Path(args.plot) if args.plot else out.with_suffix(".png")
    outputs = [out, plot] + ([Path(args.cp), Path(args.cp).with_suffix(".png")] if args.cp else [])
    for k, path in enumerate(outputs):
        check_output(path, "--out" if k == 0 else "--plot" if k == 1 else "--cp", inputs=[args.scene],
                     others=[p for p in outputs[:k]], force=args.force)
    try:
        config, shape = scaled(scene, factor)
        for a in angles:   # every angle must fit the domain before the run starts
            shape.moved(angle=-math.radians(a)).validate(config.nx, config.ny)
    except Exception as exc:   # ShapeError, ConfigError: one line
        raise UserError(f"{args.scene}: {str(exc).splitlines()[0]}") from None
    from feelflow.app.inputs import check_memory, check_work

    # the scaled grid: the scene files' node bound and the memory it needs, before the run
    check_work(config.nx, config.ny, 0, f"{args.scene} at --scale {factor}", "grid")
    check_memory(config.nx, config.ny, f"{args.scene} at --scale {factor}", "grid")

    from feelflow.app.cli.commands.run import warn_outside_stable_region

    warn_outside_stable_region(scene, args.scene)
    speed = config.inflow_speed
    chord = chord_of(shape)
    sweep = PolarSweep(angles, speed, chord, sample_steps=max(10, 25 * factor), tolerance=args.tolerance)
    backend = resolve_backend(backend, config)
    solver = make_solver(backend, config)
    solver.enable_force_models(["momentum_exchange"])
    probe = None
    if args.cp:
        from feelflow.solver.forces.surface_pressure import SurfacePressureProbe

        probe = SurfacePressureProbe()
        solver.add_force_model(probe)
    re = speed * chord / config.nu
    print(f"polar of {args.scene} x{factor}: {config.nx} x {config.ny}, chord {chord:g} cells, Re {re:.4g} on the "
          f"chord, {config.collision}, {backend}; settled when the window means (window {sweep.window} samples of "
          f"{sweep.sample_steps} steps) drift by < {args.tolerance:g}", flush=True)
    cps = []

    def report(point, cp):
        flag = "" if point.settled else "  (not settled)"
        print(f"  alpha {point.alpha:6.2f}  C_L {point.cl:8.4f} +- {point.cl_std:.4f}  C_D {point.cd:8.4f}  "
              f"{point.steps} steps{flag}", flush=True)
        if cp is not None:
            cps.append((point.alpha, cp))

    from feelflow.solver import backend as backends
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            run_sweep(solver, shape, sweep, probe=probe, on_point=report)
    except backends.SolverDiverged as exc:
        print(f"feelflow: the flow diverged ({str(exc).splitlines()[0]}); the {len(sweep.points)} angles before "
              f"it are written", file=sys.stderr)
    finally:
        solver.close()

    save_csv(out, sweep.HEADER, sweep.rows(), "--out")
    from feelflow.app.reports.polar_plots import cp_image, polar_image

    alpha0 = naca_zero_lift_angle(shape.camber, shape.camber_position) if shape.kind == "naca" else 0.0
    title = (f"{_name(shape)}, Re {re:.4g} on the chord, {config.nx} x {config.ny} (chord {chord:g} cells), "
             f"{config.collision}")
    polar_image(sweep.points, plot, title, alpha0)
    if args.cp:
        rows = [[f"{a:g}"] + r for a, cp in cps for r in cp.rows()]
        save_csv(args.cp, ["alpha_deg"] + (cps[0][1].header if cps else ["side", "x_over_c", "cp", "x", "y"]),
                 rows, "--cp")
        cp_image([(f"alpha {a:g} deg", cp) for a, cp in cps], Path(args.cp).with_suffix(".png"), f"C_p: {title}")
    slope = lift_slope(sweep.points)
    best = max_lift(sweep.points)
    fitted = max_lift_fit(sweep.points)
    summary = [f"{out}: {len(sweep.points)} angles; image {plot}"]
    if slope is not None:
        summary.append(f"dC_L/dalpha {slope:.3f} per radian for |alpha| <= 4 ({slope / (2 * math.pi):.2f} x 2 pi)")
    if best is not None:
        summary.append(f"max C_L {best[1]:.4f} at {best[0]:g} degrees")
    if fitted is not None:
        summary.append(f"fitted maximum C_L {fitted[1]:.3f} at {fitted[0]:.1f} degrees (parabola within 8 degrees)")
    print("; ".join(summary))
    return 1 if len(sweep.points) < len(angles) else 0


def _name(shape) -> str:
    if shape.kind == "naca":
        return f"NACA {shape.digits}" if shape.digits else "NACA section"
    return shape.kind.replace("_", " ")
