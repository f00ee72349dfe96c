"""The safety rules of the force loop, in one place (docs/guide/haptic-devices.md).

A gain g in [0, 1] multiplies the force every tick:
  - hard faults set g = 0 at once: the stop key (latched until `clear_stop`), a NaN/inf force
    sample (until the next finite one), a disconnect (final);
  - soft faults fade g to 0 in `fade_time` (< 50 ms): the solver stalls (no sample within
    `stall_timeout` after the next one was due), the app pauses;
  - with no fault, g ramps up linearly over `ramp_time` (on start, resume, or after any fault).
Then `clamp_force` limits the magnitude to the device maximum, always (drivers clamp again).
"""
from __future__ import annotations

from dataclasses import dataclass

HARD = ("stopped", "nan", "disconnected")
SOFT = ("paused", "stall")


@dataclass
class SafetyConfig:
    stall_timeout: float = 0.030  # s after a sample was due before the solver counts as stalled
    fade_time: float = 0.015  # s to fade to zero on a soft fault
    ramp_time: float = 0.5  # s to ramp from zero to full force
    stop_buttons: int = 0  # device buttons that act as the stop key

    def __post_init__(self):
        if not (0 < self.fade_time <= 0.05 and 0 < self.stall_timeout and self.stall_timeout + self.fade_time <= 0.05):
            raise ValueError("safety: stall_timeout + fade_time must be positive and at most 50 ms")
        if not self.ramp_time > 0:
            raise ValueError("safety: ramp_time must be positive")


class SafetyGate:
    def __init__(self, config: SafetyConfig | None = None):
        self.config = config or SafetyConfig()
        self.faults: set[str] = set()
        self.gain = 0.0
        self.counts = {k: 0 for k in HARD + SOFT}
        self._t = None

    def set_fault(self, name: str, on: bool = True) -> None:
        if on and name not in self.faults:
            self.faults.add(name)
            self.counts[name] += 1
        elif not on:
            self.faults.discard(name)

    def update(self, now: float) -> float:
        """Advance to time `now`; returns the gain to apply to the force this tick."""
        dt = 0.0 if self._t is None else max(now - self._t, 0.0)
        self._t = now
        if not self.faults.isdisjoint(HARD):
            self.gain = 0.0
        elif self.faults:
            self.gain = max(0.0, self.gain - dt / self.config.fade_time)
        else:
            self.gain = min(1.0, self.gain + dt / self.config.ramp_time)
        return self.gain

    @property
    def state(self) -> str:
        for name in HARD + SOFT:
            if name in self.faults:
                return name
        return "ramping" if self.gain < 1.0 else "ok"
