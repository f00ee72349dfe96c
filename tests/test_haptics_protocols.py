"""Protocol exchange tables: what the host sends, what the device answers, byte for byte.

Serial devices are their simulators behind a real pseudo-terminal, opened with pyserial like a
real port; HID devices are their simulators at the hidapi boundary.
"""
import math
import struct
import time

import pytest
import serial

from feelflow.haptics.drivers.haply2diy import PORTS
from feelflow.haptics.protocols import diyhid, hapkit, haply
from feelflow.haptics.protocols import spacemouse as sm
from feelflow.haptics.sim.hapkit_sim import HapkitSim
from feelflow.haptics.sim.haply_sim import HaplySim
from feelflow.haptics.sim.hid_sim import DiyHidSim, SpaceMouseSim

H = bytes.fromhex


def exchange(port: serial.Serial, host: bytes, expect_len: int, timeout=2.0) -> bytes:
    port.write(host)
    out = b""
    deadline = time.monotonic() + timeout
    while len(out) < expect_len and time.monotonic() < deadline:
        out += port.read(expect_len - len(out))
    if expect_len == 0:  # make sure nothing comes back
        time.sleep(0.05)
        out += port.read(64)
    return out


@pytest.fixture
def haply_port():
    sim = HaplySim()
    # the hand where both arms point straight out: th1 = 0, th2 = 180 deg (hand-computed)
    sim.hand.set(0.0, math.sqrt(0.09 ** 2 - 0.07 ** 2))
    port = serial.Serial(sim.port, 115200, timeout=0.2)
    yield sim, port
    port.close()
    sim.stop()


# hAPI M3 firmware v1.5, device id 5, the 2DIY port set-up (docs/guide/haptic-devices.md)
HAPLY_TABLE = [
    # host sends                                   device answers
    ("00 05",                                       ""),  # reset
    ("01 05 03 00 01 03 00 01 00 00"                       # setup: motors on ports 1+2 (CW, CCW),
     " 00 00 74 c2 00 00 28 46"                            # encoders ditto, no sensors/pwm;
     " 00 00 71 43 00 00 28 46",                    ""),  # (-61 deg, 10752) (241 deg, 10752)
    ("02 05 00 00 00 00 00 00 00 00",               "05 00 00 34 43 00 00 00 00"),  # 180.0, 0.0 deg
    ("02 05 00 00 00 3f 00 00 80 bf",               "05 00 00 34 43 00 00 00 00"),  # torques .5, -1
]


def test_haply_exchange_table(haply_port):
    sim, port = haply_port
    for host, device in HAPLY_TABLE:
        assert exchange(port, H(host), len(H(device))) == H(device), host
    assert sim.device_id == 5
    assert sim.encoders == {1: (-61.0, 10752.0), 2: (241.0, 10752.0)}
    # the board clamps each motor to MAX_TORQUE (0.123 N m), as the firmware does
    assert sim.torques == {1: pytest.approx(0.123), 2: pytest.approx(-0.123)}


def test_haply_driver_encodes_the_table():
    assert haply.encode_reset(5) == H(HAPLY_TABLE[0][0])
    assert haply.encode_setup(5, PORTS) == H(HAPLY_TABLE[1][0])
    assert haply.encode_write(5, [0.5, -1.0]) == H(HAPLY_TABLE[3][0])


def test_haply_state_split_across_reads_and_newest_wins():
    p = haply.StateParser(5, 2)
    a = haply.encode_state(5, [10.0, 20.0])
    b = haply.encode_state(5, [11.0, 21.0])
    assert p.feed(a[:4]) is None
    assert p.feed(a[4:] + b[:2]) == (10.0, 20.0)
    assert p.feed(b[2:]) == (11.0, 21.0)
    assert p.feed(a + b) == (11.0, 21.0) and p.stale_replies == 1


# FeelFlow paddle protocol v1 (CRC-16/CCITT-FALSE)
HAPKIT_TABLE = [
    # host sends                         device answers
    ("a5 5a 01 01 00 9d c8",              # HELLO
     "a5 5a 01 81 0f 01 0a d7 23 bd 0a d7 23 3d 00 00 00 40 64 00 87 d6"),  # INFO 1 dof, +-0.04 m, 2 N, fw 100
    ("a5 5a 01 02 06 01 00 00 00 00 3f ce 5f",   # FORCE seq 1, 0.5 N
     "a5 5a 01 82 07 01 00 00 00 00 00 00 d0 88"),  # STATE seq 1, x 0.0 m, no buttons
    ("a5 5a 01 03 00 ff ae",              # STOP
     "a5 5a 01 82 07 00 00 00 00 00 00 00 b1 30"),  # STATE seq 0
]


def test_crc_is_ccitt_false():
    assert hapkit.crc16(b"123456789") == 0x29B1  # the published check value of CRC-16/CCITT-FALSE


def test_hapkit_exchange_table():
    sim = HapkitSim()
    port = serial.Serial(sim.port, 115200, timeout=0.2)
    try:
        for host, device in HAPKIT_TABLE:
            assert exchange(port, H(host), len(H(device))) == H(device), host
        assert sim.motor_force == 0.0  # after STOP
    finally:
        port.close()
        sim.stop()


