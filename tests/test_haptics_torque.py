"""The torque's way to a device with a rotational axis (haptics/loop.py): scaled like the force,
clamped to the axis's maximum, zeroed by the same stall and NaN rules, and sent to no device
without such an axis. No driver in FeelFlow has a rotational axis that outputs force yet, so the
device here is a stand-in at the hardware edge (a Device subclass that records its commands);
the loop, its thread, its timing and its safety gate are the real ones."""
from __future__ import annotations

import math
import time

import pytest

from feelflow.haptics import ForceLoop, LoopConfig, SafetyConfig, open_device
from feelflow.haptics.drivers.base import Device, clamp_torque
from feelflow.haptics.types import Capabilities, Pose
from haptics_helpers import Feeder, wait_for

PEAK, PEAK_TORQUE = 0.01, 0.08  # lattice units; each felt as half its device maximum


class RotaryStandIn(Device):
    """A 2-DOF device with a rotational axis of 0.2 N m; records what it is sent."""

    driver_name = "rotary-stand-in"

    def __init__(self):
        super().__init__(transport=None, url="stand-in://rotary")
        self.torques = []

    def open(self):
        self.capabilities = Capabilities("rotary stand-in", 2, ((0.0, 0.1), (0.0, 0.1)), 4.0, max_torque=0.2)

    def close(self):
        self._closed = True

    def poll(self):
        return Pose(0.05, 0.05, 0.0, 0, time.monotonic())

    def _send_force(self, fx, fy):
        pass

    def _send_torque(self, torque):
        self.torques.append(torque)


def make_loop(dev, **kw):
    cfg = LoopConfig(tunnel_rect=(0, 0, 200, 100), expected_peak=PEAK, expected_peak_torque=PEAK_TORQUE,
                     comfort_fraction=0.5, safety=SafetyConfig(ramp_time=0.05), realtime=False, **kw)
    return ForceLoop(dev, cfg)


def test_clamp_torque():
    assert clamp_torque(0.5, 0.2) == 0.2 and clamp_torque(-0.5, 0.2) == -0.2 and clamp_torque(0.1, 0.2) == 0.1
    assert clamp_torque(math.nan, 0.2) == 0.0 and clamp_torque(math.inf, 0.2) == 0.0


def test_a_rotational_axis_feels_the_torque_through_the_force_path_safety():
    dev = RotaryStandIn()
    dev.open()
    loop = make_loop(dev)
    half = 0.5 * dev.capabilities.max_torque
    with Feeder(loop, PEAK) as feeder:
        feeder.torque = -PEAK_TORQUE                   # clockwise: the body resists a turn
        loop.start()
        try:
            assert wait_for(lambda: loop.torque_sent < -0.95 * half, 3.0), loop.torque_sent
            assert loop.torque_sent == pytest.approx(-half, rel=0.05)   # scaled like the force
            feeder.torque = -100 * PEAK_TORQUE         # a scene far beyond its expected peak
            assert wait_for(lambda: loop.torque_sent == -dev.capabilities.max_torque, 2.0)
            assert min(dev.torques) >= -dev.capabilities.max_torque   # clamped, never beyond
            feeder.torque = math.nan                   # a NaN torque zeroes force and torque at once
            assert wait_for(lambda: loop.status().state == "nan" and loop.torque_sent == 0.0
                            and loop.status().force == (0.0, 0.0), 2.0)
            feeder.torque = PEAK_TORQUE
            assert wait_for(lambda: loop.torque_sent > 0.95 * half, 3.0)
            feeder.sending = False                     # the solver stalls: the torque goes to zero
            assert wait_for(lambda: loop.status().state == "stall" and loop.torque_sent == 0.0, 2.0)
        finally:
            loop.stop()
    assert dev.torques[-1] == 0.0                       # stopped: zero on the axis


def test_a_device_without_a_rotational_axis_gets_no_torque():
    dev = open_device("sim://hapkit")
    try:
        loop = make_loop(dev)
        with Feeder(loop, PEAK) as feeder:
            feeder.torque = PEAK_TORQUE
            loop.start()
            try:
                assert wait_for(lambda: math.hypot(*loop.status().force) > 0.4 * dev.capabilities.max_force, 3.0)
                assert loop.torque_sent == 0.0 and dev.write_torque(1.0) == 0.0
            finally:
                loop.stop()
    finally:
        dev.close()
