"""A Hapkit-style 1-DOF paddle speaking FeelFlow's framed serial protocol (protocols.hapkit)."""
from __future__ import annotations

import time

from feelflow.haptics.drivers.base import Device
from feelflow.haptics.errors import DeviceError
from feelflow.haptics.protocols import hapkit
from feelflow.haptics.types import Capabilities, Pose


class Hapkit(Device):
    driver_name = "hapkit"
    baudrate = 1_000_000  # the paddle sketch's speed: a FORCE + a STATE frame every ms need it
    continuous = True

    def __init__(self, transport, url: str = ""):
        super().__init__(transport, url)
        self.parser = hapkit.FrameParser(accept=(hapkit.INFO, hapkit.STATE))
        self.info: hapkit.Info | None = None
        self._seq = 0

    def open(self) -> None:
        self.transport.reset_input()
        deadline = time.monotonic() + 1.5
        while self.info is None:
            self.transport.write(hapkit.encode_hello())
            t0 = time.monotonic()
            while self.info is None and time.monotonic() - t0 < 0.2:
                for kind, msg in self.parser.feed(self.transport.read_available()):
                    if kind == hapkit.INFO:
                        self.info = msg
                time.sleep(0.001)
            if self.info is None and time.monotonic() > deadline:
                raise DeviceError(f"{self.url}: no answer to HELLO (is the FeelFlow paddle sketch on it?)")
        i = self.info
        self.capabilities = Capabilities("Hapkit paddle", 1, ((i.x_min, i.x_max), (0.0, 0.0)),
                                         i.max_force, True, "position", 1000.0)

    def poll(self) -> Pose | None:
        newest = None
        for kind, msg in self.parser.feed(self.transport.read_available()):
            if kind == hapkit.STATE:
                newest = msg
        if newest is None:
            return None
        self.last_pose = Pose(newest.x, 0.0, 0.0, newest.buttons, time.monotonic())
        return self.last_pose

    def _send_force(self, fx: float, fy: float) -> None:
        self._seq = (self._seq + 1) & 0xFFFF
        self.transport.write(hapkit.encode_force(self._seq, fx))

    def close(self) -> None:
        if not self._closed:
            try:
                self.transport.write(hapkit.encode_stop())
            except DeviceError:
                pass
        super().close()

    @property
    def counters(self) -> dict:
        p = self.parser
        return {"good": p.good, "dropped_bytes": p.dropped_bytes, "bad_crc": p.bad_crc,
                "bad_version": p.bad_version, "malformed": p.malformed, "unexpected": p.unexpected}
