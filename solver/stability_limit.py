"""The measured stability limit of the scheme on the window's hard cases, in one place.

Measured by `feelflow validate --case stability --json docs/science/data/stability-numpy.json`
(solver/validation/stability.py: a plate thinner than a cell at 45 deg, an impulsively started
cylinder, a cylinder shaken and spun at the Mach cap, the wedge pointing upstream; 192 x 96,
float32, 6 d / U steps a point, the window's absorbing sponge, AMD EPYC 2 vCPUs, 2026-11-22;
the map is in docs/science/validation.md, 'Stability'). What the data say (lattice units, U the wind,
nu the viscosity, d the body size in cells):

* TRT (Lambda = 3/16, the window's operator): the most restrictive case is the shaken cylinder.
  Its highest cell Reynolds number Re_cell = U / nu below which every point was stable is
  8.75 / 8.75 / 4.375 at d = 10 / 20 / 40: neither Re_cell nor Re_D = U d / nu is constant;
  Re_cell sqrt(d) is 27.7 / 39.1 / 27.7 (27.7 / 27.95 / 27.7 without the absorbing layer),
  and K is the smallest. The fixed-body cases (plate, wedge, impulsive
  start) stay stable up to Re_cell = 10 at d = 20 (sqrt(d) Re_cell = 44.7) and fail from 11.25.
* BGK: within 6 d / U only the shaken cylinder failed, at the panel's extreme corner (Re_cell
  45 at d = 20; K_bgk = 156.5); runs of 30 d / U at that corner (`python -m
  feelflow.solver.validation.stability --u 0.09 --nu 0.002 --collision bgk --convective-times 30`): the
  shaken cylinder runs away after 1200 steps, the other three last.
  Its limit is therefore not measured finely; BGK gets TRT's K, at which all four cases ran
  30 d / U stably with both operators (`... --u 0.09 --k 27.67 --collision bgk|trt
  --convective-times 30`).

* rr (recursive-regularised BGK, solver/regularised.py), runs of 30 d / U (`python -m
  feelflow.solver.validation.stability --u U --nu NU --collision rr --size 10 20 40
  --convective-times 30 --backend gl`; every run is listed in docs/science/collision-operators.md).
  At the window's wind U = 0.05 every hard case, moving ones included, held U / nu = 75 at
  d = 10 and 20; at U = 0.09, 75 at d = 10 and 50 at d = 20 (at 75 the shaken cylinder passes
  the scan's bound). At d = 40 (the body blocks 42 % of the 96-row tunnel) U / nu = 75 fails
  (the wedge diverges); from U / nu = 30 to 50 the shaken cylinder stays finite (30 d / U at 50)
  but its max |u| reaches 0.35 - 0.39, past the bound, while the fixed bodies hold 50. The
  d = 40 entry is the lowest U / nu run there, 30: not a limit the bound confirms.
  The limit is the cell Reynolds number U / nu of STABLE_CELL_REYNOLDS for the smallest
  scanned size not below the body's (beyond 40 cells the d = 40 value falls as 1 / sqrt(d),
  TRT's law, not measured), at winds up to RR_WIND; above it, the limit falls as RR_WIND / U
  (U^2 / nu held: at U = 0.09 and d <= 20 that is 41.7, where 50 held and 75 did not).

So the TRT / BGK limit is `U sqrt(d) / nu <= K` with K per collision operator (the smallest measured
Re_cell sqrt(d) below which every run was stable); below d = 10 (the smallest size scanned) the
d = 10 value is used. The window keeps U sqrt(d) / nu <= SAFETY_MARGIN K.
"""
from __future__ import annotations

import math

#: collision -> K: every scanned hard case was stable for U sqrt(d) / nu <= K (see above;
#: BGK: TRT's value, its own limit lies beyond the 6 d / U scan)
STABLE_U_SQRT_D_OVER_NU = {"trt": 27.67, "bgk": 27.67}

#: collision -> ((d, Re_cell), ...): per scanned body size, the cell Reynolds number U / nu up to
#: which every hard case held 30 d / U (see above)
STABLE_CELL_REYNOLDS = {"rr": ((20.0, 75.0), (40.0, 30.0))}
#: the wind at which STABLE_CELL_REYNOLDS was measured; faster winds get U^2 / nu held (see above)
RR_WIND = 0.05

#: the smallest body size scanned; smaller bodies get its limit (not extrapolated upwards)
SMALLEST_SIZE_MEASURED = 10.0

#: fraction of the measured limit the window allows: the scan ran 6 d / U steps per point on
#: four shapes, the window runs for hours with any shape a student draws
SAFETY_MARGIN = 0.8


def measured_cell_reynolds(collision: str, size: float, speed: float = 0.0) -> float:
    """Highest Re_cell = U / nu measured stable for a body of `size` cells (no margin); `speed`
    matters only for operators measured at one wind (STABLE_CELL_REYNOLDS)."""
    if collision in STABLE_CELL_REYNOLDS:
        table = STABLE_CELL_REYNOLDS[collision]
        re_cell = next((r for d, r in table if float(size) <= d), None)
        if re_cell is None:
            d, r = table[-1]
            re_cell = r * math.sqrt(d / float(size))
        return re_cell * min(1.0, RR_WIND / abs(speed)) if speed else re_cell
    return STABLE_U_SQRT_D_OVER_NU[collision] / math.sqrt(max(float(size), SMALLEST_SIZE_MEASURED))


def max_cell_reynolds(collision: str, size: float, speed: float = 0.0) -> float:
    """The Re_cell the window allows for this collision operator, body size and wind (margin included)."""
    return SAFETY_MARGIN * measured_cell_reynolds(collision, size, speed)


def min_stable_viscosity(speed: float, collision: str, size: float) -> float:
    """The smallest viscosity that keeps wind `speed` past a body of `size` cells in the guarded region."""
    return abs(speed) / max_cell_reynolds(collision, size, speed)


def inside(speed: float, nu: float, collision: str, size: float) -> bool:
    """Does (speed, nu, size) lie inside the guarded region (with a rounding tolerance)?"""
    return nu >= min_stable_viscosity(speed, collision, size) * (1 - 1e-9)
