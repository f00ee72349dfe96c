"""The cpu backend's compiled loops (numba): one fused pull-stream + collide pass over the grid,
and a pass over the few boundary nodes that redoes them with what the boundaries own.

docs/algorithm.md, steps 1-3; the collision is solver/collision.py's, node by node: BGK
(Bhatnagar, Gross & Krook 1954) or TRT (Ginzburg, Verhaeghe & d'Humieres 2008), Guo, Zheng &
Shi (2002) forcing, the compressible or He & Luo (1997) equilibrium, the outlet sponge's
per-column rates and absorbing layer. Populations are shifted, g_i = f_i - w_i RHO0; the
arithmetic is in the storage's precision (float32 as numpy's and gl's, or float64), its
constants a tuple K = (1/2, 1, 3, w0, w1, w5, RHO0) of that type. Lattice order as solver/lattice.py (0 rest, 1-4
E N W S, 5-8 NE NW SW SE); the module checks that order on import rather than retyping it.
Compiled with cache=True: the JIT cost (seconds) is paid once per machine.
"""
from __future__ import annotations

import functools
import os

# numba's OpenMP threads sleep between steps instead of spinning: on a busy 2-core machine the
# spinning doubled the CPU time per node (docs/science/cpu-backend.md); read when the OpenMP
# runtime starts, so set before the first parallel kernel runs.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import numba  # noqa: E402
import numpy as np
from numba import prange  # noqa: E402

from feelflow.solver.lattice import C, RHO0, W  # noqa: E402

# The kernels spell the directions out (pull from x - c_i) for speed: hold them to the one
# definition of the lattice.
_ORDER = ((0, 0), (1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (-1, 1), (-1, -1), (1, -1))
if tuple(map(tuple, C.tolist())) != _ORDER:
    raise ImportError("solver/cpu_kernels.py spells out a lattice order solver/lattice.py no longer has")
W0, W1, W5 = float(W[0]), float(W[1]), float(W[5])
R0 = float(RHO0)

_JIT = dict(cache=True, nogil=True, error_model="numpy", fastmath={"contract", "arcp", "nsz", "reassoc"})


@numba.njit(inline="always", **_JIT)
def _pair(fi, fb, cu, deq, hrho, q2, rho, w, op, om, trt, uF, cF, has_force, K):
    """Collide the opposite pair (i, ib) with cu = 3 c_i.u and cF = c_i.F (solver/collision.py)."""
    half, one, three = K[0], K[1], K[2]
    sym = deq + hrho * (cu * cu - q2)  # feq+ = w sym
    anti = rho * cu                    # feq- = w anti
    if trt:
        t1 = half * op * (fi + fb) - op * w * sym
        t2 = half * om * (fi - fb) - om * w * anti
        ni = fi - t1 - t2
        nb = fb - t1 + t2
    else:
        ni = fi * (one - op) + op * w * (sym + anti)
        nb = fb * (one - op) + op * w * (sym - anti)
    if has_force:
        ev = (one - half * op) * w * (three * cF * cu - three * uF)
        od = (one - half * om) * w * three * cF
        ni += ev + od
        nb += ev - od
    return ni, nb


@numba.njit(inline="always", **_JIT)
def _collide(f0, f1, f2, f3, f4, f5, f6, f7, f8, op, om, keep, target, trt, incomp, has_keep,
             Fx, Fy, has_force, K):
    """One node's collision of shifted pre-collision populations; returns (f*0..f*8, drho)."""
    half, one, three, w0, w1, w5, r0 = K
    drho = f0 + f1 + f2 + f3 + f4 + f5 + f6 + f7 + f8
    rho = r0 if incomp else r0 + drho
    jx = f1 - f3 + f5 - f6 - f7 + f8
    jy = f2 - f4 + f5 + f6 - f7 - f8
    if has_force:
        jx += half * Fx
        jy += half * Fy
    ux = jx / rho
    uy = jy / rho
    deq = drho
    if has_keep:  # absorbing layer: relax towards (RHO0, u_target)
        deq = drho * keep
        ux = ux * keep + target * (one - keep)
        uy = uy * keep
    hrho = half * rho
    q2 = three * (ux * ux + uy * uy)
    uF = ux * Fx + uy * Fy
    n0 = f0 * (one - op) + op * w0 * (deq - hrho * q2)
    if has_force:
        n0 -= (one - half * op) * w0 * three * uF
    n1, n3 = _pair(f1, f3, three * ux, deq, hrho, q2, rho, w1, op, om, trt, uF, Fx, has_force, K)
    n2, n4 = _pair(f2, f4, three * uy, deq, hrho, q2, rho, w1, op, om, trt, uF, Fy, has_force, K)
    n5, n7 = _pair(f5, f7, three * (ux + uy), deq, hrho, q2, rho, w5, op, om, trt, uF, Fx + Fy, has_force, K)
    n6, n8 = _pair(f6, f8, three * (uy - ux), deq, hrho, q2, rho, w5, op, om, trt, uF, Fy - Fx, has_force, K)
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


#: columns per chunk: the pulled populations and the results of a chunk stay in L1
CHUNK = 128


@numba.njit(inline="always", **_JIT)
def _chunk(b, o, n, op, om, t, trt, incomp, Fx, Fy, has_force, K):
    """Collide n nodes of the gathered populations b (9, CHUNK) into o, one pair of rates (op,
    om) for all: written without per-node branches or arrays beside b and o, so LLVM
    vectorises it. Returns sum drho."""
    s = 0.0
    for k in range(n):
        r = _collide(b[0, k], b[1, k], b[2, k], b[3, k], b[4, k], b[5, k], b[6, k], b[7, k], b[8, k],
                     op, om, op, t, trt, incomp, False, Fx, Fy, has_force, K)
        _store_k(o, k, r)
        s += r[9]
    return s


@numba.njit(inline="always", **_JIT)
def _store_k(o, k, r):
    o[0, k] = r[0]
    o[1, k] = r[1]
    o[2, k] = r[2]
    o[3, k] = r[3]
    o[4, k] = r[4]
    o[5, k] = r[5]
    o[6, k] = r[6]
    o[7, k] = r[7]
    o[8, k] = r[8]


@numba.njit(inline="always", **_JIT)
def _pull(g, y, ym, yp, x, xm, xp):
    return (g[0, y, x], g[1, y, xm], g[2, ym, x], g[3, y, xp], g[4, yp, x],
            g[5, ym, xm], g[6, ym, xp], g[7, yp, xp], g[8, yp, xm])


@numba.njit(inline="always", **_JIT)
def _edge(g, out, y, ym, yp, x, op, om, keep, t, Fx, Fy, trt, incomp, has_keep, has_force, K):
    """One node with periodic neighbours and its own column's rates; returns drho."""
    nx = g.shape[2]
    f = _pull(g, y, ym, yp, x, x - 1 if x > 0 else nx - 1, x + 1 if x < nx - 1 else 0)
    r = _collide(f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7], f[8], op[x], om[x], keep[x], t,
                 trt, incomp, has_keep, Fx, Fy, has_force, K)
    _store(out, y, x, r)
    return r[9]


