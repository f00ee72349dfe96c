"""The measured frame rates the status bar shows: solver steps per second, frames per second
and million lattice updates per second (MLUPS), each counted over about one second."""
from __future__ import annotations

import time


class FrameRates:
    """Counts steps and frames and turns them into rates once a second."""

    def __init__(self):
        self.now = {"steps_per_s": 0.0, "fps": 0.0, "mlups": 0.0}
        self._window = [time.perf_counter(), 0, 0]   # start, steps, frames

    def count(self, now: float, steps: int, nodes: int):
        """One frame of `steps` solver steps on a grid of `nodes` nodes, ending at `now` (s)."""
        w = self._window
        w[1] += steps
        w[2] += 1
        if now - w[0] >= 1.0:
            dt = now - w[0]
            self.now = {"steps_per_s": w[1] / dt, "fps": w[2] / dt, "mlups": w[1] * nodes / dt / 1e6}
            self._window = [now, 0, 0]
