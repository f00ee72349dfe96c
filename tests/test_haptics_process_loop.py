"""The force loop in a child process: the same safety behaviour behind the same API."""
import math
import time

import pytest

from feelflow.haptics import DeviceError, LoopConfig, SafetyConfig
from feelflow.haptics.process_loop import ProcessForceLoop
from haptics_helpers import Feeder, force, wait_for

PEAK = 0.01


@pytest.fixture
def ploop():
    loop = ProcessForceLoop("sim://diyhid", LoopConfig(tunnel_rect=(0, 0, 200, 100), expected_peak=PEAK,
                                                       safety=SafetyConfig(ramp_time=0.1)))
    yield loop
    loop.close()


def test_forces_flow_and_body_target_comes_back(ploop):
    assert ploop.capabilities.max_force == pytest.approx(3.0) and ploop.driver_name == "diyhid"
    ploop.start()
    with Feeder(ploop, PEAK):
        assert wait_for(lambda: force(ploop) > 0.45 * 3.0)
        bt = ploop.body_target()
        assert bt.valid and bt.x == pytest.approx(100.0, abs=0.5)  # hand at the centre
        assert wait_for(lambda: ploop.status().samples > 0)  # (statistics come at 10 Hz)
        st = ploop.status()
        assert st.running and st.state in ("ok", "ramping")
        assert wait_for(lambda: ploop.status().device_counters.get("good", 0) > 0)


def test_safety_rules_hold_across_the_process_boundary(ploop):
    ploop.start()
    with Feeder(ploop, PEAK) as feeder:
        assert wait_for(lambda: force(ploop) > 0.45 * 3.0)
        ploop.emergency_stop()
        assert wait_for(lambda: ploop.status().state == "stopped" and force(ploop) == 0.0)
        ploop.clear_stop()
        assert wait_for(lambda: force(ploop) > 0.45 * 3.0)
        feeder.fx = math.nan
        assert wait_for(lambda: ploop.status().state == "nan" and force(ploop) == 0.0)
        feeder.fx = PEAK
        assert wait_for(lambda: force(ploop) > 0.45 * 3.0)
        feeder.sending = False
        assert wait_for(lambda: ploop.status().state == "stall" and force(ploop) == 0.0)
        feeder.sending = True
        ploop.pause()
        assert wait_for(lambda: ploop.status().state == "paused" and force(ploop) == 0.0)
    with pytest.raises(ValueError):
        ploop.set_scaling(-1.0)


def test_closing_zeroes_and_ends_the_child(ploop):
    ploop.start()
    with Feeder(ploop, PEAK):
        assert wait_for(lambda: force(ploop) > 0.45 * 3.0)
    ploop.close()
    assert ploop._proc.poll() == 0
    assert ploop.status().force == (0.0, 0.0) and not ploop.status().running


def test_bad_device_is_a_device_error():
    with pytest.raises(DeviceError, match="unknown simulator"):
        ProcessForceLoop("sim://nothing")


def test_a_dead_child_is_reported_as_a_disconnect():
    reasons = []
    loop = ProcessForceLoop("sim://hapkit", LoopConfig(expected_peak=PEAK), on_disconnect=reasons.append)
    try:
        loop.start()
        loop._proc.kill()
        assert wait_for(lambda: reasons, 3.0)
        assert loop.status().state == "disconnected"
        with pytest.raises(DeviceError):
            time.sleep(0.05)
            for _ in range(100):  # the pipe breaks: submitting raises DeviceDisconnected
                loop.stop()
    finally:
        loop.close()