@functools.lru_cache(maxsize=None)
def make_kernels(trt: bool, incomp: bool, has_keep: bool, has_force: bool, dtype: str = "float32"):
    """(stream_collide, redo_nodes) compiled for one collision variant and storage type: the
    flags and constants are constants of the compiled code, so the inner loop has no branches
    (cached per variant). The rates, keep, target and force passed to them are of `dtype`.
    Their closures hold only these flags and constants, never another compiled function: numba's
    on-disk cache keys a closure by its variables' pickled bytes, and a compiled function pickles
    with an id that is new in every process, so such a closure would compile again at every start."""
    T = np.dtype(dtype).type
    K = (T(0.5), T(1.0), T(3.0), T(W0), T(W1), T(W5), T(R0))

    @numba.njit(parallel=True, **_JIT)
    def stream_collide(g, out, op, om, keep, target, xs, Fx, Fy):
        """out = collide(pull(g)) over the whole grid, periodic in x and y, rows in parallel.
        Columns 1 .. xs-1 share the rates op[1], om[1] (no sponge there) and run in chunks;
        column 0 and xs .. nx-1 (the sponge: per-column rates, the absorbing layer) node by
        node. target: (ny,) the absorbing layer's x-velocity. Returns sum drho."""
        ny, nx = g.shape[1], g.shape[2]
        rows = np.zeros(ny)
        op0, om0 = op[min(1, nx - 1)], om[min(1, nx - 1)]
        for y in prange(ny):
            ym = y - 1 if y > 0 else ny - 1
            yp = y + 1 if y < ny - 1 else 0
            t = target[y]
            b = np.empty((9, CHUNK), g.dtype)
            o = np.empty((9, CHUNK), g.dtype)
            s = 0.0
            for x0 in range(1, xs, CHUNK):
                n = min(CHUNK, xs - x0)
                x1 = x0 + n
                b[0, :n] = g[0, y, x0:x1]
                b[1, :n] = g[1, y, x0 - 1:x1 - 1]
                b[2, :n] = g[2, ym, x0:x1]
                b[3, :n] = g[3, y, x0 + 1:x1 + 1]
                b[4, :n] = g[4, yp, x0:x1]
                b[5, :n] = g[5, ym, x0 - 1:x1 - 1]
                b[6, :n] = g[6, ym, x0 + 1:x1 + 1]
                b[7, :n] = g[7, yp, x0 + 1:x1 + 1]
                b[8, :n] = g[8, yp, x0 - 1:x1 - 1]
                s += _chunk(b, o, n, op0, om0, t, trt, incomp, Fx, Fy, has_force, K)
                out[:, y, x0:x1] = o[:, :n]
            s += _edge(g, out, y, ym, yp, 0, op, om, keep, t, Fx, Fy, trt, incomp, has_keep, has_force, K)
            for x in range(xs, nx):
                s += _edge(g, out, y, ym, yp, x, op, om, keep, t, Fx, Fy, trt, incomp, has_keep, has_force, K)
            rows[y] = s
        return rows.sum()

    @numba.njit(**_JIT)
    def redo_nodes(g, pre, over, ny_, nx_, out, op, om, keep, target, Fx, Fy):
        """For each node (ny_[k], nx_[k]) whose bit i of over[k] is set, population i comes from
        `pre` (what a boundary rule wrote) instead of the periodic pull; collide and store.
        Returns sum drho over those nodes."""
        ny, nx = g.shape[1], g.shape[2]
        f = np.empty(9, g.dtype)
        total = 0.0
        for k in range(len(ny_)):
            y, x, bits = ny_[k], nx_[k], over[k]
            ym = y - 1 if y > 0 else ny - 1
            yp = y + 1 if y < ny - 1 else 0
            p = _pull(g, y, ym, yp, x, x - 1 if x > 0 else nx - 1, x + 1 if x < nx - 1 else 0)
            for i in range(9):
                f[i] = pre[i, y, x] if (bits >> i) & 1 else p[i]
            r = _collide(f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7], f[8], op[x], om[x], keep[x],
                         target[y], trt, incomp, has_keep, Fx, Fy, has_force, K)
            _store(out, y, x, r)
            total += r[9]
        return total

    return stream_collide, redo_nodes

