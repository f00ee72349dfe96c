"""The running wind tunnel behind the window (Qt-free, so it is testable on its own): the
composition of its parts, each in its own module (the panel's parameters and the flow they
make, the solver, the body's kinematics, the force history, the local stability guard, the
surface-pressure watches, a wind sweep or motion script), and `advance(n)`, one frame.
Lattice units (docs/science/algorithm.md).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from feelflow.app.model import readouts
from feelflow.app.model.body_input import BodyInput
from feelflow.app.model.body_kinematics import BodyKinematics
from feelflow.app.model.body_motion import advance_with_motion
from feelflow.app.model.flow_choice import QUIET_INLET_RATE, FlowChoice, default_base_config, stable_params  # noqa: F401 (re-exported)
from feelflow.app.model.force_history import History
from feelflow.app.model.local_stability import LocalStabilityGuard
from feelflow.app.model.pressure_watches import PressureWatches
from feelflow.app.model.wind_sweep import SLEW_STEPS, WindSweep
from feelflow.solver import units
from feelflow.app.sessions import SessionSolver
from feelflow.solver.backend import create_solver
from feelflow.solver.config import FlowConfig
from feelflow.solver.inflow import ramp
from feelflow.solver.motion import MotionRunner
from feelflow.solver.operator_choice import Choice

#: grid presets offered in the side panel: label -> (nx, ny)
GRID_PRESETS = {
    "192 x 96 (fast)": (192, 96),
    "256 x 128 (default)": (256, 128),
    "384 x 192": (384, 192),
    "512 x 256 (fine)": (512, 256),
}
DEFAULT_GRID = (256, 128)

#: force models a student chooses between: registry name -> label
FORCE_MODELS = {
    "momentum_exchange": "Momentum exchange",
    "macroscopic": "Macroscopic (drag equation)",
    "pressure": "Pressure integration",
}

#: y-boundaries offered as "wall type": config value -> label
WALLS = {"no_slip": "Solid walls (no slip)", "free_slip": "Slippery walls (free slip)",
         "periodic": "No walls (periodic)"}


@dataclass
class Params:
    """What the side panel edits (lattice units; angle in degrees)."""

    grid: tuple[int, int] = DEFAULT_GRID
    shape: str = "cylinder"
    size: float = 20.0
    angle_deg: float = 0.0
    wind: float = 0.05
    nu: float = 0.02
    wall: str = "no_slip"
    force_model: str = "momentum_exchange"
    compare_all: bool = False


def wrap_degrees(degrees: float) -> float:
    """An angle in [-180, 180): what the panel's angle box shows for any number of turns."""
    return (degrees + 180.0) % 360.0 - 180.0


def phase_name(velocity, wind: float) -> str:
    """Plain words for a scripted phase (the 2007 thesis's experiments)."""
    vx, vy = velocity
    if vx == 0.0 and vy == 0.0:
        return "stopped"
    if wind and vy == 0.0:
        return "moving with the stream" if vx * wind > 0 else "moving against the stream"
    return f"moving at ({vx:.3f}, {vy:.3f})"


class OfBody:
    """A member of the body's kinematics (`Simulation.body`) that the `TunnelModel` interface
    (app/model/tunnel.py) names on the model itself: read and set through the Simulation."""

    def __init__(self, name: str):
        self.name = name

    def __get__(self, sim, owner=None):
        return self if sim is None else getattr(sim.body, self.name)

    def __set__(self, sim, value):
        setattr(sim.body, self.name, value)


