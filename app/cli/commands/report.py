"""`feelflow report seed`: reproduce the seed's experiments with all four force models and write
docs/science/seed-report.md with PNG plots (the work is in app/reports/seed.py).
`feelflow report lessons [--only KEY,...] [--compare] [--json PATH]`: run the Presets menu's
lessons headless as the window does and print how steady their forces are (app/lesson_report.py).
`feelflow report scenes [--only NAME,...] [--compare] [--json PATH]`: run the example scenes with an
outlet sponge as `feelflow run` does and print how calm their tunnel is (app/scene_report.py).
`feelflow report ringdown [--only window,d16,...] [--phase-steps N] [--json PATH]`: how long the
tunnel's sound rings in the drag after a body stops, with the old boundaries and the quiet
tunnel's, in one table (app/reports/ringdown.py).
`feelflow report towed [--refill A,B] [--impulse A,B] [--json PATH]`: a cylinder towed through fluid at
rest against the same one held in a stream: mean drag and its noise per step (app/reports/towed.py).

Parts (`--only`): protocol (or one diameter, protocol:d32), shapes, sweep, lift; each stores its
series in OUT/seed-report/data-<part>.json (data-protocol-<d>.json per diameter), and the report
is written from every part stored there, so parts can be run separately (or again, or in
parallel) and `--replot` rebuilds text and plots without running.
"""
from __future__ import annotations

import sys
from pathlib import Path

from feelflow.app.errors import UserError

TARGETS = ("seed", "lessons", "scenes", "ringdown", "towed")


def add_arguments(parser):
    parser.add_argument("target", choices=TARGETS,
                        help="which report (seed: the thesis's experiments; lessons: the Presets menu's lessons; "
                             "scenes: how calm the example scenes' tunnels are; ringdown: how long sound rings in "
                             "the drag after a stop, old and quiet boundaries; towed: a towed body's drag against a held "
                             "one's, and its noise)")
    parser.add_argument("--backend", default="numpy", metavar="numpy|gl",
                        help="solver backend (default: numpy; towed also takes cpu)")
    parser.add_argument("--refill", default=None, metavar="SCHEME[,SCHEME]",
                        help="towed: how uncovered nodes are refilled (equilibrium, nonequilibrium; default: the "
                             "solver's); several run one after the other")
    parser.add_argument("--impulse", default=None, metavar="SCHEME[,SCHEME]",
                        help="towed: how covered/uncovered nodes' momentum enters the force (relative, absolute, "
                             "none; default: the solver's)")
    parser.add_argument("--quick", action="store_true",
                        help="a few dozen steps per run: a smoke test of the whole chain, not physics")
    parser.add_argument("--phase-steps", default=None, metavar="N",
                        help="steps per protocol phase instead of the scenes' 15000 (stated in the report)")
    parser.add_argument("--only", default=None, metavar="PART[,PART]",
                        help="run only these parts: protocol (or protocol:d16, :d24, :d32), shapes, sweep, "
                             "lift (default: all); for lessons, lesson keys (drag_speed, lift, ...); for "
                             "scenes, scene names (default, plate, ...); for ringdown, window, d16, d24, d32")
    parser.add_argument("--compare", action="store_true",
                        help="lessons: also run each one plain (no absorbing layer, wind everywhere from the "
                             "first step, sudden wind changes); scenes: also without the absorbing layer")
    parser.add_argument("--json", default=None, metavar="PATH", help="lessons, scenes: also write the runs as JSON")
    parser.add_argument("--force", action="store_true", help="replace --json if it exists")
    parser.add_argument("--scenes", default="scenes", metavar="DIR", help="folder holding the scenes (default: scenes)")
    parser.add_argument("--scene", default=None, metavar="FILE",
                        help="ringdown: run this scene file as it stands instead (its own boundaries and motion; "
                             "the swing 1000-3000 steps after its last moving phase ends)")
    parser.add_argument("--out", default="docs/science", metavar="DIR",
                        help="folder for seed-report.md and seed-report/ (default: docs/science)")
    parser.add_argument("--replot", action="store_true",
                        help="rebuild text and plots from the stored series without running the flow")


