"""Throwaway probe (twenty-first session, docs/validation.md 2D-2 item 13; not product code,
nothing imports it): Ginzburg & d'Humieres' central linear interpolation (CLI; Phys. Rev. E 68
(2003) 066614, the multireflection family's linear member) in place of Bouzidi's linear rule,
numpy backend, patched in for one 2D-2 or 2D-1 run.

In solver/bouzidi.py's form f_i^in(x) = a f*_ib(x) + b f*_ib(x + c_i) + c f*_i(x) + d, CLI is
    a = 1, b = k, c = -k, k = (1 - 2q) / (1 + 2q), d = 12 w RHO0 c_i.u_w / (1 + 2q)
for every q, where the second node x + c_i is fluid (d from a uniform flow moving with the wall:
d = 3 w RHO0 c_i.u_w (1 + a + b - c)); elsewhere the linear rule stays.

    python docs/bench/s21/probe_cli_bouzidi.py 2d2 40     (or: 2d1 20 [U_m])
"""
import os
import sys

sys.path[:0] = [".", os.path.dirname(os.path.dirname(os.path.abspath(__file__)))]
import numpy as np
import solver.bouzidi as bz
from probe_run_case import run_case

_lin_build = bz.build_links


def build_links(q, solid, x0, y0, center, velocity, omega, wrap=(False, False)):
    L = _lin_build(q, solid, x0, y0, center, velocity, omega, wrap)
    fy, fx, ok = bz.second_nodes(q, solid, L.i, L.iy, L.ix, wrap)
    qq = L.q
    cu = bz.W[L.i] * bz.RHO0 * (bz.C[L.i, 0] * L.uw[:, 0] + bz.C[L.i, 1] * L.uw[:, 1])
    k = (1 - 2 * qq) / (1 + 2 * qq)
    a = np.where(ok, 1.0, L.a)
    b = np.where(ok, k, L.b)
    c = np.where(ok, -k, L.c)
    d = np.where(ok, 12.0 * cu / (1 + 2 * qq), L.d)
    return bz.BodyLinks(L.i, L.ib, L.iy, L.ix, np.where(ok, fy, L.fy), np.where(ok, fx, L.fx), qq, L.uw,
                        a, b, c, d)


import solver.body, solver.forces.momentum_exchange as me
for m in (bz, solver.body, me):
    m.build_links = build_links

run_case(sys.argv)
