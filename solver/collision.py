"""D2Q9 collision on shifted populations, in place, for the numpy backend (docs/science/algorithm.md, step 2-3).

BGK (Bhatnagar, Gross & Krook 1954) and TRT (Ginzburg, Verhaeghe & d'Humieres 2008) with the
Guo, Zheng & Shi (2002) forcing. Populations are g_i = f_i - w_i RHO0; with drho = sum g the
equilibrium is f^eq_i - w_i RHO0 = w_i (drho + rho (3 c.u + 9/2 (c.u)^2 - 3/2 u^2)), split over
each opposite pair (i, ib) into an even part w_i sym and an odd part w_i anti:
    sym = drho + rho/2 ((3 c.u)^2 - 3 u^2),  anti = rho (3 c.u).
With `incompressible` (He & Luo 1997, J. Stat. Phys. 88, 927) the velocity terms take RHO0 in
place of rho and u = j / RHO0: the density fluctuation then enters the equilibrium only through
drho, which removes the O(Ma^2) compressibility terms rho u u of the momentum flux.
The grid is processed in blocks of rows so the ~15 work arrays stay in cache; every operation
writes into preallocated scratch (no temporaries).
"""
from __future__ import annotations

import numpy as np

from feelflow.solver.lattice import C, RHO0, W

#: opposite pairs (i, ib); the loop computes c_i . u for i
PAIRS = ((1, 3), (2, 4), (5, 7), (6, 8))
#: nodes per block (tuned on 2 cores: small enough for L2, large enough to hide numpy overhead)
BLOCK_NODES = 32768


