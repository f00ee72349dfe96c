"""The cpu backend's compiled loops (numba): n tunnel steps in one call, each a serial pass over
what the boundaries own and one fused stream + collide pass over the grid (rows in parallel),
streaming with the AA pattern between natural ends (`make_kernel`).

docs/science/algorithm.md, steps 1-3, and docs/science/cpu-backend.md. The collision is node by
node that of solver/collision.py (BGK, Bhatnagar, Gross & Krook 1954; TRT, Ginzburg, Verhaeghe &
d'Humieres 2008) or of solver/regularised.py (recursive-regularised BGK, Malaspinas 2015, Coreixas
et al. 2017, with the optional Smagorinsky viscosity) or of solver/kbc.py (entropic KBC, Karlin,
Boesch & Chikatamarla 2014, likewise), with Guo, Zheng & Shi (2002) forcing, the
compressible or He & Luo (1997) equilibrium and the outlet sponge's per-column rates and
absorbing layer (solver/sponge.py). The boundary pass writes what rules d, c, b and a write in
the numpy backend (solver/inflow.py's outlet and inlet, solver/quiet_inlet.py, the walls,
solver/bouzidi.py's links with the moving-wall term), sums the momentum exchange on the links
(solver/forces/momentum_exchange.py); the grid pass takes those populations at the nodes that own
them, and the solid nodes are reset. Populations are shifted, g_i = f_i - w_i RHO0; the collision's arithmetic is in
the storage's precision (float32 as numpy's and gl's, or float64) with its constants in a tuple K
of that type (`constants`); the boundary rules are evaluated in float64, as numpy's. Lattice order
as solver/lattice.py (0 rest, 1-4 E N W S, 5-8 NE NW SW SE); the module checks that order on
import rather than retyping it. Compiled with cache=True: the JIT cost (tens of seconds per
variant) is paid once per machine; nogil=True, so the window can draw while a step runs.
"""
from __future__ import annotations

import functools
import math
import os

# numba's OpenMP threads sleep between steps instead of spinning: on a busy 2-core machine the
# spinning doubled the CPU time per node (docs/science/cpu-backend.md); read when the OpenMP
# runtime starts, so set before the first parallel kernel runs.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import numba  # noqa: E402
import numpy as np  # noqa: E402
from numba import prange  # noqa: E402

from feelflow.solver.lattice import C, OPP, RHO0, W  # noqa: E402

