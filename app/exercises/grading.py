"""Grading a class: score many shape files on every core, one row per file, ranked.

A file that is not a valid shape file, or a shape that breaks a constraint, gets its row with
the reason; it never stops the grading. Scores come from `scoring.score_shape` (float64 on numpy,
the reference, or on the compiled cpu backend, which gives the same digits; `resolve_backend`
picks the faster for `--backend auto`), the same function the window calls, so a shape scores
the same digits here and there.
"""
from __future__ import annotations

import os
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from feelflow.app.errors import UserError, shown, shown_path
from feelflow.app.exercises import scoring

#: row status besides scoring's SCORED / NOT_SETTLED
BREAKS = "breaks a constraint"
INVALID = "not a shape file"
CSV_HEADER = ["rank", "file", "status", "score", "verdict", "cd", "cl", "steps", "seconds", "reason", "tied",
              "grid_uncertainty"]


@dataclass
class Row:
    file: str
    status: str
    score: float | None = None
    verdict: str = "ok"
    cd: float | None = None
    cl: float | None = None
    steps: int = 0
    seconds: float = 0.0
    reason: str = ""
    scale: int = 1
    averaging: str = ""
    cpu_seconds: float = 0.0

    @property
    def ok(self) -> bool:
        return self.status == scoring.SCORED


#: most shape files one grading may score (a class folder of 30 is usual)
MAX_FILES = 10_000


def shape_files(paths) -> list[Path]:
    """The shape files named: files as given, folders' *.json entries (sorted; one that is not a
    regular file gets its row saying so); UserError (one line) for a path that does not exist,
    more than MAX_FILES files, or when nothing is left."""
    import os

    from feelflow.app.inputs import is_folder

    out = []
    for p in map(Path, paths):
        if is_folder(p):
            try:
                with os.scandir(p) as it:
                    names = []
                    for entry in it:
                        if entry.name.lower().endswith(".json"):
                            names.append(entry.name)
                            if len(names) > MAX_FILES:
                                break
            except OSError as exc:
                raise UserError(f"{shown_path(p)}: cannot list the folder ({exc.strerror or exc})") from None
            out += [p / name for name in sorted(names)]
        elif os.path.lexists(p):   # a link that cannot be followed gets its row saying why
            out.append(p)
        else:
            raise UserError(f"{shown_path(p)}: no such shape file or folder")
        if len(out) > MAX_FILES:
            raise UserError(f"{shown_path(p)}: more than {MAX_FILES} shape files to score")
    if not out:
        raise UserError("no shape files (*.json) among " + shown(", ".join(map(str, paths)), 200))
    return out


@lru_cache(maxsize=8)
def _exercise(path: str):
    from feelflow.app.exercises.format import load_exercise

    return load_exercise(path)


def score_file(exercise, path, scale: int = 1, backend: str = "numpy") -> Row:
    """One shape file's row (never raises for a bad shape file or a broken constraint)."""
    from feelflow.app.exercises.constraints import check_shape
    from feelflow.shapes.base import ShapeError
    from feelflow.app.shape_files import load_shape

    name = str(path)
    try:
        shape = load_shape(path)
    except ShapeError as exc:
        text, shown_name = str(exc).splitlines()[0], shown_path(path)
        reason = text[len(shown_name) + 2:] if text.startswith(shown_name + ": ") else text
        return Row(name, INVALID, verdict="-", reason=reason,
                   scale=scale)
    problems = check_shape(exercise, shape)
    if problems:
        return Row(name, BREAKS, verdict="; ".join(problems), reason=problems[0], scale=scale)
    r = scoring.score_shape(exercise, shape, scale, backend=backend)
    return Row(name, r.status, r.score, "ok", r.cd, r.cl, r.steps, r.seconds, r.reason, scale, r.averaging, r.cpu_seconds)


def _worker(job) -> Row:
    exercise_path, path, scale, backend = job
    return score_file(_exercise(exercise_path), path, scale, backend)


