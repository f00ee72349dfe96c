"""The body's kinematics in the live tunnel (Qt-free): where the body is and how fast it moves
and turns, where an input pulls it, and what moves it between frames. A mouse or device pulls
a target; a critically damped spring-damper moves the body towards it and an angle spring
turns it (virtual coupling, Colgate, Stanley & Brown 1995: app/model/coupling.py), its speed
capped at the Mach limit; the body keeps `EDGE_MARGIN` cells inside the domain. The
`Simulation` (app/model/simulation.py) holds one and places the body in the flow when its pose
changes. Lattice units: cells, cells per step, radians.
"""
from __future__ import annotations

import math

from feelflow.app.model.body_input import BodyInput
from feelflow.app.model.body_motion import is_moving
from feelflow.app.model.coupling import AngleSpring, SpringDamper
from feelflow.solver.config import FlowConfig

#: distance (cells) the body's bounding box keeps from the domain edges
EDGE_MARGIN = 8.0


def stream_of(config: FlowConfig, wind: float | None = None) -> tuple[float, float]:
    """The wind the body's speed is capped relative to (app/model/coupling.py): the inflow in
    the tunnel (`wind` where given, else the configuration's), none in a periodic box."""
    if config.x_boundary != "tunnel":
        return (0.0, 0.0)
    return (float(config.inflow_speed if wind is None else wind), 0.0)


class BodyKinematics:
    """The body's pose and what moves it: the placed `shape`, its reference point `pos`
    (cells), velocity `vel` (cells per step), `angle` and turn `rate` (radians, per step),
    the angle it is asked to turn to (`angle_target`), where an input pulls it (`target`),
    the hold-still switch, the spring-damper and angle spring, and whether the Mach cap
    limited its speed (`capped`)."""

    def __init__(self, shape, pos: tuple[float, float], angle: float, config: FlowConfig):
        self.shape = shape
        self.pos, self.vel = pos, (0.0, 0.0)
        self.angle, self.rate = angle, 0.0
        self.angle_target = angle
        self.hold_still = False      # the body ignores pulls and turns (the polygon editor, some lessons)
        self.capped = False          # the Mach cap limited the body's speed in the last frame
        self._target = None          # where an input pulls the body (`drive`), or None
        self._asked = (None, None)   # (degrees, radians) of the last turn_to: see target_degrees
        self._clamped = (False, False)   # the last `clamp` pushed the body back in x, y
        self.coupling = SpringDamper(max_speed=config.max_speed, stream=stream_of(config))
        self._grid = (config.nx, config.ny)

    # --- the tunnel it moves in --------------------------------------------------------------
    def use_config(self, config: FlowConfig):
        """A new flow: its grid bounds the pose, its Mach cap and wind bound the speed."""
        self.coupling = SpringDamper(max_speed=config.max_speed, stream=stream_of(config))
        self._grid = (config.nx, config.ny)

    def wind_changed(self, config: FlowConfig, wind: float):
        """The inflow changed live: the speed is capped relative to the new wind."""
        self.coupling.stream = stream_of(config, wind)

    # --- where it is ------------------------------------------------------------------------
    def restart(self, pos: tuple[float, float], angle: float):
        """At rest at `pos`, `angle`, nothing pulling it."""
        self.pos, self.vel = pos, (0.0, 0.0)
        self.angle, self.rate = angle, 0.0
        self.angle_target = angle
        self._target = None

    def stop(self):
        """At rest where it is, nothing pulling or turning it; the shape placed at the pose."""
        self.vel, self.rate, self._target = (0.0, 0.0), 0.0, None
        self.angle_target = self.angle
        self.shape = self.shape.moved(*self.pos, self.angle)

    def reshape(self, shape, angle: float):
        """A new body at `angle` (and asked to stay there), kept inside the margins."""
        self.shape = shape
        self.angle = self.angle_target = angle
        self.clamp()

    def move_to(self, pos: tuple[float, float]):
        """The body put at `pos` (a scene's pose), kept inside the margins."""
        self.pos = pos
        self.shape = self.shape.moved(*self.pos, self.angle)
        self.clamp()

    # --- input --------------------------------------------------------------------------------
    @property
    def target(self):
        """Where an input pulls the body, (x, y) cells, or None: set only through `drive`."""
        return self._target

    def drive(self, request: BodyInput):
        """A pull moves the spring-damper's target; a turn asks the angle spring for an angle
        (`turn_to`). While the body holds still the pose ignores both until that ends."""
        if request.let_go:
            self._target = None
        elif request.target is not None:
            self._target = request.target
        if request.angle_deg is not None:
            self.turn_to(request.angle_deg)

    def turn_to(self, degrees: float):
        """Ask for the angle `degrees` (any turn count: 190 turns 20 from 170, not 340 back)."""
        self.angle_target = math.radians(degrees)
        self._asked = (degrees, self.angle_target)

    def target_degrees(self, panel_degrees: float) -> float:
        """The angle asked for, in degrees, exactly as it was asked (by `turn_to`, else the
        panel's `panel_degrees`) where it was: radians -> degrees -> radians is not exact in
        floating point, and an undo must give back the very angle it took away."""
        asked, radians = self._asked
        if radians == self.angle_target:
            return asked
        if math.radians(panel_degrees) == self.angle_target:
            return panel_degrees
        return math.degrees(self.angle_target)

    # --- between frames -----------------------------------------------------------------------
    def moving(self) -> bool:
        """Whether the next step moves or turns the body (app/model/body_motion.py is_moving)."""
        if self.hold_still:
            return bool(self.rate) or self.vel != (0.0, 0.0)
        return is_moving(self.vel, self.rate, self.pos, self._target, self.angle, self.angle_target)

    def move(self, steps: int) -> bool:
        """Advance the pose `steps` steps through the springs (a held body stops), kept inside
        the margins; True when the body has to be placed again (it moved, turned or was
        turning)."""
        old = (self.pos, self.angle)
        if self.hold_still:
            self.vel = (0.0, 0.0)
        else:
            self.pos, self.vel, capped = self.coupling.advance(self.pos, self.vel, self._target, steps)
            self.capped |= capped
        rate_before = self.rate
        if not self.hold_still:
            self.angle, self.rate = AngleSpring().advance(self.angle, self.rate, self.angle_target, steps) \
                if (self.angle != self.angle_target or self.rate) else (self.angle, 0.0)
        if self.clamp():
            clamped_x, clamped_y = self._clamped
            self.vel = (0.0 if clamped_x else self.vel[0], 0.0 if clamped_y else self.vel[1])
        if (self.pos, self.angle) != old or rate_before:
            self.shape = self.shape.moved(*self.pos, self.angle)
            return True
        return False

    def clamp(self) -> bool:
        """Keep the body EDGE_MARGIN cells inside the domain; True if it had to be pushed back."""
        shape = self.shape.moved(*self.pos, self.angle)
        x0, y0, x1, y1 = shape.bounding_box()
        nx, ny = self._grid
        dx = max(0.0, EDGE_MARGIN - x0) - max(0.0, x1 - (nx - 1 - EDGE_MARGIN))
        dy = max(0.0, EDGE_MARGIN - y0) - max(0.0, y1 - (ny - 1 - EDGE_MARGIN))
        self._clamped = (dx != 0, dy != 0)
        if dx or dy:
            self.pos = (self.pos[0] + dx, self.pos[1] + dy)
            self.shape = shape.moved(*self.pos, self.angle)
            return True
        return False
