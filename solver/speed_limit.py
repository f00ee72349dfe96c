"""The Mach limit on everything that moves: one clamp for the body and the inflow.

LBM's error grows with Ma^2 (Krueger et al. 2017, sec. 4.5); `FlowConfig.max_speed` = mach_limit * c_s.
The callers keep the returned `capped` flag so the app can show that the limit bit.
"""
from __future__ import annotations

import math


def cap_speed(vx: float, vy: float, max_speed: float) -> tuple[float, float, bool]:
    """Scale (vx, vy) down to |v| <= max_speed, keeping its direction; (vx, vy, capped)."""
    speed = math.hypot(vx, vy)
    if not math.isfinite(speed):
        raise ValueError(f"velocity ({vx}, {vy}) is not finite")
    if speed <= max_speed:
        return float(vx), float(vy), False
    s = max_speed / speed
    return vx * s, vy * s, True


def cap_rigid_motion(velocity, omega: float, radius: float, max_speed: float):
    """Cap a rigid motion so its fastest surface point, |V| + |Omega| R, stays <= max_speed.

    Both V and Omega are scaled by the same factor. Returns ((vx, vy), omega, capped).
    """
    vx, vy = float(velocity[0]), float(velocity[1])
    omega = float(omega)
    top = math.hypot(vx, vy) + abs(omega) * max(radius, 0.0)
    if not math.isfinite(top):
        raise ValueError(f"body motion {velocity}, omega={omega} is not finite")
    if top <= max_speed:
        return (vx, vy), omega, False
    s = max_speed / top
    return (vx * s, vy * s), omega * s, True