def _share_cores(threads: int) -> None:
    """A grading process's initializer: the compiled cpu backend's threads it may use (the
    processes share the cores: more threads than cores wait on each other at every step)."""
    import numba

    numba.set_num_threads(max(1, min(threads, numba.config.NUMBA_NUM_THREADS)))


def _warm_up(exercise_path: str, path: str, scale: int) -> None:
    """One step of a cpu-backend scoring run of `path` (without a body if it is not a valid shape
    file): compiles, or loads from numba's disk cache, what the grading processes then load."""
    from feelflow.app.exercises.constraints import posed
    from feelflow.app.shape_files import load_shape
    from feelflow.shapes.base import ShapeError
    from feelflow.solver.backend import create_solver

    exercise = _exercise(exercise_path)
    try:
        body = posed(exercise, load_shape(path), scale)
    except (ShapeError, UserError):
        body = None
    solver = create_solver("cpu", exercise.scene.scaled(scale).flow_config())
    try:
        solver.enable_force_models([scoring.FORCE_MODEL])
        if body is not None:
            solver.set_body(body)
        solver.step(1)
    finally:
        solver.close()


def default_workers() -> int:
    return os.cpu_count() or 1


#: `--backend auto` (the command line's default): the faster of scoring.BACKENDS on this machine
AUTO = "auto"
#: the choice store's "renderer" part for scoring (float64 on the CPU: no GL renderer decides it)
CHOICE_KEY = "float64 scoring"


def _timed_choice(config, store_path: str, body=None) -> tuple[str, str]:
    """choose_backend on `config`, with `body` (a posed shape) placed as the scoring run places
    it, so that the trial also compiles what scoring it needs (the body's raster of its kind)
    once, before the graders start; None: the default trial's cylinder."""
    from feelflow.app.model.backend_choice import JsonFileStore, choose_backend
    from feelflow.solver.backend import create_solver

    def setup(solver):
        solver.enable_force_models([scoring.FORCE_MODEL])
        solver.set_body(body)

    kwargs = {} if body is None else {"setup": setup}
    choice = choose_backend(config, lambda name, cfg: create_solver(name, cfg), JsonFileStore(store_path),
                            renderer=CHOICE_KEY, candidates=scoring.BACKENDS, **kwargs)
    return choice.backend, choice.describe(config.nx, config.ny)


def _trial_body(exercise, scale: int):
    """The exercise's first reference shape, posed as scoring poses it, or None."""
    from feelflow.app.exercises.constraints import posed
    from feelflow.app.shape_files import load_shape
    from feelflow.shapes.base import ShapeError

    if not exercise.references:
        return None
    try:
        return posed(exercise, load_shape(exercise.references[0].path), scale)
    except (ShapeError, UserError):
        return None


def resolve_backend(backend: str, exercise, scale: int = 1, store_path=None,
                    mp_context=None) -> tuple[str, str | None]:
    """`backend` as given, or for AUTO the faster of scoring.BACKENDS (both float64, the same
    scores: docs/science/cpu-backend.md) on the exercise's grid at `scale`, timed briefly once
    and remembered per grid (app/model/backend_choice.py, in the user's cache like `feelflow run
    --backend auto`); returns (backend, the line saying why, or None). The command line and the
    window's Score it both choose here. The timing runs in a child process: numba's OpenMP
    threads, once started, would make the forked graders abort. `mp_context`: how that child
    starts (multiprocessing's default, a fork, unless given; the window, whose process may
    already run numba's threads, passes a spawn context)."""
    if backend != AUTO:
        return backend, None
    from feelflow.app.model.backend_choice import JsonFileStore, choice_key, default_store_path

    config = exercise.scene.scaled(scale).flow_config()
    path = str(store_path if store_path is not None else default_store_path())
    known = JsonFileStore(path).get(choice_key(CHOICE_KEY, config.nx, config.ny))
    if known in scoring.BACKENDS:
        return known, f"scoring backend {known} (remembered for {config.nx} x {config.ny})"
    try:
        with ProcessPoolExecutor(max_workers=1, mp_context=mp_context) as pool:
            name, line = pool.submit(_timed_choice, config, path, _trial_body(exercise, scale)).result()
    except RuntimeError as exc:   # neither can run (choose_backend says why)
        raise UserError(f"--backend auto: {exc}") from None
    return name, f"scoring {line}"


