"""Linear (von Neumann) stability of a collision operator in a uniform flow: the fastest wind
at which no small disturbance of any wavelength grows.

The analysis of Sterling & Chen (J. Comput. Phys. 123 (1996) 196) and, for the regularised
operators, Coreixas et al. (Phys. Rev. E 96 (2017) 033306, sec. IV; Wissocq, Sagaut & Boussuge,
J. Comput. Phys. 380 (2019) 311): linearise one lattice Boltzmann step about the equilibrium of
density RHO0 and velocity u. A disturbance f'_i(x) = F_i exp(i k.x) is collided,
F -> J F with J = d f* / d f the Jacobian of the collision at that equilibrium, then streamed,
F_i -> exp(-i k.c_i) F_i; the step is stable at u when every eigenvalue of
M(k) = diag(exp(-i k.c_i)) J has modulus at most 1 for every k.

J is taken by central differences of the numpy reference operator itself (solver/collision.py,
solver/regularised.py), so what is analysed is the code that runs, not a transcription of it:
deleting a term of the operator moves the limit (tests/test_collision_rr.py). k runs over a
`K_POINTS` x `K_POINTS` grid of [-pi, pi)^2. `max_stable_speed` bisects the wind along a
direction for the largest speed at which M(k) stays within 1 + `GROWTH_TOL`.

    python -m feelflow.solver.validation.linear_stability --collision rr --nu 0.001 0.004
"""
from __future__ import annotations

import argparse
import math

import numpy as np

from feelflow.solver.lattice import C, Q, equilibrium

K_POINTS = 48
#: growth per step still counted as neutral (central differences are exact to ~1e-10)
GROWTH_TOL = 1e-7
#: TRT's magic number, as the window runs it (FlowConfig.trt_magic)
TRT_MAGIC = 3.0 / 16.0
EPS = 1e-6


def _collider(collision: str, nu: float, n: int, smagorinsky: float = 0.0):
    from feelflow.solver.collision import Collider
    from feelflow.solver.regularised import RegularisedCollider

    tau = 3.0 * nu + 0.5
    op = 1.0 / tau
    if collision == "rr":
        return RegularisedCollider(1, n, np.float64, op, smagorinsky=smagorinsky)
    if collision == "trt":
        return Collider(1, n, np.float64, op, 1.0 / (0.5 + TRT_MAGIC / (tau - 0.5)), trt=True)
    if collision == "bgk":
        return Collider(1, n, np.float64, op, op, trt=False)
    raise ValueError(f"unknown collision {collision!r}: rr, trt or bgk")


def base_state(collision: str, ux: float, uy: float) -> np.ndarray:
    """The operator's own equilibrium at (RHO0, u), shifted populations f - w RHO0, shape (9,)."""
    order = 3 if collision == "rr" else 2
    one = np.ones((1, 1))
    f = equilibrium(one, ux * one, uy * one, order=order).astype(np.float64)[:, 0, 0]
    from feelflow.solver.lattice import W, RHO0
    return f - W * RHO0


def jacobian(collision: str, nu: float, ux: float, uy: float, smagorinsky: float = 0.0) -> np.ndarray:
    """J[i, j] = d f*_i / d f_j at the operator's equilibrium (central differences)."""
    base = base_state(collision, ux, uy)
    f = np.repeat(base[:, None], 2 * Q, axis=1)
    for j in range(Q):
        f[j, 2 * j] += EPS
        f[j, 2 * j + 1] -= EPS
    f = f[:, None, :].copy()
    _collider(collision, nu, 2 * Q, smagorinsky)(f)
    post = f[:, 0, :]
    return (post[:, 0::2] - post[:, 1::2]) / (2.0 * EPS)


def growth(collision: str, nu: float, ux: float, uy: float, k_points: int = K_POINTS,
           smagorinsky: float = 0.0) -> float:
    """Largest |eigenvalue| of M(k) over the k grid: > 1 means some disturbance grows."""
    J = jacobian(collision, nu, ux, uy, smagorinsky)
    k = -math.pi + 2.0 * math.pi * np.arange(k_points) / k_points
    kx, ky = np.meshgrid(k, k, indexing="ij")
    phase = np.exp(-1j * (kx[..., None] * C[:, 0] + ky[..., None] * C[:, 1]))     # (k, k, 9)
    M = phase[..., :, None] * J[None, None, :, :]
    return float(np.abs(np.linalg.eigvals(M)).max())


def is_stable(collision: str, nu: float, speed: float, angle_deg: float = 0.0, **kw) -> bool:
    a = math.radians(angle_deg)
    return growth(collision, nu, speed * math.cos(a), speed * math.sin(a), **kw) <= 1.0 + GROWTH_TOL


def max_stable_speed(collision: str, nu: float, angle_deg: float = 0.0, high: float = 0.5,
                     tol: float = 1e-3, **kw) -> float:
    """The largest wind (lattice units) along `angle_deg` at which the uniform flow is linearly
    stable, by bisection on [0, high] to `tol` (0 where even a fluid at rest is unstable)."""
    if not is_stable(collision, nu, 0.0, angle_deg, **kw):
        return 0.0
    lo, hi = 0.0, high
    if is_stable(collision, nu, hi, angle_deg, **kw):
        return hi
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        if is_stable(collision, nu, mid, angle_deg, **kw):
            lo = mid
        else:
            hi = mid
    return lo


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--collision", nargs="+", default=["rr"])
    ap.add_argument("--nu", type=float, nargs="+", default=[0.001, 0.004])
    ap.add_argument("--angle", type=float, nargs="+", default=[0.0, 45.0])
    args = ap.parse_args(argv)
    for collision in args.collision:
        for nu in args.nu:
            for angle in args.angle:
                u = max_stable_speed(collision, nu, angle)
                print(f"{collision:4s} nu {nu:g} angle {angle:g}: max stable |u| {u:.3f} "
                      f"(U/nu {u / nu:.0f}, Ma {u * math.sqrt(3):.2f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
