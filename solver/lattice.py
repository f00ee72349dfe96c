"""The D2Q9 lattice: the one definition of velocities, weights and opposites.

Everything else (numpy backend, GLSL constants, force models) reads these; nothing retypes them.
Reference: Qian, d'Humieres & Lallemand (1992); Krueger et al., *The Lattice Boltzmann Method*
(2017), sec. 3.4. Ordering: 0 rest, 1-4 axis (E, N, W, S), 5-8 diagonals (NE, NW, SW, SE).
"""
from __future__ import annotations

import numpy as np

Q = 9
#: lattice velocities c_i, shape (9, 2), integer (x, y)
C = np.array(
    [[0, 0], [1, 0], [0, 1], [-1, 0], [0, -1], [1, 1], [-1, 1], [-1, -1], [1, -1]],
    dtype=np.int64,
)
#: weights w_i (eq. 12 of the seed)
W = np.array([4 / 9] + [1 / 9] * 4 + [1 / 36] * 4, dtype=np.float64)
#: index of the opposite velocity: C[OPP[i]] == -C[i]
OPP = np.array([0, 3, 4, 1, 2, 7, 8, 5, 6], dtype=np.int64)
#: speed of sound squared, c_s^2 = 1/3 (lattice units)
CS2 = 1.0 / 3.0
#: reference density of the fluid at rest
RHO0 = 1.0


def equilibrium(rho, ux, uy, incompressible: bool = False, order: int = 2):
    """Second-order equilibrium f_i^eq (seed eq. 9), shape (9, *rho.shape).

    f_i^eq = w_i rho (1 + 3 c.u + 9/2 (c.u)^2 - 3/2 u.u); with `incompressible` He & Luo's
    (1997) f_i^eq = w_i (rho + RHO0 (3 c.u + 9/2 (c.u)^2 - 3/2 u.u)) (docs/science/algorithm.md, step 3).
    `order` 3 adds the third-order Hermite terms D2Q9 holds, the equilibrium of the
    recursive-regularised operator (solver/regularised.py; Malaspinas 2015, eq. 11):
    + w_i 27/2 rho (H_xxy ux^2 uy + H_xyy ux uy^2), H_xxy = c_x^2 c_y - c_y / 3, H_xyy = c_x c_y^2 - c_x / 3.
    """
    rho = np.asarray(rho)
    ux = np.asarray(ux)
    uy = np.asarray(uy)
    dtype = np.result_type(rho, ux, uy, np.float32)
    lead = (Q,) + (1,) * np.broadcast(rho, ux, uy).ndim  # all nine directions at once, each
    cx, cy, w = C[:, 0].reshape(lead), C[:, 1].reshape(lead), W.reshape(lead)  # as c_i, w_i alone
    usq = 1.5 * (ux * ux + uy * uy)
    cu = 3.0 * (cx * ux + cy * uy)
    third = 0.0
    if order == 3:
        third = 13.5 * ux * uy * ((cx * cx - 1.0 / 3.0) * cy * ux + (cy * cy - 1.0 / 3.0) * cx * uy)
    elif order != 2:
        raise ValueError(f"equilibrium order {order!r}: 2 or 3")
    if incompressible:
        return (w * (rho + RHO0 * (cu + 0.5 * cu * cu - usq + third))).astype(dtype, copy=False)
    return (w * rho * (1.0 + cu + 0.5 * cu * cu - usq + third)).astype(dtype, copy=False)


def glsl_constants() -> str:
    """GLSL declarations of the lattice, injected into shaders where `// @LATTICE` stands."""
    cs = ", ".join(f"ivec2({cx}, {cy})" for cx, cy in C)
    ws = ", ".join(f"{w:.17g}" for w in W)
    os_ = ", ".join(str(o) for o in OPP)
    return (
        f"const int Q = {Q};\n"
        f"const ivec2 C[9] = ivec2[9]({cs});\n"
        f"const float W[9] = float[9]({ws});\n"
        f"const int OPP[9] = int[9]({os_});\n"
        f"const float CS2 = {CS2:.17g};\n"
        f"const float RHO0 = {RHO0:.17g};"
    )
