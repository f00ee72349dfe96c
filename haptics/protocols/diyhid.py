"""FeelFlow's vendor-defined HID reports for do-it-yourself force boards (version 1).

Raw 64-byte reports without report ids (Teensy "Raw HID": usage page 0xFFAB, usage 0x0200;
default VID:PID 16c0:0486), so hidapi writes are b'\\x00' + 64 bytes. Little-endian.

Board -> host (input report)
  STATE 0x01: version u8, seq u8, x i32 um, y i32 um, angle i16 mrad, buttons u8, status u8
  INFO  0x83: version u8, dof u8, max_force u16 mN, x_min i32 um, x_max i32 um,
              y_min i32 um, y_max i32 um
Host -> board (output report)
  FORCE 0x02: version u8, seq u8, fx i16 mN, fy i16 mN, flags u8 (bit 0: motors enabled)
  INFO_REQUEST 0x03: version u8            -> the board answers INFO
The board sends STATE at its own rate (1 kHz), clamps forces to max_force and switches the
motors off when no FORCE report came for 50 ms.
"""
from __future__ import annotations

import struct
from dataclasses import dataclass

VERSION = 1
REPORT_SIZE = 64
USAGE_PAGE = 0xFFAB
USAGE = 0x0200
DEFAULT_VID, DEFAULT_PID = 0x16C0, 0x0486

STATE, FORCE, INFO_REQUEST, INFO = 0x01, 0x02, 0x03, 0x83
_STATE = struct.Struct("<BBBiihBB")
_FORCE = struct.Struct("<BBBhhB")
_INFO = struct.Struct("<BBBHiiii")


@dataclass(frozen=True)
class State:
    seq: int
    x: float  # metres
    y: float
    angle: float  # radians
    buttons: int
    status: int


@dataclass(frozen=True)
class Info:
    dof: int
    max_force: float  # newtons
    workspace: tuple[tuple[float, float], tuple[float, float]]


def _pad(b: bytes) -> bytes:
    return b + bytes(REPORT_SIZE - len(b))


def encode_state(s: State) -> bytes:
    return _pad(_STATE.pack(STATE, VERSION, s.seq & 0xFF, round(s.x * 1e6), round(s.y * 1e6),
                            round(s.angle * 1e3), s.buttons & 0xFF, s.status & 0xFF))


def encode_info(i: Info) -> bytes:
    (x0, x1), (y0, y1) = i.workspace
    return _pad(_INFO.pack(INFO, VERSION, i.dof, round(i.max_force * 1e3),
                           round(x0 * 1e6), round(x1 * 1e6), round(y0 * 1e6), round(y1 * 1e6)))


def encode_force(seq: int, fx: float, fy: float, enabled: bool = True) -> bytes:
    """The output report, with hidapi's leading report-id byte 0."""
    clip = lambda v: max(-32767, min(32767, round(v * 1e3)))  # noqa: E731
    return b"\x00" + _pad(_FORCE.pack(FORCE, VERSION, seq & 0xFF, clip(fx), clip(fy), 1 if enabled else 0))


def encode_info_request() -> bytes:
    return b"\x00" + _pad(bytes([INFO_REQUEST, VERSION]))


def decode_input(report: bytes):
    """An input report -> State or Info; None if truncated, of another version, or unknown."""
    if len(report) < 2 or report[1] != VERSION:
        return None
    if report[0] == STATE and len(report) >= _STATE.size:
        _, _, seq, x, y, a, b, st = _STATE.unpack_from(report)
        return State(seq, x * 1e-6, y * 1e-6, a * 1e-3, b, st)
    if report[0] == INFO and len(report) >= _INFO.size:
        _, _, dof, mf, x0, x1, y0, y1 = _INFO.unpack_from(report)
        if mf == 0 or x1 <= x0 or dof not in (1, 2):
            return None
        return Info(dof, mf * 1e-3, ((x0 * 1e-6, x1 * 1e-6), (y0 * 1e-6, y1 * 1e-6)))
    return None


def decode_output(report: bytes):
    """What the board reads (no leading id byte): ('force', seq, fx, fy, enabled),
    ('info_request',) or None."""
    if len(report) < 2 or report[1] != VERSION:
        return None
    if report[0] == FORCE and len(report) >= _FORCE.size:
        _, _, seq, fx, fy, fl = _FORCE.unpack_from(report)
        return ("force", seq, fx * 1e-3, fy * 1e-3, bool(fl & 1))
    if report[0] == INFO_REQUEST:
        return ("info_request",)
    return None
