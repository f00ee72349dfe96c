"""The measured stability limit of the scheme on the window's hard cases, in one place.

The limit is a cell (grid) Reynolds number Re_cell = U / nu (lattice units: U in cells per
step, nu in cells^2 per step): above it the hard cases of a classroom diverge. Measured by
`feelflow validate --case stability --json docs/bench/stability.json` (solver/validation/
stability.py: thin plate at 45 deg, impulsive start, a cylinder shaken and spun at the Mach cap,
wedge pointing upstream; 192 x 96, body 20 cells; the README's Validation section has the map).
`MAX_CELL_REYNOLDS` is, per collision operator, the highest Re_cell below which every scanned
point of every scene stayed stable; the window keeps Re_cell <= SAFETY_MARGIN x that.
"""
from __future__ import annotations

#: collision -> highest Re_cell = U / nu at which every hard case was still stable (the scan)
MAX_CELL_REYNOLDS = {"bgk": 5.0, "trt": 5.0}

#: fraction of the measured limit the window allows: the scan ran 6 d / U steps per point, the
#: window runs for hours, with any shape a student draws
SAFETY_MARGIN = 0.8


def max_cell_reynolds(collision: str) -> float:
    """The Re_cell the window allows for this collision operator (margin included)."""
    return SAFETY_MARGIN * MAX_CELL_REYNOLDS[collision]


def min_stable_viscosity(speed: float, collision: str) -> float:
    """The smallest viscosity that keeps wind `speed` inside the guarded region."""
    return abs(speed) / max_cell_reynolds(collision)


def inside(speed: float, nu: float, collision: str) -> bool:
    """Does (speed, nu) lie inside the guarded region (with a rounding tolerance)?"""
    return nu >= min_stable_viscosity(speed, collision) * (1 - 1e-9)
