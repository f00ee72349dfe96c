"""Malformed and truncated device packets are dropped and counted; the loop keeps running."""
import struct
import time

import pytest

from feelflow.haptics import ForceLoop, LoopConfig, open_device
from feelflow.haptics.protocols import diyhid, hapkit, haply
from haptics_helpers import Feeder, wait_for


def run_loop(dev):
    loop = ForceLoop(dev, LoopConfig(expected_peak=0.01))
    loop.feeder = Feeder(loop, 0.01)
    loop.start()
    return loop


def stop(loop):
    loop.feeder.close()
    loop.stop()


def test_haply_garbage_and_truncated_replies():
    dev = open_device("sim://haply2diy")
    loop = run_loop(dev)
    try:
        assert wait_for(lambda: dev.counters["good"] > 50)
        before = dict(dev.counters)
        sim = dev.simulator
        sim.inject(b"\xff\xfe\x00garbage")  # noise
        sim.inject(bytes([5]) + b"\x00\x00")  # a truncated reply
        sim.inject(bytes([5]) + struct.pack("<2f", float("nan"), 0.0))  # NaN angle
        sim.inject(bytes([5]) + struct.pack("<2f", 1e9, 0.0))  # impossible angle
        sim.hand.set(0.02, 0.11)
        assert wait_for(lambda: dev.counters["dropped_bytes"] > before["dropped_bytes"])
        assert wait_for(lambda: abs(dev.last_pose.x - 0.02) < 1e-3)
        assert loop.status().running and loop.status().state != "disconnected"
        assert dev.last_pose.x == pytest.approx(0.02, abs=1e-3)  # still tracking the hand
    finally:
        stop(loop)
        dev.close()


def test_haply_parser_counts_what_it_drops():
    p = haply.StateParser(5, 2)
    good = haply.encode_state(5, [1.0, 2.0])
    assert p.feed(b"\x01\x02" + good) == (1.0, 2.0)
    assert p.dropped_bytes == 2
    assert p.feed(bytes([5]) + struct.pack("<2f", float("inf"), 0.0) + good) == (1.0, 2.0)
    assert p.bad_replies >= 1


def test_hapkit_bad_frames_are_counted():
    dev = open_device("sim://hapkit")
    loop = run_loop(dev)
    try:
        assert wait_for(lambda: dev.counters["good"] > 50)
        sim = dev.simulator
        frame = hapkit.encode_state(hapkit.State(1, 0.01, 0))
        sim.inject(frame[:-1] + bytes([frame[-1] ^ 0xFF]))  # bad CRC
        sim.inject(hapkit.encode(hapkit.STATE, frame[5:-2], version=2))  # a future version
        sim.inject(hapkit.encode(hapkit.STATE, b"\x00\x01"))  # payload too short
        sim.inject(hapkit.encode(hapkit.FORCE, struct.pack("<Hf", 1, 1.0)))  # host-only type
        sim.inject(b"\xa5\x5a\x01\x82\xff")  # length beyond the maximum
        sim.inject(b"\x00\x11\x22\xa5")  # noise, ends on half a sync word
        sim.inject(frame[:6])  # truncated
        assert wait_for(lambda: dev.counters["unexpected"] == 1 and dev.counters["malformed"] >= 2)
        c = dev.counters
        assert c["bad_crc"] >= 1 and c["bad_version"] == 1 and c["unexpected"] == 1
        assert c["malformed"] >= 2 and c["dropped_bytes"] > 0
        assert loop.status().running
    finally:
        stop(loop)
        dev.close()


def test_hid_short_and_foreign_reports_are_counted():
    dev = open_device("sim://diyhid")
    loop = run_loop(dev)
    try:
        assert wait_for(lambda: dev.counters["good"] > 50)
        good = diyhid.encode_state(diyhid.State(3, 0.01, 0.0, 0.0, 0, 0))
        dev.simulator.inject(good[:5])  # truncated
        dev.simulator.inject(good[:1] + b"\x07" + good[2:])  # another protocol version
        dev.simulator.inject(b"\x55" * 64)  # unknown report type
        assert wait_for(lambda: dev.counters["dropped"] >= 3, 1.0)
        assert loop.status().running
    finally:
        stop(loop)
        dev.close()


def test_spacemouse_moves_the_pose_and_ignores_unknown_reports():
    dev = open_device("sim://spacemouse")
    loop = run_loop(dev)
    try:
        dev.simulator.inject(b"\x01\x00")  # truncated
        dev.simulator.inject(b"\x17\x64")  # battery report: not ours
        dev.simulator.set_deflection(350, 0, 0, 0, 0, 0)  # full push to the right
        time.sleep(0.2)
        dev.simulator.set_deflection(0, 0, 0, 0, 0, 0)
        assert wait_for(lambda: dev.counters["dropped"] >= 2, 1.0)
        time.sleep(0.05)  # the release report has been read
        x = dev.last_pose.x
        assert 0.005 < x <= 0.05  # ~0.1 m/s for ~0.2 s, inside the virtual workspace
        time.sleep(0.1)
        assert dev.last_pose.x == pytest.approx(x, abs=1e-9)  # released: it stays
        assert loop.status().running and loop.status().force == (0.0, 0.0)  # input only
        dev.simulator.press(1)
        assert wait_for(lambda: loop.body_target().buttons == 1, 1.0)
    finally:
        stop(loop)
        dev.close()