def main(args) -> int:
    from feelflow.app.files import check_output, check_output_folder

    if args.json:   # before any run
        check_output(args.json, "--json", force=args.force)
    if args.target == "lessons":
        return lessons(args)
    if args.target == "scenes":
        return scene_calm(args)
    if args.target == "ringdown":
        return ringdown(args)
    if args.target == "towed":
        return towed(args)
    from feelflow.app.reports.seed import PARTS, PROTOCOL, run_part, save_part, write_report

    out = check_output_folder(args.out, "--out")
    phase_steps = phase_steps_option(args.phase_steps, 1)
    parts = PARTS
    keys = None  # protocol diameters
    if args.only is not None:
        parts = tuple(p.strip() for p in args.only.split(",") if p.strip())
        diameters = tuple(key for key, _ in PROTOCOL)
        keys = tuple(p.split(":", 1)[1] for p in parts if p.startswith("protocol:")) or None
        parts = tuple(dict.fromkeys("protocol" if p.startswith("protocol:") else p for p in parts))
        bad = [p for p in parts if p not in PARTS] + [k for k in keys or () if k not in diameters]
        if bad or not parts:
            raise UserError(f"--only: unknown part {bad[0] if bad else args.only!r}; choose from "
                            f"{', '.join(PARTS)} (protocol:{'|'.join(diameters)} for one diameter)")
    if not args.replot:
        scenes = Path(args.scenes)
        if not scenes.is_dir():
            raise UserError(f"--scenes: {args.scenes!r} is not a folder")
        for part in parts:
            print(f"feelflow report seed: {part} on {args.backend}", file=sys.stderr, flush=True)
            data = run_part(part, scenes, args.backend, args.quick, phase_steps,
                            log=lambda line: print(line, file=sys.stderr, flush=True), keys=keys)
            save_part(out / "seed-report", data)
    path = write_report(out)
    print(f"{path}: written")
    return 0


def lessons(args) -> int:
    from feelflow.app.headless import gl_context
    from feelflow.app.reports.lessons import format_table, run_lesson
    from feelflow.app.model.presets import PRESETS

    keys = _chosen(args.only, list(PRESETS), "lesson")
    if args.backend == "gl":
        gl_context()   # one line on stderr, exit 2, when there is no EGL context
    elif args.backend != "numpy":
        raise UserError(f"--backend: must be numpy or gl, got {args.backend!r}")
    runs = []
    for key in keys:
        for plain in ((False, True) if args.compare else (False,)):
            print(f"feelflow report lessons: {key}{' (plain)' if plain else ''} on {args.backend}",
                  file=sys.stderr, flush=True)
            runs.append(run_lesson(key, args.backend, plain=plain, make_ctx=gl_context))
    return _print_runs(runs, format_table(runs), args.json)


def scene_calm(args) -> int:
    from feelflow.app.reports.scenes import SCENES, format_table, run_scene_calm

    folder = Path(args.scenes)
    names = _chosen(args.only, list(SCENES), "scene")
    missing = [n for n in names if not (folder / f"{n}.toml").is_file()]
    if missing:
        raise UserError(f"--scenes: {str(folder / (missing[0] + '.toml'))!r} not found")
    runs = []
    for name in names:
        for without in ((False, True) if args.compare else (False,)):
            print(f"feelflow report scenes: {name}{' (without the absorbing layer)' if without else ''} "
                  f"on {args.backend}", file=sys.stderr, flush=True)
            runs.append(run_scene_calm(folder / f"{name}.toml", args.backend, without_layer=without,
                                       steps=40 if args.quick else None))
    return _print_runs(runs, format_table(runs), args.json)


