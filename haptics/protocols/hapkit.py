"""FeelFlow's serial protocol for a Hapkit-style 1-DOF paddle (version 1; docs/guide/haptic-devices.md).

Frame: 0xA5 0x5A | version u8 | type u8 | length u8 | payload | crc u16 (little-endian)
where crc is CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF; Python's binascii.crc_hqx) over
version, type, length and payload. All numbers little-endian; floats IEEE-754 single.

Host -> paddle                         Paddle -> host
  0x01 HELLO  (empty)                    0x81 INFO  dof u8, x_min f32 m, x_max f32 m,
                                                    max_force f32 N, firmware u16
  0x02 FORCE  seq u16, force f32 N       0x82 STATE seq u16 (echo), x f32 m, buttons u8
  0x03 STOP   (empty)                    0x82 STATE (seq 0), motor off until the next FORCE
The paddle switches its motor off by itself when no FORCE frame came for 50 ms (watchdog)
and clamps every command to its own max_force.
"""
from __future__ import annotations

import binascii
import math
import struct
from dataclasses import dataclass

SYNC = b"\xa5\x5a"
VERSION = 1
MAX_PAYLOAD = 32

HELLO, FORCE, STOP = 0x01, 0x02, 0x03
INFO, STATE = 0x81, 0x82

_INFO = struct.Struct("<BfffH")
_FORCE = struct.Struct("<Hf")
_STATE = struct.Struct("<HfB")
PAYLOAD_SIZE = {HELLO: 0, FORCE: _FORCE.size, STOP: 0, INFO: _INFO.size, STATE: _STATE.size}


def crc16(data: bytes) -> int:
    return binascii.crc_hqx(data, 0xFFFF)


def encode(msg_type: int, payload: bytes = b"", version: int = VERSION) -> bytes:
    body = bytes([version, msg_type, len(payload)]) + payload
    return SYNC + body + struct.pack("<H", crc16(body))


@dataclass(frozen=True)
class Info:
    dof: int
    x_min: float
    x_max: float
    max_force: float
    firmware: int


@dataclass(frozen=True)
class State:
    seq: int
    x: float
    buttons: int


def encode_hello() -> bytes:
    return encode(HELLO)


def encode_force(seq: int, force_n: float) -> bytes:
    return encode(FORCE, _FORCE.pack(seq & 0xFFFF, force_n))


def encode_stop() -> bytes:
    return encode(STOP)


def encode_info(info: Info) -> bytes:
    return encode(INFO, _INFO.pack(info.dof, info.x_min, info.x_max, info.max_force, info.firmware))


def encode_state(state: State) -> bytes:
    return encode(STATE, _STATE.pack(state.seq & 0xFFFF, state.x, state.buttons))


def decode_payload(msg_type: int, payload: bytes):
    """The message a frame carries, or None if its payload is malformed."""
    if PAYLOAD_SIZE.get(msg_type) != len(payload):
        return None
    if msg_type == INFO:
        info = Info(*_INFO.unpack(payload))
        ok = all(math.isfinite(v) for v in (info.x_min, info.x_max, info.max_force))
        return info if ok and info.max_force > 0 and info.x_max > info.x_min else None
    if msg_type == STATE:
        state = State(*_STATE.unpack(payload))
        return state if math.isfinite(state.x) else None
    if msg_type == FORCE:
        seq, f = _FORCE.unpack(payload)
        return (seq, f) if math.isfinite(f) else None
    return ()  # HELLO / STOP carry nothing


class FrameParser:
    """Splits a byte stream into (type, message) pairs; bad frames are dropped and counted.

    `accept` limits which types are expected (a host expects INFO/STATE, a paddle
    HELLO/FORCE/STOP); others count as `unexpected`.
    """

    def __init__(self, accept=(INFO, STATE)):
        self.accept = set(accept)
        self._buf = bytearray()
        self.dropped_bytes = 0
        self.bad_crc = 0
        self.bad_version = 0
        self.malformed = 0
        self.unexpected = 0
        self.good = 0

    def feed(self, data: bytes) -> list:
        self._buf += data
        out = []
        buf = self._buf
        while True:
            i = buf.find(SYNC)
            if i < 0:
                keep = 1 if buf[-1:] == SYNC[:1] else 0
                self.dropped_bytes += len(buf) - keep
                del buf[:len(buf) - keep]
                break
            if i:
                self.dropped_bytes += i
                del buf[:i]
            if len(buf) < 5:
                break
            version, msg_type, length = buf[2], buf[3], buf[4]
            if length > MAX_PAYLOAD:
                self.malformed += 1
                self.dropped_bytes += 2
                del buf[:2]
                continue
            end = 5 + length + 2
            if len(buf) < end:
                break
            body = bytes(buf[2:5 + length])
            (crc,) = struct.unpack_from("<H", buf, 5 + length)
            if crc != crc16(body):
                self.bad_crc += 1
                self.dropped_bytes += 2
                del buf[:2]  # resynchronise on the next sync pattern
                continue
            del buf[:end]
            if version != VERSION:
                self.bad_version += 1
                continue
            if msg_type not in self.accept:
                self.unexpected += 1
                continue
            msg = decode_payload(msg_type, body[3:])
            if msg is None:
                self.malformed += 1
                continue
            self.good += 1
            out.append((msg_type, msg))
        return out