# The kernels spell the directions out (pull from x - c_i) for speed: hold them to the one
# definition of the lattice.
_ORDER = ((0, 0), (1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (-1, 1), (-1, -1), (1, -1))
if tuple(map(tuple, C.tolist())) != _ORDER:
    raise ImportError("solver/cpu_kernels.py spells out a lattice order solver/lattice.py no longer has")
W0, W1, W5 = float(W[0]), float(W[1]), float(W[5])
R0 = float(RHO0)
#: the lattice as arrays for the boundary pass (float64, as numpy's boundary rules)
_CX = C[:, 0].astype(np.float64)
_CY = C[:, 1].astype(np.float64)
_W = W.astype(np.float64)
_OPP = OPP.astype(np.int64)
#: i -> j with c_j = (c_i,x, -c_i,y): specular reflection at a horizontal wall (as numpy_backend)
_MIRROR_Y = np.array([0, 1, 4, 3, 2, 8, 7, 6, 5], dtype=np.int64)
#: walls: 0 periodic in y, 1 no-slip, 2 free-slip
WALLS = {"periodic": 0, "no_slip": 1, "free_slip": 2}

_JIT = dict(cache=True, nogil=True, error_model="numpy", fastmath={"contract", "arcp", "nsz", "reassoc"})
#: the tunnel kernel's parallelism: its prange over blocks of rows and nothing else; numba must
#: not fuse its loops (or turn its array expressions into loops of their own to fuse)
_PARALLEL = {"prange": True, "fusion": False, "setitem": False, "numpy": False, "comprehension": False,
             "reduction": False, "inplace_binop": False, "stencil": False}


def constants(dtype) -> tuple:
    """K: the collision's constants in the storage's type, (1/2, 1, 3, w0, w1, w5, RHO0, 1/3,
    3/2, 9/2, 9, 2)."""
    T = np.dtype(dtype).type
    return (T(0.5), T(1.0), T(3.0), T(W0), T(W1), T(W5), T(R0), T(1.0 / 3.0), T(1.5), T(4.5), T(9.0), T(2.0))


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
    """BGK / TRT: one node's collision of shifted pre-collision populations; returns (f*0..f*8, drho)."""
    half, one, three, w0, w1, w5, r0 = K[0], K[1], K[2], K[3], K[4], K[5], K[6]
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
def _rr_pair(cu, cF, even, odd, odd_eq, base, rho, kn, w, src, uF, has_force, K):
    """The regularised pair (i, ib): f*_i = w (feq_i + (1 - omega) reg_i) + Guo's source, with
    reg_i = even + odd, reg_ib = even - odd and odd_eq the equilibrium's third-order part
    (odd in c_i) (solver/regularised.py)."""
    half, three = K[0], K[2]
    fe = base + half * rho * cu * cu + kn * even
    fo = rho * cu + odd_eq + kn * odd
    ni = w * (fe + fo)
    nb = w * (fe - fo)
    if has_force:
        ev = src * w * (three * cu * cF - three * uF)
        od = src * w * three * cF
        ni += ev + od
        nb += ev - od
    return ni, nb


@numba.njit(inline="always", **_JIT)
def _collide_rr(f0, f1, f2, f3, f4, f5, f6, f7, f8, omega, keep, target, incomp, has_keep,
                Fx, Fy, has_force, smag, K):
    """Recursive-regularised BGK with the third-order equilibrium (solver/regularised.py, its
    moments and Hermite coefficients spelled out per opposite pair), optionally with the Smagorinsky rate (smag = 18 sqrt(2) C^2,
    smag > 0 only in the variant compiled for it); returns (f*0..f*8, drho)."""
    half, one, three, w0, w1, w5, r0 = K[0], K[1], K[2], K[3], K[4], K[5], K[6]
    third, th2, n2, nine, two = K[7], K[8], K[9], K[10], K[11]
    drho = f0 + f1 + f2 + f3 + f4 + f5 + f6 + f7 + f8
    rho = r0 if incomp else r0 + drho
    sx = f1 + f5 + f8
    wx = f3 + f6 + f7
    jx = sx - wx
    jy = (f2 + f5 + f6) - (f4 + f7 + f8)
    exx = sx + wx
    eyy = f2 + f4 + f5 + f6 + f7 + f8
    exy = (f5 + f7) - (f6 + f8)
    ux = (jx + half * Fx) / rho
    uy = (jy + half * Fy) / rho
    deq = drho
    if has_keep:
        deq = drho * keep
        ux = keep * ux + (one - keep) * target
        uy = keep * uy
    a0 = drho - deq
    a1x = jx - rho * ux
    a1y = jy - rho * uy
    pxx = exx - deq * third - rho * ux * ux
    pyy = eyy - deq * third - rho * uy * uy
    pxy = exy - rho * ux * uy
    axx = pxx - a0 * third
    ayy = pyy - a0 * third
    axxy = two * ux * pxy + uy * axx
    axyy = two * uy * pxy + ux * ayy
    if smag > 0:
        tau0 = one / omega
        stress = math.sqrt(pxx * pxx + pyy * pyy + two * pxy * pxy)
        omega = one / (half * (tau0 + math.sqrt(tau0 * tau0 + smag * stress / (drho + r0))))
    kn = one - omega
    src = one - half * omega
    base = deq - rho * th2 * (ux * ux + uy * uy)
    reg0 = a0 - th2 * (axx + ayy)
    uF = ux * Fx + uy * Fy
    n0 = w0 * (base + kn * reg0)
    if has_force:
        n0 -= src * w0 * three * uF
    ed = reg0 + n2 * (axx + ayy)
    # third order: the equilibrium's 27/2 rho (H_xxy ux^2 uy + H_xyy ux uy^2) shares its
    # Hermite coefficients with the recursive a_xxy, a_xyy
    eq_xxy = rho * ux * uy * ux
    eq_xyy = rho * ux * uy * uy
    n1, n3 = _rr_pair(three * ux, Fx, reg0 + n2 * axx, three * a1x - n2 * axyy, -n2 * eq_xyy, base, rho, kn,
                      w1, src, uF, has_force, K)
    n2_, n4 = _rr_pair(three * uy, Fy, reg0 + n2 * ayy, three * a1y - n2 * axxy, -n2 * eq_xxy, base, rho, kn,
                       w1, src, uF, has_force, K)
    n5, n7 = _rr_pair(three * (ux + uy), Fx + Fy, ed + nine * pxy, three * (a1x + a1y) + nine * (axyy + axxy),
                      nine * (eq_xyy + eq_xxy), base, rho, kn, w5, src, uF, has_force, K)
    n6, n8 = _rr_pair(three * (uy - ux), Fy - Fx, ed - nine * pxy, three * (a1y - a1x) + nine * (axxy - axyy),
                      nine * (eq_xxy - eq_xyy), base, rho, kn, w5, src, uF, has_force, K)
    return n0, n1, n2_, n3, n4, n5, n6, n7, n8, drho


@numba.njit(inline="always", **_JIT)
def _kbc_node(b, o, k, omega, keep, target, incomp, has_keep, Fx, Fy, has_force, smag):
    """Entropic KBC (solver/kbc.py: Karlin, Boesch & Chikatamarla 2014) of node k's gathered
    populations b[:, k] into o[:, k], in float64 (the numpy reference mixes float32 storage with
    float64 weights); smag > 0 only in the Smagorinsky variant. Two passes over the directions:
    the first writes Delta h into o and sums the entropic products <Delta s|Delta h>,
    <Delta h|Delta h>; the second the post-collision state. Returns drho."""
    drho = 0.0
    jx = 0.0
    jy = 0.0
    exx = 0.0
    eyy = 0.0
    exy = 0.0
    for i in range(9):
        v = np.float64(b[i, k])
        drho += v
        jx += _CX[i] * v
        jy += _CY[i] * v
        exx += _CX[i] * _CX[i] * v
        eyy += _CY[i] * _CY[i] * v
        exy += _CX[i] * _CY[i] * v
    rho = R0 if incomp else R0 + drho
    fx = np.float64(Fx)
    fy = np.float64(Fy)
    ux = (jx + 0.5 * fx) / rho
    uy = (jy + 0.5 * fy) / rho
    deq = drho
    if has_keep:   # absorbing layer (solver/sponge.py)
        kp = np.float64(keep)
        deq = drho * kp
        ux = kp * ux + (1.0 - kp) * np.float64(target)
        uy = kp * uy
    om = np.float64(omega)
    a0 = drho - deq
    a1x = jx - rho * ux
    a1y = jy - rho * uy
    n_diff = (exx - eyy) - rho * (ux * ux - uy * uy)
    pxy = exy - rho * ux * uy
    if smag > 0:
        pxx = exx - deq / 3.0 - rho * ux * ux
        pyy = eyy - deq / 3.0 - rho * uy * uy
        stress = math.sqrt(pxx * pxx + pyy * pyy + 2.0 * pxy * pxy)
        tau0 = 1.0 / om
        om = 1.0 / (0.5 * (tau0 + math.sqrt(tau0 * tau0 + np.float64(smag) * stress / (drho + R0))))
    beta = 0.5 * om
    rho_uxy = rho * ux * uy
    eq_xxy = rho_uxy * ux
    eq_xyy = rho_uxy * uy
    base = deq - 1.5 * rho * (ux * ux + uy * uy)
    sh = 0.0
    hh = 0.0
    for i in range(9):
        cx, cy, w = _CX[i], _CY[i], _W[i]
        cu = 3.0 * (cx * ux + cy * uy)
        feq = w * (base + rho * (cu + 0.5 * cu * cu) + 13.5 * (cy * cy - 1.0 / 3.0) * cx * eq_xyy
                   + 13.5 * (cx * cx - 1.0 / 3.0) * cy * eq_xxy)
        dk = w * (a0 + 3.0 * (cx * a1x + cy * a1y))
        ds = 0.25 * cx * cy * pxy + 0.25 * (cx * cx - cy * cy) * n_diff
        dh = np.float64(b[i, k]) - feq - dk - ds
        inv = 1.0 / (feq + w * R0)
        sh += ds * dh * inv
        hh += dh * dh * inv
        o[i, k] = dh
    gamma = 1.0 / beta - (2.0 - 1.0 / beta) * sh / hh if hh > 1e-30 else 2.0
    step = beta * gamma
    src = 1.0 - 0.5 * om
    uF = ux * fx + uy * fy
    for i in range(9):
        cx, cy, w = _CX[i], _CY[i], _W[i]
        dk = w * (a0 + 3.0 * (cx * a1x + cy * a1y))
        ds = 0.25 * cx * cy * pxy + 0.25 * (cx * cx - cy * cy) * n_diff
        v = np.float64(b[i, k]) - om * dk - 2.0 * beta * ds - step * np.float64(o[i, k])
        if has_force:
            cF = cx * fx + cy * fy
            cu = 3.0 * (cx * ux + cy * uy)
            v += src * w * (3.0 * cu * cF - 3.0 * uF + 3.0 * cF)
        o[i, k] = v
    return drho


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


#: columns per chunk: the pulled populations and the results of a chunk stay in L1
CHUNK = 128


@numba.njit(inline="always", **_JIT)
def _chunk(b, o, n, op, om, t, trt, incomp, Fx, Fy, has_force, K):
    """BGK / TRT: collide n gathered nodes b (9, CHUNK) into o with one pair of rates (op, om)
    for all: written without per-node branches or arrays beside b and o, so LLVM vectorises it.
    Returns sum drho."""
    s = 0.0
    for k in range(n):
        r = _collide(b[0, k], b[1, k], b[2, k], b[3, k], b[4, k], b[5, k], b[6, k], b[7, k], b[8, k],
                     op, om, op, t, trt, incomp, False, Fx, Fy, has_force, K)
        _store_k(o, k, r)
        s += r[9]
    return s


@numba.njit(inline="always", **_JIT)
def _chunk_rr(b, o, n, op, t, incomp, Fx, Fy, has_force, smag, K):
    """As _chunk for the recursive-regularised operator."""
    s = 0.0
    for k in range(n):
        r = _collide_rr(b[0, k], b[1, k], b[2, k], b[3, k], b[4, k], b[5, k], b[6, k], b[7, k], b[8, k],
                        op, op, t, incomp, False, Fx, Fy, has_force, smag, K)
        _store_k(o, k, r)
        s += r[9]
    return s


@numba.njit(inline="always", **_JIT)
def _chunk_kbc(b, o, n, op, t, incomp, Fx, Fy, has_force, smag):
    """As _chunk for the entropic KBC operator."""
    s = 0.0
    for k in range(n):
        s += _kbc_node(b, o, k, op, op, t, incomp, False, Fx, Fy, has_force, smag)
    return s


@numba.njit(inline="always", **_JIT)
def _columns_kbc(b, o, n, cols, op, keep, t, incomp, has_keep, Fx, Fy, has_force, smag):
    """As _columns for the entropic KBC operator."""
    s = 0.0
    for k in range(n):
        x = cols[k]
        s += _kbc_node(b, o, k, op[x], keep[x], t, incomp, has_keep, Fx, Fy, has_force, smag)
    return s


@numba.njit(inline="always", **_JIT)
def _columns(b, o, n, cols, op, om, keep, t, trt, incomp, has_keep, Fx, Fy, has_force, K):
    """BGK / TRT: as _chunk with node k in column cols[k] (its own rates and absorbing layer:
    the sponge's columns; the seam columns; the boundary nodes). Returns sum drho."""
    s = 0.0
    for k in range(n):
        x = cols[k]
        r = _collide(b[0, k], b[1, k], b[2, k], b[3, k], b[4, k], b[5, k], b[6, k], b[7, k], b[8, k],
                     op[x], om[x], keep[x], t, trt, incomp, has_keep, Fx, Fy, has_force, K)
        _store_k(o, k, r)
        s += r[9]
    return s


@numba.njit(inline="always", **_JIT)
def _columns_rr(b, o, n, cols, op, keep, t, incomp, has_keep, Fx, Fy, has_force, smag, K):
    """As _columns for the recursive-regularised operator."""
    s = 0.0
    for k in range(n):
        x = cols[k]
        r = _collide_rr(b[0, k], b[1, k], b[2, k], b[3, k], b[4, k], b[5, k], b[6, k], b[7, k], b[8, k],
                        op[x], keep[x], t, incomp, has_keep, Fx, Fy, has_force, smag, K)
        _store_k(o, k, r)
        s += r[9]
    return s


@numba.njit(inline="always", **_JIT)
def _wall_in(b, pre, y, x0, n, lower):
    """b[i, :n] = pre[i, y, x0 .. x0+n-1] for the populations a wall at y = -1/2 (lower) or
    ny - 1/2 writes: rule b on a wall row's chunk inside the parallel pass."""
    for i in ((2, 5, 6) if lower else (4, 7, 8)):
        _copy_in(b, i, pre[i, y, x0:x0 + n], n)


#: the lattice velocities as integers, for the layout accessors
_CXI = C[:, 0].astype(np.int64)
_CYI = C[:, 1].astype(np.int64)
#: where the state of a step's input or output lives (the AA pattern, `make_kernel`): NATURAL
#: f*_i(x) in slot i of node x (the solver's state between calls); STREAMED f*_i(x) in slot i of
#: node x + c_i (an AA odd step's output: each node's incoming populations in its own slots);
#: SWAPPED f*_i(x) in slot opp(i) of node x (an AA even step's output)
NATURAL, STREAMED, SWAPPED = 0, 1, 2


@numba.njit(inline="always", **_JIT)
def _wrap(v, n):
    """v periodic in 0 .. n-1 for -n <= v < 2n (a branch: an integer modulo costs tens of cycles)."""
    if v < 0:
        return v + n
    if v >= n:
        return v - n
    return v


@numba.njit(inline="always", **_JIT)
def _post(g, lay, i, y, x):
    """f*_i at node (y, x), the post-collision population i, from g in layout `lay`."""
    if lay == NATURAL:
        return g[i, y, x]
    if lay == SWAPPED:
        return g[_OPP[i], y, x]
    ny, nx = g.shape[1], g.shape[2]
    return g[i, _wrap(y + _CYI[i], ny), _wrap(x + _CXI[i], nx)]


@numba.njit(inline="always", **_JIT)
def _put(g, lay, i, y, x, v):
    """Store f*_i of node (y, x) = v into g in layout `lay`."""
    if lay == NATURAL:
        g[i, y, x] = v
    elif lay == SWAPPED:
        g[_OPP[i], y, x] = v
    else:
        ny, nx = g.shape[1], g.shape[2]
        g[i, _wrap(y + _CYI[i], ny), _wrap(x + _CXI[i], nx)] = v


@numba.njit(inline="always", **_JIT)
def _copy_in(b, i, src, n):
    """b[i, :n] = src[:n], an element loop over views (LLVM vectorises it; numba's slice
    assignment, with its overlap check, costs the kernel's compile far more)."""
    for k in range(n):
        b[i, k] = src[k]


@numba.njit(inline="always", **_JIT)
def _copy_out(dst, o, i, n):
    """dst[:n] = o[i, :n], as _copy_in."""
    for k in range(n):
        dst[k] = o[i, k]


@numba.njit(inline="always", **_JIT)
def _gather_from(g, lay, b, y, x0, n):
    """b[i, :n] = the incoming population i of nodes (y, x0 .. x0+n-1), 1 <= x0, x0 + n < nx,
    from g in layout `lay`: f*_i of the node at x - c_i (NATURAL: slot i there; SWAPPED: slot
    opp(i) there; STREAMED: slot i of the node itself)."""
    ny = g.shape[1]
    for i in range(9):
        if lay == STREAMED:
            _copy_in(b, i, g[i, y, x0:x0 + n], n)
        else:
            slot = i if lay == NATURAL else _OPP[i]
            xx = x0 - _CXI[i]
            _copy_in(b, i, g[slot, _wrap(y - _CYI[i], ny), xx:xx + n], n)


@numba.njit(inline="always", **_JIT)
def _store_to(g, lay, o, y, x0, n):
    """Store o[i, :n], f*_i of nodes (y, x0 .. x0+n-1), 1 <= x0, x0 + n < nx, into g in layout
    `lay` (STREAMED: slot i of the node at x + c_i; SWAPPED: slot opp(i) of the node itself)."""
    ny = g.shape[1]
    for i in range(9):
        if lay == STREAMED:
            xx = x0 + _CXI[i]
            _copy_out(g[i, _wrap(y + _CYI[i], ny), xx:xx + n], o, i, n)
        else:
            slot = i if lay == NATURAL else _OPP[i]
            _copy_out(g[slot, y, x0:x0 + n], o, i, n)


@numba.njit(inline="always", **_JIT)
def _velocity(g, lay, y, x):
    """u = sum c f / sum f at one node, post-collision, in float64."""
    rho = R0
    jx = 0.0
    jy = 0.0
    for i in range(9):
        v = np.float64(_post(g, lay, i, y, x))
        rho += v
        jx += _CX[i] * v
        jy += _CY[i] * v
    return jx / rho, jy / rho


@numba.njit(**_JIT)
def _outlet(g, lay, pre):
    """Rule d (solver/inflow.py outlet_incoming), anti-bounce-back at x = nx - 1/2, in float64."""
    ny, nx = g.shape[1], g.shape[2]
    for y in range(ny):
        ux0, uy0 = _velocity(g, lay, y, nx - 2)
        ux1, uy1 = _velocity(g, lay, y, nx - 1)
        bx = 1.5 * ux1 - 0.5 * ux0
        by = 1.5 * uy1 - 0.5 * uy0
        usq = bx * bx + by * by
        for i in (3, 6, 7):
            cu = _CX[i] * bx + _CY[i] * by
            pre[i, y, nx - 1] = -np.float64(_post(g, lay, _OPP[i], y, nx - 1)) + 2.0 * _W[i] * R0 * (4.5 * cu * cu - 1.5 * usq)


@numba.njit(**_JIT)
def _inlet(g, lay, pre, r, wall_profile, quiet, rate, coefficient, drho_ref):
    """Rule c (moving-wall half-way bounce-back at x = -1/2, each link with its own inflow) and
    the quiet inlet's correction (solver/quiet_inlet.py; drho_ref updated in place)."""
    ny = g.shape[1]
    for y in range(ny):
        corr = 0.0
        if quiet:
            d = _post(g, lay, 0, y, 0)
            for i in range(1, 9):
                d += _post(g, lay, i, y, 0)
            drho_ref[y] += rate * (d - drho_ref[y])
            corr = -coefficient * (d - drho_ref[y])
        for k in range(3):
            i = (1, 5, 8)[k]
            c = 6.0 * _W[i] * R0
            pre[i, y, 0] = np.float64(_post(g, lay, _OPP[i], y, 0)) + c * r * wall_profile[k, y] + c * corr


@numba.njit(**_JIT)
def _walls(g, lay, pre, walls, periodic_x):
    """Rule b: half-way bounce-back (walls 1) or specular reflection (walls 2) at y = -1/2 and
    ny - 1/2; a free-slip tunnel corner keeps the inlet/outlet rule."""
    ny, nx = g.shape[1], g.shape[2]
    for side in range(2):
        row = 0 if side == 0 else ny - 1
        for k in range(3):
            i = (2, 5, 6)[k] if side == 0 else (4, 7, 8)[k]
            if walls == 1:
                ib = _OPP[i]
                for x in range(nx):
                    pre[i, row, x] = _post(g, lay, ib, row, x)
                continue
            j = _MIRROR_Y[i]
            cx = int(_CX[i])
            if cx == 0:
                for x in range(nx):
                    pre[i, row, x] = _post(g, lay, j, row, x)
            elif cx == 1:
                for x in range(1, nx):
                    pre[i, row, x] = _post(g, lay, j, row, x - 1)
                if periodic_x:
                    pre[i, row, 0] = _post(g, lay, j, row, nx - 1)
            else:
                for x in range(nx - 1):
                    pre[i, row, x] = _post(g, lay, j, row, x + 1)
                if periodic_x:
                    pre[i, row, nx - 1] = _post(g, lay, j, row, 0)


@numba.njit(**_JIT)
def _links(g, lay, pre, li, ly, lx, lfy, lfx, la, lb, lc, ld, luwx, luwy, lpx, lpy, sums):
    """Rule a (solver/bouzidi.py incoming, float64) on every body link, and the momentum
    exchange on them (solver/forces/momentum_exchange.py, full f = g + w RHO0):
    sums += (Galilean fx, fy, classic fx, fy, Galilean p x F, classic p x F) without the
    cover/uncover impulse, p = (lpx, lpy) the link's wall crossing x - q c_i in grid
    coordinates (the caller takes the centre's moment c x F off: the torque about c)."""
    for k in range(len(li)):
        i = li[k]
        ib = _OPP[i]
        y, x = ly[k], lx[k]
        g_out = np.float64(_post(g, lay, ib, y, x))
        v = (la[k] * g_out + lb[k] * np.float64(_post(g, lay, ib, lfy[k], lfx[k]))
             + lc[k] * np.float64(_post(g, lay, i, y, x)) + ld[k])
        pre[i, y, x] = v
        wr = _W[i] * R0
        f_out = g_out + wr
        f_in = v + wr
        cx, cy = _CX[i], _CY[i]
        gx = (-cx - luwx[k]) * f_out - (cx - luwx[k]) * f_in
        gy = (-cy - luwy[k]) * f_out - (cy - luwy[k]) * f_in
        sx = -cx * (f_out + f_in)
        sy = -cy * (f_out + f_in)
        sums[0] += gx
        sums[1] += gy
        sums[2] += sx
        sums[3] += sy
        sums[4] += lpx[k] * gy - lpy[k] * gx
        sums[5] += lpx[k] * sy - lpy[k] * sx


@numba.njit(**_JIT)
def rows_of_nodes(ry, rx, rbits, ny):
    """The kernel's boundary-node list by row: (rp (ny+1,), xs, bits), row y's nodes
    xs[rp[y] .. rp[y+1]] sorted by x, from nodes (ry, rx, rbits) that each come once."""
    n = len(ry)
    rp = np.zeros(ny + 1, np.int64)
    for k in range(n):
        rp[ry[k] + 1] += 1
    for y in range(ny):
        rp[y + 1] += rp[y]
    fill = rp[:-1].copy()
    xs = np.empty(n, np.int64)
    bits = np.empty(n, np.int64)
    for k in range(n):
        j = fill[ry[k]]
        xs[j], bits[j] = rx[k], rbits[k]
        fill[ry[k]] += 1
    for y in range(ny):  # insertion sort: a row holds a handful of nodes
        for a in range(rp[y] + 1, rp[y + 1]):
            xa, ba = xs[a], bits[a]
            b = a - 1
            while b >= rp[y] and xs[b] > xa:
                xs[b + 1], bits[b + 1] = xs[b], bits[b]
                b -= 1
            xs[b + 1], bits[b + 1] = xa, ba
    return rp, xs, bits


@numba.njit(inline="always", **_JIT)
def _ramp(t, ramp_steps):
    """solver/inflow.py ramp: (1 - cos(pi t / T)) / 2 for t < T, else 1."""
    if ramp_steps <= 0 or t >= ramp_steps:
        return 1.0
    return 0.5 * (1.0 - math.cos(math.pi * t / ramp_steps))


@functools.lru_cache(maxsize=None)
def make_kernel(kind: str, incomp: bool, has_keep: bool, has_force: bool, dtype: str = "float32",
                smagorinsky: bool = False):
    """`advance`, compiled for one collision variant (kind "bgk", "trt" or "rr"; rr with or
    without the Smagorinsky viscosity) and storage type: the flags and constants are constants
    of the compiled code, so the inner loop has no branches (cached per variant). The rates,
    keep, target and force passed to it are of `dtype`.
    Its closure holds only these flags and constants, never another compiled function: numba's
    on-disk cache keys a closure by its variables' pickled bytes, and a compiled function pickles
    with an id that is new in every process, so such a closure would compile again at every start."""
    if kind not in ("bgk", "trt", "rr", "kbc"):
        raise ValueError(f"the cpu backend compiles bgk, trt, rr and kbc, not {kind!r}")
    K = constants(dtype)
    rr = kind == "rr"   # the closure's branches on these constants are pruned before inlining,
    trt = kind == "trt"  # so each variant compiles one operator
    kbc = kind == "kbc"
    smag_on = bool(smagorinsky) and (rr or kbc)

    @numba.njit(parallel=_PARALLEL, **_JIT)
    def advance(n, t0, ramp_steps, g, out, pre, op, om, keep, target, xs, Fx, Fy, smag, scratch, sums,
                tunnel, walls, periodic_x, profile, wall_profile, quiet_rate, quiet_coefficient, drho_ref,
                li, ly, lx, lfy, lfx, la, lb, lc, ld, luwx, luwy, lpx, lpy, force,
                rp, nxs, nbits, sy, sx, solid_g):
        """n steps from time t0 of the post-collision state in g (NATURAL layout); returns
        (steps done, finite, where): it stops after the first step whose density is not finite
        (that state is kept, in the layout of that step's output); the state is in g if `where`
        is 0, in out if 1.

        The streaming pattern is AA (Bailey, Myre, Walsh, Lilja & Saar 2009;
        docs/science/cpu-backend.md): the first step pulls from g (NATURAL) and writes its
        output STREAMED into out; the steps between run in place in out, alternately
        STREAMED -> SWAPPED and SWAPPED -> STREAMED (each node reads and writes the same nine
        places, which no other node touches); the last writes NATURAL back into g. One step
        alone reads g and writes out, both NATURAL. Each step, in the numpy backend's order:
        1. rules d (outlet), c (inlet with the ramp r(t) of `ramp_steps`, each link's inflow
           r wall_profile, the quiet inlet's correction once the ramp is over: quiet_rate > 0),
           b (walls: 0 periodic, 1 no-slip, 2 free-slip) and a (the body links li..luwy, in grid
           coordinates) into pre, from the post-collision state (read through `_post`); the
           momentum exchange summed into force (6,) over the n steps (Galilean fx, fy, classic
           fx, fy, no impulse, and their moments about the grid origin from the wall crossings
           lpx, lpy: _links);
        2. stream + collide of every node, blocks of rows in parallel (scratch (B, 2, 9, CHUNK):
           each block's gather and result buffers, nothing allocated in the parallel loop; sums
           (B,) each block's sum drho): columns 1 .. xs-1 share the rates op[1], om[1];
           xs .. nx-2 (the sponge) take their own column's; target (ny,) the absorbing layer's
           x-velocity r profile; a wall row takes the populations its wall writes from pre
           (_wall_in); the nodes listed by row (rp, nxs, nbits: `rows_of_nodes`; row y's
           nxs[rp[y] .. rp[y+1]], sorted by x) take population i from pre where bit i of their
           bits is set before they collide: every node of columns 0 and nx-1 (done node by
           node after the row's chunks: they pull across the periodic seam) and every node
           that owns a body link;
        3. the solid nodes (sy, sx) reset to solid_g."""
        ny, nx = g.shape[1], g.shape[2]
        nb = scratch.shape[0]
        per = (ny + nb - 1) // nb
        op0, om0 = op[min(1, nx - 1)], om[min(1, nx - 1)]
        sm = smag if smag_on else 0.0
        cols = np.arange(nx)
        force[:] = 0.0
        for step in range(n):
            t = t0 + step
            in_out = step < n - 1 or n == 1
            src = g if step == 0 else out
            dst = out if in_out else g
            lin = NATURAL if step == 0 else (STREAMED if step % 2 == 1 else SWAPPED)
            if step == n - 1:
                lout = NATURAL
            elif step == 0:
                lout = STREAMED
            else:
                lout = SWAPPED if step % 2 == 1 else STREAMED
            if tunnel:
                r = _ramp(t, ramp_steps)
                for y in range(ny):
                    target[y] = r * profile[y]
                _outlet(src, lin, pre)
                quiet = quiet_rate > 0 and r >= 1.0
                _inlet(src, lin, pre, r, wall_profile, quiet, quiet_rate, quiet_coefficient, drho_ref)
            if walls != 0:
                _walls(src, lin, pre, walls, periodic_x)
            _links(src, lin, pre, li, ly, lx, lfy, lfx, la, lb, lc, ld, luwx, luwy, lpx, lpy, force)
            for blk in prange(nb):
                bb = scratch[blk, 0]
                o = scratch[blk, 1]
                s = 0.0
                for y in range(blk * per, min(ny, (blk + 1) * per)):
                    tg = target[y]
                    wall_row = walls != 0 and (y == 0 or y == ny - 1)
                    k0, k1 = rp[y], rp[y + 1]
                    k = k0
                    while k < k1 and nxs[k] == 0:
                        k += 1
                    x0 = 1
                    while x0 < nx - 1:   # chunks end at xs: the sponge starts a chunk
                        m = min(CHUNK, (xs if x0 < xs else nx - 1) - x0)
                        _gather_from(src, lin, bb, y, x0, m)
                        if wall_row:
                            _wall_in(bb, pre, y, x0, m, y == 0)
                        while k < k1 and nxs[k] < x0 + m:   # the row's listed nodes in this chunk
                            x, bits = nxs[k], nbits[k]
                            for i in range(9):
                                if (bits >> i) & 1:
                                    bb[i, x - x0] = pre[i, y, x]
                            k += 1
                        if x0 < xs:        # the rates of column 1 for the whole chunk
                            if rr:
                                s += _chunk_rr(bb, o, m, op0, tg, incomp, Fx, Fy, has_force, sm, K)
                            elif kbc:
                                s += _chunk_kbc(bb, o, m, op0, tg, incomp, Fx, Fy, has_force, sm)
                            else:
                                s += _chunk(bb, o, m, op0, om0, tg, trt, incomp, Fx, Fy, has_force, K)
                        else:              # each column its own rates (the sponge)
                            c = cols[x0:x0 + m]
                            if rr:
                                s += _columns_rr(bb, o, m, c, op, keep, tg, incomp, has_keep, Fx, Fy, has_force,
                                                 sm, K)
                            elif kbc:
                                s += _columns_kbc(bb, o, m, c, op, keep, tg, incomp, has_keep, Fx, Fy, has_force, sm)
                            else:
                                s += _columns(bb, o, m, c, op, om, keep, tg, trt, incomp, has_keep, Fx, Fy,
                                              has_force, K)
                        _store_to(dst, lout, o, y, x0, m)
                        x0 += m
                    for side in range(2 if nx > 1 else 1):  # the seam columns, periodic neighbours
                        x = 0 if side == 0 else nx - 1
                        bits = 0
                        for kk in range(k0, k1):
                            if nxs[kk] == x:
                                bits = nbits[kk]
                        for i in range(9):
                            if (bits >> i) & 1:
                                bb[i, 0] = pre[i, y, x]
                            else:
                                bb[i, 0] = _post(src, lin, i, _wrap(y - _CYI[i], ny), _wrap(x - _CXI[i], nx))
                        c = cols[x:x + 1]
                        if rr:
                            s += _columns_rr(bb, o, 1, c, op, keep, tg, incomp, has_keep, Fx, Fy, has_force, sm, K)
                        elif kbc:
                            s += _columns_kbc(bb, o, 1, c, op, keep, tg, incomp, has_keep, Fx, Fy, has_force, sm)
                        else:
                            s += _columns(bb, o, 1, c, op, om, keep, tg, trt, incomp, has_keep, Fx, Fy, has_force, K)
                        for i in range(9):
                            _put(dst, lout, i, y, x, o[i, 0])
                sums[blk] = s
            total = sums.sum()
            for k in range(len(sy)):
                for i in range(9):
                    _put(dst, lout, i, sy[k], sx[k], solid_g[i, k])
            if not np.isfinite(total):
                return step + 1, False, 1 if in_out else 0
        return n, True, 1 if n == 1 else 0

    return advance


# --- the AA streaming pattern, measured against the two buffers above --------------------------
@numba.njit(inline="always", **_JIT)
def _gather_aa(g, b, y, ym, yp, x0, n):
    """The odd AA step's reads: b[i, k] = g[opp(i), y - c_iy, x - c_ix] at x = x0 + k, the
    population the last (even) step stored at the node it came from, 1 <= x0, x0 + n < nx."""
    x1 = x0 + n
    b[0, :n] = g[0, y, x0:x1]
    b[1, :n] = g[3, y, x0 - 1:x1 - 1]
    b[2, :n] = g[4, ym, x0:x1]
    b[3, :n] = g[1, y, x0 + 1:x1 + 1]
    b[4, :n] = g[2, yp, x0:x1]
    b[5, :n] = g[7, ym, x0 - 1:x1 - 1]
    b[6, :n] = g[8, ym, x0 + 1:x1 + 1]
    b[7, :n] = g[5, yp, x0 + 1:x1 + 1]
    b[8, :n] = g[6, yp, x0 - 1:x1 - 1]


@numba.njit(inline="always", **_JIT)
def _scatter_aa(g, o, y, ym, yp, x0, n):
    """The odd AA step's writes: g[i, y + c_iy, x + c_ix] = o[i, k], the very places its reads
    came from (so each node touches its own nine places and the step runs in place)."""
    x1 = x0 + n
    g[0, y, x0:x1] = o[0, :n]
    g[1, y, x0 + 1:x1 + 1] = o[1, :n]
    g[2, yp, x0:x1] = o[2, :n]
    g[3, y, x0 - 1:x1 - 1] = o[3, :n]
    g[4, ym, x0:x1] = o[4, :n]
    g[5, yp, x0 + 1:x1 + 1] = o[5, :n]
    g[6, yp, x0 - 1:x1 - 1] = o[6, :n]
    g[7, ym, x0 - 1:x1 - 1] = o[7, :n]
    g[8, ym, x0 + 1:x1 + 1] = o[8, :n]


@numba.njit(inline="always", **_JIT)
def _seam_aa(g, b, o, y, ym, yp, x, op, om, trt, K):
    """The odd AA step at one node of the first or last column (periodic neighbours)."""
    nx = g.shape[2]
    xm = x - 1 if x > 0 else nx - 1
    xp = x + 1 if x < nx - 1 else 0
    b[0, 0] = g[0, y, x]
    b[1, 0] = g[3, y, xm]
    b[2, 0] = g[4, ym, x]
    b[3, 0] = g[1, y, xp]
    b[4, 0] = g[2, yp, x]
    b[5, 0] = g[7, ym, xm]
    b[6, 0] = g[8, ym, xp]
    b[7, 0] = g[5, yp, xp]
    b[8, 0] = g[6, yp, xm]
    s = _chunk(b, o, 1, op, om, K[0] * 0, trt, False, K[0] * 0, K[0] * 0, False, K)
    g[0, y, x] = o[0, 0]
    g[1, y, xp] = o[1, 0]
    g[2, yp, x] = o[2, 0]
    g[3, y, xm] = o[3, 0]
    g[4, ym, x] = o[4, 0]
    g[5, yp, xp] = o[5, 0]
    g[6, yp, xm] = o[6, 0]
    g[7, ym, xm] = o[7, 0]
    g[8, ym, xp] = o[8, 0]
    return s


@functools.lru_cache(maxsize=None)
def make_box_aa(kind: str = "trt", dtype: str = "float32"):
    """`advance_aa`: the periodic box (BGK or TRT, no force, no sponge) stepped in place in ONE
    buffer with the AA pattern (Bailey, Myre, Walsh, Lilja & Saar 2009, "Accelerating lattice
    Boltzmann fluid flow simulations using graphics processors"), for `feelflow bench streaming`
    to measure against the two-buffer kernel above (docs/science/cpu-backend.md). Not used by
    the solver backends.

    The state between steps is the pre-collision populations f_i(x) in natural order after an
    odd number of AA steps' pairs (an "even" state). An even step collides each node in place
    and stores f*_i in slot opp(i) of the same node; an odd step reads each node's incoming
    populations from the slots the even step filled at its neighbours, collides, and writes
    f*_i to slot i of node x + c_i: streamed, in natural order again. Each node of either step
    reads and writes the same nine places, which no other node touches, so the rows run in
    parallel without a second buffer. After two AA steps the buffer holds what streaming the
    two-buffer kernel's state (post-collision) gives after two steps."""
    if kind not in ("bgk", "trt"):
        raise ValueError(f"the AA box kernel compiles bgk and trt, not {kind!r}")
    K = constants(dtype)
    trt = kind == "trt"

    @numba.njit(parallel=True, **_JIT)
    def advance_aa(n, odd, g, op, om, scratch, sums):
        """n AA steps in place on g (9, ny, nx), the first an odd step if `odd`; op, om the
        rates; scratch (B, 2, 9, CHUNK), sums (B,). Returns (steps done, finite) as `advance`."""
        ny, nx = g.shape[1], g.shape[2]
        nb = scratch.shape[0]
        per = (ny + nb - 1) // nb
        zero = K[0] * 0
        for step in range(n):
            is_odd = (step + odd) % 2 == 1
            for blk in prange(nb):
                bb = scratch[blk, 0]
                o = scratch[blk, 1]
                s = 0.0
                for y in range(blk * per, min(ny, (blk + 1) * per)):
                    ym = y - 1 if y > 0 else ny - 1
                    yp = y + 1 if y < ny - 1 else 0
                    if is_odd:
                        s += _seam_aa(g, bb, o, y, ym, yp, 0, op, om, trt, K)
                        x0 = 1
                        while x0 < nx - 1:
                            m = min(CHUNK, nx - 1 - x0)
                            _gather_aa(g, bb, y, ym, yp, x0, m)
                            s += _chunk(bb, o, m, op, om, zero, trt, False, zero, zero, False, K)
                            _scatter_aa(g, o, y, ym, yp, x0, m)
                            x0 += m
                        if nx > 1:
                            s += _seam_aa(g, bb, o, y, ym, yp, nx - 1, op, om, trt, K)
                    else:
                        x0 = 0
                        while x0 < nx:
                            m = min(CHUNK, nx - x0)
                            x1 = x0 + m
                            for i in range(9):
                                bb[i, :m] = g[i, y, x0:x1]
                            s += _chunk(bb, o, m, op, om, zero, trt, False, zero, zero, False, K)
                            g[0, y, x0:x1] = o[0, :m]
                            g[3, y, x0:x1] = o[1, :m]
                            g[4, y, x0:x1] = o[2, :m]
                            g[1, y, x0:x1] = o[3, :m]
                            g[2, y, x0:x1] = o[4, :m]
                            g[7, y, x0:x1] = o[5, :m]
                            g[8, y, x0:x1] = o[6, :m]
                            g[5, y, x0:x1] = o[7, :m]
                            g[6, y, x0:x1] = o[8, :m]
                            x0 = x1
                sums[blk] = s
            if not np.isfinite(sums.sum()):
                return step + 1, False
        return n, True

    return advance_aa
