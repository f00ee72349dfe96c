"""Relaxation rates of the collision from the viscosity (BGK, TRT, and rr: one rate as BGK).

tau = 3 nu + 1/2 (c_s^2 = 1/3); omega+ = 1 / tau. TRT (Ginzburg, Verhaeghe & d'Humieres,
Commun. Comput. Phys. 3 (2008) 427): the odd rate omega- follows from the magic number
Lambda = (1/omega+ - 1/2)(1/omega- - 1/2) = `trt_magic`; BGK: omega- = omega+.
"""
from __future__ import annotations

import numpy as np

from feelflow.solver.config import FlowConfig
from feelflow.solver.sponge import sponge_position, sponge_viscosity


def relaxation_rates(config: FlowConfig):
    """(omega+, omega-) as scalars, or (nx,) rows where the outlet sponge raises nu
    (solver/sponge.py)."""
    tau = 3.0 * np.asarray(sponge_viscosity(config), dtype=np.float64) + 0.5
    omega_p = 1.0 / tau
    if config.collision == "trt":
        omega_m = 1.0 / (0.5 + config.trt_magic / (tau - 0.5))
    else:
        omega_m = omega_p
    if sponge_position(config) is None:
        return float(omega_p), float(omega_m)
    return omega_p, omega_m
