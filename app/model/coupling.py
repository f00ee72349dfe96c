"""The mouse's grip on the body: a critically damped spring-damper (virtual coupling,
Colgate, Stanley & Brown 1995), with the body's speed capped at the Mach limit.

Lattice units throughout: positions in cells, time in solver steps.
"""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass
class SpringDamper:
    """x'' = w0^2 (target - x) - 2 w0 x' (critical damping), |x'| <= max_speed."""

    w0: float = 0.02          # natural frequency, radians per step (settles in ~ 4/w0 steps)
    max_speed: float = 0.098  # cells per step

    def advance(self, pos, vel, target, steps: int):
        """Integrate `steps` steps (semi-implicit Euler). Returns (pos, vel, capped)."""
        x, y = pos
        vx, vy = vel
        capped = False
        w0 = self.w0
        for _ in range(max(1, int(steps))):
            if target is None:  # let go: the body brakes to a stop
                ax, ay = -2 * w0 * vx, -2 * w0 * vy
            else:
                ax = w0 * w0 * (target[0] - x) - 2 * w0 * vx
                ay = w0 * w0 * (target[1] - y) - 2 * w0 * vy
            vx += ax
            vy += ay
            s = math.hypot(vx, vy)
            if s > self.max_speed:
                vx, vy = vx * self.max_speed / s, vy * self.max_speed / s
                capped = True
            x += vx
            y += vy
        return (x, y), (vx, vy), capped


@dataclass
class AngleSpring:
    """The same coupling for the angle of attack; `max_rate` keeps the tip below the Mach limit."""

    w0: float = 0.03
    max_rate: float = 0.005  # radians per step

    def advance(self, angle: float, rate: float, target: float, steps: int):
        for _ in range(max(1, int(steps))):
            rate += self.w0 * self.w0 * (target - angle) - 2 * self.w0 * rate
            rate = max(-self.max_rate, min(self.max_rate, rate))
            angle += rate
        if abs(target - angle) < 1e-4 and abs(rate) < 1e-5:
            angle, rate = target, 0.0
        return angle, rate
