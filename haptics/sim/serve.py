"""A serial device simulator in its own process, as real hardware is: `python -m feelflow.haptics.sim.serve
haply2diy|hapkit` creates the simulator (behind a pseudo-terminal), prints one JSON line
{"port": "/dev/pts/N"} and then obeys one JSON command per line on stdin (the simulated hand,
fault injection, what the device was commanded). EOF on stdin stops it.

In one process with the force loop, the simulator's thread and the loop share the interpreter
lock; on a loaded machine that starved the simulated board for 250 ms now and then (read as a
disconnect). A separate process keeps "the device" independent of the host, like a real board.
`RemoteSim` is the host-side handle, with the attributes the tests and the bench use.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import time


def _make(kind: str):
    if kind == "haply2diy":
        from feelflow.haptics.sim.haply_sim import HaplySim
        return HaplySim()
    if kind == "hapkit":
        from feelflow.haptics.sim.hapkit_sim import HapkitSim
        return HapkitSim()
    raise SystemExit(f"unknown serial simulator {kind!r}")


def serve(kind: str) -> int:
    sim = _make(kind)
    out = sys.stdout

    def reply(obj) -> None:
        out.write(json.dumps(obj) + "\n")
        out.flush()

    reply({"port": sim.port})
    for line in sys.stdin:
        try:
            cmd = json.loads(line)
        except ValueError:
            continue
        op = cmd.get("op")
        if op == "hand":
            sim.hand.set(cmd["x"], cmd.get("y", 0.0))
        elif op == "buttons":
            sim.hand.buttons = int(cmd["mask"])
        elif op == "inject":
            sim.inject(bytes.fromhex(cmd["hex"]))
        elif op == "mute":
            sim.muted = bool(cmd["on"])
        elif op == "disconnect":
            sim.disconnect()
        elif op == "state":
            f = sim.forces
            reply({"last": list(f.last), "max": f.max_magnitude, "count": f.count,
                   "hand": list(sim.hand.get()), "errors": list(sim.errors)})
        elif op == "stop":
            break
    sim.stop()
    return 0


class _RemoteHand:
    def __init__(self, owner: "RemoteSim", workspace):
        self._owner = owner
        self._xy = (0.0, 0.0)
        self._buttons = 0
        self.workspace = workspace
        self.moved_at = None

    def set(self, x: float, y: float = 0.0) -> None:
        self.moved_at = time.monotonic()
        self._xy = (x, y)
        self._owner.send({"op": "hand", "x": x, "y": y})

    def get(self):
        return self._owner.state()["hand"]

    @property
    def buttons(self) -> int:
        return self._buttons

    @buttons.setter
    def buttons(self, mask: int) -> None:
        self._buttons = mask
        self._owner.send({"op": "buttons", "mask": mask})


class _RemoteForces:
    def __init__(self, owner: "RemoteSim"):
        self._owner = owner

    @property
    def last(self):
        return tuple(self._owner.state()["last"])

    @property
    def max_magnitude(self) -> float:
        return self._owner.state()["max"]

    @property
    def count(self) -> int:
        return self._owner.state()["count"]


class RemoteSim:
    """Host-side handle on a simulator process (same attributes as the in-process simulators
    that tests and the bench use: port, hand, forces, inject, muted, disconnect, stop, errors)."""

    def __init__(self, kind: str, workspace=None):
        self._proc = subprocess.Popen([sys.executable, "-m", "feelflow.haptics.sim.serve", kind],
                                      stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        self._lock = threading.Lock()
        line = self._proc.stdout.readline()
        if not line:
            raise RuntimeError(f"simulator {kind} did not start")
        self.port = json.loads(line)["port"]
        self.hand = _RemoteHand(self, workspace)
        self.forces = _RemoteForces(self)
        self._muted = False
        self._last_state = {"last": [0.0, 0.0], "max": 0.0, "count": 0, "hand": [0.0, 0.0], "errors": []}

    def send(self, cmd: dict) -> None:
        with self._lock:
            try:
                self._proc.stdin.write(json.dumps(cmd) + "\n")
                self._proc.stdin.flush()
            except (OSError, ValueError):
                pass

    def state(self) -> dict:
        with self._lock:
            try:
                self._proc.stdin.write(json.dumps({"op": "state"}) + "\n")
                self._proc.stdin.flush()
                self._last_state = json.loads(self._proc.stdout.readline())
            except (OSError, ValueError):  # the simulator process has ended: what it last said
                self._last_state = dict(self._last_state, errors=["simulator process ended"])
            return self._last_state

    @property
    def errors(self):
        return self.state()["errors"]

    def inject(self, data: bytes) -> None:
        self.send({"op": "inject", "hex": bytes(data).hex()})

    @property
    def muted(self) -> bool:
        return self._muted

    @muted.setter
    def muted(self, on: bool) -> None:
        self._muted = bool(on)
        self.send({"op": "mute", "on": self._muted})

    def disconnect(self) -> None:
        self.send({"op": "disconnect"})

    def stop(self) -> None:
        if self._proc.poll() is None:
            self.send({"op": "stop"})
            try:
                self._proc.stdin.close()
            except OSError:
                pass
            try:
                self._proc.wait(3.0)
            except subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait(1.0)


if __name__ == "__main__":
    sys.exit(serve(sys.argv[1]))
