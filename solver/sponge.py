"""The sponges of a tunnel: a viscosity ramp and an absorbing layer in its last columns, and an
absorbing layer in its first columns.

In the last L = `sponge_cells` columns, with s = (ix - (nx - L) + 1) / L rising from 1/L to 1:
- the viscosity grows to nu (1 + (A - 1) s^2), A = `sponge_strength`, which damps vortices
  before they reach the pressure outlet;
- with `sponge_absorb` = a > 0, the absorbing layer: the equilibria use the density fluctuation
  keep drho and the velocity keep u + (1 - keep) u_in(iy, t), keep = 1 - a s^2, so each
  collision relaxes the node towards the far-field state (RHO0, the inflow profile) at
  omega+ a s^2, and sound leaves the tunnel instead of ringing between the velocity inlet and
  the pressure outlet (Kam, Leung & Chew, Phys. Rev. E 74 (2006) 036704; Xu & Sagaut,
  J. Comput. Phys. 245 (2013) 14, who analyse both kinds of layer for lattice Boltzmann).
The inlet's layer (`inlet_sponge_cells` = L_in > 0, with sponge_absorb = a > 0) relaxes the
velocity alone in the first L_in columns, keep_u = 1 - a s_in^2 with s_in = (L_in - ix) / L_in
falling from 1 at the inlet column to 1/L_in; the viscosity and the density are left alone, so
the tunnel's mean pressure rise towards the inlet (what drives the flow past the body) stays
and no mass is drawn from the inflow. Without it the velocity inlet reflects every sound wave
back into the tunnel (docs/science/quiet-tunnel.md).
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


def inlet_position(config: FlowConfig):
    """None (no inlet layer), or the (nx,) row s_in = (L_in - ix) / L_in clipped at 0: 1 at the
    inlet column, falling to 1/L_in at column L_in - 1 and 0 beyond (L_in = inlet_sponge_cells)."""
    L = config.inlet_sponge_cells if config.x_boundary == "tunnel" else 0
    if L == 0:
        return None
    ix = np.arange(config.nx, dtype=np.float64)
    return np.clip((L - ix) / L, 0.0, None)


def absorb_keep(config: FlowConfig):
    """None, or the (nx,) row keep(ix) = 1 - a (s^2 + s_in^2) (a = sponge_absorb) of the
    absorbing layers at the outlet and the inlet: the velocity's keep (module docstring)."""
    rows = [p for p in (sponge_position(config), inlet_position(config)) if p is not None]
    if not rows or config.sponge_absorb == 0.0:
        return None
    return 1.0 - config.sponge_absorb * sum(p * p for p in rows)


def density_keep(config: FlowConfig):
    """None, or the (nx,) row 1 - a s^2 of the density fluctuation: the outlet's layer only
    (the inlet's relaxes the velocity alone, module docstring)."""
    s = sponge_position(config)
    if absorb_keep(config) is None:
        return None
    return np.ones(config.nx) if s is None else 1.0 - config.sponge_absorb * s * s
