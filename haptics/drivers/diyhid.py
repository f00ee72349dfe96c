"""A do-it-yourself force board speaking FeelFlow's vendor-defined HID reports (protocols.diyhid)."""
from __future__ import annotations

import time

from feelflow.haptics.drivers.base import Device
from feelflow.haptics.errors import DeviceError
from feelflow.haptics.protocols import diyhid
from feelflow.haptics.types import Capabilities, Pose


class DiyHid(Device):
    driver_name = "diyhid"
    continuous = True

    def __init__(self, transport, url: str = ""):
        super().__init__(transport, url)
        self.info: diyhid.Info | None = None
        self._seq = 0
        self.good = 0
        self.dropped = 0

    def open(self) -> None:
        deadline = time.monotonic() + 1.0
        self.transport.write_report(diyhid.encode_info_request())
        while self.info is None:
            report = self.transport.read_report(diyhid.REPORT_SIZE)
            msg = diyhid.decode_input(report) if report else None
            if isinstance(msg, diyhid.Info):
                self.info = msg
            elif not report:
                if time.monotonic() > deadline:
                    raise DeviceError(f"{self.url}: no INFO report (is the FeelFlow HID sketch on it?)")
                time.sleep(0.001)
        i = self.info
        self.capabilities = Capabilities("DIY HID board", i.dof, i.workspace, i.max_force, True,
                                         "position", 1000.0)

    def poll(self) -> Pose | None:
        newest = None
        while True:
            report = self.transport.read_report(diyhid.REPORT_SIZE)
            if not report:
                break
            msg = diyhid.decode_input(report)
            if isinstance(msg, diyhid.State):
                newest = msg
                self.good += 1
            elif msg is None:
                self.dropped += 1
        if newest is None:
            return None
        self.last_pose = Pose(newest.x, newest.y, newest.angle, newest.buttons, time.monotonic())
        return self.last_pose

    def read_pose(self, timeout: float = 1.0) -> Pose:
        deadline = time.monotonic() + timeout
        while True:
            pose = self.poll()
            if pose is not None:
                return pose
            if time.monotonic() > deadline:
                raise DeviceError(f"{self.url}: no STATE report within {timeout:.1f} s")
            time.sleep(0.0005)

    def _send_force(self, fx: float, fy: float) -> None:
        self._seq = (self._seq + 1) & 0xFF
        self.transport.write_report(diyhid.encode_force(self._seq, fx, fy, True))

    @property
    def counters(self) -> dict:
        return {"good": self.good, "dropped": self.dropped}
