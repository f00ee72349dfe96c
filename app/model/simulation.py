"""The running wind tunnel behind the window (Qt-free, so it is testable on its own):
the solver, the body and its pose, the mouse coupling, the force models in use, and the
force history the plot and readouts show. Lattice units (docs/science/algorithm.md).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from feelflow.app.model import readouts
from feelflow.app.model.body_input import BodyInput
from feelflow.app.model.body_motion import advance_with_motion, is_moving
from feelflow.app.model.flow_choice import QUIET_INLET_RATE, FlowChoice, default_base_config, stable_params  # noqa: F401 (re-exported)
from feelflow.app.model.force_history import History
from feelflow.app.model.wind_sweep import SLEW_STEPS, WindSweep
from feelflow.app.model.coupling import AngleSpring, SpringDamper
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

#: distance (cells) the body's bounding box keeps from the domain edges
EDGE_MARGIN = 8.0


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


class Simulation:
    """The running tunnel: owns the solver (a `SessionSolver`), the body and its pose, and runs
    `advance(n)`: n steps and one force sample. Its parts, each set up here:
    - the panel's parameters (`params`) and the flow they make (`flow_choice`,
      app/model/flow_choice.py: the base configuration, the collision operator, the stability
      guard; `guard_note` says what the last change had to adjust, None when nothing);
    - the body's pose and its input: the mouse's spring-damper (`coupling`) and the angle spring
      (app/model/coupling.py), through `drive(BodyInput)`;
    - a motion script (`runner`, solver/motion.py) or a wind sweep (`sweep`,
      app/model/wind_sweep.py) when one runs;
    - the force history (`history`, app/model/force_history.py), the reporter the plot reads.
    """

    #: a sweep's change of wind is spread over this many steps (app/model/wind_sweep.py)
    SWEEP_SLEW_STEPS = SLEW_STEPS

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
        self.hold_still = False
        self._asked = (None, None)   # (degrees, radians) of the last turn_to: see target_degrees
        self.runner: MotionRunner | None = None   # a scripted motion (the seed's protocol), or None
        self.sweep: WindSweep | None = None       # a wind-speed sweep (a lesson), or None
        self.sweep_slew_steps = self.SWEEP_SLEW_STEPS   # for the next sweep (0: changes at once)
        #: the base configuration, the collision operator and the stability guard (app/model/flow_choice.py)
        self.flow_choice = FlowChoice(base_config, self.params.grid)
        self.params, self.guard_note = self.flow_choice.stable(self.params)
        self._guard_read_at = None   # solver step of the last max |u| the local guard read
        self.guard_changed = False   # the local guard changed the flow (the window shows guard_note)
        self.polar = None            # app/model/live_polar.LivePolar: an angle-of-attack sweep
        self.surface_watch = None    # app/model/live_polar.SurfacePressureWatch: C_p along the surface
        self.capped = False          # the Mach cap limited the body's speed in the last frame
        #: the coefficients' reference length when it is not the body's size (an exercise's)
        self.reference_override: readouts.ReferenceLength | None = None
        self.config = self.flow_config()
        # one SessionSolver for the life of the window (app/sessions/): rebuilt, never replaced
        self.solver = SessionSolver(create_solver(self.backend, self.config, ctx=ctx))
        self.coupling = SpringDamper(max_speed=self.config.max_speed, stream=self._stream(self.config))
        # the body's pose: reference point (cells), velocity (cells per step), angle and its rate
        self.pos, self.vel = self.start_position(self.config), (0.0, 0.0)
        self.angle, self.rate = math.radians(self.params.angle_deg), 0.0
        self.angle_target = self.angle
        self._target = None          # where an input pulls the body (`drive`), or None
        self._clamped_x = self._clamped_y = False   # the last _clamp_pose pushed the body back in x, y
        self.shape = self.make_shape(self.params, self.polygon, *self.pos, self.angle).validate(
            self.config.nx, self.config.ny)
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
            self.pos, self.vel = self.start_position(config), (0.0, 0.0)
            self.angle, self.rate = math.radians(self.params.angle_deg), 0.0
            self.angle_target = self.angle
            self._target = None
            self.history.clear()
        if self.runner is not None and not keep_flow:
            self.runner = None
        self.config = config
        self.coupling = SpringDamper(max_speed=config.max_speed, stream=self._stream(config))
        if not keep_flow:
            self.shape = self.make_shape(self.params, self.polygon, *self.pos, self.angle).validate(config.nx, config.ny)
        self._place_body()

    def _place_body(self):
        """The body inside the margins, the force models enabled, the body placed in the flow."""
        self._clamp_pose()
        self._enable_models()
        self.solver.set_body(self.shape, self.vel, 0.0)

    @staticmethod
    def _stream(config: FlowConfig, wind: float | None = None) -> tuple[float, float]:
        """The wind the body's speed is capped relative to (app/model/coupling.py): the inflow in
        the tunnel, none in a periodic box."""
        if config.x_boundary != "tunnel":
            return (0.0, 0.0)
        return (float(config.inflow_speed if wind is None else wind), 0.0)

    def _enable_models(self):
        names = list(FORCE_MODELS) if self.params.compare_all else [self.params.force_model]
        self.solver.enable_force_models(names)
        for probe in self._probes():
            self.solver.add_force_model(probe)

    def _probes(self):
        """The surface-pressure probes switched on (the C_p view, the polar), beside the force models."""
        watch = self.polar or self.surface_watch   # one probe: the polar's serves the C_p view too
        return [] if watch is None else [watch.probe]

    def watch_surface_pressure(self, on: bool = True):
        """Switch the pressure model's wall sampling on for C_p along the surface (the C_p view)."""
        if on and self.surface_watch is None:
            from feelflow.app.model.live_polar import SurfacePressureWatch

            self.surface_watch = SurfacePressureWatch()
        elif not on:
            self.surface_watch = None
        self._enable_models()

    def start_polar(self, angles, sample_steps: int = 25, **settling):
        """An angle-of-attack sweep (app/model/live_polar.py): the body held still at each angle
        of `angles` (degrees, nose up positive) until its forces settle, then the next."""
        from feelflow.app.model.live_polar import LivePolar

        self.polar = LivePolar(self, angles, sample_steps=sample_steps, **settling)
        self._enable_models()
        self.polar.start(self)

    # --- what the panel changes ------------------------------------------------------------
    def set_shape(self, kind=None, size=None, angle_deg=None, polygon=None):
        """Change the body; raises shapes' ShapeError (one line) and keeps the old body if invalid."""
        params = replace(self.params, **{k: v for k, v in
                                          (("shape", kind), ("size", size), ("angle_deg", angle_deg)) if v is not None})
        poly = self.polygon if polygon is None else polygon
        angle = math.radians(params.angle_deg) if angle_deg is not None else self.angle
        shape = self.make_shape(params, poly, *self.pos, angle).validate(self.config.nx, self.config.ny)
        self.params, self.polygon, self.shape = params, poly, shape
        self.angle = self.angle_target = angle
        self._clamp_pose()
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
            self.coupling.stream = self._stream(self.config, params.wind)
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
        self.runner = self.sweep = self.polar = None
        self.vel, self.rate, self._target = (0.0, 0.0), 0.0, None
        self.angle_target = self.angle
        self.shape = self.shape.moved(*self.pos, self.angle)
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
        self.runner = None
        self.sweep = self.polar = None
        self._build(keep_flow=False)
        self.pos = (scene.body.x, scene.body.y)
        self.shape = self.shape.moved(*self.pos, self.angle)
        self._clamp_pose()
        self.solver.set_body(self.shape, (0.0, 0.0), 0.0)
        if scene.motion.phases:
            self.start_script(scene.motion)

    # --- body input -----------------------------------------------------------------------
    @property
    def target(self):
        """Where an input pulls the body, (x, y) cells, or None: set only through `drive`."""
        return self._target

    def drive(self, request: BodyInput) -> bool:
        """The one way in for body input (mouse, haptic device, script: app/model/body_input.py).
        A pull moves the target of the spring-damper that moves the body (coupling.py); a turn
        asks the angle spring for an angle (`turn_to`). While the body holds still or a motion
        script runs, the pose ignores both until that ends, as it always has. Returns True."""
        if request.let_go:
            self._target = None
        elif request.target is not None:
            self._target = request.target
        if request.angle_deg is not None:
            self.turn_to(request.angle_deg)
        return True

    def hit(self, x: float, y: float, tolerance: float = 2.0) -> bool:
        """Is the lattice point (x, y) on the body (or within `tolerance` cells of it)?"""
        return shape_hit(self.shape, x, y, tolerance)

    def turn_to(self, degrees: float):
        """Ask for the angle `degrees` (any turn count: 190 turns 20 from 170, not 340 back):
        the body swings there through the angle spring (rate capped below the Mach limit), and
        the panel's angle (params.angle_deg, wrapped to [-180, 180)) says where it is going."""
        self.angle_target = math.radians(degrees)
        self.params = replace(self.params, angle_deg=wrap_degrees(degrees))
        self._asked = (degrees, self.angle_target)

    def target_degrees(self) -> float:
        """The angle the body is asked to turn to, in degrees (any number of turns), exactly as it
        was asked (by `turn_to` or the panel) where it was: radians -> degrees -> radians is not
        exact in floating point, and an undo must give back the very angle it took away."""
        asked, radians = self._asked
        if radians == self.angle_target:
            return asked
        if math.radians(self.params.angle_deg) == self.angle_target:
            return self.params.angle_deg
        return math.degrees(self.angle_target)

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
            acc = advance_with_motion(self.solver, n, self._move_body, self._body_moves, torques)
            self.capped |= self.solver.speed_capped
        forces = {k: (v[0] / n, v[1] / n) for k, v in acc.items()}
        torques = {k: t / n for k, t in torques.items()}
        for probe in self._probes():   # a probe's force is the pressure model's: not a model of its own
            forces.pop(probe.name, None)
            torques.pop(probe.name, None)
        self.last_torques = torques
        if self.polar is not None:
            self.polar.after_advance(self, forces, n)
        self.history.add(self.solver.time, self.vel, self.relative_wind(), forces, torques)
        self.apply_local_guard()
        return forces

    def apply_local_guard(self) -> bool:
        """The local stability guard (solver/local_guard.py): when the last physical-range check
        found the fastest node outside the running operator's stable region, raise the viscosity
        to the one that brings it back (for the operator that viscosity gets), keeping the flow;
        `guard_note` and `guard_changed` say so in one line. Returns whether it acted."""
        from feelflow.solver import local_guard

        at = self.solver.max_speed_at
        if at is None or at == self._guard_read_at:
            return False
        self._guard_read_at = at
        verdict = local_guard.check(self.config.collision, self.params.nu, self.solver.max_speed_seen)
        if verdict.inside:
            return False
        if verdict.nu_needed is None:
            self.guard_note = verdict.line(self.operator_for().label)
            self.guard_changed = True
            return True
        nu = verdict.nu_needed
        for _ in range(3):   # the chooser may pick another operator at the new viscosity: its region counts
            op = self.operator_for(replace(self.params, nu=nu)).collision
            again = local_guard.check(op, nu, verdict.max_speed).nu_needed
            if again is None or again <= nu:
                break
            nu = again
        nu = math.ceil(nu * 1e4 - 1e-6) / 1e4
        label = self.operator_for().label
        self.set_flow(nu=nu)
        self.guard_note = verdict.line(label, nu_set=self.params.nu)
        self.guard_changed = True
        return True

    def _body_moves(self) -> bool:
        """Whether the next step moves or turns the body (app/model/body_motion.py is_moving)."""
        if self.hold_still:
            return bool(self.rate) or self.vel != (0.0, 0.0)
        return is_moving(self.vel, self.rate, self.pos, self._target, self.angle, self.angle_target)

    def _move_body(self, steps: int):
        old = (self.pos, self.angle)
        if self.hold_still:
            self.vel = (0.0, 0.0)
        else:
            self.pos, self.vel, capped = self.coupling.advance(self.pos, self.vel, self._target, steps)
            self.capped |= capped
        omega_before = self.rate
        if not self.hold_still:
            self.angle, self.rate = AngleSpring().advance(self.angle, self.rate, self.angle_target, steps) \
                if (self.angle != self.angle_target or self.rate) else (self.angle, 0.0)
        if self._clamp_pose():
            self.vel = (0.0 if self._clamped_x else self.vel[0], 0.0 if self._clamped_y else self.vel[1])
        if (self.pos, self.angle) != old or omega_before:
            self.shape = self.shape.moved(*self.pos, self.angle)
            self.solver.set_body(self.shape, self.vel, self.rate)

    def _clamp_pose(self) -> bool:
        """Keep the body EDGE_MARGIN cells inside the domain; True if it had to be pushed back."""
        shape = self.shape.moved(*self.pos, self.angle)
        x0, y0, x1, y1 = shape.bounding_box()
        nx, ny = self.config.nx, self.config.ny
        dx = max(0.0, EDGE_MARGIN - x0) - max(0.0, x1 - (nx - 1 - EDGE_MARGIN))
        dy = max(0.0, EDGE_MARGIN - y0) - max(0.0, y1 - (ny - 1 - EDGE_MARGIN))
        self._clamped_x, self._clamped_y = dx != 0, dy != 0
        if dx or dy:
            self.pos = (self.pos[0] + dx, self.pos[1] + dy)
            self.shape = shape.moved(*self.pos, self.angle)
            return True
        return False

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
