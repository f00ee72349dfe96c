"""The simulated student's hand: where the handle is, changed by tests, the bench or a script."""
from __future__ import annotations

import math
import threading
import time


class Hand:
    """Handle position (metres, device frame) and buttons, thread-safe.

    With `wander=True` the hand traces a slow Lissajous figure inside `workspace`, so a
    simulated device moves the body in class demos without anyone touching it.
    """

    def __init__(self, x: float = 0.0, y: float = 0.0, workspace=None, wander: bool = False):
        self._lock = threading.Lock()
        self._x, self._y = x, y
        self.buttons = 0
        self.workspace = workspace
        self.wander = wander
        self._t0 = time.monotonic()
        self.moved_at = None  # monotonic time of the last set()

    def set(self, x: float, y: float = 0.0) -> None:
        with self._lock:
            self._x, self._y = x, y
            self.wander = False
            self.moved_at = time.monotonic()

    def get(self) -> tuple[float, float]:
        with self._lock:
            if self.wander and self.workspace is not None:
                (x0, x1), (y0, y1) = self.workspace
                t = time.monotonic() - self._t0
                cx, cy, ax, ay = (x0 + x1) / 2, (y0 + y1) / 2, 0.35 * (x1 - x0), 0.35 * (y1 - y0)
                return cx + ax * math.sin(0.5 * t), cy + ay * math.sin(0.37 * t)
            return self._x, self._y


class ForceLog:
    """What the host commanded, as the device understood it (newtons, device frame)."""

    def __init__(self):
        self._lock = threading.Lock()
        self.last = (0.0, 0.0)
        self.max_magnitude = 0.0
        self.count = 0
        self.changed_at = None  # monotonic time the command last changed

    def record(self, fx: float, fy: float) -> None:
        with self._lock:
            if (fx, fy) != self.last:
                self.changed_at = time.monotonic()
            self.last = (fx, fy)
            self.count += 1
            self.max_magnitude = max(self.max_magnitude, math.hypot(fx, fy))
