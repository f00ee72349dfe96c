"""HID devices simulated at the hidapi boundary: objects with the hid.device methods FeelFlow
uses (open, open_path, set_nonblocking, read, write, get_feature_report, close). Reports are the
real byte layouts (protocols.spacemouse, protocols.diyhid)."""
from __future__ import annotations

import collections
import threading
import time

from feelflow.haptics.protocols import diyhid
from feelflow.haptics.protocols import spacemouse as sm
from feelflow.haptics.sim.hand import ForceLog, Hand


class _HidBase:
    def __init__(self):
        self._queue = collections.deque()
        self._lock = threading.Lock()
        self.unplugged = False
        self.closed = False

    # hid.device API ---------------------------------------------------------------------
    def open(self, vid=None, pid=None, serial=None):
        return None

    def open_path(self, path):
        return None

    def set_nonblocking(self, flag):
        self._check()
        return 0

    def _check(self):
        if self.unplugged:
            raise OSError("read error (device disconnected)")

    def read(self, size, timeout_ms=0):
        self._check()
        self._produce()
        with self._lock:
            if not self._queue:
                return []
            return list(self._queue.popleft()[:size])

    def write(self, data):
        self._check()
        return len(data)

    def get_feature_report(self, report_id, size):
        self._check()
        return []

    def close(self):
        self.closed = True

    # simulator side -----------------------------------------------------------------------
    def _produce(self):
        pass

    def inject(self, report: bytes) -> None:
        """Queue a raw input report (tests: malformed or truncated ones)."""
        with self._lock:
            self._queue.append(bytes(report))

    def unplug(self) -> None:
        self.unplugged = True

    def stop(self) -> None:
        self.closed = True


class SpaceMouseSim(_HidBase):
    """A SpaceNavigator (046d:c626): 7-byte reports 1 (translation), 2 (rotation), 3 (buttons),
    sent while the cap is deflected at about 60 Hz, and once on release."""

    vid, pid = 0x046D, 0xC626

    def __init__(self):
        super().__init__()
        self.translation = (0, 0, 0)
        self.rotation = (0, 0, 0)
        self._last_sent = 0.0

    def set_deflection(self, tx=0, ty=0, tz=0, rx=0, ry=0, rz=0) -> None:
        self.translation, self.rotation = (tx, ty, tz), (rx, ry, rz)
        self.inject(sm.encode_translation(*self.translation))
        self.inject(sm.encode_rotation(*self.rotation))

    def press(self, mask: int) -> None:
        self.inject(sm.encode_buttons(mask))

    def _produce(self):
        now = time.monotonic()
        if any(self.translation + self.rotation) and now - self._last_sent > 1 / 60:
            self._last_sent = now
            self.inject(sm.encode_translation(*self.translation))
            self.inject(sm.encode_rotation(*self.rotation))


class DiyHidSim(_HidBase):
    """A board running haptics/firmware/diy_hid_board: streams STATE at 1 kHz, answers
    INFO_REQUEST, clamps forces and zeroes them after 50 ms without a FORCE report."""

    vid, pid = diyhid.DEFAULT_VID, diyhid.DEFAULT_PID
    INFO = diyhid.Info(dof=2, max_force=3.0, workspace=((-0.05, 0.05), (-0.04, 0.04)))
    WATCHDOG_S = 0.050

    def __init__(self, hand: Hand | None = None):
        super().__init__()
        self.info = self.INFO
        self.hand = hand or Hand(0.0, 0.0, self.info.workspace)
        self.forces = ForceLog()
        self.motor = (0.0, 0.0)
        self.last_force_at = None
        self._seq = 0
        self._next_state = 0.0

    def write(self, data):
        self._check()
        msg = diyhid.decode_output(bytes(data[1:]))  # data[0] is hidapi's report id 0
        if msg is None:
            return len(data)
        if msg[0] == "info_request":
            self.inject(diyhid.encode_info(self.info))
        else:
            _, _, fx, fy, enabled = msg
            from feelflow.haptics.drivers.base import clamp_force
            self.motor = clamp_force(fx, fy, self.info.max_force) if enabled else (0.0, 0.0)
            self.last_force_at = time.monotonic()
            self.forces.record(*self.motor)
        return len(data)

    def _produce(self):
        now = time.monotonic()
        if self.last_force_at is not None and now - self.last_force_at > self.WATCHDOG_S:
            self.motor = (0.0, 0.0)
        if now >= self._next_state:
            self._next_state = max(self._next_state + 0.001, now - 0.002)
            self._seq = (self._seq + 1) & 0xFF
            x, y = self.hand.get()
            self.inject(diyhid.encode_state(diyhid.State(self._seq, x, y, 0.0, self.hand.buttons, 0)))
