"""3Dconnexion SpaceMouse as an input device (no force): its cap's deflection is a velocity.

The pose is the deflection integrated over time inside a virtual workspace of +-5 cm (a
position the tunnel mapping treats like any other device's); `angle` integrates the twist.
Mapping: device x right -> pose x; pushing the cap away from you (device -y) -> pose +y.
"""
from __future__ import annotations

import time

from feelflow.haptics.drivers.base import Device
from feelflow.haptics.protocols import spacemouse as sm
from feelflow.haptics.types import Capabilities, Pose

HALF_WIDTH = 0.05  # metres of virtual workspace each side
SPEED = 0.10  # metres per second at full deflection
TWIST_SPEED = 1.5  # radians per second at full twist
DEAD_ZONE = 0.04  # fraction of full scale ignored (the cap never rests exactly at zero)


class SpaceMouse(Device):
    driver_name = "spacemouse"
    continuous = False

    def __init__(self, transport, url: str = "", name: str = "SpaceMouse"):
        super().__init__(transport, url)
        self.name = name
        self._defl = (0.0, 0.0, 0.0)  # x, y, twist in [-1, 1]
        self._buttons = 0
        self._x = self._y = self._angle = 0.0
        self._t = None
        self.good = 0
        self.dropped = 0

    def open(self) -> None:
        w = ((-HALF_WIDTH, HALF_WIDTH), (-HALF_WIDTH, HALF_WIDTH))
        self.capabilities = Capabilities(self.name, 2, w, 0.0, False, "velocity", 60.0)
        self._t = time.monotonic()
        self.last_pose = Pose(0.0, 0.0, 0.0, 0, self._t)

    @staticmethod
    def _norm(v: int) -> float:
        f = max(-1.0, min(1.0, v / sm.FULL_SCALE))
        if abs(f) < DEAD_ZONE:
            return 0.0
        return (f - DEAD_ZONE if f > 0 else f + DEAD_ZONE) / (1 - DEAD_ZONE)

    def poll(self) -> Pose | None:
        now = time.monotonic()
        dt = now - self._t if self._t is not None else 0.0
        self._t = now
        # integrate the deflection held since the last poll, then take the new reports
        dx, dy, dr = self._defl
        self._x = max(-HALF_WIDTH, min(HALF_WIDTH, self._x + dx * SPEED * dt))
        self._y = max(-HALF_WIDTH, min(HALF_WIDTH, self._y + dy * SPEED * dt))
        self._angle += dr * TWIST_SPEED * dt
        while True:
            report = self.transport.read_report(64)
            if not report:
                break
            m = sm.decode_report(report)
            if m is None:
                self.dropped += 1
                continue
            self.good += 1
            if m.translation is not None:
                tx, ty, _ = m.translation
                self._defl = (self._norm(tx), -self._norm(ty), self._defl[2])
            if m.rotation is not None:
                self._defl = (self._defl[0], self._defl[1], -self._norm(m.rotation[2]))
            if m.buttons is not None:
                self._buttons = m.buttons
        self.last_pose = Pose(self._x, self._y, self._angle, self._buttons, now)
        return self.last_pose

    def _send_force(self, fx: float, fy: float) -> None:
        pass  # input only

    @property
    def counters(self) -> dict:
        return {"good": self.good, "dropped": self.dropped}
