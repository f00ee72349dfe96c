"""From solver force samples (tens to hundreds of Hz) to a smooth 1 kHz force in newtons.

1. Interpolation: each new sample starts a linear ramp from the current output to the new value,
   lasting the measured sample interval (a first-order hold that adds at most one interval of
   delay and never extrapolates, so it cannot overshoot the samples).
2. Low-pass: a first-order IIR, y += a (x - y), a = 1 - exp(-2 pi f_c dt).
3. Scaling: newtons = lattice force * gain, gain = comfort_fraction * device max / expected peak,
   so the scene's expected peak is felt as a comfortable fraction of what the device can give.
The safety gate (haptics.safety) and the clamp come after this.
"""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class ForceScale:
    """Lattice force -> newtons. expected_peak: the scene's largest expected |F| (lattice units);
    comfort_fraction: the fraction of the device maximum that peak should feel like (0..1]."""

    expected_peak: float
    comfort_fraction: float
    device_max: float

    def __post_init__(self):
        if not (math.isfinite(self.expected_peak) and self.expected_peak > 0):
            raise ValueError(f"expected peak force must be a positive number, got {self.expected_peak!r}")
        if not (math.isfinite(self.comfort_fraction) and 0 < self.comfort_fraction <= 1):
            raise ValueError(f"comfort fraction must be in (0, 1], got {self.comfort_fraction!r}")
        if not (math.isfinite(self.device_max) and self.device_max >= 0):
            raise ValueError(f"device maximum force must be >= 0, got {self.device_max!r}")

    @property
    def gain(self) -> float:
        """Newtons per lattice force unit."""
        return self.comfort_fraction * self.device_max / self.expected_peak


class ForceInterpolator:
    """First-order hold between samples plus a first-order low-pass, evaluated at loop ticks."""

    MIN_INTERVAL, MAX_INTERVAL = 0.001, 0.2

    def __init__(self, cutoff_hz: float = 30.0):
        if not cutoff_hz > 0:
            raise ValueError("force filter cutoff must be positive")
        self.cutoff_hz = cutoff_hz
        self.reset()

    def reset(self) -> None:
        self.interval = 0.02  # estimate of the sample interval, seconds
        self._last_arrival = None
        self._from = (0.0, 0.0)
        self._to = (0.0, 0.0)
        self._t0 = 0.0
        self._held = (0.0, 0.0)
        self.output = (0.0, 0.0)
        self._t_prev = None

    def add(self, fx: float, fy: float, arrival: float) -> None:
        """A new (finite) sample arrived at time `arrival` (seconds, monotonic)."""
        if self._last_arrival is not None:
            dt = min(max(arrival - self._last_arrival, self.MIN_INTERVAL), self.MAX_INTERVAL)
            self.interval += 0.3 * (dt - self.interval)
        self._last_arrival = arrival
        self._from = self._held
        self._to = (fx, fy)
        self._t0 = arrival

    def held(self, now: float) -> tuple[float, float]:
        u = min(max((now - self._t0) / self.interval, 0.0), 1.0)
        self._held = (self._from[0] + u * (self._to[0] - self._from[0]),
                      self._from[1] + u * (self._to[1] - self._from[1]))
        return self._held

    def evaluate(self, now: float) -> tuple[float, float]:
        """The filtered force at time `now` (call once per tick, times increasing)."""
        hx, hy = self.held(now)
        dt = 0.001 if self._t_prev is None else min(max(now - self._t_prev, 0.0), 0.05)
        self._t_prev = now
        a = 1.0 - math.exp(-2 * math.pi * self.cutoff_hz * dt)
        ox, oy = self.output
        self.output = (ox + a * (hx - ox), oy + a * (hy - oy))
        return self.output

    @property
    def next_due(self) -> float | None:
        """When the next sample is expected (None before the first one)."""
        return None if self._last_arrival is None else self._last_arrival + self.interval
