"""TEMPORARY stand-ins until shapes/ and the numpy backend land on main (then deleted).

A minimal D2Q9 BGK tunnel (half-way bounce-back, moving-wall term) and a circle shape, only so
the window has something to show while the real modules are written elsewhere.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from solver.backend import Solver
from solver.lattice import C, OPP, W, equilibrium


@dataclass(frozen=True)
class StandInCircle:
    x: float = 0.0
    y: float = 0.0
    angle: float = 0.0
    diameter: float = 20.0
    kind = "cylinder"

    def moved(self, x=None, y=None, angle=None):
        return StandInCircle(self.x if x is None else x, self.y if y is None else y,
                             self.angle if angle is None else angle, self.diameter)

    def contains(self, px, py):
        return (px - self.x) ** 2 + (py - self.y) ** 2 <= (self.diameter / 2) ** 2

    def outline(self):
        t = np.linspace(0, 2 * np.pi, 65)
        return np.c_[self.x + self.diameter / 2 * np.cos(t + self.angle), self.y + self.diameter / 2 * np.sin(t + self.angle)]

    def bounding_box(self):
        r = self.diameter / 2
        return (self.x - r, self.y - r, self.x + r, self.y + r)

    def frontal_area(self, flow_direction):
        return self.diameter

    def validate(self, nx=None, ny=None):
        return self

    def to_dict(self):
        return {"kind": "cylinder", "x": self.x, "y": self.y, "angle": self.angle, "diameter": self.diameter}


class StandInSolver(Solver):
    name = "standin"

    def __init__(self, config, **_):
        super().__init__(config)
        c = self.config
        self.f = equilibrium(np.ones((c.ny, c.nx)), np.zeros((c.ny, c.nx)), np.zeros((c.ny, c.nx))).astype(np.float64)
        self.solid = np.zeros((c.ny, c.nx), bool)
        self.v = (0.0, 0.0)
        self._models = []
        self._force = (0.0, 0.0)
        self._yy, self._xx = np.mgrid[0:c.ny, 0:c.nx].astype(float)

    def set_body(self, shape, velocity=(0.0, 0.0), omega=0.0):
        self.solid = np.zeros_like(self.solid) if shape is None else shape.contains(self._xx, self._yy)
        self.v = velocity

    def enable_force_models(self, names):
        self._models = list(names)

    def forces(self):
        return {m: self._force for m in self._models}

    def distributions(self):
        return self.f.copy()

    def set_distributions(self, f):
        self.f = np.array(f, dtype=np.float64)

    def step(self, n=1):
        c = self.config
        omega = 1.0 / c.tau
        fx = fy = 0.0
        for _ in range(n):
            t = self.time
            ramp = 0.5 * (1 - np.cos(np.pi * t / c.inflow_ramp_steps)) if t < c.inflow_ramp_steps else 1.0
            u_in = c.inflow_speed * ramp
            f = self.f
            fin = np.empty_like(f)
            for i in range(9):
                fin[i] = np.roll(f[i], (C[i, 1], C[i, 0]), axis=(0, 1))
            # walls (y), inlet/outlet (x), body: half-way bounce-back
            for i in range(9):
                cx, cy = C[i]
                ib = OPP[i]
                if cy == 1:
                    fin[i, 0] = f[ib, 0]
                if cy == -1:
                    fin[i, -1] = f[ib, -1]
                if cx == 1:
                    fin[i, :, 0] = f[ib, :, 0] + 6 * W[i] * cx * u_in
                if cx == -1:
                    fin[i, :, -1] = f[i, :, -1]
                src_solid = np.roll(self.solid, (cy, cx), axis=(0, 1)) & ~self.solid
                bb = f[ib][src_solid] + 6 * W[i] * (cx * self.v[0] + cy * self.v[1])
                fin[i][src_solid] = bb
                fx += -cx * (f[ib][src_solid] + bb).sum()
                fy += -cy * (f[ib][src_solid] + bb).sum()
            rho = fin.sum(0)
            ux = (fin * C[:, 0, None, None]).sum(0) / rho
            uy = (fin * C[:, 1, None, None]).sum(0) / rho
            feq = equilibrium(rho, ux, uy)
            self.f = fin - omega * (fin - feq)
            self.f[:, self.solid] = equilibrium(np.ones(1), np.full(1, self.v[0]), np.full(1, self.v[1]))
            self.time += 1
        self._force = (fx / n, fy / n)
