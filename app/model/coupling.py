"""The mouse's grip on the body: a critically damped spring-damper (virtual coupling,
Colgate, Stanley & Brown 1995), with the body's speed capped at the Mach limit, both in the
tunnel's frame and relative to the wind (`stream`): a body pulled against a wind of 0.09 at 0.09
would meet the fluid at twice the Mach limit's speed, beyond where the accuracy cases hold
(docs/science/collision-operators.md, 'Mach number').

Lattice units throughout: positions in cells, time in solver steps.
"""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass
class SpringDamper:
    """x'' = w0^2 (target - x) - 2 w0 x' (critical damping), |x'| <= max_speed and
    |x' - stream| <= max_speed (the wind's velocity, cells per step; (0, 0) in still fluid)."""

    w0: float = 0.02          # natural frequency, radians per step (settles in ~ 4/w0 steps)
    max_speed: float = 0.098  # cells per step
    stream: tuple = (0.0, 0.0)

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
            (vx, vy), bit = cap_relative(vx, vy, self.stream, self.max_speed)
            capped |= bit
            x += vx
            y += vy
        return (x, y), (vx, vy), capped


def cap_relative(vx: float, vy: float, stream, max_speed: float):
    """(vx, vy) with its speed relative to `stream` scaled down to max_speed, then its own speed:
    both stay within max_speed (the disc about the stream holds 0 when |stream| <= max_speed, so the
    second scaling keeps the first). Returns ((vx, vy), capped)."""
    sx, sy = float(stream[0]), float(stream[1])
    capped = False
    rel = math.hypot(vx - sx, vy - sy)
    if rel > max_speed:
        k = max_speed / rel
        vx, vy = sx + (vx - sx) * k, sy + (vy - sy) * k
        capped = True
    s = math.hypot(vx, vy)
    if s > max_speed:
        vx, vy = vx * max_speed / s, vy * max_speed / s
        capped = True
    return (vx, vy), capped


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
