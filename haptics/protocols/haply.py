"""The Haply hAPI serial protocol, as the M3 board firmware v1.5 speaks it (used by the 2DIY).

Read from HaplyHaptics/Haply-Arduino-Firmware-Versions (Haply_M3_Firmware_V1_5: command_instructions,
setup_device, write_states, read_states) and HaplyHaptics/UnityHAPI (hAPI/Device.cs:
Device_set_parameters, Device_write_torques); see docs/guide/haptic-devices.md for the byte tables.

Host -> board (no framing, no checksum; floats are IEEE-754 single, little-endian):
  reset  : 0x00, id
  setup  : 0x01, id, motor_mask, dir per active motor, encoder_mask, dir per active encoder,
           n_sensors(0), n_pwms(0), (offset_deg f32, resolution f32) per active encoder
  write  : 0x02, id, torque_Nm f32 per active motor            -> board answers a state reply
Board -> host:
  state  : id, angle_deg f32 per active encoder
Masks: bit i set = port i+1 in use; per-port values go in port order (port 1 first).
"""
from __future__ import annotations

import math
import struct
from dataclasses import dataclass

CMD_RESET = 0
CMD_SETUP = 1
CMD_WRITE = 2
CW, CCW = 0, 1


@dataclass(frozen=True)
class PortSetup:
    """One motor port as the host configures it."""

    port: int  # 1..4
    motor_dir: int  # CW or CCW
    encoder_dir: int
    encoder_offset_deg: float
    encoder_resolution: float  # counts per revolution


def _mask(ports) -> int:
    m = 0
    for p in ports:
        if not 1 <= p <= 4:
            raise ValueError(f"port {p} is not 1..4")
        m |= 1 << (p - 1)
    return m


def encode_reset(device_id: int) -> bytes:
    return bytes([CMD_RESET, device_id])


def encode_setup(device_id: int, ports: list[PortSetup]) -> bytes:
    ports = sorted(ports, key=lambda p: p.port)
    mask = _mask(p.port for p in ports)
    out = bytearray([CMD_SETUP, device_id, mask, *[p.motor_dir for p in ports],
                     mask, *[p.encoder_dir for p in ports], 0, 0])
    for p in ports:
        out += struct.pack("<ff", p.encoder_offset_deg, p.encoder_resolution)
    return bytes(out)


def encode_write(device_id: int, torques_in_port_order: list[float]) -> bytes:
    return bytes([CMD_WRITE, device_id]) + struct.pack(f"<{len(torques_in_port_order)}f",
                                                       *torques_in_port_order)


def state_size(n_encoders: int) -> int:
    return 1 + 4 * n_encoders


def encode_state(device_id: int, angles_deg_in_port_order: list[float]) -> bytes:
    return bytes([device_id]) + struct.pack(f"<{len(angles_deg_in_port_order)}f", *angles_deg_in_port_order)


class StateParser:
    """Finds the newest plausible state reply in a byte stream.

    The protocol has no checksum, so a reply is accepted when it starts with our device id,
    is complete, and holds finite angles within +-720 degrees; anything else is dropped and
    counted (`dropped_bytes`, `bad_replies`). Older complete replies are skipped in favour of
    the newest one (`stale_replies`): the force loop wants the latest pose, not a backlog.
    """

    MAX_ABS_DEG = 720.0

    def __init__(self, device_id: int, n_encoders: int):
        self.device_id = device_id
        self.n = n_encoders
        self.size = state_size(n_encoders)
        self._buf = bytearray()
        self.dropped_bytes = 0
        self.bad_replies = 0
        self.stale_replies = 0
        self.good_replies = 0

    def _decode(self, frame: bytes):
        angles = struct.unpack(f"<{self.n}f", frame[1:])
        if all(math.isfinite(a) and abs(a) <= self.MAX_ABS_DEG for a in angles):
            return angles
        return None

    def feed(self, data: bytes):
        """Add bytes; return the newest good reply's angles (degrees, port order) or None."""
        self._buf += data
        newest = None
        start = 0
        buf = self._buf
        while start + self.size <= len(buf):
            if buf[start] != self.device_id:
                start += 1
                self.dropped_bytes += 1
                continue
            angles = self._decode(bytes(buf[start:start + self.size]))
            if angles is None:
                self.bad_replies += 1
                self.dropped_bytes += 1
                start += 1
                continue
            if newest is not None:
                self.stale_replies += 1
            newest = angles
            start += self.size
        if newest is not None:
            self.good_replies += 1
        del buf[:start]  # everything before `start` was consumed or rejected
        if len(buf) > 4 * self.size:  # never let garbage pile up
            self.dropped_bytes += len(buf) - self.size
            del buf[:-self.size]
        return newest
