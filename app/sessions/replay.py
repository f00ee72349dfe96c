"""Replaying a session a bounded number of solver steps at a time, so that a window can draw
between two calls (`feelflow session replay` runs the same player to the end in one go).

`SessionPlayer` feeds the events of a `Session` in recorded order (`seq`) through the same
`SessionSolver` that recorded them (driver.py), so on the recording backend and machine
the force series comes out bit for bit (docs/reference/session-format.md, "Replay and playback"). A force row
is one `step(n)` call: by default the player never splits it, so one `advance` may run past its
budget by at most the steps of one row; with `split_rows=True` (the window's replay) it runs a
row longer than the whole budget in parts that fit it (`SessionSolver.step_part`: the same
flow, the row's forces equal up to rounding), so a session recorded with long rows (`feelflow
run --record`, a row per output interval) replays as smoothly as one recorded in the window.

Qt-free: used by `replay` (below, for `feelflow session replay`), the window's replay
(app/model/replay_simulation.py) and tests.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from feelflow.app.sessions.driver import SessionSolver, carry_flow
from feelflow.app.sessions.format import Session, SessionError, config_from_dict, shape_from_dict
from feelflow.app.sessions.recorder import SessionRecorder
from feelflow.solver.backend import BackendError, SolverDiverged, create_solver


class ReplayedRow(NamedTuple):
    """One replayed `step(n)` call: the session step at its end, the steps it covered, the body
    (x, y, vx, vy) during it (NaN: no body), {model: (fx, fy)} (mean over the call; NaN where the
    flow diverged), the inflow speed in use and {model: torque} (mean over the call)."""

    step: int
    n: int
    body: tuple
    forces: dict
    inflow_speed: float
    torques: dict



def check_replay_memory(session: Session, source) -> None:
    """SessionError (one line naming the need and the limit) before a replay when the largest
    grid the session uses (its scene or a recorded rebuild) needs more memory than can be used
    here (app/inputs.py's estimate)."""
    from feelflow.app.errors import UserError
    from feelflow.app.inputs import check_memory

    grids = [(session.config.nx, session.config.ny)] + [
        (p["value"]["config"]["nx"], p["value"]["config"]["ny"]) for p in session.parameters
        if p.get("name") == "rebuild"]
    nx, ny = max(grids, key=lambda g: g[0] * g[1])
    try:
        check_memory(nx, ny, str(source), "the largest grid it uses")
    except UserError as exc:
        raise SessionError(str(exc)) from None


class SessionPlayer:
    """An incremental replay of `session` on `backend` (default: the recorded one).

    `advance(max_steps)` applies events until about `max_steps` solver steps are simulated;
    `solver` is the flow to draw, `shape` the body as placed now, `rows` the force rows replayed
    so far. A file that asks for something impossible raises `SessionError` (one line naming the
    event). Close it (or use it as a context manager) to free the backend."""

    def __init__(self, session: Session, backend: str | None = None, *, factory=None, ctx=None):
        self.session = session
        self.backend = backend or session.backend
        if factory is None:
            factory = lambda config: create_solver(self.backend, config, ctx=ctx)  # noqa: E731
        start = session.start
        placed = session.body if start is not None and start["body_placed"] else None
        try:
            if start is None:
                solver = factory(session.config)
            else:  # the flow as it was when recording began, then its placement as it was
                solver = carry_flow(factory, session.config, session.state, start["time"], placed,
                                    session.inlet_reference)
        except (ValueError, BackendError) as exc:  # ShapeError, ConfigError, or not on this backend
            raise SessionError(f"{session.source}: the recorded scene cannot be built: "
                               f"{str(exc).splitlines()[0]}") from None
        self.recorder = SessionRecorder(session.config, session.body, session.force_models, backend=self.backend,
                                        scene_toml=session.manifest["scene"].get("toml"),
                                        scene_source=session.manifest["scene"].get("source"))
        self._driver = SessionSolver(solver, self.recorder, factory=factory)
        if start is not None:
            d = self._driver
            self.recorder.start, self.recorder.state = start, session.state
            self.recorder.inlet_reference = session.inlet_reference
            d.models, d.inflow_speed = tuple(start["force_models"]), start["inflow_speed"]
            d.shape, d.velocity, d.omega = placed, tuple(start["velocity"]), start["omega"]
            d.adopt(solver)
        self.geometry = session.body   # the geometry the next input places
        self.diverged_at: int | None = None
        self.rows: list[ReplayedRow] = []
        self._events = session.events()
        # steps of the first force row at or after each event (0 after the last row)
        self._row_ahead = [0] * (len(self._events) + 1)
        for k in range(len(self._events) - 1, -1, -1):
            ev = self._events[k]
            self._row_ahead[k] = ev[2] if ev[0] == "forces" else self._row_ahead[k + 1]
        self._next = 0
        self._closed = False

    # --- where the replay is --------------------------------------------------------------
    @property
    def solver(self) -> SessionSolver:
        """The flow being replayed (draw `feelflow.solver.field_texture()` or `feelflow.solver.macroscopic()`)."""
        return self._driver

    @property
    def step(self) -> int:
        """Session steps replayed so far (with the parts of a row in progress)."""
        return self._driver.clock + self._driver.partial_steps

    @property
    def row_index(self) -> int:
        """The force row the flow is in (its parts running) or last completed; -1 before any."""
        return len(self.rows) - (0 if self._driver.partial_steps else 1)

    @property
    def total_steps(self) -> int:
        return self.session.steps

    @property
    def events_done(self) -> int:
        return self._next

    @property
    def events_total(self) -> int:
        return len(self._events)

    @property
    def done(self) -> bool:
        return self._next >= len(self._events)

    @property
    def shape(self):
        """The body as last placed (its pose during the last replayed row), or None."""
        return self._driver.shape

    @property
    def velocity(self):
        return self._driver.velocity

    @property
    def inflow_speed(self) -> float:
        d = self._driver
        return float(d.inflow_speed if d.inflow_speed is not None else d.solver.config.inflow_speed)

    @property
    def models(self) -> tuple[str, ...]:
        """The force models enabled now."""
        return self._driver.models

    # --- running ---------------------------------------------------------------------------
    def advance(self, max_steps: int, split_rows: bool = False) -> int:
        """Apply events until `max_steps` solver steps are simulated and return the steps
        simulated. A row that fits in `max_steps` is never split (at least one force row runs
        unless done); a longer one runs whole without `split_rows`, and in parts of the budget
        with it, across calls (`rows` gets it when its last part has run). It stops right
        after a row or part, before the inputs that lead to the next one, so `shape` is the
        pose the flow last felt (that of row `row_index`)."""
        steps = 0
        events = self._events
        max_steps = max(1, int(max_steps))
        while self._next < len(events):
            ev = events[self._next]
            if split_rows and ev[0] == "forces" and (self._driver.partial_steps or ev[2] > max_steps):
                k = min(ev[2] - self._driver.partial_steps, max_steps - steps)
                if k <= 0:
                    break
                if self._run_row(self._next, ev, part=k):
                    self._next += 1
                steps += k
                if steps >= max_steps:
                    break
                continue
            ahead = self._row_ahead[self._next]
            if steps and steps + ahead > max_steps and not (split_rows and ahead > max_steps):
                break   # (a row longer than the budget is split anyway: start it in this call)
            self._apply(self._next, ev)
            self._next += 1
            if ev[0] == "forces":
                steps += ev[2]
                if steps >= max_steps:
                    break
        return steps

    def _apply(self, k: int, ev) -> None:
        driver, kind = self._driver, ev[0]
        try:
            if kind == "input":
                (x, y, angle), (vx, vy, omega) = ev[2], ev[3]
                if self.geometry is None:
                    raise SessionError(f"{self.session.source}: input at step {ev[1]} moves a body "
                                       "the session has not got")
                driver.set_body(self.geometry.moved(x=x, y=y, angle=angle), (vx, vy), omega)
            elif kind == "parameter":
                self._parameter(ev[2], ev[3])
            else:
                self._run_row(k, ev)
        except SessionError:
            raise
        except (ValueError, BackendError) as exc:  # the file asks for something impossible (here)
            raise self._cannot(k, ev, exc) from None

    def _run_row(self, k: int, ev, part: int | None = None) -> bool:
        """The force row `ev` (event k): whole, or `part` more of its steps. True when the row
        is complete (and appended to `rows`)."""
        driver = self._driver
        try:
            try:
                if part is None:
                    driver.step(ev[2])
                    complete = True
                else:
                    complete = driver.step_part(part, ev[2])
            except SolverDiverged:
                self.diverged_at = driver.clock
                complete = True
        except (ValueError, BackendError) as exc:
            raise self._cannot(k, ev, exc) from None
        if complete:
            step, n, body, forces, torques = self.recorder.rows(len(self.rows))[0]
            self.rows.append(ReplayedRow(step, n, body, forces, self.inflow_speed, torques))
        return complete

    def _cannot(self, k: int, ev, exc) -> SessionError:
        return SessionError(f"{self.session.source}: event {k} ({ev[0]} at step {ev[1]}) cannot be replayed: "
                            f"{str(exc).splitlines()[0]}")

    def _parameter(self, name, value) -> None:
        driver = self._driver
        if name == "body":
            if value is None:
                driver.set_body(None)
                self.geometry = None
            else:
                self.geometry = shape_from_dict(value, "body", None)
        elif name == "inflow_speed":
            driver.set_inflow_speed(value)
        elif name == "nu":
            driver.set_viscosity(value)
        elif name == "force_models":
            driver.enable_force_models(value)
        elif name == "reset":
            driver.reset()
            self.diverged_at = None
        elif name == "rebuild":
            driver.rebuild(config_from_dict(value["config"]), value["keep_flow"])
            self.diverged_at = None
        elif name == "pause":
            driver.pause()
        elif name == "resume":
            driver.resume()

    # --- the outcome -----------------------------------------------------------------------
    def result(self) -> ReplayResult:
        """The replayed series next to the recorded one (meaningful once `done`)."""
        session = self.session
        replayed = self.recorder.session()
        values = np.full_like(session.forces["values"], np.nan)
        for j, m in enumerate(session.models):
            if m in replayed.models:
                i = replayed.models.index(m)
                values[:len(replayed.forces["values"]), 2 * j:2 * j + 2] = replayed.forces["values"][:, 2 * i:2 * i + 2]
        torques = np.full_like(session.forces["torques"], np.nan)
        for j, m in enumerate(session.models):
            if m in replayed.models:
                i = replayed.models.index(m)
                torques[:len(replayed.forces["torques"]), j] = replayed.forces["torques"][:, i]
        recorded = session.forces["values"]
        both_nan = np.isnan(values) & np.isnan(recorded)
        diff = np.where(both_nan, 0.0, np.abs(values - recorded))
        diff = np.where(np.isnan(diff), np.inf, diff)
        max_dev = float(diff.max()) if diff.size else 0.0
        finite = recorded[np.isfinite(recorded)]
        max_force = float(np.abs(finite).max()) if finite.size else 0.0
        return ReplayResult(replayed, values, max_dev, max_force, self.diverged_at, torques)

    def close(self) -> None:
        """Free the backend (idempotent)."""
        if not self._closed:
            self._closed = True
            self._driver.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


@dataclass
class ReplayResult:
    """The re-simulated series next to the recorded one."""

    session: Session          # the replay's own recording
    values: np.ndarray        # (m, 2 * len(models)) replayed forces in the recorded column order
    max_deviation: float      # largest |replayed - recorded| (inf where one is missing)
    max_force: float          # largest |recorded force| (the scale of the deviation)
    diverged_at: int | None   # session step where the replay diverged, if it did
    torques: np.ndarray | None = None   # (m, len(models)) replayed torques in the recorded column order

    @property
    def relative_deviation(self) -> float:
        return self.max_deviation / self.max_force if self.max_force > 0 else self.max_deviation


def replay(session: Session, backend: str | None = None, *, factory=None, ctx=None, progress=None) -> ReplayResult:
    """Re-simulate `session` on `backend` (default: the recorded one) by feeding its events
    through a `SessionSolver` in recorded order (`SessionPlayer` below, the one code path the
    window's replay runs too); compare the force series. `progress(events done, events)` is
    called after each force row."""
    with SessionPlayer(session, backend, factory=factory, ctx=ctx) as player:
        while not player.done:
            player.advance(1)
            if progress is not None:
                progress(player.events_done, player.events_total)
        return player.result()
