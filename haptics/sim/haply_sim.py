"""A Haply M3 board (firmware v1.5) driving a 2DIY pantograph, behind a pseudo-terminal.

It parses the hAPI byte stream the way the firmware does (command byte, then fields whose count
depends on the set-up masks), answers each write with the encoder angles of the simulated hand's
position (inverse kinematics, quantised to the encoder resolution) and converts the torques it
receives back to a handle force (recorded in `forces`), clamping each motor to MAX_TORQUE as the
firmware does.
"""
from __future__ import annotations

import collections
import math
import struct

from feelflow.haptics.drivers.haply2diy import MAX_TORQUE, WORKSPACE
from feelflow.haptics.kinematics import HAPLY_2DIY, OutOfReach
from feelflow.haptics.protocols import haply
from feelflow.haptics.sim.hand import ForceLog, Hand
from feelflow.haptics.sim.pty_device import PtyDevice


class HaplySim(PtyDevice):
    def __init__(self, hand: Hand | None = None):
        self.hand = hand or Hand(0.0, 0.10, WORKSPACE)
        self.forces = ForceLog()
        self.mech = HAPLY_2DIY
        self.device_id = None
        self.encoders = {}  # port -> (offset, resolution)
        self.motors = []  # ports, in order
        self.torques = {}  # port -> last torque
        self.commands = collections.deque(maxlen=64)  # the last commands seen, for tests
        self._buf = bytearray()
        self._reported = None  # (th1, th2) radians last sent to the host
        super().__init__()

    def _need(self, n: int) -> bool:
        return len(self._buf) >= n

    def _parse_one(self):
        """Consume one complete command from the buffer; None if incomplete."""
        b = self._buf
        cmd = b[0]
        if cmd == haply.CMD_RESET:
            if not self._need(2):
                return None
            self.device_id, self.encoders, self.motors = b[1], {}, []
            del b[:2]
            return (cmd, None)
        if cmd == haply.CMD_SETUP:
            if not self._need(3):
                return None
            mmask = b[2]
            nm = bin(mmask & 0xF).count("1")
            i = 3 + nm
            if not self._need(i + 1):
                return None
            emask = b[i]
            ne = bin(emask & 0xF).count("1")
            i += 1 + ne
            if not self._need(i + 1):
                return None
            ns = b[i]
            i += 1 + ns
            if not self._need(i + 1):
                return None
            npwm = b[i]
            i += 1 + npwm
            if not self._need(i + 8 * ne):
                return None
            params = struct.unpack_from(f"<{2 * ne}f", b, i)
            eports = [p for p in range(1, 5) if emask >> (p - 1) & 1]
            self.device_id = b[1]
            self.encoders = {p: (params[2 * k], params[2 * k + 1]) for k, p in enumerate(eports)}
            self.motors = [p for p in range(1, 5) if mmask >> (p - 1) & 1]
            del b[:i + 8 * ne]
            return (cmd, None)
        if cmd == haply.CMD_WRITE:
            n = 2 + 4 * len(self.motors)
            if not self._need(n):
                return None
            torques = struct.unpack_from(f"<{len(self.motors)}f", b, 2)
            did = b[1]
            del b[:n]
            self.torques = {p: max(-MAX_TORQUE, min(MAX_TORQUE, t)) if math.isfinite(t) else 0.0
                            for p, t in zip(self.motors, torques)}
            return (cmd, did)
        del b[:1]  # unknown command byte: the firmware's switch ignores it
        return ("junk", None)

    def joint_angles(self):
        x, y = self.hand.get()
        try:
            return self.mech.inverse(x, y)
        except OutOfReach:
            return self.mech.inverse(0.0, 0.10)

    def on_bytes(self, data: bytes) -> bytes:
        self._buf += data
        out = bytearray()
        while self._buf:
            got = self._parse_one()
            if got is None:
                break
            cmd, did = got
            self.commands.append(cmd)
            if cmd == haply.CMD_WRITE and did == self.device_id and self.encoders:
                th1, th2 = self.joint_angles()
                joint = {2: th1, 1: th2}  # port 2 carries joint 1 on a 2DIY
                angles = []
                for p in sorted(self.encoders):
                    _, res = self.encoders[p]
                    deg = math.degrees(joint.get(p, 0.0))
                    angles.append(round(deg * res / 360.0) * 360.0 / res)  # encoder quantisation
                t1, t2 = self.torques.get(2, 0.0), self.torques.get(1, 0.0)
                try:  # the force these torques make at the pose the host was told (its Jacobian)
                    q1, q2 = self._reported or (th1, th2)
                    fx, fy = self.mech.force_from_torques(q1, q2, t1, t2)
                except (ValueError, ArithmeticError):
                    fx = fy = 0.0
                self.forces.record(fx, fy)
                by_port = dict(zip(sorted(self.encoders), angles))
                self._reported = (math.radians(by_port.get(2, 0.0)), math.radians(by_port.get(1, 0.0)))
                out += haply.encode_state(self.device_id, angles)
        return bytes(out)
