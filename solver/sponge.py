"""The outlet sponge of a tunnel: a viscosity ramp and an absorbing layer in its last columns.

In the last L = `sponge_cells` columns, with s = (ix - (nx - L) + 1) / L rising from 1/L to 1:
- the viscosity grows to nu (1 + (A - 1) s^2), A = `sponge_strength`, which damps vortices
  before they reach the pressure outlet;
- with `sponge_absorb` = a > 0, the absorbing layer: the equilibria use the density fluctuation
  keep drho and the velocity keep u + (1 - keep) u_in(iy, t), keep = 1 - a s^2, so each
  collision relaxes the node towards the far-field state (RHO0, the inflow profile) at
  omega+ a s^2, and sound leaves the tunnel instead of ringing between the velocity inlet and
  the pressure outlet (Kam, Leung & Chew, Phys. Rev. E 74 (2006) 036704; Xu & Sagaut,
  J. Comput. Phys. 245 (2013) 14, who analyse both kinds of layer for lattice Boltzmann).
Both backends take their per-column rates from here; the numpy backend applies them in
`solver/collision.py`, the gl backend in `shaders/lbm_step.glsl` (variant SPONGE).
"""
from __future__ import annotations

import numpy as np

from feelflow.solver.config import FlowConfig


def sponge_position(config: FlowConfig):
    """None (no sponge), or the (nx,) row s = (ix - (nx - L) + 1) / L clipped at 0: 0 before the
    outlet sponge's L = sponge_cells columns, rising to 1 at the last column."""
    L = config.sponge_cells if config.x_boundary == "tunnel" else 0
    if L == 0:
        return None
    ix = np.arange(config.nx, dtype=np.float64)
    return np.clip((ix - (config.nx - L) + 1) / L, 0.0, None)


def sponge_viscosity(config: FlowConfig):
    """The kinematic viscosity: config.nu, or the (nx,) row nu (1 + (A - 1) s^2) with a sponge."""
    s = sponge_position(config)
    if s is None:
        return config.nu
    return config.nu * (1.0 + (config.sponge_strength - 1.0) * s * s)


def absorb_keep(config: FlowConfig):
    """None, or the (nx,) row keep(ix) = 1 - a s^2 (a = sponge_absorb) of the absorbing layer
    (module docstring)."""
    s = sponge_position(config)
    if s is None or config.sponge_absorb == 0.0:
        return None
    return 1.0 - config.sponge_absorb * s * s
