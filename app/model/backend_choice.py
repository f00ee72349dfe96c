"""The right backend on every machine: time the available solver backends briefly on the grid
that will run, use the fastest, and remember the choice per (GL renderer, grid).

Which backend is fastest depends on the machine (a GPU's gl, Mesa's llvmpipe on a few cores,
the compiled cpu backend, numpy), so it is measured, not assumed (docs/science/cpu-backend.md).
Each candidate runs the way the window drives it: the scene's config, the body moved every
`MOVE_EVERY` steps with the momentum-exchange force (a tunnel with a cylinder of ny/8 unless a
`setup` callable places something else), timed after a warm-up (the first step includes JIT
and shader compilation, paid once). A `ChoiceStore` remembers the winner; the window backs it
with QSettings (`get`/`set` on a key), the command line with a small JSON file. A remembered
choice is used as it is: nothing re-times or switches while a lesson runs.
"""
from __future__ import annotations

import os
import re
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

#: what `--backend auto` and the window compare, in order of preference on a tie
CANDIDATES = ("cpu", "gl", "numpy")
#: seconds of timed stepping per backend (after its warm-up)
SECONDS = 0.25
WARMUP_STEPS = 3
MOVE_EVERY = 10


@dataclass
class Timing:
    """One backend's measurement: steps per second on the grid, or why it cannot run here."""

    backend: str
    steps_per_s: float = 0.0
    mlups: float = 0.0
    error: str | None = None

    def describe(self) -> str:
        if self.error is not None:
            return f"{self.backend} unavailable ({self.error})"
        return f"{self.backend} {self.steps_per_s:.0f} steps/s"


@dataclass
class Choice:
    """The backend to use, the timings it came from (empty when remembered) and the store key."""

    backend: str
    key: str
    timings: list[Timing] = field(default_factory=list)
    remembered: bool = False

    def describe(self, nx: int, ny: int) -> str:
        """One line for the status bar or the terminal."""
        if self.remembered:
            return f"backend {self.backend} (remembered for this renderer and {nx} x {ny})"
        ours = next(t for t in self.timings if t.backend == self.backend)
        return (f"backend {self.backend}: {ours.steps_per_s:.0f} steps/s at {nx} x {ny}, the fastest of "
                + ", ".join(t.describe() for t in self.timings))


class JsonFileStore:
    """A ChoiceStore in a small JSON file (the command line's), written atomically; a missing or
    unreadable file is an empty store."""

    def __init__(self, path):
        self.path = Path(path)

    def _read(self) -> dict:
        from feelflow.app.errors import UserError
        from feelflow.app.inputs import exists, load_json

        if not exists(self.path):
            return {}
        try:   # the one bounded reader (app/inputs.py): a pipe or a huge file is an empty store
            data = load_json(self.path, "backend choice file", 1 << 20)
        except UserError:
            return {}
        return data if isinstance(data, dict) else {}

    def get(self, key: str) -> str | None:
        value = self._read().get(key)
        return value if isinstance(value, str) else None

    def set(self, key: str, value: str) -> None:
        from feelflow.app.files import write_json_atomic

        data = self._read()
        data[key] = value
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            write_json_atomic(self.path, data)
        except OSError:
            pass  # not remembered: the next run measures again


def default_store_path() -> Path:
    """$XDG_CACHE_HOME/feelflow/backend-choice.json (~/.cache when unset)."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "feelflow" / "backend-choice.json"


def choice_key(renderer: str, nx: int, ny: int) -> str:
    """The store key of a (GL renderer, grid): 'backend/<renderer>/<nx>x<ny>', the renderer
    reduced to letters, digits and . _ - (QSettings treats '/' as a group separator)."""
    name = re.sub(r"[^A-Za-z0-9._-]+", "_", renderer.strip()) or "none"
    return f"backend/{name}/{nx}x{ny}"


#: the least viscosity a timing trial runs at (U/nu <= 2 for any wind the window allows)
TIMING_NU = 0.05


def _default_setup(solver) -> None:
    """The window's default kind of scene: a cylinder of ny/8 at nx/4, momentum exchange."""
    from feelflow.shapes import Cylinder

    cfg = solver.config
    solver.enable_force_models(["momentum_exchange"])
    solver.set_body(Cylinder(cfg.ny / 8, x=cfg.nx / 4, y=cfg.ny / 2), velocity=(0.0, 0.0))


def time_backend(name: str, config, make_solver, seconds: float = SECONDS, setup=_default_setup) -> Timing:
    """Steps per second of backend `name` on `config` (see the module docstring). make_solver(name,
    config) builds it; any exception it raises is this backend's `error` (one line).
    The trial runs `config`'s grid, operator, precision and boundaries at a viscosity of at least
    TIMING_NU: a step costs the same at any viscosity, and a scene the user runs outside the
    stable region must not diverge in the trial (it would then fail before its own first step)."""
    config = replace(config, nu=max(config.nu, TIMING_NU))
    try:
        solver = make_solver(name, config)
    except Exception as exc:  # noqa: BLE001 - a backend that cannot start is reported, not fatal
        return Timing(name, error=str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
    try:
        if setup is not None:
            setup(solver)
        body = solver.body

        def advance(n):
            solver.step(n)
            if body is not None:  # moved (to where it is) as the window does every frame
                solver.set_body(body.shape, velocity=body.velocity, omega=body.omega)

        advance(WARMUP_STEPS)
        solver.finish()
        steps, t0 = 0, time.perf_counter()
        while True:
            advance(MOVE_EVERY)
            solver.finish()
            steps += MOVE_EVERY
            elapsed = time.perf_counter() - t0
            if elapsed >= seconds:
                break
    finally:
        solver.close()
    rate = steps / elapsed
    return Timing(name, steps_per_s=rate, mlups=rate * config.nx * config.ny / 1e6)


def choose_backend(config, make_solver, store=None, renderer: str = "none", candidates=CANDIDATES,
                   seconds: float = SECONDS, setup=_default_setup, remeasure: bool = False) -> Choice:
    """The fastest of `candidates` on `config`'s grid, remembered in `store` under
    choice_key(renderer, nx, ny); a remembered choice among the candidates is returned without
    measuring unless `remeasure`. Raises RuntimeError when no candidate can run."""
    key = choice_key(renderer, config.nx, config.ny)
    if store is not None and not remeasure:
        known = store.get(key)
        if known in candidates:
            return Choice(known, key, remembered=True)
    timings = [time_backend(name, config, make_solver, seconds, setup) for name in candidates]
    usable = [t for t in timings if t.error is None]
    if not usable:
        raise RuntimeError("no solver backend can run here: " + "; ".join(t.describe() for t in timings))
    best = max(usable, key=lambda t: t.steps_per_s)
    if store is not None:
        store.set(key, best.backend)
    return Choice(best.backend, key, timings)
