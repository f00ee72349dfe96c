"""The quiet (characteristic) velocity inlet: it passes sound that reaches it from inside.

A bare velocity inlet fixes u at x = -1/2 and reflects every sound wave (a closed end for
sound). In one dimension a wave running upstream carries u' = -c_s rho' / RHO0; the inlet lets
it out when its wall velocity follows that wave, i.e. when the incoming characteristic
u + c_s rho' / RHO0 is held and the outgoing one is free (Thompson 1987; for lattice Boltzmann
Izquierdo & Fueyo, Phys. Rev. E 78 (2008) 046707, and Heubes, Bartel & Ehrhardt, J. Comput.
Appl. Math. 262 (2014) 51). Rule c's wall velocity of row iy becomes

    u_w = u_in(iy, t) - c_s (drho(0, iy) - drho_ref(iy)) / RHO0,

drho(0, iy) the density fluctuation of the inlet node's stored (post-collision) populations.
The reference drho_ref follows drho at the inlet slowly, drho_ref += k (drho - drho_ref) each
step (k = `inlet_nonreflecting`, about 1e-3), so the tunnel's mean pressure rise towards the
inlet (what drives the flow past the body) is kept in it and the mean inflow stays u_in;
waves faster than about k / (2 pi) cycles per step leave. While the inflow ramps up
(ramp(t) < 1) the inlet is the bare velocity inlet and the reference is held: the inlet's
density then is the ramp's sound, and a reference that learnt it bent the mean inflow for
thousands of steps after the ramp (docs/science/quiet-tunnel.md). drho_ref starts at 0 and
restarts there when the distributions are set. Both backends: the numpy backend keeps drho_ref as a
(ny,) row; the gl backend in G4's spare channel z of texel column 0 (solver/gl_layout.py).
docs/science/quiet-tunnel.md.
"""
from __future__ import annotations

import math

import numpy as np

from feelflow.solver.lattice import CS2, RHO0

#: c_s / RHO0, the correction's coefficient
CS_OVER_RHO0 = math.sqrt(CS2) / RHO0


def shortest_ramp(nx: int) -> int:
    """The shortest inflow ramp (steps) the quiet inlet takes: half a period of the tunnel's
    slowest sound mode, 2 nx / c_s (the quarter-wave mode between the velocity inlet and the
    pressure outlet has period 4 nx / c_s). A ramp from rest that is shorter leaves that mode
    ringing strongly when it ends; the quiet inlet lets that sound out as a swing of the inflow,
    and in a 400-column tunnel after a 1000-step ramp (0.36 of the period) the inflow's mean
    stayed 2.7 % high for 5000 steps (docs/science/quiet-tunnel.md, 'Ramps'). A ramp of 0 (the
    wind everywhere from the first step, as in the window) is always taken."""
    return math.ceil(2.0 * nx / math.sqrt(CS2))


def quiet_terms(rate: float, ramp_value: float) -> tuple[float, float]:
    """(the reference's rate, the correction's coefficient c_s / RHO0) this step: (rate,
    CS_OVER_RHO0) once the inflow ramp is over, (0, 0) while it runs (module docstring)."""
    return (rate, CS_OVER_RHO0) if ramp_value >= 1.0 else (0.0, 0.0)


def wall_velocity_correction(drho: np.ndarray, drho_ref: np.ndarray, rate: float,
                             coefficient: float = CS_OVER_RHO0) -> np.ndarray:
    """Update `drho_ref` in place (drho_ref += rate (drho - drho_ref)) and return the (ny,)
    correction -coefficient (drho - drho_ref) added to rule c's wall velocity of every inlet
    link of the row (module docstring). drho: the inlet column's density fluctuation, (ny,)."""
    drho_ref += rate * (drho - drho_ref)
    return (-coefficient) * (drho - drho_ref)


def checked_reference(solver, row) -> np.ndarray:
    """`row` as a finite (ny,) float64 reference for `solver` (a Solver with the quiet inlet:
    Solver.set_inlet_reference), else ValueError naming what is wrong."""
    if not solver.has_quiet_inlet:
        raise ValueError("this flow has no quiet inlet (inlet_nonreflecting = 0): no reference to set")
    row = np.asarray(row, dtype=np.float64)
    if row.shape != (solver.config.ny,) or not np.isfinite(row).all():
        raise ValueError(f"the quiet inlet's reference must be {solver.config.ny} finite numbers, got shape {row.shape}")
    return row
