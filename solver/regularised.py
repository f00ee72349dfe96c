"""Recursive-regularised BGK collision with an optional Smagorinsky eddy viscosity, numpy backend.

Regularisation (Latt & Chopard, Math. Comput. Simul. 72 (2006) 165) replaces the
non-equilibrium part n_i = f_i - f^eq_i by its projection on the Hermite polynomials up to
second order before it is relaxed; the recursive variant (Malaspinas, arXiv:1505.06900 (2015),
eqs. 11-13 and 31; Coreixas et al., Phys. Rev. E 96 (2017) 033306, sec. III and Appendix A)
keeps every Hermite polynomial the D2Q9 lattice holds up to third order, H_xxy and H_xyy
(H_xxx = c_x^3 - c_x vanishes on D2Q9), in the equilibrium and in the non-equilibrium part:

* the equilibrium is the third-order Hermite expansion of the Maxwellian (Malaspinas eq. 11 with
  a^(3)eq = rho u u u):
      f^eq_i = w_i [rho + 3 rho c.u + 9/2 rho (H_xx ux^2 + H_yy uy^2 + 2 H_xy ux uy)
                    + 27/2 rho (H_xxy ux^2 uy + H_xyy ux uy^2)];
  the third-order terms cancel the ux^2 uy and ux uy^2 errors of the D2Q9 momentum flux's
  divergence, so a shear wave advected across the grid decays at the viscosity (Galilean
  invariance; tests/test_collision_rr.py) and the uniform flow stays linearly stable to faster
  winds (solver/validation/linear_stability.py);
* the third-order non-equilibrium coefficients come recursively from the second-order ones
  (Malaspinas eq. 31): a_xxy = 2 u_x a_xy + u_y a_xx, a_xyy = 2 u_y a_xy + u_x a_yy.

With H_xx = c_x^2 - 1/3, H_xy = c_x c_y, H_xxy = c_x^2 c_y - c_y / 3 (and symmetric ones):
    n_i^reg = w_i [a0 + 3 c.a1 + 9/2 (H_xx a_xx + H_yy a_yy + 2 H_xy a_xy) + 27/2 (H_xxy a_xxy + H_xyy a_xyy)]
    f*_i = f^eq_i + (1 - omega) n_i^reg + (1 - omega / 2) S_i        (Guo, Zheng & Shi 2002)
The third-order equilibrium leaves the moments up to second order unchanged (H_xxy is orthogonal
to every lower Hermite polynomial under the D2Q9 weights), so a0, a1 and a2 are read from f as
for the second-order equilibrium.
The moments up to second order relax exactly as BGK's (a0, a1 are kept: they are non-zero only
in the sponge's absorbing layer and by the Guo half-force shift), so the hydrodynamics is BGK's;
the ghost moments, which carry the instability near tau = 1/2, are set from the hydrodynamic ones.
Up to second order the equilibrium is the one of solver/collision.py (compressible, or He &
Luo's incompressible, where the velocity terms take RHO0 in place of rho).

Smagorinsky (Hou et al., J. Comput. Phys. 118 (1995) 329; Malaspinas & Sagaut, J. Fluid Mech.
700 (2012) 514): the node's relaxation time grows with the non-equilibrium stress |Pi| =
sqrt(Pi_xx^2 + Pi_yy^2 + 2 Pi_xy^2), tau = (tau0 + sqrt(tau0^2 + 18 sqrt(2) C^2 |Pi| / rho)) / 2,
C the Smagorinsky constant (`FlowConfig.smagorinsky`); C = 0 leaves tau0.
The gl backend runs the same operator (shaders/collide_rr.glsl).
"""
from __future__ import annotations

import math

import numpy as np

from feelflow.solver.lattice import C, RHO0, W

#: nodes per block: the ~30 work arrays stay in cache
BLOCK_NODES = 16384


def smagorinsky_factor(constant: float) -> float:
    """18 sqrt(2) C^2: the factor of |Pi| / rho under the square root (module docstring)."""
    return 18.0 * math.sqrt(2.0) * float(constant) ** 2


