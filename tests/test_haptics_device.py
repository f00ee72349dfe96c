"""Real hardware (opt-in): FEELFLOW_DEVICE=serial:///dev/ttyACM0?driver=haply2diy pytest -m device

Checks the handshake, that poses arrive at the loop rate, and that the loop's safety rules hold
on the real device. Nothing here runs without a device (the tier is deselected by default).
"""
import os
import time

import pytest

from feelflow.haptics import ForceLoop, ForceSample, LoopConfig, open_device

URL = os.environ.get("FEELFLOW_DEVICE")
pytestmark = [pytest.mark.device,
              pytest.mark.skipif(not URL, reason="set FEELFLOW_DEVICE to a device URL")]


@pytest.fixture
def device():
    dev = open_device(URL)
    yield dev
    dev.close()


def test_handshake_and_pose(device):
    caps = device.capabilities
    assert caps.dof in (1, 2) and caps.max_force >= 0
    pose = device.read_pose(timeout=1.0)
    (x0, x1), _ = caps.workspace
    assert x0 - 0.05 <= pose.x <= x1 + 0.05


def test_loop_runs_and_stops_safely(device):
    loop = ForceLoop(device, LoopConfig(expected_peak=1.0, comfort_fraction=0.2))
    loop.start()
    try:
        t0 = time.monotonic()
        while time.monotonic() - t0 < 1.0:  # a gentle constant push (20 % of the maximum)
            loop.submit_force(ForceSample(0.5, 0.0, time.monotonic()))
            time.sleep(0.01)
        st = loop.status()
        assert st.running and st.rate_hz > 900
        assert st.max_force_commanded <= device.capabilities.max_force
        loop.emergency_stop()
        time.sleep(0.05)
        assert loop.status().force == (0.0, 0.0)
    finally:
        loop.stop()