def grade(exercise, paths, workers: int | None = None, scales=(1,), progress=None,
          backend: str = "numpy") -> tuple[list[Row], float]:
    """Score every (file, scale) on `workers` processes (default: every core) with the solver
    `backend` (float64; scoring.BACKENDS). Returns the rows in the order of `paths` x `scales`
    and the wall seconds. `progress(done, total)` after each."""
    if exercise.path is None:
        raise ValueError("grading needs an exercise loaded from a file")
    jobs = [(str(exercise.path), str(p), s, backend) for p in paths for s in scales]
    workers = max(1, min(workers or default_workers(), len(jobs)))
    start = time.perf_counter()
    rows: list[Row | None] = [None] * len(jobs)
    if workers == 1:
        for i, job in enumerate(jobs):
            rows[i] = _worker(job)
            if progress:
                progress(i + 1, len(jobs))
    else:
        initializer, initargs = None, ()
        if backend == "cpu":
            initializer, initargs = _share_cores, (max(1, default_workers() // workers),)
            # the kernels compile once here, in a process of its own, not in every grading
            # process at once (a first run, or the first after an update of the kernels)
            with ProcessPoolExecutor(max_workers=1) as warm:
                try:
                    warm.submit(_warm_up, *jobs[0][:3]).result()
                except Exception:  # noqa: BLE001 - the graders' own runs report what is wrong
                    pass
        with ProcessPoolExecutor(max_workers=workers, initializer=initializer, initargs=initargs) as pool:
            futures = {pool.submit(_worker, job): i for i, job in enumerate(jobs)}
            for n, fut in enumerate(as_completed(futures), 1):
                rows[futures[fut]] = fut.result()
                if progress:
                    progress(n, len(jobs))
    return rows, time.perf_counter() - start


def ranked(exercise, rows: list[Row]) -> list[Row]:
    """Best first (by score, in the objective's direction); not settled, broken and invalid last;
    ties by file name."""
    order = {scoring.SCORED: 0, scoring.NOT_SETTLED: 1, BREAKS: 2, INVALID: 3}

    def key(r: Row):
        if r.ok:
            return (0, r.score if exercise.objective.better == "lower" else -r.score, r.file)
        return (order.get(r.status, 4), 0.0, r.file)
    return sorted(rows, key=key)


def ranks(exercise, rows: list[Row]) -> list[int | None]:
    """Each row's rank (None when not scored), ties within the exercise's grid uncertainty
    sharing one (app/exercises/uncertainty.py)."""
    from feelflow.app.exercises.uncertainty import tied_ranks

    scored = [r.score for r in rows if r.ok]
    tied = iter(tied_ranks(scored, exercise.objective.better, exercise.objective.uncertainty))
    return [next(tied) if r.ok else None for r in rows]


def csv_rows(rows: list[Row], exercise=None) -> list[list]:
    """CSV cells for ranked rows; numbers with repr() digits (every digit, so reruns compare
    exactly; the printed table has the digits the grid uncertainty supports). With the
    exercise, ranks are shared by ties (the `tied` column says "yes") and the exercise's grid
    uncertainty is in every scored row."""
    if exercise is not None:
        rank = ranks(exercise, rows)
        u = exercise.objective.uncertainty
    else:
        n = iter(range(1, len(rows) + 1))
        rank = [next(n) if r.ok else None for r in rows]
        u = None
    out = []
    for k, r in zip(rank, rows):
        tied = "yes" if k is not None and rank.count(k) > 1 else ""
        out.append([k if k is not None else "", r.file, r.status, "" if r.score is None else repr(r.score),
                    r.verdict, "" if r.cd is None else repr(r.cd), "" if r.cl is None else repr(r.cl), r.steps,
                    f"{r.seconds:.2f}", r.reason, tied, "" if u is None or not r.ok else repr(u)])
    return out
