"""Tunnel ends: inlet velocity (smooth ramp-up times a profile) and the pressure outlet.

docs/science/algorithm.md, rules c and d and 'Inflow'. One definition for both backends: `ramp`,
`profile` (per row) and `inlet_wall_profile` (per inlet link: rule c) (the numpy backend
multiplies them each step with the profiles cached, the gl backend uploads the profiles as a
texture and the ramp as a uniform); `inflow_velocity` is the row's product, the definition the
tests check; the gl backend implements `outlet_incoming` in GLSL.
"""
from __future__ import annotations

import math

import numpy as np

from feelflow.solver.lattice import C, OPP, RHO0, W

#: the populations the inlet supplies (c_x = +1)
INLET_DIRECTIONS = (1, 5, 8)
#: the populations the outlet supplies (c_x = -1)
OUTLET_DIRECTIONS = (3, 6, 7)


def ramp(t: int, ramp_steps: int) -> float:
    """(1 - cos(pi t / T)) / 2 for t < T, else 1 (a C^1 start from rest, no pressure shock)."""
    if ramp_steps <= 0 or t >= ramp_steps:
        return 1.0
    return 0.5 * (1.0 - math.cos(math.pi * t / ramp_steps))


def profile_at(s, ny: int, speed: float, kind: str) -> np.ndarray:
    """Inlet x-velocity at heights `s` above the lower wall (cells; walls at s = 0 and s = ny,
    i.e. y = -1/2 and ny - 1/2), float64 array shaped like `s`.

    uniform: U everywhere. parabolic: the Poiseuille profile 4 U s (H - s) / H^2 with H = ny, so
    U is the centre-line (peak) speed.
    """
    s = np.asarray(s, dtype=np.float64)
    if kind == "uniform":
        return np.full(s.shape, float(speed))
    if kind == "parabolic":
        return 4.0 * speed * s * (ny - s) / float(ny) ** 2
    raise ValueError(f"unknown inflow profile {kind!r}")


def profile(ny: int, speed: float, kind: str) -> np.ndarray:
    """Inlet x-velocity per row iy (at the row's height s = iy + 1/2), (ny,) float64."""
    return profile_at(np.arange(ny) + 0.5, ny, speed, kind)


def inlet_wall_profile(ny: int, speed: float, kind: str) -> np.ndarray:
    """Rule c's wall velocity per link, (3, ny) float64 ordered as INLET_DIRECTIONS.

    The population i of row iy enters from the ghost node (-1, iy - c_iy); half-way bounce-back
    reflects it at the link's midpoint (-1/2, iy - c_iy / 2), so the moving-wall term takes the
    inflow there (Ladd 1994: the wall velocity at the point where the link meets the wall), at
    s = iy + 1/2 - c_iy / 2: the row's own height for i = 1, half a cell below for i = 5, half a
    cell above for i = 8. The row's own velocity for the diagonals is off by half a cell's change
    of the profile, a first-order error that shears the flow at the inlet (docs/science/validation.md,
    Schaefer-Turek 2D-1).
    """
    s = np.arange(ny) + 0.5
    return np.stack([profile_at(s - 0.5 * C[i, 1], ny, speed, kind) for i in INLET_DIRECTIONS])


def inflow_velocity(config, t: int, speed: float | None = None) -> np.ndarray:
    """u_in,x(iy, t) = ramp(t) * profile(iy), (ny,) float64; `speed` overrides config.inflow_speed."""
    u = config.inflow_speed if speed is None else speed
    return ramp(t, config.inflow_ramp_steps) * profile(config.ny, u, config.inflow_profile)


def outlet_incoming(g_last: np.ndarray) -> np.ndarray:
    """Rule d, anti-bounce-back pressure outlet at x = nx - 1/2 (Krueger et al. 2017, eq. 5.53;
    Izquierdo & Fueyo 2008): for i in OUTLET_DIRECTIONS, at the last column,
        f_i^in = -f*_ib + 2 w_i RHO0 (1 + 9/2 (c_i.u_b)^2 - 3/2 u_b^2),
        u_b = u(nx-1) + (u(nx-1) - u(nx-2)) / 2,  u = sum c f* / sum f*,
    written for shifted populations: g_i^in = -g*_ib + 2 w_i RHO0 (9/2 (c_i.u_b)^2 - 3/2 u_b^2).

    g_last: (9, ny, 2) shifted post-collision populations of the last two columns.
    Returns (3, ny) in g_last's dtype, ordered as OUTLET_DIRECTIONS.
    """
    g = g_last.astype(np.float64)
    rho = g.sum(axis=0) + RHO0
    ux = np.tensordot(C[:, 0].astype(np.float64), g, axes=1) / rho
    uy = np.tensordot(C[:, 1].astype(np.float64), g, axes=1) / rho
    bx = 1.5 * ux[:, 1] - 0.5 * ux[:, 0]
    by = 1.5 * uy[:, 1] - 0.5 * uy[:, 0]
    usq = bx * bx + by * by
    out = np.empty((len(OUTLET_DIRECTIONS), g.shape[1]), dtype=g_last.dtype)
    for k, i in enumerate(OUTLET_DIRECTIONS):
        cu = C[i, 0] * bx + C[i, 1] * by
        out[k] = -g[OPP[i], :, 1] + 2.0 * W[i] * RHO0 * (4.5 * cu * cu - 1.5 * usq)
    return out
