"""The viscous (shear) force on the body from the lattice's own stress, for splitting a total
force into its pressure and viscous parts.

The deviatoric stress is local in LBM: sigma'_ab = -(1 - omega/2) Pi^neq_ab, with
Pi^neq_ab = sum_i c_ia c_ib (f_i^in - f_i^eq) (Chapman-Enskog analysis; Krueger et al., *The Lattice
Boltzmann Method* (2017), ch. 4). The window holds the
post-collision f* = f^in - omega (f^in - f^eq); the second moment is even, so it relaxes with
omega+ in BGK and TRT alike: Pi^neq(f*) = (1 - omega) Pi^neq(f^in), hence
sigma' = -(1 - omega/2) / (1 - omega) Pi^neq(f*) (undefined at tau = 1, where f* = f^eq).

Each component is extrapolated to the wall from the fluid side (`sampling.fluid_extrapolate`) and
integrated over `shape.surface_elements`: F_visc = sum sigma' . n dA. The force of the fluid on the
body is F = sum (-p n + sigma' . n) dA, so F_pressure = F_total - F_visc.
"""
from __future__ import annotations

import numpy as np

from feelflow.solver.forces.base import BodyWindow
from feelflow.solver.forces.sampling import fluid_extrapolate, moments
from feelflow.solver.lattice import C, equilibrium


def viscous_stress(window: BodyWindow):
    """(sxx, sxy, syy) deviatoric stress on the window's nodes (h, w) each."""
    omega = 1.0 / window.config.tau
    if abs(1.0 - omega) < 1e-6:
        raise ValueError("viscous stress cannot be read from post-collision populations at tau = 1")
    f = np.asarray(window.f, dtype=np.float64)
    rho, ux, uy = moments(window)
    fneq = f - equilibrium(rho, ux, uy, incompressible=window.config.incompressible)
    cx = C[:, 0].astype(np.float64)
    cy = C[:, 1].astype(np.float64)
    factor = -(1.0 - omega / 2.0) / (1.0 - omega)
    sxx = factor * np.tensordot(cx * cx, fneq, axes=1)
    sxy = factor * np.tensordot(cx * cy, fneq, axes=1)
    syy = factor * np.tensordot(cy * cy, fneq, axes=1)
    return sxx, sxy, syy


def viscous_force(window: BodyWindow, spacing: float = 0.5, radius: float = 2.5) -> tuple[float, float]:
    """Shear force of the fluid on the body, sum sigma' . n dA (lattice units per step)."""
    pts, normals, lengths = window.shape.surface_elements(spacing)
    pts = np.asarray(pts, dtype=np.float64)
    normals = np.asarray(normals, dtype=np.float64)
    lengths = np.asarray(lengths, dtype=np.float64)
    sxx, sxy, syy = (fluid_extrapolate(window, s, pts[:, 0], pts[:, 1], radius) for s in viscous_stress(window))
    fx = np.sum((sxx * normals[:, 0] + sxy * normals[:, 1]) * lengths)
    fy = np.sum((sxy * normals[:, 0] + syy * normals[:, 1]) * lengths)
    return float(fx), float(fy)
