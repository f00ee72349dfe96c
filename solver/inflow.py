"""Inlet velocity: smooth ramp-up times a profile (docs/algorithm.md, 'Inflow').

One definition for both backends; the gl backend feeds `inflow_velocity` into its uniforms.
"""
from __future__ import annotations

import math

import numpy as np


def ramp(t: int, ramp_steps: int) -> float:
    """(1 - cos(pi t / T)) / 2 for t < T, else 1 (a C^1 start from rest, no pressure shock)."""
    if ramp_steps <= 0 or t >= ramp_steps:
        return 1.0
    return 0.5 * (1.0 - math.cos(math.pi * t / ramp_steps))


def profile(ny: int, speed: float, kind: str) -> np.ndarray:
    """Inlet x-velocity per row iy, (ny,) float64.

    uniform: U everywhere. parabolic: Poiseuille profile between walls at -1/2 and ny - 1/2,
    4 U s (H - s) / H^2 with s = iy + 1/2, H = ny, so U is the centre-line (peak) speed.
    """
    if kind == "uniform":
        return np.full(ny, float(speed))
    if kind == "parabolic":
        s = np.arange(ny, dtype=np.float64) + 0.5
        return 4.0 * speed * s * (ny - s) / float(ny) ** 2
    raise ValueError(f"unknown inflow profile {kind!r}")


def inflow_velocity(config, t: int, speed: float | None = None) -> np.ndarray:
    """u_in,x(iy, t) = ramp(t) * profile(iy), (ny,) float64; `speed` overrides config.inflow_speed."""
    u = config.inflow_speed if speed is None else speed
    return ramp(t, config.inflow_ramp_steps) * profile(config.ny, u, config.inflow_profile)