def ringdown(args) -> int:
    from feelflow.app.headless import gl_context
    from feelflow.app.reports.ringdown import (AFTER_WINDOW, QUICK_PHASE_STEPS, SEED_DIAMETERS, format_table,
                                                run_seed, run_window)

    if args.backend == "gl":
        gl_context()   # one line on stderr, exit 2, when there is no EGL context
    elif args.backend != "numpy":
        raise UserError(f"--backend: must be numpy or gl, got {args.backend!r}")
    if args.scene is not None:
        from feelflow.app.reports.ringdown import load_moving_scene, run_scene

        load_moving_scene(args.scene)   # one line, exit 2, before any run
        print(f"feelflow report ringdown: {args.scene} on {args.backend}", file=sys.stderr, flush=True)
        runs = [run_scene(args.scene, args.backend, (100, 300) if args.quick else AFTER_WINDOW)]
        return _print_runs(runs, format_table(runs), args.json)
    phase_steps = phase_steps_option(args.phase_steps, 1000)
    folder = Path(args.scenes)
    cases = _chosen(args.only, ["window", *SEED_DIAMETERS], "case")
    runs = []
    for case in cases:
        for before in (True, False):
            print(f"feelflow report ringdown: {case} ({'before' if before else 'after'}) on {args.backend}",
                  file=sys.stderr, flush=True)
            if case == "window":
                runs.append(run_window(args.backend, before, quick=args.quick))
            else:
                if not (folder / f"seed_protocol_{case}.toml").is_file():
                    raise UserError(f"--scenes: {str(folder / f'seed_protocol_{case}.toml')!r} not found")
                runs.append(run_seed(case, args.backend, before, folder,
                                     QUICK_PHASE_STEPS if args.quick else phase_steps))
    return _print_runs(runs, format_table(runs), args.json)


def towed(args) -> int:
    from feelflow.app.headless import gl_context
    from feelflow.app.reports.towed import format_table, run
    from feelflow.solver.body import IMPULSE_SCHEMES, REFILL_SCHEMES

    if args.backend == "gl":
        gl_context()   # one line on stderr, exit 2, when there is no EGL context
    elif args.backend not in ("numpy", "cpu"):
        raise UserError(f"--backend: must be numpy, cpu or gl, got {args.backend!r}")
    refills = [None] if args.refill is None else _chosen(args.refill, list(REFILL_SCHEMES), "scheme", "--refill")
    impulses = [None] if args.impulse is None else _chosen(args.impulse, list(IMPULSE_SCHEMES), "scheme", "--impulse")
    print(f"feelflow report towed: held on {args.backend}", file=sys.stderr, flush=True)
    runs = [run(args.backend, False, quick=args.quick)]
    for refill in refills:
        for impulse in impulses:
            print(f"feelflow report towed: towed (refill {refill or 'default'}, impulse {impulse or 'default'}) "
                  f"on {args.backend}", file=sys.stderr, flush=True)
            runs.append(run(args.backend, True, quick=args.quick, refill=refill, impulse=impulse))
    return _print_runs(runs, format_table(runs), args.json)


def _chosen(only: str | None, choices: list[str], what: str, option: str = "--only") -> list[str]:
    """The names given to --only (comma-separated), all of `choices` without it; UserError names
    the first unknown one."""
    if only is None:
        return choices
    names = [k.strip() for k in only.split(",") if k.strip()]
    bad = [k for k in names if k not in choices]
    if bad or not names:
        raise UserError(f"{option}: unknown {what} {bad[0] if bad else only!r}; choose from {', '.join(choices)}")
    return names


def _print_runs(runs: list[dict], table: str, json_path: str | None) -> int:
    """Print the report's table; with --json also write the runs and the machine (atomically)."""
    import json

    from feelflow.app.bench.solver_speed import machine
    from feelflow.app.files import save_text

    print(table)
    if json_path:
        save_text(json_path, json.dumps({"machine": machine(), "runs": runs}, indent=1) + "\n", "--json")
    return 0


def phase_steps_option(text, minimum: int) -> int | None:
    """--phase-steps as an integer of at least `minimum` (None when not given); UserError otherwise."""
    if text is None:
        return None
    try:
        steps = int(text)
    except ValueError:
        steps = minimum - 1
    if steps < minimum:
        what = "a positive integer" if minimum == 1 else f"an integer >= {minimum}"
        raise UserError(f"--phase-steps: must be {what}, got {text!r}")
    return steps
