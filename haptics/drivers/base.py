"""The one device interface every driver implements.

Forces are newtons in the DEVICE frame; poses metres in the device frame (haptics.types.Pose).
`write_force` clamps to `capabilities.max_force` itself, so a driver can never be asked for more
than its device can give, whatever the caller computed (the force loop clamps as well).
"""
from __future__ import annotations

import math
import time
from abc import ABC, abstractmethod

from feelflow.haptics.errors import DeviceError
from feelflow.haptics.types import Capabilities, Pose


def clamp_force(fx: float, fy: float, max_force: float) -> tuple[float, float]:
    """(fx, fy) scaled down so its magnitude is at most max_force; non-finite -> (0, 0)."""
    if not (math.isfinite(fx) and math.isfinite(fy)) or max_force <= 0:
        return 0.0, 0.0
    mag = math.hypot(fx, fy)
    if mag > max_force:
        s = max_force / mag
        return fx * s, fy * s
    return fx, fy


def clamp_torque(torque: float, max_torque: float) -> float:
    """A torque within +-max_torque; non-finite gives 0 (never pass NaN to a motor)."""
    if not math.isfinite(torque):
        return 0.0
    return max(-max_torque, min(max_torque, torque))


class Device(ABC):
    """A haptic device (or an input-only one) behind a transport."""

    #: True when the device answers every force command with a pose (the loop then treats
    #: a long silence as a disconnect); False for devices that report only on change.
    continuous = True
    driver_name = "abstract"
    baudrate = 115200  # serial drivers: the firmware's speed (native-USB boards ignore it)

    def __init__(self, transport, url: str = ""):
        self.transport = transport
        self.url = url
        self.capabilities: Capabilities | None = None
        self.last_pose: Pose | None = None
        self.last_command = (0.0, 0.0)
        self.simulator = None  # set by open_device for sim:// devices
        self._closed = False

    # -- life cycle -------------------------------------------------------------------
    @abstractmethod
    def open(self) -> None:
        """Handshake; fills `capabilities`. Raises DeviceError when the device does not answer."""

    def close(self) -> None:
        """Zero force, close the transport (and stop the simulator behind a sim:// device)."""
        if self._closed:
            return
        self._closed = True
        try:
            if self.capabilities is not None and self.capabilities.can_output_force:
                self._send_force(0.0, 0.0)
                if self.capabilities.max_torque > 0:
                    self._send_torque(0.0)
        except DeviceError:
            pass
        self.transport.close()
        if self.simulator is not None:
            self.simulator.stop()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # -- I/O ----------------------------------------------------------------------------
    @abstractmethod
    def poll(self) -> Pose | None:
        """The newest pose that arrived since the last call, without waiting (None if none)."""

    def read_pose(self, timeout: float = 1.0) -> Pose:
        """Wait for a fresh pose (re-sending the last force command where the protocol needs a
        request). Raises DeviceError on timeout."""
        deadline = time.monotonic() + timeout
        while True:
            if self.continuous and self.capabilities is not None and self.capabilities.can_output_force:
                self._send_force(*self.last_command)
            pose = None
            t_req = time.monotonic()
            while pose is None and time.monotonic() - t_req < 0.02:
                pose = self.poll()
                if pose is None:
                    time.sleep(0.0005)
            if pose is not None:
                return pose
            if not self.continuous and self.last_pose is not None:
                return self.last_pose
            if time.monotonic() > deadline:
                raise DeviceError(f"{self.url or self.driver_name}: no pose within {timeout:.1f} s")

    def write_force(self, fx: float, fy: float = 0.0) -> tuple[float, float]:
        """Command (fx, fy) newtons, clamped to the device maximum; returns what was sent."""
        caps = self.capabilities
        if caps is None or not caps.can_output_force:
            self.last_command = (0.0, 0.0)
            return 0.0, 0.0
        fx, fy = clamp_force(fx, fy if caps.dof >= 2 else 0.0, caps.max_force)
        self._send_force(fx, fy)
        self.last_command = (fx, fy)
        return fx, fy

    @abstractmethod
    def _send_force(self, fx: float, fy: float) -> None:
        """Encode and send an already clamped force."""

    def write_torque(self, torque: float) -> float:
        """Command `torque` newton metres on the rotational axis, clamped to its maximum; returns
        what was sent (0 where the device has no rotational axis that outputs force)."""
        caps = self.capabilities
        if caps is None or not caps.can_output_force or caps.max_torque <= 0:
            return 0.0
        torque = clamp_torque(torque, caps.max_torque)
        self._send_torque(torque)
        return torque

    def _send_torque(self, torque: float) -> None:
        """Encode and send an already clamped torque (devices with max_torque > 0 define it)."""
        raise DeviceError(f"{self.url or self.driver_name}: no rotational axis to drive")

    @property
    def counters(self) -> dict:
        """Protocol health: good packets and what was dropped (malformed, truncated, stale)."""
        return {}
