"""Motion scripts: a body driven through phases of constant velocity (the seed's experiment:
stopped, moving with the stream, stopped, moving against it).

`MotionRunner` is the one place that turns a script into `feelflow.solver.set_body` calls: `feelflow run`,
the validation cases, the report and the GUI's scripted mode all use it. Positions advance exactly by the velocity
each step (sub-cell poses), and the body is re-placed before every step it moves.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from feelflow.solver.force_average import StepWeightedMean

#: phase kinds a scene may name instead of an explicit velocity
MOVES = ("stop", "with", "against")


@dataclass(frozen=True)
class Phase:
    """`steps` steps at body velocity `velocity` (lattice units per step), with, where `period`
    > 0, a sinusoidal displacement `amplitude` sin(2 pi k / period) on top (k: steps into the
    phase; an in-line oscillating cylinder, Duetsch et al., J. Fluid Mech. 360 (1998) 249, moves
    as x = -A sin(2 pi f t): amplitude (-A, 0), period 1 / f)."""

    steps: int
    velocity: tuple[float, float] = (0.0, 0.0)
    amplitude: tuple[float, float] = (0.0, 0.0)
    period: float = 0.0

    @property
    def oscillates(self) -> bool:
        return self.period > 0 and self.amplitude != (0.0, 0.0)

    def displacement(self, k: int) -> tuple[float, float]:
        """Displacement after k steps of this phase."""
        dx, dy = k * self.velocity[0], k * self.velocity[1]
        if self.oscillates:
            s = math.sin(2.0 * math.pi * k / self.period)
            dx, dy = dx + self.amplitude[0] * s, dy + self.amplitude[1] * s
        return dx, dy

    def step_velocity(self, k: int) -> tuple[float, float]:
        """The body velocity during step k of this phase: what the pose moves in that step (so
        that the positions the runner places and the wall velocity agree exactly)."""
        if not self.oscillates:
            return self.velocity
        (x0, y0), (x1, y1) = self.displacement(k), self.displacement(k + 1)
        return x1 - x0, y1 - y0

    @property
    def peak_speed(self) -> float:
        """An upper bound of the phase's speed: |V| + 2 pi |A| / period."""
        extra = 2.0 * math.pi * math.hypot(*self.amplitude) / self.period if self.oscillates else 0.0
        return math.hypot(*self.velocity) + extra

    def turning_points(self) -> list[int]:
        """Steps into the phase near which a sinusoidal displacement peaks (both neighbours of
        each quarter and three-quarter period), for bounding where the body goes."""
        if not self.oscillates:
            return []
        out, t = [], self.period / 4.0
        while t < self.steps:
            out += [int(math.floor(t)), int(math.ceil(t))]
            t += self.period / 2.0
        return [k for k in out if 0 <= k <= self.steps]


def phase_velocity(move: str, speed: float, stream_direction=(1.0, 0.0)) -> tuple[float, float]:
    """The velocity of a named phase: stopped, with the stream or against it, at `speed`."""
    if move not in MOVES:
        raise ValueError(f"must be one of {MOVES}, got {move!r}")
    sign = {"stop": 0.0, "with": 1.0, "against": -1.0}[move]
    return (sign * speed * stream_direction[0], sign * speed * stream_direction[1])


class MotionScript:
    """Phases one after the other; after the last one the body stays where it is, at rest."""

    def __init__(self, phases=()):
        self.phases = tuple(phases)

    @property
    def total_steps(self) -> int:
        return sum(p.steps for p in self.phases)

    def velocity_at(self, t: int) -> tuple[float, float]:
        """Body velocity during step t (t = 0 is the first step)."""
        start = 0
        for phase in self.phases:
            if t < start + phase.steps:
                return phase.step_velocity(t - start)
            start += phase.steps
        return (0.0, 0.0)

    def steps_left_in_phase(self, t: int) -> int | None:
        """Steps from t to the end of its phase (None after the script: no end)."""
        start = 0
        for phase in self.phases:
            start += phase.steps
            if t < start:
                return start - t
        return None

    def displacement(self, t: int) -> tuple[float, float]:
        """Body displacement after t steps."""
        dx = dy = 0.0
        start = 0
        for phase in self.phases:
            k = min(phase.steps, max(0, t - start))
            px, py = phase.displacement(k)
            dx += px
            dy += py
            start += phase.steps
        return dx, dy

    def extreme_displacements(self, steps: int):
        """Displacements at the start, at every phase end and near every turning point of an
        oscillating phase, up to `steps` (elsewhere the pose moves monotonically, so these
        bound where the body goes)."""
        times = [0]
        start = 0
        for phase in self.phases:
            times += [min(start + k, steps) for k in phase.turning_points()]
            start += phase.steps
            times.append(min(start, steps))
        times.append(steps)
        return [(t, self.displacement(t)) for t in sorted(set(times))]


class MotionRunner:
    """Moves `shape` through `script` in `solver`; returns mean forces per model.

    Pose at step t: X(t) = X(0) + displacement(t). Before every step in which the body moves,
    `feelflow.solver.set_body(shape at X(t), V(t))`; while it rests, the solver steps in blocks.
    """

    def __init__(self, solver, shape, script: MotionScript):
        self.solver = solver
        self.script = script
        self.shape0 = shape
        self.t = 0
        self._placed = None  # (t, velocity) of the last set_body
        self.last_torques: dict[str, float] = {}  # mean torque per model of the last advance
        self._place(self.script.velocity_at(0))

    @property
    def position(self) -> tuple[float, float]:
        dx, dy = self.script.displacement(self.t)
        return self.shape0.x + dx, self.shape0.y + dy

    @property
    def shape(self):
        """The body at its current pose."""
        x, y = self.position
        return self.shape0.moved(x=x, y=y)

    def _place(self, velocity):
        self.solver.set_body(self.shape, velocity=velocity)
        self._placed = (self.t, velocity)

    def advance(self, n: int) -> dict[str, tuple[float, float]]:
        """Run n steps along the script; the force per model averaged over them (the torques'
        means in `last_torques`). Raises
        `SolverDiverged` when the flow has left the physical range (`Solver.check_physical`)."""
        total = StepWeightedMean()

        remaining = n
        while remaining > 0:
            v = self.script.velocity_at(self.t)
            moving = v != (0.0, 0.0)
            if moving:
                if self._placed != (self.t, v):
                    self._place(v)
                k = 1
            else:
                if self._placed is None or self._placed[1] != v:
                    self._place(v)
                left = self.script.steps_left_in_phase(self.t)
                k = remaining if left is None else min(remaining, left)
            self.solver.step(k)
            total.add(self.solver.forces(), k, self.solver.torques())
            self.t += k
            remaining -= k
        self.solver.check_physical()   # SolverDiverged when the flow left the physical range
        self.last_torques = total.torque_mean()
        return total.mean()
