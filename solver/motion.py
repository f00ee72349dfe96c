"""Motion scripts: a body driven through phases of constant velocity (the seed's experiment:
stopped, moving with the stream, stopped, moving against it).

`MotionRunner` is the one place that turns a script into `feelflow.solver.set_body` calls: `feelflow run`,
the validation cases, the report and the GUI's scripted mode all use it. Positions advance exactly by the velocity
each step (sub-cell poses), and the body is re-placed before every step it moves.
"""
from __future__ import annotations

from dataclasses import dataclass

from feelflow.solver.force_average import StepWeightedMean

#: phase kinds a scene may name instead of an explicit velocity
MOVES = ("stop", "with", "against")


@dataclass(frozen=True)
class Phase:
    """`steps` steps at body velocity `velocity` (lattice units per step)."""

    steps: int
    velocity: tuple[float, float] = (0.0, 0.0)


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
                return phase.velocity
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
            dx += k * phase.velocity[0]
            dy += k * phase.velocity[1]
            start += phase.steps
        return dx, dy

    def extreme_displacements(self, steps: int):
        """Displacements at the start and at every phase end up to `steps` (the pose moves
        linearly within a phase, so these bound where the body goes)."""
        times = [0]
        start = 0
        for phase in self.phases:
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
        """Run n steps along the script; the force per model averaged over them. Raises
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
            total.add(self.solver.forces(), k)
            self.t += k
            remaining -= k
        self.solver.check_physical()   # SolverDiverged when the flow left the physical range
        return total.mean()
