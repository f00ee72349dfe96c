"""Entropic KBC collision (Karlin, Boesch & Chikatamarla, Phys. Rev. E 90 (2014) 031302(R)),
D2Q9, numpy reference, with the Guo forcing and an optional Smagorinsky eddy viscosity.

The deviation from equilibrium Delta_i = f_i - f^eq_i is split by moments (the paper's
natural-moment representation of D2Q9, its eq. 8):
* the kinematic part Delta k: density and momentum (non-zero only with the Guo half-force shift
  and in the sponge's absorbing layer): w_i (a0 + 3 c.a1), relaxed at omega as BGK's;
* the shear part Delta s, from the normal-stress difference N = sum (c_x^2 - c_y^2) Delta and
  Pi_xy = sum c_x c_y Delta:  Delta s_(+-1,0) = N / 4, Delta s_(0,+-1) = -N / 4,
  Delta s_(s,l) = s l Pi_xy / 4 on the diagonals, 0 at rest; relaxed at omega = 2 beta, which
  sets the viscosity nu = (1 / omega - 1/2) / 3;
* the rest, Delta h = Delta - Delta k - Delta s (the trace of the stress, the third- and
  fourth-order moments), relaxed at beta gamma with gamma chosen node by node so the
  post-collision state has the largest entropy to first order (the paper's eq. 13):
      gamma = 1 / beta - (2 - 1 / beta) <Delta s | Delta h> / <Delta h | Delta h>,
  <X | Y> = sum_i X_i Y_i / f^eq_i. gamma = 2 is BGK; where Delta h vanishes gamma is 2.
    f*_i = f_i - omega Delta k_i - beta (2 Delta s_i + gamma Delta h_i) + (1 - omega / 2) S_i.

The equilibrium is rr's third-order Hermite one (solver/regularised.py, solver/lattice.py
`equilibrium(order=3)`); the paper uses the product-form entropic equilibrium, which agrees
with it to third order in u. Smagorinsky as rr's (Hou et al. 1995): tau from the
non-equilibrium stress |Pi| of Delta. Runs on the numpy backend and, compiled, on the cpu backend
(solver/cpu_kernels.py); solver/backend.py refuses it on gl.
"""
from __future__ import annotations

import numpy as np

from feelflow.solver.lattice import C, RHO0, W
from feelflow.solver.regularised import RegularisedCollider

#: <Delta h | Delta h> below which gamma is taken as 2 (BGK): no higher-order deviation to steer
TINY = 1e-30


class KBCCollider(RegularisedCollider):
    """In-place KBC collision of a (9, ny, nx) array of shifted populations: the set-up and the
    blocking of solver.regularised.RegularisedCollider, with the KBC step in `_block`."""

    def _block(self, f, target) -> float:
        """Moments from sums of populations (as solver/regularised.py), then two passes over the
        nine directions: the first writes f - omega Delta k - 2 beta Delta s and accumulates the
        entropic products, the second subtracts beta gamma Delta h."""
        f0, f1, f2, f3, f4, f5, f6, f7, f8 = f
        drho = f0 + f1 + f2 + f3 + f4 + f5 + f6 + f7 + f8
        rho = RHO0 if self.incompressible else drho + RHO0
        sx = f1 + f5 + f8
        wx = f3 + f6 + f7
        jx = sx - wx
        jy = (f2 + f5 + f6) - (f4 + f7 + f8)
        exx = sx + wx
        eyy = f2 + f4 + f5 + f6 + f7 + f8
        exy = (f5 + f7) - (f6 + f8)
        Fx, Fy = self.force
        ux = (jx + 0.5 * Fx) / rho
        uy = (jy + 0.5 * Fy) / rho
        deq = drho
        if self.keep is not None:   # absorbing layer (solver/sponge.py): as the other colliders
            keep = self.keep.astype(f.dtype)
            deq = drho * keep
            ux = keep * ux + (1.0 - keep) * target.astype(f.dtype)
            uy = keep * uy
        a0 = drho - deq
        a1x = jx - rho * ux
        a1y = jy - rho * uy
        n_diff = (exx - eyy) - rho * (ux * ux - uy * uy)      # N of Delta (the deq / 3 terms cancel)
        pxy = exy - rho * ux * uy
        if self.smag:
            pxx = exx - deq / 3.0 - rho * ux * ux
            pyy = eyy - deq / 3.0 - rho * uy * uy
            stress = np.sqrt(pxx * pxx + pyy * pyy + 2.0 * pxy * pxy)
            tau0 = self.tau0 if np.isscalar(self.tau0) else self.tau0.astype(f.dtype)
            omega = 1.0 / (0.5 * (tau0 + np.sqrt(tau0 * tau0 + self.smag * stress / (drho + RHO0))))
        else:
            omega = self.omega if np.isscalar(self.omega) else self.omega.astype(f.dtype)
        beta = 0.5 * omega
        usq = 1.5 * (ux * ux + uy * uy)
        rho_uxy = rho * ux * uy
        eq_xxy, eq_xyy = rho_uxy * ux, rho_uxy * uy
        base = deq - rho * usq
        sh = 0.0
        hh = 0.0
        dhs = []
        for i in range(9):
            cx, cy = float(C[i, 0]), float(C[i, 1])
            feq = base
            dk = a0
            if cx or cy:
                cu = 3.0 * (cx * ux + cy * uy)
                feq = feq + rho * (cu + 0.5 * cu * cu)
                dk = dk + 3.0 * (cx * a1x + cy * a1y)
            if cx:
                feq = feq + 13.5 * (cy * cy - 1.0 / 3.0) * cx * eq_xyy
            if cy:
                feq = feq + 13.5 * (cx * cx - 1.0 / 3.0) * cy * eq_xxy
            feq = W[i] * feq                                      # shifted, as f
            dk = W[i] * dk
            if cx and cy:
                ds = (0.25 * cx * cy) * pxy
            elif cx or cy:
                ds = (0.25 * (cx * cx - cy * cy)) * n_diff
            else:
                ds = 0.0
            dh = f[i] - feq - dk - ds
            inv = 1.0 / (feq + W[i] * RHO0)
            sh = sh + ds * dh * inv
            hh = hh + dh * dh * inv
            dhs.append(dh)
            f[i] = f[i] - omega * dk - 2.0 * beta * ds
        safe = hh > TINY
        gamma = np.where(safe, 1.0 / beta - (2.0 - 1.0 / beta) * sh / np.where(safe, hh, 1.0), 2.0)
        step = beta * gamma
        if self.has_force:
            uF = ux * Fx + uy * Fy
            src = 1.0 - 0.5 * omega
        for i in range(9):
            f[i] -= (step * dhs[i]).astype(f.dtype, copy=False)
            if self.has_force:
                cx, cy = float(C[i, 0]), float(C[i, 1])
                cF = cx * Fx + cy * Fy
                cu = 3.0 * (cx * ux + cy * uy)
                f[i] += (src * (W[i] * (3.0 * cu * cF - 3.0 * uF + 3.0 * cF))).astype(f.dtype, copy=False)
        return float(drho.sum())
