"""Each safety rule of the force loop, by a test that fails without the rule .

The loop runs for real (its own thread, 1 kHz) against simulators speaking the real protocols;
a feeder thread plays the solver. Timing assertions are generous (a loaded 2-core machine):
they check that the force reaches zero, and well inside a bound, never how fast the loop is.
"""
import math
import time

import numpy as np
import pytest

from feelflow.haptics import ForceLoop, LoopConfig, SafetyConfig, open_device
from feelflow.haptics.drivers.base import clamp_force
from haptics_helpers import Feeder, force, force_after, record, wait_for

PEAK = 0.01  # lattice units; felt as half the device maximum


@pytest.fixture(params=["sim://hapkit", "sim://diyhid", "sim://haply2diy"])
def device(request):
    dev = open_device(request.param)
    yield dev
    dev.close()


def make_loop(dev, ramp=0.1, **kw):
    safety = kw.pop("safety", SafetyConfig(ramp_time=ramp))
    cfg = LoopConfig(tunnel_rect=(0, 0, 200, 100), expected_peak=PEAK, comfort_fraction=0.5,
                     record=True, safety=safety, **kw)
    return ForceLoop(dev, cfg)


def reaches_half_max(loop, dev, timeout=3.0) -> bool:
    """The steady force (PEAK -> half the device maximum) is reached."""
    return wait_for(lambda: force(loop) > 0.45 * dev.capabilities.max_force, timeout)


def test_ramp_up_on_start_is_smooth(device):
    loop = make_loop(device, ramp=0.3)
    with Feeder(loop, PEAK):
        t0 = time.monotonic()
        loop.start()
        try:
            assert reaches_half_max(loop, device)
            time.sleep(0.4)
            t, f = force_after(loop, t0)
            full = 0.5 * device.capabilities.max_force
            assert f.max() == pytest.approx(full, rel=0.05)
            # without the ramp the force is ~full 50 ms after the first sample (20 ms hold +
            # 5 ms filter); with a 0.3 s ramp it is at most ~half of it 150 ms after start
            early = f[t < t0 + 0.15]
            assert early.size and early.max() < 0.6 * full
            # no step between consecutive ticks (a tick delayed by a GIL stall on a loaded
            # machine may legitimately carry a larger ramp increment: the ramp is in time)
            normal = np.diff(t) < 0.002
            assert np.max(np.diff(f)[normal]) < 0.1 * full
        finally:
            loop.stop()


def test_stall_zeroes_force(device):
    loop = make_loop(device)
    with Feeder(loop, PEAK) as feeder:
        loop.start()
        try:
            assert reaches_half_max(loop, device)
            feeder.sending = False
            t_last = time.monotonic()  # (at most one more sample after this)
            assert wait_for(lambda: loop.status().force == (0.0, 0.0), 1.0)
            assert loop.status().state == "stall", loop.status()
            t, f = force_after(loop, t_last)
            t_zero = t[np.argmax(f == 0.0)]
            # rule: zero within 50 ms after the next sample was due (10 ms); generous bound
            assert t_zero - t_last < 0.010 + 0.050 + 0.100
            assert wait_for(lambda: device.simulator.forces.last == (0.0, 0.0), 0.5)
            feeder.sending = True  # the solver comes back: force ramps up again
            assert reaches_half_max(loop, device)
        finally:
            loop.stop()


def test_nan_sample_zeroes_force_at_once(device):
    loop = make_loop(device)
    with Feeder(loop, PEAK) as feeder:
        loop.start()
        try:
            assert reaches_half_max(loop, device)
            feeder.fx = math.nan  # the solver diverged and keeps producing garbage
            t_nan = time.monotonic()
            assert wait_for(lambda: loop.status().nan_samples >= 10, 2.0)
            t, f = force_after(loop, t_nan + 0.015)  # (one tick, one feeder period late)
            assert f.size and np.all(f == 0.0)
            assert loop.status().state == "nan"
            feeder.fx = PEAK  # finite samples again: the force comes back, ramped
            assert reaches_half_max(loop, device)
        finally:
            loop.stop()


def test_pause_fades_force_out_and_resume_brings_it_back(device):
    loop = make_loop(device)
    with Feeder(loop, PEAK):  # the solver may keep going; a paused app must not push
        loop.start()
        try:
            assert reaches_half_max(loop, device)
            t_pause = time.monotonic()
            loop.pause()
            time.sleep(0.2)
            t, f = force_after(loop, t_pause)
            assert np.all(f[t > t_pause + 0.05] == 0.0)
            assert loop.status().state == "paused"
            loop.resume()
            assert reaches_half_max(loop, device)
        finally:
            loop.stop()


def test_stop_key_latches_zero_force(device):
    loop = make_loop(device)
    with Feeder(loop, PEAK):
        loop.start()
        try:
            assert reaches_half_max(loop, device)
            t_stop = time.monotonic()
            loop.emergency_stop()
            time.sleep(0.3)
            t, f = force_after(loop, t_stop + 0.002)
            assert f.size and np.all(f == 0.0)
            assert loop.status().state == "stopped"
            loop.clear_stop()
            assert reaches_half_max(loop, device)
        finally:
            loop.stop()


