"""From the device to the body: workspace -> tunnel mapping and the virtual coupling.

The virtual coupling (Colgate, Stanley & Brown 1995, "Issues in the haptic display of tool use")
joins the device proxy to the simulated body by a spring-damper, so the body moves smoothly and
at a bounded speed whatever the device does, and the slow solver (tens to hundreds of steps per
frame) never sees the 1 kHz device jitter. The body is a unit mass on a spring-damper to the
proxy: a = w^2 (p_dev - p_body) + 2 zeta w (v_dev - v_body), w = 2 pi f_c, integrated
semi-implicitly at the loop rate (stable for w dt << 1). Damping on the RELATIVE velocity means
no lag while the hand moves steadily; the price is an overshoot of e^-2 (13.5 %) after an
instantaneous step of the proxy at zeta = 1 (a hand does not step; tests check the analytic
step response). The proxy velocity is a finite difference, low-passed at 50 Hz.
"""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class TunnelMap:
    """Linear map from the device workspace (metres) onto a tunnel rectangle (lattice nodes).

    rect: (x0, y0, x1, y1) in lattice nodes. flip_y: device +y is tunnel -y (a pantograph's y
    points away from its motors, towards the student). A 1-DOF device maps to the rectangle's
    horizontal mid-line.
    """

    workspace: tuple[tuple[float, float], tuple[float, float]]
    rect: tuple[float, float, float, float]
    flip_y: bool = False
    dof: int = 2

    def _scales(self):
        (wx0, wx1), (wy0, wy1) = self.workspace
        x0, y0, x1, y1 = self.rect
        sx = (x1 - x0) / (wx1 - wx0)
        sy = (y1 - y0) / (wy1 - wy0) if wy1 > wy0 else 0.0
        return sx, (-sy if self.flip_y else sy)

    def to_tunnel(self, x: float, y: float) -> tuple[float, float]:
        (wx0, wx1), (wy0, wy1) = self.workspace
        x0, y0, x1, y1 = self.rect
        sx, sy = self._scales()
        tx = x0 + (min(max(x, wx0), wx1) - wx0) * sx
        if self.dof < 2 or wy1 <= wy0:
            return tx, 0.5 * (y0 + y1)
        yc = min(max(y, wy0), wy1)
        ty = (y1 - (yc - wy0) * -sy) if self.flip_y else (y0 + (yc - wy0) * sy)
        return tx, ty

    def vector_to_device(self, fx: float, fy: float) -> tuple[float, float]:
        """A tunnel-axis vector expressed in device axes (signs only; magnitudes unchanged)."""
        return fx, (-fy if self.flip_y else fy)

    def torque_to_device(self, torque: float) -> float:
        """A tunnel-axis torque (counter-clockwise positive) about the device's rotational axis:
        a flipped y axis turns the sense of rotation round."""
        return -torque if self.flip_y else torque


class VirtualCoupling:
    """A critically damped spring-damper pulling the body towards the device proxy."""

    def __init__(self, natural_hz: float = 15.0, damping: float = 1.0, max_speed: float = math.inf,
                 velocity_filter_hz: float = 50.0):
        if not (natural_hz > 0 and damping > 0 and max_speed > 0):
            raise ValueError("coupling: natural_hz, damping and max_speed must be positive")
        self.w = 2 * math.pi * natural_hz
        self.zeta = damping
        self.max_speed = max_speed
        self.vf_hz = velocity_filter_hz
        self.reset()

    def reset(self) -> None:
        self.body = None  # (x, y)
        self.vel = (0.0, 0.0)
        self._proxy = None
        self._proxy_vel = (0.0, 0.0)

    def step(self, proxy: tuple[float, float], dt: float):
        """Advance by dt seconds towards `proxy`; returns (body (x, y), velocity (vx, vy))."""
        if self.body is None:
            self.body, self._proxy = proxy, proxy
            return self.body, self.vel
        dt = min(max(dt, 1e-5), 0.01)  # a late tick never becomes a huge explicit step
        a = 1.0 - math.exp(-2 * math.pi * self.vf_hz * dt)
        pvx = (proxy[0] - self._proxy[0]) / dt
        pvy = (proxy[1] - self._proxy[1]) / dt
        self._proxy_vel = (self._proxy_vel[0] + a * (pvx - self._proxy_vel[0]),
                           self._proxy_vel[1] + a * (pvy - self._proxy_vel[1]))
        self._proxy = proxy
        w2, c = self.w * self.w, 2 * self.zeta * self.w
        ax = w2 * (proxy[0] - self.body[0]) + c * (self._proxy_vel[0] - self.vel[0])
        ay = w2 * (proxy[1] - self.body[1]) + c * (self._proxy_vel[1] - self.vel[1])
        vx, vy = self.vel[0] + ax * dt, self.vel[1] + ay * dt
        speed = math.hypot(vx, vy)
        if speed > self.max_speed:
            vx, vy = vx * self.max_speed / speed, vy * self.max_speed / speed
        self.vel = (vx, vy)
        self.body = (self.body[0] + vx * dt, self.body[1] + vy * dt)
        return self.body, self.vel
