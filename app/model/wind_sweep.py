"""A wind sweep: the inlet's speed held at each of several values in turn (the 'Drag grows with
speed' lesson), as a `MotionRunner` (solver/motion.py) drives the body through a script.

Each change of wind is spread over `slew_steps` (linear), not made at once: a sudden change
sends a pressure pulse (rho c_s dU) through the tunnel that rings between the walls, across the
stream, where the outlet's absorbing layer cannot take it out; 500 steps is a little more than
that ringing's period at the lessons' 128 rows (2 ny / c_s = 443 steps). Measured (`feelflow
report lessons --compare`, docs/science/validation.md 'Calm tunnels'): the drag's scatter over
the second half of each hold falls severalfold. Qt-free; lattice units (steps, cells per step).
"""
from __future__ import annotations

from dataclasses import dataclass

#: steps over which each change of wind is spread (module docstring)
SLEW_STEPS = 500


@dataclass(frozen=True)
class WindSweep:
    """Hold each of `speeds` for `hold_steps` steps, the first from step `start`."""

    speeds: tuple[float, ...]
    hold_steps: int
    start: int
    slew_steps: int = SLEW_STEPS

    @property
    def end(self) -> int:
        """The step at which the sweep ends."""
        return self.start + len(self.speeds) * self.hold_steps

    def stage(self, time: int) -> int | None:
        """Which speed holds at step `time` (0 before the start), or None once the sweep is over."""
        k = max(0, time - self.start) // self.hold_steps
        return k if k < len(self.speeds) else None

    def wind(self, time: int) -> float | None:
        """The inlet's speed at step `time`: each step to the next speed spread over
        `slew_steps`; None when the sweep is over."""
        k = self.stage(time)
        if k is None:
            return None
        if k == 0 or self.slew_steps <= 0:
            return self.speeds[k]
        frac = min(1.0, (time - self.start - k * self.hold_steps) / self.slew_steps)
        return self.speeds[k - 1] + frac * (self.speeds[k] - self.speeds[k - 1])