def test_hapkit_driver_encodes_the_table():
    assert hapkit.encode_hello() == H(HAPKIT_TABLE[0][0])
    assert hapkit.encode_force(1, 0.5) == H(HAPKIT_TABLE[1][0])
    assert hapkit.encode_stop() == H(HAPKIT_TABLE[2][0])


def test_hapkit_paddle_clamps_and_its_watchdog_zeroes_the_motor():
    sim = HapkitSim()
    port = serial.Serial(sim.port, 115200, timeout=0.2)
    try:
        exchange(port, hapkit.encode_force(7, 50.0), 14)
        assert sim.motor_force == pytest.approx(2.0)  # clamped to the paddle's max_force
        time.sleep(0.2)  # no FORCE for >> 50 ms
        assert sim.motor_force == 0.0 and sim.watchdog_trips == 1
    finally:
        port.close()
        sim.stop()


# SpaceMouse input reports (device -> host only)
SPACEMOUSE_TABLE = [
    ("01 5e 01 a2 fe 00 00", sm.Motion(translation=(350, -350, 0))),
    ("02 00 00 e2 ff 00 00", sm.Motion(rotation=(0, -30, 0))),
    ("03 01 00", sm.Motion(buttons=1)),
    ("03 03 00", sm.Motion(buttons=3)),
    ("01 0a 00 f6 ff 00 00 01 00 02 00 03 00", sm.Motion(translation=(10, -10, 0), rotation=(1, 2, 3))),
    ("01 5e 01", None),  # truncated
    ("07 00 00", None),  # a report we do not use
]


@pytest.mark.parametrize("report,motion", SPACEMOUSE_TABLE)
def test_spacemouse_reports(report, motion):
    assert sm.decode_report(H(report)) == motion


def test_spacemouse_sim_sends_real_reports():
    sim = SpaceMouseSim()
    sim.set_deflection(350, -350, 0, 0, 0, 0)
    assert bytes(sim.read(64)) == H("01 5e 01 a2 fe 00 00")
    assert bytes(sim.read(64)) == H("02 00 00 00 00 00 00")


def test_diyhid_exchange_table():
    sim = DiyHidSim()
    # host: INFO_REQUEST -> board: INFO (2 dof, 3 N, +-5 cm x +-4 cm)
    sim.write(H("00 03 01") + bytes(62))
    reports = [bytes(sim.read(64)) for _ in range(3)]
    info = [r for r in reports if r[0] == diyhid.INFO][0]
    assert info[:21] == H("83 01 02 b8 0b b0 3c ff ff 50 c3 00 00 c0 63 ff ff 40 9c 00 00")
    assert len(info) == 64
    # host: FORCE seq 9, fx 1.5 N, fy -0.25 N, enabled -> board drives (1.5, -0.25)
    sim.write(H("00 02 01 09 dc 05 06 ff 01") + bytes(58))
    assert sim.motor == pytest.approx((1.5, -0.25))
    assert diyhid.encode_force(9, 1.5, -0.25)[:9] == H("00 02 01 09 dc 05 06 ff 01")
    # board: STATE with the hand at (1 cm, -2 cm)
    sim.hand.set(0.01, -0.02)
    time.sleep(0.002)
    states = [bytes(r) for r in iter(lambda: sim.read(64), [])]
    last = diyhid.decode_input(states[-1])
    assert (last.x, last.y) == pytest.approx((0.01, -0.02))
    assert states[-1][3:11] == struct.pack("<ii", 10000, -20000)


def test_diyhid_rejects_other_versions_and_truncation():
    good = diyhid.encode_state(diyhid.State(1, 0.01, 0.0, 0.0, 0, 0))
    assert diyhid.decode_input(good) is not None
    assert diyhid.decode_input(good[:1] + b"\x02" + good[2:]) is None  # version 2
    assert diyhid.decode_input(good[:8]) is None  # truncated


def test_hapkit_driver_over_pyserial_loopback():
    # loop:// echoes what is written: the driver's own FORCE frames come back and are rejected
    # as host-only ('unexpected'); a STATE frame written into the loop is read as the pose.
    from feelflow.haptics.drivers.hapkit import Hapkit
    from feelflow.haptics.transport import SerialTransport

    dev = Hapkit(SerialTransport("loop://"), "loop://")
    dev.transport.write(hapkit.encode_state(hapkit.State(3, 0.012, 1)))
    pose = dev.poll()
    assert (pose.x, pose.buttons) == (pytest.approx(0.012), 1)
    dev._send_force(0.5, 0.0)
    assert dev.poll() is None and dev.counters["unexpected"] == 1
    dev.transport.close()


def test_hid_driver_choice_by_usb_id():
    from feelflow.haptics.registry import hid_driver_for

    assert hid_driver_for(0x046D, 0xC626) == "spacemouse"
    assert hid_driver_for(0x256F, 0xC635) == "spacemouse"
    assert hid_driver_for(0x16C0, 0x0486) == "diyhid"
    assert hid_driver_for(0x16C0, 0x0486, usage_page=0x0001) is None  # a Teensy keyboard
    assert hid_driver_for(0x1234, 0x5678) is None
