"""Shared helpers for the haptics tests (kept out of conftest.py, which other helpers own)."""
from __future__ import annotations

import time

import numpy as np


def wait_for(cond, timeout=2.0, step=0.002):
    """Poll `cond()` until true or timeout; returns its last value."""
    deadline = time.monotonic() + timeout
    while True:
        v = cond()
        if v or time.monotonic() > deadline:
            return v
        time.sleep(step)


def feed(loop, value, seconds, hz=100.0, fy=0.0):
    """Play the solver: submit a constant lattice force at `hz` for `seconds`."""
    from haptics import ForceSample

    end = time.monotonic() + seconds
    while time.monotonic() < end:
        loop.submit_force(ForceSample(value, fy, time.monotonic()))
        time.sleep(1.0 / hz)


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