class Collider:
    """In-place collision of a (9, ny, nx) array of shifted populations.

    omega_p, omega_m: scalars, or (nx,) rows (outlet sponge). force: (Fx, Fy) body-force density.
    keep: None, or an (nx,) row (the sponge's absorbing layer, solver.sponge.absorb_keep):
    the equilibria use the density fluctuation drho * keep and the velocity
    keep u + (1 - keep) u_target, so each collision relaxes the node towards (RHO0, u_target) at
    omega+ (1 - keep); u_target = (target(iy), 0), `target` passed per call.
    incompressible: He & Luo's equilibrium (module docstring): rho -> RHO0 in the velocity terms.
    """

    def __init__(self, ny: int, nx: int, dtype, omega_p, omega_m, trt: bool, force=(0.0, 0.0),
                 block_nodes: int = BLOCK_NODES, keep=None, incompressible: bool = False):
        self.nx, self.ny = nx, ny
        self.rows = max(1, min(ny, block_nodes // nx))
        self.dtype = np.dtype(dtype)
        self.trt = bool(trt)
        self.incompressible = bool(incompressible)
        self.force = (float(force[0]), float(force[1]))
        self.has_force = self.force != (0.0, 0.0)
        dt = self.dtype

        def coef(x):
            # in the storage's type, scalars too: a float64 scalar (numpy's W[k] is one) would
            # make every ufunc below loop in float64 on float32 arrays and cast back (NEP 50)
            return dt.type(x) if np.isscalar(x) else np.asarray(x, dtype=dt)

        op = omega_p if np.isscalar(omega_p) else np.asarray(omega_p, dtype=np.float64)
        om = omega_m if np.isscalar(omega_m) else np.asarray(omega_m, dtype=np.float64)
        self.op, self.om = coef(op), coef(om)
        self.one_minus_op = coef(1.0 - op)
        self.op_half, self.om_half = coef(0.5 * op), coef(0.5 * om)
        self.op_w = {k: coef(op * W[k]) for k in range(9)}
        self.om_w = {k: coef(om * W[k]) for k in range(9)}
        # Guo: (1 - omega+/2) S+ and (1 - omega-/2) S-
        self.src_p = {k: coef((1.0 - 0.5 * op) * W[k]) for k in range(9)}
        self.src_m = {k: coef((1.0 - 0.5 * om) * W[k]) for k in range(9)}
        shape = (self.rows, nx)
        self.keep = None if keep is None else np.asarray(keep, dtype=dt)
        self.release = None if keep is None else np.asarray(1.0 - np.asarray(keep, np.float64), dtype=dt)
        names = ("drho", "deq", "rho", "hrho", "ux", "uy", "q2", "cu", "sym", "anti", "t1", "t2", "uF")
        self._s = {n: np.empty(shape, dtype=dt) for n in names}
        if self.incompressible:
            self._s["rho"].fill(RHO0)  # He & Luo: the velocity terms and u = j / rho take RHO0

    def __call__(self, f: np.ndarray, target=None) -> float:
        """Collide f (9, ny, nx) in place; return sum of drho (for the divergence check).
        target: (ny,) x-velocity the absorbing layer relaxes towards (with `keep` only)."""
        total = 0.0
        if self.keep is not None:
            target = np.asarray(target, dtype=self.dtype)[:, None]
        for y0 in range(0, self.ny, self.rows):
            y1 = min(self.ny, y0 + self.rows)
            total += self._block(f[:, y0:y1, :], y1 - y0, None if target is None else target[y0:y1])
        return total

    def _block(self, f, n: int, target=None) -> float:
        s = {k: v[:n] for k, v in self._s.items()}
        drho, rho, hrho, ux, uy, q2 = s["drho"], s["rho"], s["hrho"], s["ux"], s["uy"], s["q2"]
        cu, sym, anti, t1, t2 = s["cu"], s["sym"], s["anti"], s["t1"], s["t2"]
        add, sub, mul = np.add, np.subtract, np.multiply
        f0, f1, f2, f3, f4, f5, f6, f7, f8 = f
        # moments
        add(f0, f1, out=drho)
        for k in (f2, f3, f4, f5, f6, f7, f8):
            drho += k
        if not self.incompressible:    # (incompressible: rho holds RHO0 from __init__)
            add(drho, RHO0, out=rho)
        if self.keep is None:
            deq = drho                 # the equilibria's density fluctuation
        else:
            deq = s["deq"]
            mul(drho, self.keep, out=deq)
        sub(f1, f3, out=ux)
        ux += f5
        ux -= f6
        ux -= f7
        ux += f8
        sub(f2, f4, out=uy)
        uy += f5
        uy += f6
        uy -= f7
        uy -= f8
        Fx, Fy = self.force
        if self.has_force:
            ux += 0.5 * Fx
            uy += 0.5 * Fy
        np.divide(1.0, rho, out=t1)
        ux *= t1
        uy *= t1
        if self.keep is not None:      # absorbing layer: u -> keep u + (1 - keep) u_target
            ux *= self.keep
            mul(target, self.release, out=t1)
            ux += t1
            uy *= self.keep
        mul(rho, 0.5, out=hrho)
        mul(ux, ux, out=q2)
        mul(uy, uy, out=t1)
        q2 += t1
        q2 *= 3.0                      # q2 = 3 u^2
        if self.has_force:
            uF = s["uF"]
            mul(ux, Fx, out=uF)
            mul(uy, Fy, out=t1)
            uF += t1                   # u . F
        # rest population: f0 += omega+ (w0 (drho - rho/2 3u^2) - f0)
        mul(hrho, q2, out=t1)
        sub(deq, t1, out=t1)
        t1 *= self.op_w[0]
        f0 *= self.one_minus_op
        f0 += t1
        if self.has_force:
            mul(uF, -3.0, out=t1)
            t1 *= self.src_p[0]
            f0 += t1
        for i, ib in PAIRS:
            cx, cy = int(C[i, 0]), int(C[i, 1])
            fi, fb = f[i], f[ib]
            if cy == 0:
                mul(ux, 3.0, out=cu)
            elif cx == 0:
                mul(uy, 3.0, out=cu)
            elif cx == cy:
                add(ux, uy, out=cu)
                cu *= 3.0
            else:
                sub(uy, ux, out=cu)
                cu *= 3.0
            mul(cu, cu, out=sym)
            sym -= q2
            sym *= hrho
            sym += deq                 # feq+ = w sym
            mul(rho, cu, out=anti)     # feq- = w anti
            if self.trt:
                # dp = omega+ (f+ - feq+), dm = omega- (f- - feq-); f_i -= dp + dm, f_ib -= dp - dm
                add(fi, fb, out=t1)
                t1 *= self.op_half
                sym *= self.op_w[i]
                t1 -= sym
                sub(fi, fb, out=t2)
                t2 *= self.om_half
                anti *= self.om_w[i]
                t2 -= anti
                fi -= t1
                fi -= t2
                fb -= t1
                fb += t2
            else:
                # f += omega (feq - f)
                sym *= self.op_w[i]
                anti *= self.op_w[i]
                fi *= self.one_minus_op
                fi += sym
                fi += anti
                fb *= self.one_minus_op
                fb += sym
                fb -= anti
            if self.has_force:
                # S_i = w_i [3 c_i.F - 3 u.F + 9 (c_i.u)(c_i.F)]: even part w (3 cu cF - 3 uF),
                # odd part w 3 cF (cu = 3 c.u here)
                cF = cx * Fx + cy * Fy
                mul(cu, 3.0 * cF, out=t1)
                t2[...] = uF
                t2 *= 3.0
                t1 -= t2
                t1 *= self.src_p[i]
                fi += t1
                fb += t1
                odd = 3.0 * cF
                if np.isscalar(self.src_m[i]):
                    fi += odd * self.src_m[i]
                    fb -= odd * self.src_m[i]
                else:
                    mul(self.src_m[i], odd, out=t2[0])
                    fi += t2[0]
                    fb -= t2[0]
        return float(drho.sum())

