"""Haply 2DIY: a 2-DOF pantograph on the Haply M3 board (hAPI serial protocol, firmware v1.5).

Port set-up as the hAPI examples configure a 2DIY (generation 2): actuator 1 on port 2 (CCW),
actuator 2 on port 1 (CW); encoder 1 on port 2 (CCW, offset 241 deg), encoder 2 on port 1 (CW,
offset -61 deg), 10752 counts per revolution. Motor 1 is the pantograph's th1 (right arm).
"""
from __future__ import annotations

import math
import time

from feelflow.haptics.drivers.base import Device
from feelflow.haptics.errors import DeviceError
from feelflow.haptics.kinematics import HAPLY_2DIY, OutOfReach
from feelflow.haptics.protocols import haply
from feelflow.haptics.types import Capabilities, Pose

DEVICE_ID = 5
#: port -> (motor dir, encoder dir, encoder offset deg, resolution); port 2 = joint 1
PORTS = [haply.PortSetup(1, haply.CW, haply.CW, -61.0, 10752.0),
         haply.PortSetup(2, haply.CCW, haply.CCW, 241.0, 10752.0)]
#: M3 firmware MAX_TORQUE is 0.123 N m per motor; at the 0.07 m arm that is ~1.76 N; we allow
#: 1.5 N at the handle so no pose asks a motor for more than it can give near the centre.
MAX_FORCE = 1.5
WORKSPACE = ((-0.06, 0.06), (0.06, 0.14))
MAX_TORQUE = 0.123


class Haply2DIY(Device):
    driver_name = "haply2diy"
    continuous = True

    def __init__(self, transport, url: str = "", device_id: int = DEVICE_ID):
        super().__init__(transport, url)
        self.device_id = device_id
        self.mech = HAPLY_2DIY
        self.parser = haply.StateParser(device_id, len(PORTS))
        self._angles = None  # (th1, th2) radians of the last good reply
        self.unreachable = 0

    def open(self) -> None:
        self.transport.reset_input()
        self.transport.write(haply.encode_reset(self.device_id))
        self.transport.write(haply.encode_setup(self.device_id, PORTS))
        self.capabilities = Capabilities("Haply 2DIY", 2, WORKSPACE, MAX_FORCE, True, "position", 1000.0)
        try:
            self.read_pose(timeout=1.0)
        except DeviceError:
            raise DeviceError(f"{self.url}: the Haply board did not answer (is firmware v1.5 on it?)") from None

    def poll(self) -> Pose | None:
        angles = self.parser.feed(self.transport.read_available())
        if angles is None:
            return None
        # port order: port 1 = encoder 2 (th2), port 2 = encoder 1 (th1)
        th2, th1 = (math.radians(a) for a in angles)
        try:
            x, y = self.mech.forward(th1, th2)
        except OutOfReach:
            self.unreachable += 1
            return None
        self._angles = (th1, th2)
        self.last_pose = Pose(x, y, 0.0, 0, time.monotonic())
        return self.last_pose

    def _send_force(self, fx: float, fy: float) -> None:
        if self._angles is None or (fx == 0.0 and fy == 0.0):
            t1 = t2 = 0.0
        else:
            t1, t2 = self.mech.torques(*self._angles, fx, fy)
            peak = max(abs(t1), abs(t2))
            if peak > MAX_TORQUE:  # near a singularity: scale down, keep the direction
                t1, t2 = t1 * MAX_TORQUE / peak, t2 * MAX_TORQUE / peak
        self.transport.write(haply.encode_write(self.device_id, [t2, t1]))  # port order

    @property
    def counters(self) -> dict:
        p = self.parser
        return {"good": p.good_replies, "dropped_bytes": p.dropped_bytes, "bad": p.bad_replies,
                "stale": p.stale_replies, "unreachable": self.unreachable}