class Simulation:
    """The running tunnel: the composition of its parts, each set up here, and `advance(n)`: n
    steps and one force sample.
    - the panel's parameters (`params`) and the flow they make (`flow_choice`,
      app/model/flow_choice.py: the base configuration, the collision operator, the stability
      guard; `guard_note` says what the last change had to adjust, None when nothing);
    - the flow (`solver`, a `SessionSolver`: app/sessions/driver.py);
    - the body's kinematics (`body`, app/model/body_kinematics.py): its pose, the input pulling
      it and the springs that move it; its pose is also read here (`pos`, `angle`, ...);
    - a motion script (`runner`, solver/motion.py) or a wind sweep (`sweep`,
      app/model/wind_sweep.py) when one runs;
    - the force history (`history`, app/model/force_history.py), the reporter the plot reads;
    - the local stability guard (`local_guard`, app/model/local_stability.py);
    - the surface-pressure watches (`pressure`, app/model/pressure_watches.py): the C_p view's
      and the live polar's.
    """

    #: a sweep's change of wind is spread over this many steps (app/model/wind_sweep.py)
    SWEEP_SLEW_STEPS = SLEW_STEPS

    shape = OfBody("shape")             # the body where the flow feels it
    pos = OfBody("pos")                 # its reference point (cells)
    vel = OfBody("vel")                 # its velocity (cells per step)
    angle = OfBody("angle")             # its angle (radians)
    angle_target = OfBody("angle_target")   # the angle it is asked to turn to (radians)
    hold_still = OfBody("hold_still")   # it ignores pulls and turns (the polygon editor, some lessons)
    capped = OfBody("capped")           # the Mach cap limited its speed in the last frame

    def __init__(self, params: Params | None = None, backend: str = "numpy", ctx=None, shape_factory=None,
                 base_config: FlowConfig | None = None):
        from feelflow.app.model.bodies import make_shape

        self.params = params or Params()
        self.backend = backend
        self.ctx = ctx
        self.make_shape = shape_factory or make_shape
        self.polygon = None          # vertices of the custom polygon (body frame), or None
        self.history = History()
        self.last_torques: dict[str, float] = {}  # each model's mean torque over the last advance
        self.runner: MotionRunner | None = None   # a scripted motion (the seed's protocol), or None
        self.sweep: WindSweep | None = None       # a wind-speed sweep (a lesson), or None
        self.sweep_slew_steps = self.SWEEP_SLEW_STEPS   # for the next sweep (0: changes at once)
        #: the base configuration, the collision operator and the stability guard (app/model/flow_choice.py)
        self.flow_choice = FlowChoice(base_config, self.params.grid)
        self.params, self.guard_note = self.flow_choice.stable(self.params)
        self.local_guard = LocalStabilityGuard()
        self.guard_changed = False   # the local guard changed the flow (the window shows guard_note)
        self.pressure = PressureWatches()
        #: the coefficients' reference length when it is not the body's size (an exercise's)
        self.reference_override: readouts.ReferenceLength | None = None
        self.config = self.flow_config()
        # one SessionSolver for the life of the window (app/sessions/): rebuilt, never replaced
        self.solver = SessionSolver(create_solver(self.backend, self.config, ctx=ctx))
        pos, angle = self.start_position(self.config), math.radians(self.params.angle_deg)
        shape = self.make_shape(self.params, self.polygon, *pos, angle).validate(self.config.nx, self.config.ny)
        self.body = BodyKinematics(shape, pos, angle, self.config)
        self._place_body()

    @staticmethod
    def start_position(config: FlowConfig) -> tuple[float, float]:
        """Where a new tunnel puts the body: a third of the way down, on the centre line."""
        return (config.nx * 0.3, config.ny * 0.5)

    # --- construction --------------------------------------------------------------------
    def operator_for(self, params: Params | None = None) -> Choice:
        """The collision operator for `params` (default: the panel's) and why (FlowChoice)."""
        return self.flow_choice.operator_for(params or self.params)

    def flow_config(self, params: Params | None = None) -> FlowConfig:
        """The flow configuration for `params` (default: the panel's; FlowChoice)."""
        return self.flow_choice.config_for(params or self.params)

    def _build(self, keep_flow: bool):
        """The flow for the parameters now, from the old one where `keep_flow` and the grid is the
        same (recorded as a rebuild when a session is being recorded); else from rest, with the
        body back at its start and the history cleared."""
        config = self.flow_config()
        same_grid = (self.config.nx, self.config.ny) == (config.nx, config.ny)
        self.solver.rebuild(config, keep_flow=keep_flow and same_grid)
        if not (keep_flow and same_grid):
            self.body.restart(self.start_position(config), math.radians(self.params.angle_deg))
            self.history.clear()
        if self.runner is not None and not keep_flow:
            self.runner = None
        self.config = config
        self.body.use_config(config)
        if not keep_flow:
            self.body.shape = self.make_shape(self.params, self.polygon, *self.pos, self.angle).validate(
                config.nx, config.ny)
        self._place_body()

    def _place_body(self):
        """The body inside the margins, the force models enabled, the body placed in the flow."""
        self.body.clamp()
        self._enable_models()
        self.solver.set_body(self.shape, self.vel, 0.0)

    def _enable_models(self):
        names = list(FORCE_MODELS) if self.params.compare_all else [self.params.force_model]
        self.solver.enable_force_models(names)
        for probe in self.pressure.probes():   # the surface-pressure probes, beside the force models
            self.solver.add_force_model(probe)

    @property
    def polar(self):
        """The angle-of-attack sweep running in the tunnel (app/model/live_polar.py), or None."""
        return self.pressure.polar

    @property
    def surface_watch(self):
        """C_p along the surface for the plot's C_p view (app/model/live_polar.py), or None."""
        return self.pressure.surface_watch

    def surface_pressure(self):
        """C_p along the surface now, for the plot's C_p view (PressureWatches.surface_pressure),
        or None."""
        return self.pressure.surface_pressure(self)

    def watch_surface_pressure(self, on: bool = True):
        """Switch the pressure model's wall sampling on for C_p along the surface (the C_p view)."""
        self.pressure.watch_surface(on)
        self._enable_models()

    def replayed_session(self) -> None:
        """None: the live tunnel replays no session file."""
        return None

    def start_polar(self, angles, sample_steps: int = 25, **settling):
        """An angle-of-attack sweep (app/model/live_polar.py): the body held still at each angle
        of `angles` (degrees, nose up positive) until its forces settle, then the next."""
        polar = self.pressure.start_polar(self, angles, sample_steps=sample_steps, **settling)
        self._enable_models()
        polar.start(self)

    # --- what the panel changes ------------------------------------------------------------
    def set_shape(self, kind=None, size=None, angle_deg=None, polygon=None):
        """Change the body; raises shapes' ShapeError (one line) and keeps the old body if invalid."""
        params = replace(self.params, **{k: v for k, v in
                                          (("shape", kind), ("size", size), ("angle_deg", angle_deg)) if v is not None})
        poly = self.polygon if polygon is None else polygon
        angle = math.radians(params.angle_deg) if angle_deg is not None else self.angle
        shape = self.make_shape(params, poly, *self.pos, angle).validate(self.config.nx, self.config.ny)
        self.params, self.polygon = params, poly
        self.body.reshape(shape, angle)
        self.solver.set_body(self.shape, self.vel, 0.0)
        guarded, note = self.flow_choice.stable(self.params)
        if note:   # a larger body needs a thicker fluid at this wind
            self.set_flow(nu=guarded.nu)
        elif self.operator_for().collision != self.config.collision:   # the size changed the operator
            self._build(keep_flow=True)
        self.guard_note = note

    def set_flow(self, wind=None, nu=None, wall=None):
        """Change inflow speed, viscosity or walls, keeping the flow as it is (raises ConfigError)."""
        params = replace(self.params, **{k: v for k, v in (("wind", wind), ("nu", nu), ("wall", wall)) if v is not None})
        params, self.guard_note = self.flow_choice.stable(params)
        new = self.flow_config(params)  # validate first: a bad value leaves everything as it was
        only_wind = ((params.nu, params.wall) == (self.params.nu, self.params.wall)
                     and new.collision == self.config.collision)
        self.params = params
        if only_wind:
            self.solver.set_inflow_speed(params.wind)   # live, no rebuild
            self.body.wind_changed(self.config, params.wind)
        else:
            self._build(keep_flow=True)

    def set_grid(self, grid):
        self.params = replace(self.params, grid=tuple(grid))
        self._build(keep_flow=False)

    def set_force_models(self, selected=None, compare_all=None):
        self.params = replace(self.params, **{k: v for k, v in
                                              (("force_model", selected), ("compare_all", compare_all)) if v is not None})
        self._enable_models()

    def reset_flow(self):
        """The flow from its initial state again (time 0), body where it was, at rest; history cleared."""
        self.solver.reset()
        self.runner = self.sweep = None
        self.pressure.stop_polar()
        self.body.stop()
        self.solver.set_body(self.shape, (0.0, 0.0), 0.0)
        self.history.clear()

    def start_sweep(self, speeds, hold_steps: int):
        """Hold each wind speed `hold_steps` steps in turn (the 'drag grows with speed' lesson);
        the first one from the end of the inlet's start-up ramp, if it is still rising."""
        start = max(self.solver.time, self.config.inflow_ramp_steps)
        self.sweep = WindSweep(tuple(speeds), int(hold_steps), start, self.sweep_slew_steps)
        self.set_flow(wind=speeds[0])

    def sweep_end(self):
        """The step at which the sweep ends (None without a sweep)."""
        return None if self.sweep is None else self.sweep.end

    def sweep_stage(self):
        """Which speed of the sweep holds now, or None."""
        return None if self.sweep is None else self.sweep.stage(self.solver.time)

    def start_script(self, script):
        """Drive the body through a solver.motion.MotionScript (mouse and hold-still ignored)."""
        self.shape = self.shape.moved(*self.pos, self.angle)
        self.runner = MotionRunner(self.solver, self.shape, script)

    def script_phase(self):
        """(phase index, count, words) of the running script, or None."""
        r = self.runner
        if r is None:
            return None
        start = 0
        for k, phase in enumerate(r.script.phases):
            if r.t < start + phase.steps:
                return k, len(r.script.phases), phase_name(phase.velocity, self.params.wind)
            start += phase.steps
        return None

    def load_scene(self, scene):
        """Take grid, flow, body, pose and motion from an app.scene.Scene."""
        from feelflow.app.model.bodies import params_for_shape

        kind, size, verts = params_for_shape(scene.body)
        cfg = scene.config
        models = [m for m in scene.force_models if m in FORCE_MODELS] or [self.params.force_model]
        self.flow_choice.use_scene(scene)
        self.params = replace(self.params, grid=(cfg.nx, cfg.ny), shape=kind, size=size or self.params.size,
                              angle_deg=math.degrees(scene.body.angle), wind=cfg.inflow_speed, nu=cfg.nu,
                              wall=cfg.y_boundary, force_model=models[0], compare_all=len(models) > 1)
        self.params, self.guard_note = self.flow_choice.stable(self.params)
        self.polygon = verts
        self.runner = self.sweep = None
        self.pressure.stop_polar()
        self._build(keep_flow=False)
        self.body.move_to((scene.body.x, scene.body.y))
        self.solver.set_body(self.shape, (0.0, 0.0), 0.0)
        if scene.motion.phases:
            self.start_script(scene.motion)

    # --- body input -----------------------------------------------------------------------
    @property
    def target(self):
        """Where an input pulls the body, (x, y) cells, or None: set only through `drive`."""
        return self.body.target

    def drive(self, request: BodyInput) -> bool:
        """The one way in for body input (mouse, haptic device, script: app/model/body_input.py):
        to the body's kinematics (a pull moves the spring-damper's target, a turn asks the angle
        spring for an angle, as `turn_to`). While the body holds still or a motion script runs,
        the pose ignores both until that ends, as it always has. Returns True."""
        if request.angle_deg is not None:
            self.params = replace(self.params, angle_deg=wrap_degrees(request.angle_deg))
        self.body.drive(request)
        return True

    def hit(self, x: float, y: float, tolerance: float = 2.0) -> bool:
        """Is the lattice point (x, y) on the body (or within `tolerance` cells of it)?"""
        return shape_hit(self.shape, x, y, tolerance)

    def turn_to(self, degrees: float):
        """Ask for the angle `degrees` (any turn count: 190 turns 20 from 170, not 340 back):
        the body swings there through the angle spring (rate capped below the Mach limit), and
        the panel's angle (params.angle_deg, wrapped to [-180, 180)) says where it is going."""
        self.body.turn_to(degrees)
        self.params = replace(self.params, angle_deg=wrap_degrees(degrees))

    def target_degrees(self) -> float:
        """The angle the body is asked to turn to, in degrees (any number of turns), exactly as it
        was asked (app/model/body_kinematics.py `target_degrees`)."""
        return self.body.target_degrees(self.params.angle_deg)

    # --- running --------------------------------------------------------------------------
    def relative_wind(self):
        """The wind the body meets: the inlet's speed now (on its start-up ramp, solver/inflow.py)
        less the body's velocity."""
        wind = self.params.wind * ramp(self.solver.time, self.config.inflow_ramp_steps)
        return (wind - self.vel[0], -self.vel[1])

    def advance(self, n: int):
        """Run n steps, the body's pose advanced every step while it moves; record a sample."""
        n = max(1, int(n))
        if self.sweep is not None:
            wind = self.sweep.wind(self.solver.time)
            if wind is None:
                self.sweep = None
            elif wind != self.params.wind:
                self.set_flow(wind=wind)
        done = 0
        acc = {}
        torques = {}   # each model's torque summed over the steps
        self.capped = False
        if self.runner is not None:
            acc = {k: (fx * n, fy * n) for k, (fx, fy) in self.runner.advance(n).items()}
            torques = {k: t * n for k, t in self.runner.last_torques.items()}
            r = self.runner
            self.pos, self.shape = r.position, r.shape
            self.vel = r.script.velocity_at(r.t - 1)
            if r.t >= r.script.total_steps:
                self.runner = None
                self.vel = (0.0, 0.0)
            done = n
        if done < n:   # the pose advances every step while the body moves (app/model/body_motion.py)
            acc = advance_with_motion(self.solver, n, self._move_body, self.body.moving, torques)
            self.capped |= self.solver.speed_capped
        forces = {k: (v[0] / n, v[1] / n) for k, v in acc.items()}
        self.pressure.after_advance(self, forces, n)
        torques = {k: t / n for k, t in torques.items() if k in forces}   # not the probes' (a model of none)
        self.last_torques = torques
        self.history.add(self.solver.time, self.vel, self.relative_wind(), forces, torques)
        self.apply_local_guard()
        return forces

    def _move_body(self, steps: int):
        """The pose `steps` steps on (app/model/body_kinematics.py), the body placed where it moved."""
        if self.body.move(steps):
            self.solver.set_body(self.shape, self.vel, self.body.rate)

    def apply_local_guard(self) -> bool:
        """The local stability guard (app/model/local_stability.py): when the last physical-range
        check found the fastest node outside the running operator's stable region, raise the
        viscosity to the one that brings it back, keeping the flow; `guard_note` and
        `guard_changed` say so in one line. Returns whether it acted."""
        action = self.local_guard.check(self.solver, self.config.collision, self.params.nu,
                                        lambda nu: self.operator_for(replace(self.params, nu=nu)).collision)
        if action is None:
            return False
        label = self.operator_for().label
        if action.nu is None:
            self.guard_note = action.verdict.line(label)
        else:
            self.set_flow(nu=action.nu)
            self.guard_note = action.verdict.line(label, nu_set=self.params.nu)
        self.guard_changed = True
        return True

    def take_guard_change(self) -> bool:
        """Whether the local guard changed the flow since the last call (the window then says
        `guard_note`)."""
        changed, self.guard_changed = self.guard_changed, False
        return changed

    # --- what the window shows -----------------------------------------------------------
    def reference_length(self) -> readouts.ReferenceLength:
        """The length the force coefficients use (app/model/readouts.py): the body's size, or
        the one an exercise sets (`reference_override`)."""
        return self.reference_override or readouts.ReferenceLength(self.params.size)

    def reynolds(self) -> float:
        """Re of the wind over the body size (solver/units.py)."""
        return units.reynolds(self.params.wind, self.params.size, self.params.nu)

    def mach(self) -> float:
        return units.mach(self.params.wind)

    def operator_line(self) -> str:
        """Which collision operator runs and why, in one line (the status bar's)."""
        return self.operator_for().reason

    def field_texture(self, vorticity: bool = True):
        return self.solver.field_texture(vorticity=vorticity)

    def field_rgba(self) -> np.ndarray:
        return self.solver.field_rgba()


def shape_hit(shape, x: float, y: float, tolerance: float = 2.0) -> bool:
    """Is the lattice point (x, y) on `shape` or within `tolerance` cells of it (the point and
    its four neighbours at that distance)? False without a shape."""
    if shape is None:
        return False
    px = x + np.array([0, -1, 1, 0, 0]) * tolerance
    py = y + np.array([0, 0, 0, -1, 1]) * tolerance
    return bool(np.any(shape.contains(px, py)))