def test_device_stop_button_is_a_stop_key():
    dev = open_device("sim://hapkit")
    loop = make_loop(dev, safety=SafetyConfig(ramp_time=0.1, stop_buttons=0b10))
    with Feeder(loop, PEAK):
        loop.start()
        try:
            assert reaches_half_max(loop, dev)
            dev.simulator.hand.buttons = 0b10
            assert wait_for(lambda: loop.status().state == "stopped", 1.0)
            t_seen = time.monotonic()
            time.sleep(0.1)
            t, f = force_after(loop, t_seen)
            assert np.all(f == 0.0)
        finally:
            loop.stop()
            dev.close()


def test_clamp_nothing_exceeds_the_device_maximum(device):
    # a scene whose expected peak is 1000 times too small asks for 500 x the device maximum
    loop = make_loop(device)
    loop.set_scaling(PEAK / 1000, 1.0)
    m = device.capabilities.max_force
    with Feeder(loop, PEAK) as feeder:
        loop.start()
        try:
            assert wait_for(lambda: force(loop) > 0.99 * m, 3.0)
            feeder.fx, feeder.fy = -PEAK, PEAK
            time.sleep(0.2)
            r = record(loop)
            assert np.max(np.hypot(r["fx"], r["fy"])) <= m + 1e-12
            assert device.simulator.forces.max_magnitude <= m + 1e-6
        finally:
            loop.stop()


def test_clamp_function_and_scene_values_cannot_bypass_it():
    assert clamp_force(30.0, 40.0, 2.0) == pytest.approx((1.2, 1.6))
    assert clamp_force(math.nan, 1.0, 2.0) == (0.0, 0.0)
    assert clamp_force(0.3, 0.4, 2.0) == (0.3, 0.4)
    dev = open_device("sim://diyhid")
    try:
        loop = make_loop(dev)
        for bad in (0.0, -1.0, math.nan, math.inf):
            with pytest.raises(ValueError):
                loop.set_scaling(bad)
        with pytest.raises(ValueError):
            loop.set_scaling(PEAK, 1.5)  # more than the device maximum
        assert dev.write_force(100.0, 0.0) == pytest.approx((3.0, 0.0))  # the driver clamps too
    finally:
        dev.close()


def test_disconnect_serial_zeroes_and_reports():
    dev = open_device("sim://hapkit")
    reasons = []
    loop = ForceLoop(dev, LoopConfig(expected_peak=PEAK), on_disconnect=reasons.append)
    with Feeder(loop, PEAK):
        loop.start()
        try:
            assert reaches_half_max(loop, dev)
            dev.simulator.disconnect()  # cable pulled
            assert wait_for(lambda: not loop.status().running, 2.0)
            st = loop.status()
            assert st.state == "disconnected" and st.force == (0.0, 0.0) and st.gain == 0.0
            assert len(reasons) == 1
        finally:
            loop.stop()
            dev.close()


def test_disconnect_hid_unplugged():
    dev = open_device("sim://diyhid")
    reasons = []
    loop = ForceLoop(dev, LoopConfig(expected_peak=PEAK), on_disconnect=reasons.append)
    with Feeder(loop, PEAK):
        loop.start()
        try:
            assert reaches_half_max(loop, dev)
            dev.simulator.unplug()
            assert wait_for(lambda: not loop.status().running, 2.0)
            assert loop.status().state == "disconnected" and "lost" in reasons[0]
        finally:
            loop.stop()
            dev.close()


def test_device_that_hangs_counts_as_disconnected():
    dev = open_device("sim://haply2diy")
    reasons = []
    loop = ForceLoop(dev, LoopConfig(expected_peak=PEAK), on_disconnect=reasons.append)
    with Feeder(loop, PEAK):
        loop.start()
        try:
            assert reaches_half_max(loop, dev)
            dev.simulator.muted = True  # port open, board silent
            assert wait_for(lambda: not loop.status().running, 2.0)
            assert loop.status().state == "disconnected" and "no data" in reasons[0]
        finally:
            loop.stop()
            dev.close()


def test_a_failing_disconnect_callback_does_not_keep_the_motor_on():
    dev = open_device("sim://diyhid")

    def broken(reason):
        raise RuntimeError("app bug")

    loop = ForceLoop(dev, LoopConfig(expected_peak=PEAK), on_disconnect=broken)
    loop.start()
    try:
        dev.simulator.unplug()
        assert wait_for(lambda: not loop.status().running, 2.0)
        assert loop.status().force == (0.0, 0.0) and "app bug" in loop.callback_error
    finally:
        loop.stop()
        dev.close()


def test_body_follows_the_device_into_the_tunnel():
    dev = open_device("sim://diyhid")
    loop = ForceLoop(dev, LoopConfig(tunnel_rect=(0, 0, 200, 100), expected_peak=PEAK))
    loop.start()
    try:
        (x0, x1), (y0, y1) = dev.capabilities.workspace
        dev.simulator.hand.set(x1, y0)  # right edge, bottom
        assert wait_for(lambda: abs(loop.body_target().x - 200) < 0.5 and abs(loop.body_target().y) < 0.5)
        dev.simulator.hand.set(0.5 * (x0 + x1), 0.5 * (y0 + y1))
        assert wait_for(lambda: abs(loop.body_target().x - 100) < 0.5)
        assert loop.body_target().valid
    finally:
        loop.stop()
        dev.close()
