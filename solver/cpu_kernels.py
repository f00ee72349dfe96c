"""The cpu backend's compiled loops (numba): one fused pull-stream + collide pass over the grid,
and a pass over the few boundary nodes that redoes them with what the boundaries own.

docs/algorithm.md, steps 1-3; the collision is solver/collision.py's, node by node: BGK
(Bhatnagar, Gross & Krook 1954) or TRT (Ginzburg, Verhaeghe & d'Humieres 2008), Guo, Zheng &
Shi (2002) forcing, the compressible or He & Luo (1997) equilibrium, the outlet sponge's
per-column rates and absorbing layer. Populations are shifted, g_i = f_i - w_i RHO0; the
arithmetic is float64 whatever the storage. Lattice order as solver/lattice.py (0 rest, 1-4
E N W S, 5-8 NE NW SW SE); the module checks that order on import rather than retyping it.
Compiled with cache=True: the JIT cost (seconds) is paid once per machine.
"""
from __future__ import annotations

import numba
import numpy as np
from numba import prange

from feelflow.solver.lattice import C, RHO0, W

# The kernels spell the directions out (pull from x - c_i) for speed: hold them to the one
# definition of the lattice.
_ORDER = ((0, 0), (1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (-1, 1), (-1, -1), (1, -1))
if tuple(map(tuple, C.tolist())) != _ORDER:
    raise ImportError("solver/cpu_kernels.py spells out a lattice order solver/lattice.py no longer has")
W0, W1, W5 = float(W[0]), float(W[1]), float(W[5])
R0 = float(RHO0)

_JIT = dict(cache=True, nogil=True, fastmath={"contract", "arcp", "nsz"})


@numba.njit(inline="always", **_JIT)
def _pair(fi, fb, cu, deq, hrho, q2, rho, w, op, om, trt, uF, cF, has_force):
    """Collide the opposite pair (i, ib) with cu = 3 c_i.u and cF = c_i.F (solver/collision.py)."""
    sym = deq + hrho * (cu * cu - q2)  # feq+ = w sym
    anti = rho * cu                    # feq- = w anti
    if trt:
        t1 = 0.5 * op * (fi + fb) - op * w * sym
        t2 = 0.5 * om * (fi - fb) - om * w * anti
        ni = fi - t1 - t2
        nb = fb - t1 + t2
    else:
        ni = fi * (1.0 - op) + op * w * (sym + anti)
        nb = fb * (1.0 - op) + op * w * (sym - anti)
    if has_force:
        ev = (1.0 - 0.5 * op) * w * (3.0 * cF * cu - 3.0 * uF)
        od = (1.0 - 0.5 * om) * w * 3.0 * cF
        ni += ev + od
        nb += ev - od
    return ni, nb


@numba.njit(inline="always", **_JIT)
def _collide(f0, f1, f2, f3, f4, f5, f6, f7, f8, op, om, keep, target, trt, incomp, has_keep,
             Fx, Fy, has_force):
    """One node's collision of shifted pre-collision populations; returns (f*0..f*8, drho)."""
    drho = 0.0 + f0 + f1 + f2 + f3 + f4 + f5 + f6 + f7 + f8
    rho = R0 if incomp else R0 + drho
    jx = f1 - f3 + f5 - f6 - f7 + f8
    jy = f2 - f4 + f5 + f6 - f7 - f8
    if has_force:
        jx += 0.5 * Fx
        jy += 0.5 * Fy
    ux = jx / rho
    uy = jy / rho
    deq = drho
    if has_keep:  # absorbing layer: relax towards (RHO0, u_target)
        deq = drho * keep
        ux = ux * keep + target * (1.0 - keep)
        uy = uy * keep
    hrho = 0.5 * rho
    q2 = 3.0 * (ux * ux + uy * uy)
    uF = ux * Fx + uy * Fy
    n0 = f0 * (1.0 - op) + op * W0 * (deq - hrho * q2)
    if has_force:
        n0 += (1.0 - 0.5 * op) * W0 * (-3.0 * uF)
    n1, n3 = _pair(f1, f3, 3.0 * ux, deq, hrho, q2, rho, W1, op, om, trt, uF, Fx, has_force)
    n2, n4 = _pair(f2, f4, 3.0 * uy, deq, hrho, q2, rho, W1, op, om, trt, uF, Fy, has_force)
    n5, n7 = _pair(f5, f7, 3.0 * (ux + uy), deq, hrho, q2, rho, W5, op, om, trt, uF, Fx + Fy, has_force)
    n6, n8 = _pair(f6, f8, 3.0 * (uy - ux), deq, hrho, q2, rho, W5, op, om, trt, uF, Fy - Fx, has_force)
    return n0, n1, n2, n3, n4, n5, n6, n7, n8, drho


@numba.njit(inline="always", **_JIT)
def _store(out, y, x, r):
    out[0, y, x] = r[0]
    out[1, y, x] = r[1]
    out[2, y, x] = r[2]
    out[3, y, x] = r[3]
    out[4, y, x] = r[4]
    out[5, y, x] = r[5]
    out[6, y, x] = r[6]
    out[7, y, x] = r[7]
    out[8, y, x] = r[8]


@numba.njit(inline="always", **_JIT)
def _node(g, out, y, ym, yp, x, xm, xp, op, om, keep, target, trt, incomp, has_keep, Fx, Fy, has_force):
    """Pull g_i(x - c_i) for the node (y, x), collide, store; returns drho."""
    r = _collide(g[0, y, x], g[1, y, xm], g[2, ym, x], g[3, y, xp], g[4, yp, x],
                 g[5, ym, xm], g[6, ym, xp], g[7, yp, xp], g[8, yp, xm],
                 op[x], om[x], keep[x], target, trt, incomp, has_keep, Fx, Fy, has_force)
    _store(out, y, x, r)
    return r[9]


@numba.njit(parallel=True, **_JIT)
def stream_collide(g, out, op, om, keep, target, trt, incomp, has_keep, Fx, Fy, has_force):
    """The whole grid, periodic in x and y, rows in parallel: out = collide(pull(g)).
    op, om, keep: (nx,) per-column rates and absorbing factor; target: (ny,) its x-velocity.
    Returns sum drho (the divergence check)."""
    ny, nx = g.shape[1], g.shape[2]
    rows = np.zeros(ny)
    for y in prange(ny):
        ym = y - 1 if y > 0 else ny - 1
        yp = y + 1 if y < ny - 1 else 0
        t = target[y]
        s = _node(g, out, y, ym, yp, 0, nx - 1, 1 % nx, op, om, keep, t, trt, incomp, has_keep, Fx, Fy, has_force)
        for x in range(1, nx - 1):
            s += _node(g, out, y, ym, yp, x, x - 1, x + 1, op, om, keep, t, trt, incomp, has_keep, Fx, Fy, has_force)
        if nx > 1:
            s += _node(g, out, y, ym, yp, nx - 1, nx - 2, 0, op, om, keep, t, trt, incomp, has_keep,
                       Fx, Fy, has_force)
        rows[y] = s
    return rows.sum()


@numba.njit(**_JIT)
def redo_nodes(g, pre, over, ny_, nx_, out, op, om, keep, target, trt, incomp, has_keep, Fx, Fy, has_force):
    """For each node (ny_[k], nx_[k]) whose bit i of over[k] is set, population i comes from
    `pre` (what a boundary rule wrote) instead of the periodic pull; collide and store.
    Returns sum drho over those nodes."""
    ny, nx = g.shape[1], g.shape[2]
    f = np.empty(9)
    total = 0.0
    for k in range(len(ny_)):
        y, x, bits = ny_[k], nx_[k], over[k]
        for i in range(9):
            if (bits >> i) & 1:
                f[i] = pre[i, y, x]
            else:
                f[i] = g[i, (y - _CY[i]) % ny, (x - _CX[i]) % nx]
        r = _collide(f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7], f[8], op[x], om[x], keep[x],
                     target[y], trt, incomp, has_keep, Fx, Fy, has_force)
        _store(out, y, x, r)
        total += r[9]
    return total


_CX = np.array([c[0] for c in _ORDER], dtype=np.int64)
_CY = np.array([c[1] for c in _ORDER], dtype=np.int64)
