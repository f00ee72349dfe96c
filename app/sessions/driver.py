"""The solver as the app drives it (`SessionSolver`): one code path for the window, the headless
runner and the replay, which is why a replay reproduces a run bit for bit on the same backend
and machine (docs/reference/session-format.md, "Replay and playback"). Qt-free."""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from feelflow.app.sessions.format import SessionError, config_to_dict
from feelflow.app.sessions.recorder import SessionRecorder
from feelflow.solver.backend import SolverDiverged, create_solver
from feelflow.solver.config import ConfigError, FlowConfig
from feelflow.solver.force_average import StepWeightedMean


def _geometry(shape):
    """What a shape is, without where it is: its dict minus the pose."""
    if shape is None:
        return None
    d = shape.to_dict()
    for k in ("x", "y", "angle"):
        d.pop(k, None)
    return d


# --- the driver shared by recording and replay ------------------------------------------------

class SessionSolver:
    """The solver as the app drives it: a backend plus the commands a session records.

    Drive it like a backend: it is a `feelflow.solver.backend.FlowSolver` (set_body,
    set_inflow_speed, enable_force_models, step, forces, the field, the range check), plus the
    session-level commands `set_viscosity`, `reset`, `rebuild`, `pause`, `resume`. While it
    has a `recorder`, every command is recorded; `replay` feeds a recording back through these
    same methods, which is why a replay reproduces the run. Keep one SessionSolver for the whole
    life of the flow (it remembers the last placement); `start_recording` can then begin at
    any moment between two `step` calls.

    `set_viscosity`, `reset` and `rebuild` build a new backend with `factory(config)`
    (default: the same backend by name, on the wrapped solver's GL context if it has one).

    The flow's physical range (`check_physical`) is checked after each `step` call (each force
    row), or, with `check_every` = N > 1, only once at least N solver steps have run since the
    last check (the window: the check reads the whole field back). Non-finite populations are
    caught by the backends themselves at every step either way.
    """

    def __init__(self, solver, recorder: SessionRecorder | None = None, *, factory=None, body=None,
                 check_every: int = 1):
        self._solver = solver
        self.check_every = max(1, int(check_every))
        self._checked_at = None      # solver time of the last physical-range check
        self.recorder = recorder
        self._factory = factory or _same_backend_factory(solver)
        self.flow_config = solver.config  # the configuration asked for (reset returns to it)
        self.geometry_shape = recorder.body if recorder is not None else body  # last known geometry
        self.shape = None            # the body as last placed (None: no body)
        self.velocity = (0.0, 0.0)   # commanded
        self.omega = 0.0
        self.models: tuple[str, ...] = ()
        self.inflow_speed = None     # None: the config's
        self.paused = False
        self.clock = recorder.step if recorder is not None else 0
        self._part = None            # a force row being run in parts (step_part), or None

    @property
    def solver(self):
        """The backend being driven (it changes on reset, rebuild and viscosity changes)."""
        return self._solver

    # --- the flow, as the backend has it (solver.backend.FlowSolver) ----------------------
    @property
    def config(self) -> FlowConfig:
        return self._solver.config

    @property
    def name(self) -> str:
        return self._solver.name

    @property
    def time(self) -> int:
        return self._solver.time

    @property
    def speed_capped(self) -> bool:
        return self._solver.speed_capped

    @property
    def max_speed_seen(self) -> float:
        return self._solver.max_speed_seen

    @property
    def max_speed_at(self) -> int | None:
        return self._solver.max_speed_at

    @property
    def gl_context(self):
        return self._solver.gl_context

    def forces(self) -> dict[str, tuple[float, float]]:
        return self._solver.forces()

    def torques(self) -> dict[str, float]:
        return self._solver.torques()

    def macroscopic(self):
        return self._solver.macroscopic()

    def distributions(self) -> np.ndarray:
        return self._solver.distributions()

    def inlet_reference(self) -> np.ndarray | None:
        return self._solver.inlet_reference()

    def field_rgba(self) -> np.ndarray:
        return self._solver.field_rgba()

    def field_texture(self, vorticity: bool = True):
        return self._solver.field_texture(vorticity=vorticity)

    def total_mass(self) -> float:
        return self._solver.total_mass()

    # --- recording ------------------------------------------------------------
    def start_recording(self, **recorder_kwargs) -> SessionRecorder:
        """Record from now on, starting from the flow as it is (its populations and time are
        saved in the file); call it between two `step` calls. Keyword arguments go to
        `SessionRecorder` (renderer, scene_toml, scene_source, scene_dict). Returns the recorder."""
        rec = SessionRecorder(self._solver.config, self.shape if self.shape is not None else self.geometry_shape,
                              self.models, backend=self._solver.name, **recorder_kwargs)
        rec.start = {"time": int(self._solver.time), "body_placed": self.shape is not None,
                     "velocity": list(self.velocity), "omega": self.omega,
                     "force_models": list(self.models), "inflow_speed": self.inflow_speed}
        rec.state = np.ascontiguousarray(self._solver.distributions(), dtype=np.float64)
        rec.inlet_reference = self._solver.inlet_reference()
        self.recorder = rec
        self.clock = 0
        return rec

    def stop_recording(self) -> SessionRecorder | None:
        """Stop recording; returns the recorder (save it with `.save(path)`)."""
        rec, self.recorder = self.recorder, None
        return rec

    # --- solver commands ------------------------------------------------------
    def set_body(self, shape, velocity=(0.0, 0.0), omega: float = 0.0) -> None:
        rec = self.recorder
        if shape is None:
            if rec is not None:
                rec.record_parameter("body", None)
            self._solver.set_body(None)
            self.shape, self.velocity, self.omega = None, (0.0, 0.0), 0.0
            return
        velocity = (float(velocity[0]), float(velocity[1]))
        omega = float(omega)
        if rec is not None:
            if _geometry(shape) != _geometry(self.geometry_shape):
                rec.record_parameter("body", shape.to_dict())
            rec.record_input(shape.x, shape.y, shape.angle, velocity[0], velocity[1], omega)
        self._solver.set_body(shape, velocity=velocity, omega=omega)
        self.geometry_shape = self.shape = shape
        self.velocity, self.omega = velocity, omega

    def set_inflow_speed(self, speed: float) -> None:
        if self.recorder is not None:
            self.recorder.record_parameter("inflow_speed", float(speed))
        self._solver.set_inflow_speed(float(speed))
        self.inflow_speed = float(speed)

    def enable_force_models(self, names) -> None:
        names = tuple(names)
        if self.recorder is not None:
            self.recorder.record_parameter("force_models", list(names))
        self._solver.enable_force_models(names)
        self.models = names

    def add_force_model(self, model) -> None:
        """Enable an already-built model instance beside them (the C_p view's wall sampling,
        solver/forces/surface_pressure.py); not recorded: a replay computes its own."""
        self._solver.add_force_model(model)

    def step(self, n: int = 1) -> None:
        n = int(n)
        if n < 1:
            return
        start = self._solver.time
        body = self._body_row()
        try:
            self._solver.step(n)
            self.check_physical()
        except SolverDiverged as exc:
            done = max(1, min(n, exc.step - start))
            self._record_row(done, {m: (math.nan, math.nan) for m in self.models}, body)
            raise
        self._record_row(n, self._solver.forces(), body, self._solver.torques())

    def step_part(self, k: int, row_steps: int) -> bool:
        """Run k steps of a force row of `row_steps` steps that is run in parts (a replay that
        draws between them); the row is recorded when its last part has run, with the forces
        averaged over the parts weighted by their steps (equal to one `step(row_steps)` up to
        rounding; the flow itself is the same). Returns True when the row is complete.
        `partial_steps` says how far the current row has got."""
        k, row_steps = int(k), int(row_steps)
        part = self._part
        if part is None:
            part = self._part = {"done": 0, "mean": StepWeightedMean(), "body": self._body_row(),
                                 "start": self._solver.time}
        k = max(1, min(k, row_steps - part["done"]))
        try:
            self._solver.step(k)
        except SolverDiverged as exc:
            self._part = None
            done = part["done"] + max(1, min(k, exc.step - part["start"] - part["done"]))
            self._record_row(done, {m: (math.nan, math.nan) for m in self.models}, part["body"])
            raise
        part["mean"].add(self._solver.forces(), k, self._solver.torques())
        part["done"] += k
        if part["done"] < row_steps:
            return False
        try:
            self.check_physical()
        except SolverDiverged:
            self._part = None
            self._record_row(row_steps, {m: (math.nan, math.nan) for m in self.models}, part["body"])
            raise
        self._part = None
        self._record_row(row_steps, part["mean"].mean(), part["body"], part["mean"].torque_mean())
        return True

    def check_physical(self) -> None:
        """SolverDiverged when the flow left the physical range (solver.backend.Solver.check_physical);
        nothing when fewer than `check_every` solver steps have run since the last check."""
        t = self._solver.time
        if self._checked_at is not None and 0 <= t - self._checked_at < self.check_every:
            return
        self._solver.check_physical()
        self._checked_at = t

    @property
    def partial_steps(self) -> int:
        """Steps run of a force row still in parts (0 between rows)."""
        return 0 if self._part is None else self._part["done"]

    def _body_row(self):
        if self.shape is None:
            return (math.nan,) * 4
        return (self.shape.x, self.shape.y, self.velocity[0], self.velocity[1])

    def _record_row(self, n, forces, body, torques=None) -> None:
        self.clock += n
        if self.recorder is not None:
            self.recorder.record_forces(n, forces, body, torques=torques)

    # --- session commands -----------------------------------------------------
    def set_viscosity(self, nu: float) -> None:
        """Change the kinematic viscosity, keeping the flow: a new backend with the new config
        gets the current populations, time, inflow speed, force models and body."""
        config = dataclasses.replace(self.flow_config, nu=float(nu))
        try:
            config.validate()
        except ConfigError as exc:
            raise SessionError(f"viscosity: {exc}") from None
        if self.recorder is not None:
            self.recorder.record_parameter("nu", float(nu))
        self.flow_config = config
        old = self._solver
        new = carry_flow(self._factory, config, old.distributions(), old.time, self.shape, old.inlet_reference())
        self.adopt(new)
        old.close()

    def reset(self) -> None:
        """Start the flow again from the configuration's initial state (time 0); the body stays
        where it is, with its motion, force models and inflow speed."""
        if self.recorder is not None:
            self.recorder.record_parameter("reset")
        old = self._solver
        self.adopt(self._factory(self.flow_config))
        old.close()

    def rebuild(self, config: FlowConfig, keep_flow: bool = True) -> None:
        """Replace the backend with a new one for `config` (any change: grid, walls, viscosity),
        carrying the populations and time when `keep_flow` and the grid is the same. Nothing
        else is re-applied: the caller places the body and enables force models again (through
        this object, so that it is recorded)."""
        config = config.validate()
        if self.recorder is not None:
            self.recorder.record_parameter("rebuild", {"config": config_to_dict(config), "keep_flow": bool(keep_flow)})
        old = self._solver
        new = self._factory(config)
        if keep_flow and (config.nx, config.ny) == (old.config.nx, old.config.ny):
            new.set_distributions(old.distributions())
            reference = old.inlet_reference()
            if reference is not None and new.has_quiet_inlet:
                new.set_inlet_reference(reference)
            new.time = old.time
        self.flow_config = config
        self.shape, self.velocity, self.omega, self.models, self.inflow_speed = None, (0.0, 0.0), 0.0, (), None
        self._solver = new
        old.close()

    def adopt(self, new) -> None:
        if self.models:
            new.enable_force_models(self.models)
        if self.inflow_speed is not None:
            new.set_inflow_speed(self.inflow_speed)
        if self.shape is not None:
            new.set_body(self.shape, velocity=self.velocity, omega=self.omega)
        self._solver = new

    def pause(self) -> None:
        """Mark the simulation paused (no steps follow until `resume`); recorded, no physics."""
        if self.recorder is not None:
            self.recorder.record_parameter("pause")
        self.paused = True

    def resume(self) -> None:
        if self.recorder is not None:
            self.recorder.record_parameter("resume")
        self.paused = False

    def finish(self) -> None:
        self._solver.finish()

    def close(self) -> None:
        self._solver.close()


