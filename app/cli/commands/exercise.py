"""`feelflow exercise score|check|list`: grade a class's shapes, validate an exercise file.

`score EXERCISE.toml SHAPES...` scores shape files (or folders of them) on every core with a
progress bar on stderr, writes one CSV row per file (app/files.py atomic write) and prints a
ranked table (scores to the digits the exercise's grid uncertainty supports, ties within it
sharing a rank), the wall time and the time per shape. `check EXERCISE.toml` validates the file
and scores its reference solutions (exit 1 when one misses its recorded score); `--convergence`
also scores the [check] shapes, all at the exercise's resolution and at twice it, prints the
measured grid uncertainty (the largest change) and exits 1 unless the ranking is the same (ties
within the declared uncertainty allowed) and the declared uncertainty covers the measured one
(docs/guide/exercises.md quotes its tables).
Format: docs/reference/exercise-format.md. Bad input is one line on stderr and exit 2.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

from feelflow.app.errors import UserError

#: a reference's score must equal the recorded one to its four printed decimals
SCORE_DIGITS = 4


def add_arguments(parser):
    sub = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    p = sub.add_parser("score", help="score shape files (or folders of them) and rank them")
    p.add_argument("exercise", metavar="EXERCISE.toml")
    p.add_argument("shapes", metavar="SHAPES", nargs="+", help="shape JSON files or folders of them")
    p.add_argument("--out", default="scores.csv", metavar="PATH",
                   help="CSV file to write (default: scores.csv); an existing file is refused before "
                        "scoring starts unless --force is given")
    p.add_argument("--force", action="store_true",
                   help="replace --out if it exists (never the exercise file or a shape being scored)")
    p.add_argument("--workers", default=None, metavar="N", help="processes (default: every core)")
    p.add_argument("--scale", default=None, metavar="N",
                   help="score at N times the exercise's resolution (1..8; default 1; 2 to confirm a close "
                        "ranking); refused before scoring when the grid, the steps or the memory it "
                        "needs are beyond the bounds")
    p.add_argument("--backend", choices=("auto", "numpy", "cpu"), default="auto",
                   help="float64 solver for the runs: auto (default: the faster of the two here, timed once "
                        "and remembered), numpy (the reference) or the compiled cpu backend (the same "
                        "scores in about a quarter of the time: docs/science/cpu-backend.md)")
    p = sub.add_parser("check", help="validate an exercise file and score its reference solutions")
    p.add_argument("exercise", metavar="EXERCISE.toml")
    p.add_argument("--convergence", action="store_true",
                   help="also score the [check] shapes; everything at 1x and 2x the resolution; "
                        "exit 1 unless the ranking is the same")
    p.add_argument("--markdown", action="store_true", help="--convergence: print the table as Markdown")
    p.add_argument("--backend", choices=("auto", "numpy", "cpu"), default="auto",
                   help="float64 solver for the runs: auto (default: the faster here, as for 'score'), "
                        "numpy (the reference) or the compiled cpu backend (the "
                        "same scores, less time)")
    p.add_argument("--workers", default=None, metavar="N", help="processes (default: every core)")
    sub.add_parser("list", help="list the shipped exercises")


def _positive(name, text):
    from feelflow.app.cli.commands.run import positive_int_option

    return positive_int_option(name, text)


#: largest --scale (a scaled run must also fit the grid, steps and memory bounds: app/inputs.py)
MAX_SCALE = 8
#: most --workers processes
MAX_WORKERS = 256


def _workers(text):
    if text is None:
        return None
    n = _positive("--workers", text)
    if n > MAX_WORKERS:
        raise UserError(f"--workers: at most {MAX_WORKERS}, got {n}")
    return n


def _scale(text) -> int:
    if text is None:
        return 1
    n = _positive("--scale", text)
    if n > MAX_SCALE:
        raise UserError(f"--scale: must be in 1..{MAX_SCALE}, got {n}")
    return n


def _fit(exercise, scales, workers: int, jobs: int, option: str) -> int:
    """Check the work and memory of scoring at `scales` before any run (grid, steps and memory
    bounds of app/inputs.py); returns the processes that fit in memory (at most `workers`)."""
    from feelflow.app.inputs import available_memory, check_memory, check_work, run_bytes
    from feelflow.solver.config import ConfigError

    for scale in scales:
        s = exercise.scene.scaled(scale)
        where = f"{option} {scale}" if option else exercise.source
        check_work(s.nx, s.ny, s.steps, where, "scene.steps at this scale")
        check_memory(s.nx, s.ny, where, "the scaled grid")
        try:
            s.flow_config()
        except ConfigError as exc:
            raise UserError(f"{where}: the scaled scene: {exc}") from None
    need = max(run_bytes(exercise.scene.scaled(sc).nx, exercise.scene.scaled(sc).ny) for sc in scales)
    limit = available_memory()
    processes = max(1, min(workers, jobs))
    if limit is not None and need * processes > limit:
        fitting = max(1, int(limit // need))
        print(f"memory: each run needs about {need / 2 ** 30:.2f} GiB and {limit / 2 ** 30:.2f} GiB "
              f"can be used: {fitting} processes instead of {processes}", file=sys.stderr)
        return fitting
    return workers


class ProgressBar:
    """`[#####.....] done/total` on stderr, redrawn in place."""

    def __init__(self, what: str, width: int = 30):
        self.what, self.width, self.start = what, width, time.perf_counter()

    def __call__(self, done: int, total: int):
        filled = int(self.width * done / total)
        elapsed = time.perf_counter() - self.start
        sys.stderr.write(f"\r[{'#' * filled}{'.' * (self.width - filled)}] {done}/{total} {self.what}, "
                         f"{elapsed:.0f} s")
        if done == total:
            sys.stderr.write("\n")
        sys.stderr.flush()


def _fmt(v, digits=SCORE_DIGITS):
    return "-" if v is None else f"{v:.{digits}f}"


def _machine_line() -> str:
    import os

    from feelflow.app.bench.solver_speed import machine

    m = machine()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return f"machine: {m['cpu']}, {m['cores']} cores, load average {load:.2f} at the start"


def main(args) -> int:
    if args.action == "list":
        return _list()
    from feelflow.app.exercises.format import load_exercise

    exercise = load_exercise(args.exercise)
    if args.action == "score":
        return _score(exercise, args)
    return _check(exercise, args)


def _list() -> int:
    from feelflow import EXERCISE_DIR
    from feelflow.app.exercises.format import load_exercise

    for p in sorted(EXERCISE_DIR.glob("*.toml")):
        ex = load_exercise(p)
        print(f"{p.name:22s} {ex.title} ({ex.objective.kind}; {p})")
    return 0


def _uncertainty_line(exercise) -> str:
    u = exercise.objective.uncertainty
    if u is None:
        return ("grid uncertainty: not stated in the exercise file (feelflow exercise check --convergence "
                "measures it); scores with four decimals, no ties")
    return (f"grid uncertainty of a score: {u:g} (the exercise's [objective] grid_uncertainty, from "
            f"feelflow exercise check --convergence); scores closer than that are ties and share a rank (=)")


def _rank_labels(ranks) -> list[str]:
    from feelflow.app.exercises.uncertainty import rank_labels

    shown = rank_labels([k for k in ranks if k is not None])
    it = iter(shown)
    return [next(it) if k is not None else "-" for k in ranks]


def _backend(exercise, asked: str, scale: int = 1) -> str:
    """The solver the runs use: `asked`, or for auto the faster float64 one here (one line says
    which and why: app/exercises/grading.py `resolve_backend`)."""
    from feelflow.app.exercises import grading

    backend, line = grading.resolve_backend(asked, exercise, scale)
    if line is not None:
        print(f"feelflow: {line}", flush=True)
    return backend


def _score(exercise, args) -> int:
    from feelflow.app.exercises import grading
    from feelflow.app.exercises.uncertainty import fmt
    from feelflow.app.files import check_output, save_csv

    files = grading.shape_files(args.shapes)
    # the output is checked before any scoring: never an input, never a device, never an
    # existing file without --force (app/files.py)
    out = check_output(args.out, "--out", inputs=[exercise.path, *exercise.input_files(), *files],
                       force=args.force)
    workers = _workers(args.workers) or grading.default_workers()
    scale = _scale(args.scale)
    workers = _fit(exercise, (scale,), workers, len(files), "--scale" if args.scale is not None else "")
    s = exercise.scene.scaled(scale)
    print(_machine_line())
    backend = _backend(exercise, args.backend, scale)
    print(f"{exercise.title}: scoring {len(files)} shape files on {min(workers, len(files))} processes "
          f"({backend} float64, {s.nx} x {s.ny}, {s.steps} steps each)", flush=True)
    rows, wall = grading.grade(exercise, files, workers, scales=(scale,), progress=ProgressBar("shapes"),
                               backend=backend)
    rows = grading.ranked(exercise, rows)
    save_csv(out, grading.CSV_HEADER, grading.csv_rows(rows, exercise), "--out")
    o = exercise.objective
    print(f"\nobjective: {o.kind} (score = {o.quantity}, {o.better} is better"
          + (f"; hit within {o.tolerance:g} of {o.target:g}" if o.target is not None else "") + ")")
    u = o.uncertainty
    print(_uncertainty_line(exercise))
    labels = _rank_labels(grading.ranks(exercise, rows))
    print(f"{'rank':>4s}  {'score':>9s}  {'C_D':>7s}  {'C_L':>8s}  {'s':>6s}  file / verdict")
    for label, r in zip(labels, rows):
        verdict = "" if r.ok else f"  [{r.status}: {r.reason}]"
        print(f"{label:>4s}  {fmt(r.score, u):>9s}  {_fmt(r.cd, 3):>7s}  {_fmt(r.cl, 4):>8s}  "
              f"{r.seconds:6.1f}  {r.file}{verdict}")
    run_s = [r.seconds for r in rows if r.steps]
    per = f"; each scored shape's run took {sum(run_s) / len(run_s):.1f} s on average" if run_s else ""
    print(f"\n{out}: {len(rows)} rows. Wall time {wall:.1f} s for {len(files)} shapes on "
          f"{min(workers, len(files))} processes: {wall / len(files):.2f} s per shape{per}.")
    return 0


def _check(exercise, args) -> int:
    from feelflow.app.exercises import grading

    workers = _workers(args.workers) or grading.default_workers()
    scales = (1, 2) if args.convergence else (1,)
    workers = _fit(exercise, scales, workers, len(exercise.references) + len(exercise.check_shapes),
                   "--convergence at scale" if args.convergence else "")
    print(_machine_line())
    backend = _backend(exercise, args.backend)
    s = exercise.scene
    print(f"{exercise.source}: valid. {exercise.title}: {s.nx} x {s.ny}, Re {s.reynolds:g}, "
          f"U {s.inflow_speed:g}, L {s.reference_length:g} cells, {s.steps} steps; objective "
          f"{exercise.objective.kind}; {backend} float64", flush=True)
    print(_uncertainty_line(exercise))
    refs = [r.path for r in exercise.references]
    paths = refs + (list(exercise.check_shapes) if args.convergence else [])
    rows, wall = grading.grade(exercise, paths, workers, scales, progress=ProgressBar("runs"), backend=backend)
    by = {(r.file, r.scale): r for r in rows}
    failed = False
    for ref in exercise.references:
        r = by[(str(ref.path), 1)]
        if not r.ok:
            print(f"reference {ref.label}: {r.status}: {r.reason}")
            failed = True
            continue
        match = round(r.score, SCORE_DIGITS) == round(ref.score, SCORE_DIGITS)
        failed |= not match
        print(f"reference {ref.label}: score {r.score:.{SCORE_DIGITS}f} (recorded {ref.score:.{SCORE_DIGITS}f}"
              f"{'' if match else ', DIFFERS'}), C_D {r.cd:.4f}, C_L {r.cl:.4f}, {r.steps} steps, "
              f"{r.seconds:.1f} s wall, {r.cpu_seconds:.1f} s CPU ({r.averaging})")
    if args.convergence:
        failed |= _convergence(exercise, paths, by, bool(args.markdown))
    print(f"wall time {wall:.1f} s for {len(rows)} runs on {min(workers, len(rows))} processes")
    return 1 if failed else 0


def _convergence(exercise, paths, by, markdown: bool) -> bool:
    """Print both resolutions' scores, ranks (ties within the declared grid uncertainty share
    one) and differences, the measured uncertainty; True when the rankings differ beyond the
    declared ties or the declared uncertainty is smaller than the measured one."""
    from feelflow.app.exercises import grading
    from feelflow.app.exercises.uncertainty import declared, largest_change, order_changes

    o = exercise.objective
    u = o.uncertainty
    ranks, scores = {}, {}
    for scale in (1, 2):
        rows = grading.ranked(exercise, [by[(str(p), scale)] for p in paths])
        labels = _rank_labels(grading.ranks(exercise, rows))
        ranks[scale] = {r.file: label for r, label in zip(rows, labels) if r.ok}
        scores[scale] = {r.file: r.score for r in rows if r.ok}
    s = exercise.scene
    head = ["shape", f"score {s.nx}x{s.ny}", "rank", f"score {2 * s.nx}x{2 * s.ny}", "rank", "difference",
            "s (1x)", "s (2x)"]
    order = [r.file for r in grading.ranked(exercise, [by[(str(p), 1)] for p in paths])]
    lines = []
    for f in order:
        a, b = by[(f, 1)], by[(f, 2)]
        diff = (f"{b.score - a.score:+.4f} ({(b.score - a.score) / abs(a.score):+.1%})"
                if a.ok and b.ok and a.score else "-")
        lines.append([Path(f).name, _fmt(a.score) if a.ok else a.status, ranks[1].get(f, "-"),
                      _fmt(b.score) if b.ok else b.status, ranks[2].get(f, "-"), diff,
                      f"{a.seconds:.1f}", f"{b.seconds:.1f}"])
    if markdown:
        print("| " + " | ".join(head) + " |")
        print("|" + " --- |" * len(head))
        for row in lines:
            print("| " + " | ".join(row) + " |")
    else:
        print("  ".join(f"{h:>14s}" if i else f"{h:36s}" for i, h in enumerate(head)))
        for row in lines:
            print("  ".join(f"{c:>14s}" if i else f"{c:36s}" for i, c in enumerate(row)))
    measured = largest_change(scores[1], scores[2])
    failed = False
    if u is None:
        print(f"grid uncertainty: the largest change is {measured:.4f}; state it in the exercise file as "
              f"[objective] grid_uncertainty = {declared(measured):g}")
    else:
        covers = measured <= u
        failed |= not covers
        print(f"grid uncertainty: the largest change is {measured:.4f}, "
              + (f"within the declared {u:g}" if covers else
                 f"MORE than the declared {u:g} (declare {declared(measured):g})"))
    swapped = order_changes(scores[1], scores[2], o.better, u)
    unscored = [f for f in order if f not in scores[1] or f not in scores[2]]
    for a, b in swapped:
        print(f"  order changes: {Path(a).name} ahead of {Path(b).name} by more than the uncertainty on one grid, "
              f"behind it on the other")
    same = not swapped and not unscored
    ties = "" if u is None else f" (ties within {u:g} allowed)"
    print(f"ranking at {s.nx}x{s.ny} and {2 * s.nx}x{2 * s.ny}{ties}: {'the same' if same else 'DIFFERENT'}")
    return failed or not same