class RegularisedCollider:
    """In-place recursive-regularised collision of a (9, ny, nx) array of shifted populations,
    with the interface of solver.collision.Collider (omega: scalar or (nx,) row; keep: the
    absorbing layer's row or None; force: Guo body-force density)."""

    def __init__(self, ny: int, nx: int, dtype, omega, force=(0.0, 0.0), keep=None,
                 incompressible: bool = False, smagorinsky: float = 0.0, block_nodes: int = BLOCK_NODES):
        self.nx, self.ny = nx, ny
        self.rows = max(1, min(ny, block_nodes // nx))
        self.dtype = np.dtype(dtype)
        self.omega = omega if np.isscalar(omega) else np.asarray(omega, dtype=np.float64)
        self.tau0 = 1.0 / self.omega
        self.force = (float(force[0]), float(force[1]))
        self.has_force = self.force != (0.0, 0.0)
        self.keep = None if keep is None else np.asarray(keep, dtype=np.float64)
        self.incompressible = bool(incompressible)
        self.smag = smagorinsky_factor(smagorinsky)

    def __call__(self, f: np.ndarray, target=None) -> float:
        """Collide f (9, ny, nx) in place; return sum of drho (for the divergence check)."""
        total = 0.0
        if self.keep is not None:
            target = np.asarray(target, dtype=np.float64)[:, None]
        for y0 in range(0, self.ny, self.rows):
            y1 = min(self.ny, y0 + self.rows)
            total += self._block(f[:, y0:y1, :], None if target is None else target[y0:y1])
        return total

    def _block(self, f, target) -> float:
        """The moments of n come from those of f: sum f^eq = deq, sum c f^eq = rho u,
        sum c c f^eq = deq / 3 I + rho u u (the third-order terms add nothing to these)."""
        f0, f1, f2, f3, f4, f5, f6, f7, f8 = f
        drho = f0 + f1 + f2 + f3 + f4 + f5 + f6 + f7 + f8
        rho = RHO0 if self.incompressible else drho + RHO0
        sx = f1 + f5 + f8       # c_x = +1
        wx = f3 + f6 + f7       # c_x = -1
        jx = sx - wx
        jy = (f2 + f5 + f6) - (f4 + f7 + f8)
        exx = sx + wx           # sum c_x^2 f
        eyy = f2 + f4 + f5 + f6 + f7 + f8
        exy = (f5 + f7) - (f6 + f8)
        Fx, Fy = self.force
        ux = (jx + 0.5 * Fx) / rho
        uy = (jy + 0.5 * Fy) / rho
        deq = drho
        if self.keep is not None:   # absorbing layer (solver/sponge.py): as Collider
            keep = self.keep.astype(f.dtype)
            deq = drho * keep
            ux = keep * ux + (1.0 - keep) * target.astype(f.dtype)
            uy = keep * uy
        a0 = drho - deq
        a1x = jx - rho * ux
        a1y = jy - rho * uy
        pxx = exx - deq / 3.0 - rho * ux * ux
        pyy = eyy - deq / 3.0 - rho * uy * uy
        pxy = exy - rho * ux * uy
        axx = pxx - a0 / 3.0
        ayy = pyy - a0 / 3.0
        axxy = 2.0 * ux * pxy + uy * axx
        axyy = 2.0 * uy * pxy + ux * ayy
        if self.smag:
            stress = np.sqrt(pxx * pxx + pyy * pyy + 2.0 * pxy * pxy)
            tau0 = self.tau0 if np.isscalar(self.tau0) else self.tau0.astype(f.dtype)
            omega = 1.0 / (0.5 * (tau0 + np.sqrt(tau0 * tau0 + self.smag * stress / (drho + RHO0))))
        else:
            omega = self.omega if np.isscalar(self.omega) else self.omega.astype(f.dtype)
        keep_neq = 1.0 - omega
        usq = 1.5 * (ux * ux + uy * uy)
        if self.has_force:
            uF = ux * Fx + uy * Fy
            src = 1.0 - 0.5 * omega
        # the direction-independent parts: w_i [deq - rho usq + (1 - omega)(a0 - 3/2 (a_xx + a_yy))] / w_i
        base = deq - rho * usq
        reg0 = a0 - 1.5 * (axx + ayy)
        # third order: the equilibrium's rho ux^2 uy, rho ux uy^2 and the recursive non-equilibrium
        # a_xxy, a_xyy share the Hermite polynomials H_xxy, H_xyy
        rho_uxy = rho * ux * uy
        eq_xxy = rho_uxy * ux
        eq_xyy = rho_uxy * uy
        for i in range(9):
            cx, cy = float(C[i, 0]), float(C[i, 1])
            cu = 3.0 * (cx * ux + cy * uy) if (cx or cy) else None
            feq = base if cu is None else base + rho * (cu + 0.5 * cu * cu)
            reg = reg0
            if cx:
                hxyy = 13.5 * (cy * cy - 1.0 / 3.0) * cx      # 27/2 H_xyy
                feq = feq + hxyy * eq_xyy
                reg = reg + 3.0 * cx * a1x + 4.5 * axx + hxyy * axyy
            if cy:
                hxxy = 13.5 * (cx * cx - 1.0 / 3.0) * cy      # 27/2 H_xxy
                feq = feq + hxxy * eq_xxy
                reg = reg + 3.0 * cy * a1y + 4.5 * ayy + hxxy * axxy
            if cx and cy:
                reg = reg + 9.0 * cx * cy * pxy
            w = float(W[i])  # a Python float: numpy's float64 scalar would lift the float32 arrays to float64
            out = w * (feq + keep_neq * reg)
            if self.has_force:
                cF = cx * Fx + cy * Fy
                cul = 0.0 if cu is None else cu
                out = out + src * (w * (3.0 * cul * cF - 3.0 * uF + 3.0 * cF))
            f[i] = out
        return float(drho.sum())
