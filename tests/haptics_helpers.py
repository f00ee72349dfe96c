"""Shared helpers for the haptics tests (kept out of conftest.py, which other helpers own)."""
from __future__ import annotations

import math
import threading
import time

import numpy as np

from feelflow.haptics.timing import try_realtime


def wait_for(cond, timeout=3.0, step=0.002):
    """Poll `cond()` until true or timeout; returns its last value."""
    deadline = time.monotonic() + timeout
    while True:
        v = cond()
        if v or time.monotonic() > deadline:
            return v
        time.sleep(step)


class Feeder:
    """Plays the solver: submits (fx, fy) lattice force samples (and `torque`) at `hz` from its own thread.

    It asks for a real-time slot (as the loop does) so that a loaded test machine does not
    starve it: a starved feeder IS a solver stall, and the loop would rightly zero the force.
    `sending = False` stops the samples (a stall on purpose).
    """

    def __init__(self, loop, fx=0.0, fy=0.0, hz=100.0):
        from feelflow.haptics import ForceSample

        self.loop, self.fx, self.fy, self.hz = loop, fx, fy, hz
        self.torque = 0.0
        self.sending = True
        self._stop = threading.Event()
        self._sample = ForceSample
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self):
        try_realtime(5)
        next_t = time.monotonic()
        while not self._stop.is_set():
            if self.sending:
                self.loop.submit_force(self._sample(self.fx, self.fy, time.monotonic(), torque=self.torque))
            next_t += 1.0 / self.hz
            time.sleep(max(0.0, next_t - time.monotonic()))

    def close(self):
        self._stop.set()
        self._thread.join(1.0)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def force(loop) -> float:
    return math.hypot(*loop.status().force)


def record(loop):
    """The loop's per-tick recording as numpy arrays (LoopConfig(record=True)); safe while the
    loop runs (cut to the shortest list, as the loop thread appends one list after another)."""
    lists = {k: list(v) for k, v in loop.recording.items()}
    n = min(len(v) for v in lists.values())
    return {k: np.array(v[:n], dtype=float) for k, v in lists.items()}


def force_after(loop, t0):
    """(times, |F|) of the ticks at or after monotonic time t0."""
    r = record(loop)
    sel = r["t"] >= t0
    return r["t"][sel], np.hypot(r["fx"][sel], r["fy"][sel])
