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
import sys, time, json
sys.path.insert(0, ".")
import numpy as np
import solver.bouzidi as bz

_lin_build = bz.build_links


def build_links(q, solid, x0, y0, center, velocity, omega, wrap=(False, False)):
    L = _lin_build(q, solid, x0, y0, center, velocity, omega, wrap)
    h, w = solid.shape
    i, iy, ix, qq = L.i, L.iy, L.ix, L.q
    cx, cy = bz.C[i, 0], bz.C[i, 1]
    fy, fx = iy + cy, ix + cx
    if wrap[0]:
        fx = fx % w
    if wrap[1]:
        fy = fy % h
    inside = (fy >= 0) & (fy < h) & (fx >= 0) & (fx < w)
    fyc, fxc = np.clip(fy, 0, h - 1), np.clip(fx, 0, w - 1)
    ok = inside & ~solid[fyc, fxc] & (q[i, iy, ix] == 0)
    cu = bz.W[i] * bz.RHO0 * (cx * L.uw[:, 0] + cy * L.uw[:, 1])
    k = (1 - 2 * qq) / (1 + 2 * qq)
    a = np.where(ok, 1.0, L.a)
    b = np.where(ok, k, L.b)
    c = np.where(ok, -k, L.c)
    d = np.where(ok, 12.0 * cu / (1 + 2 * qq), L.d)
    return bz.BodyLinks(L.i, L.ib, L.iy, L.ix, np.where(ok, fy, L.fy), np.where(ok, fx, L.fx), qq, L.uw,
                        a, b, c, d)


import solver.body, solver.forces.momentum_exchange as me
for m in (bz, solver.body, me):
    if hasattr(m, "build_links"):
        m.build_links = build_links

from solver.backend import create_solver
case, d = sys.argv[1], int(sys.argv[2])
u = float(sys.argv[3]) if len(sys.argv) > 3 else 0.075
fac = lambda c: create_solver("numpy", c)
t0 = time.time()
if case == "2d2":
    from solver.validation import schaefer_turek_2d2 as st
    r = st.run(fac, resolution=d)
else:
    from solver.validation import schaefer_turek_2d1 as st
    r = st.run(fac, resolution=d, u_max=u)
print(case, d, json.dumps(r.quantities), r.steps, round(time.time() - t0), "s")
