"""A haptic device as the window's input: opens it through `haptics`, runs its 1 kHz force
loop, hands the body target to the simulation and the selected model's force to the device.

The loop runs as `feelflow.haptics.ProcessForceLoop`, in a process of its own: in this window the GUI,
the solver and GL calls hold Python's interpreter lock, which stalled an in-process loop
thread for 3-11 ms at the 99th percentile (docs/guide/haptic-devices.md); in its own process it kept p99
jitter under 1 ms. A disconnect (reported from the loop's watcher thread) comes back to the
GUI thread as a Qt signal."""
from __future__ import annotations

import time

from PySide6.QtCore import QObject, Signal

from feelflow.solver import units


class DeviceInput(QObject):
    disconnected = Signal(str)

    def __init__(self, url: str, tunnel_size, expected_peak: float, parent=None, expected_peak_torque: float = 1.0):
        from feelflow.haptics import LoopConfig, ProcessForceLoop

        super().__init__(parent)
        self.url = url
        nx, ny = tunnel_size
        # DeviceError / BadDeviceURL: one line for the user
        self.loop = ProcessForceLoop(url, LoopConfig(tunnel_rect=(0.0, 0.0, nx - 1.0, ny - 1.0),
                                                     expected_peak=expected_peak,
                                                     expected_peak_torque=expected_peak_torque),
                                     on_disconnect=lambda reason: self.disconnected.emit(str(reason)))
        self.loop.start()
        self.name = url

    @staticmethod
    def expected_peak(sim) -> float:
        """The force the scene can reach: C about 2 at the Mach-limit speed over the body size."""
        return 2.0 * units.dynamic_pressure(sim.config.max_speed) * sim.params.size

    @staticmethod
    def expected_peak_torque(sim) -> float:
        """The torque the scene can reach: that force at half the body size from its centre."""
        return DeviceInput.expected_peak(sim) * sim.params.size / 2.0

    def target(self):
        """(x, y) in lattice nodes where the device puts the body, or None before its first pose."""
        bt = self.loop.body_target()
        return (bt.x, bt.y) if bt.valid else None

    def submit(self, force, step: int, torque: float = 0.0):
        """The selected model's force and torque (lattice units) to the device's loop."""
        from feelflow.haptics import ForceSample

        self.loop.submit_force(ForceSample(float(force[0]), float(force[1]), time.monotonic(), step,
                                           torque=float(torque)))

    def pause(self, paused: bool):
        self.loop.pause() if paused else self.loop.resume()

    def emergency_stop(self):
        """The stop key: force to zero at the next tick, until the device is chosen again."""
        self.loop.emergency_stop()

    def close(self):
        """Zero force, close the device, end the loop's process."""
        self.loop.close()
