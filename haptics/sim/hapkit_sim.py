"""A Hapkit-style paddle running FeelFlow's paddle sketch, behind a pseudo-terminal.

Mirrors haptics/firmware/hapkit_paddle/hapkit_paddle.ino: answers HELLO with INFO and every FORCE
with STATE, clamps to MAX_FORCE, and its watchdog drops the force to zero when no FORCE frame
came for 50 ms.
"""
from __future__ import annotations

import threading
import time

from feelflow.haptics.protocols import hapkit
from feelflow.haptics.sim.hand import ForceLog, Hand
from feelflow.haptics.sim.pty_device import PtyDevice

INFO = hapkit.Info(dof=1, x_min=-0.04, x_max=0.04, max_force=2.0, firmware=100)
WATCHDOG_S = 0.050


class HapkitSim(PtyDevice):
    def __init__(self, hand: Hand | None = None, info: hapkit.Info = INFO):
        self.info = info
        self.hand = hand or Hand(0.0, 0.0, ((info.x_min, info.x_max), (0.0, 0.0)))
        self.forces = ForceLog()
        self.parser = hapkit.FrameParser(accept=(hapkit.HELLO, hapkit.FORCE, hapkit.STOP))
        self.motor_force = 0.0
        self.last_force_at = None
        self.watchdog_trips = 0
        super().__init__()
        self._wd = threading.Thread(target=self._watchdog, daemon=True)
        self._wd.start()

    def _watchdog(self):
        while not self._stop.is_set():
            time.sleep(0.005)
            if (self.motor_force != 0.0 and self.last_force_at is not None
                    and time.monotonic() - self.last_force_at > WATCHDOG_S):
                self.motor_force = 0.0
                self.watchdog_trips += 1

    def on_bytes(self, data: bytes) -> bytes:
        out = bytearray()
        for kind, msg in self.parser.feed(data):
            if kind == hapkit.HELLO:
                out += hapkit.encode_info(self.info)
                continue
            seq = 0
            if kind == hapkit.FORCE:
                seq, f = msg
                f = max(-self.info.max_force, min(self.info.max_force, f))
                self.motor_force = f
                self.last_force_at = time.monotonic()
            else:  # STOP
                self.motor_force = 0.0
            self.forces.record(self.motor_force, 0.0)
            x, _ = self.hand.get()
            out += hapkit.encode_state(hapkit.State(seq, x, self.hand.buttons))
        return bytes(out)
