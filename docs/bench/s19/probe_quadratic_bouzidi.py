"""Throwaway probe (nineteenth session, docs/validation.md 2D-2 item 11; not product code,
nothing imports it): Bouzidi's quadratic interpolated bounce-back (Bouzidi, Firdaouss &
Lallemand 2001) in place of the linear rule, numpy backend, patched in for one 2D-2 or 2D-1 run.

    python docs/bench/s19/probe_quadratic_bouzidi.py 2d2 40     (or: 2d1 20)
"""
import os
import sys

sys.path[:0] = [".", os.path.dirname(os.path.dirname(os.path.abspath(__file__)))]
import numpy as np
from probe_run_case import run_case
import solver.bouzidi as bz
from solver.lattice import C, OPP, W, RHO0

_lin_build = bz.build_links
_lin_incoming = bz.incoming

def build_links(q, solid, x0, y0, center, velocity, omega, wrap=(False, False)):
    L = _lin_build(q, solid, x0, y0, center, velocity, omega, wrap)
    h, w = solid.shape
    fluid = ~solid
    i, iy, ix, qq = L.i, L.iy, L.ix, L.q
    cx, cy = C[i, 0], C[i, 1]
    y1, x1, y2, x2 = iy + cy, ix + cx, iy + 2 * cy, ix + 2 * cx
    ok = (y2 >= 0) & (y2 < h) & (x2 >= 0) & (x2 < w) & (y1 >= 0) & (y1 < h) & (x1 >= 0) & (x1 < w)
    y1c, x1c, y2c, x2c = (np.clip(v, 0, m - 1) for v, m in ((y1, h), (x1, w), (y2, h), (x2, w)))
    ok &= fluid[y1c, x1c] & fluid[y2c, x2c] & (q[i, iy, ix] == 0) & (q[i, y1c, x1c] == 0)
    ux, uy = L.uw[:, 0], L.uw[:, 1]
    cu = W[i] * RHO0 * (cx * ux + cy * uy)
    small = qq < 0.5
    a, b, c, d = L.a.copy(), L.b.copy(), L.c.copy(), L.d.copy()
    e = np.zeros_like(a)
    fy, fx = L.fy.copy(), L.fx.copy()
    j2 = L.ib.copy()
    s = ok & small   # q(1+2q) f_ib(x) + (1-4q^2) f_ib(x+c) - q(1-2q) f_ib(x+2c) + 6 w c.u
    a[s] = qq[s] * (1 + 2 * qq[s]); b[s] = 1 - 4 * qq[s] ** 2; c[s] = 0.0; e[s] = -qq[s] * (1 - 2 * qq[s])
    d[s] = 6.0 * cu[s]; fy[s] = y1[s]; fx[s] = x1[s]; j2[s] = L.ib[s]
    g = ok & ~small  # 1/(q(2q+1)) f_ib(x) + (2q-1)/q f_i(x) + (1-2q)/(1+2q) f_i(x+c) + 6w c.u/(q(2q+1))
    a[g] = 1 / (qq[g] * (2 * qq[g] + 1)); b[g] = 0.0; c[g] = (2 * qq[g] - 1) / qq[g]
    e[g] = (1 - 2 * qq[g]) / (1 + 2 * qq[g]); d[g] = 6.0 * cu[g] / (qq[g] * (2 * qq[g] + 1))
    j2[g] = i[g]
    y2o = np.where(s, y2, np.where(g, y1, iy)); x2o = np.where(s, x2, np.where(g, x1, ix))
    L2 = bz.BodyLinks(L.i, L.ib, L.iy, L.ix, fy, fx, L.q, L.uw, a, b, c, d)
    object.__setattr__(L2, "e", e); object.__setattr__(L2, "j2", j2)
    object.__setattr__(L2, "y2", y2o); object.__setattr__(L2, "x2", x2o)
    return L2

def incoming(f, links, f_ib=None):
    out = _lin_incoming(f, links, f_ib)
    e = getattr(links, "e", None)
    if e is not None:
        out = out + e * f[links.j2, links.y2, links.x2].astype(np.float64)
    return out

import solver.body, solver.numpy_backend, solver.forces.momentum_exchange as me
for m in (bz, solver.body, me):
    m.build_links = build_links
for m in (bz, solver.numpy_backend, me):
    m.incoming = incoming

run_case(sys.argv)