def _same_backend_factory(solver):
    def factory(config):
        return create_solver(solver.name, config, ctx=solver.gl_context)
    return factory


def carry_flow(factory, config, f, time, shape, inlet_reference=None):
    """A new backend for `config` holding populations `f` at `time`, with `shape` (if any)
    placed at rest *before* the populations arrive: a fresh lattice started at rest books no
    cover impulse, and the caller's own placement afterwards covers no new node. The quiet
    inlet's reference (Solver.inlet_reference) is carried too where both flows have one."""
    new = factory(dataclasses.replace(config, initial_velocity=(0.0, 0.0)))
    if shape is not None:
        new.set_body(shape, velocity=(0.0, 0.0), omega=0.0)
    new.set_distributions(f)
    if inlet_reference is not None and new.has_quiet_inlet:
        new.set_inlet_reference(inlet_reference)
    new.time = int(time)
    return new


def record_headless(solver, scene, *, scene_toml: str | None = None, renderer: str | None = None):
    """For `feelflow run SCENE --record FILE`: wrap the run's fresh solver so that everything
    the run does to it is recorded. Returns (session_solver, recorder): hand `session_solver` to
    the motion runner instead of `solver`, then `recorder.save(FILE)` after the run."""
    recorder = SessionRecorder.from_scene(scene, scene_toml=scene_toml, backend=solver.name,
                                          renderer=renderer)
    return SessionSolver(solver, recorder), recorder
