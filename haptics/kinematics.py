"""Kinematics of the Haply 2DIY five-bar pantograph (two motors on one axis, d = 0).

Geometry (Haply hAPI `Pantograph`, 2DIY generation 2): proximal links l = 0.07 m, distal links
L = 0.09 m, motor spacing d = 0. Motor 1 drives the right proximal link to A = (l cos th1,
l sin th1); motor 2 the left one to B = (d + l cos th2, l sin th2); the handle E is where the two
distal links meet, on the far side (larger y). Angles in the hAPI convention: degrees on the wire,
radians here. Derivation of the Jacobian (our own, checked against finite differences in the
tests): differentiating |E - A|^2 = L^2 and |E - B|^2 = L^2 gives
    [(E - A)^T; (E - B)^T] dE = diag((E - A).dA/dth1, (E - B).dB/dth2) dth,
so J = M^-1 D and the motor torques for a handle force F are tau = J^T F (virtual work).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


class OutOfReach(ValueError):
    """The pose cannot be reached by the linkage."""


@dataclass(frozen=True)
class Pantograph:
    l: float = 0.07  # proximal link, metres
    L: float = 0.09  # distal link, metres
    d: float = 0.0  # distance between the motor axes, metres

    def elbows(self, th1: float, th2: float):
        a = np.array([self.l * math.cos(th1), self.l * math.sin(th1)])
        b = np.array([self.d + self.l * math.cos(th2), self.l * math.sin(th2)])
        return a, b

    def forward(self, th1: float, th2: float) -> tuple[float, float]:
        """Handle position (x, y) in metres for motor angles in radians."""
        a, b = self.elbows(th1, th2)
        mid = 0.5 * (a + b)
        ab = b - a
        dist = float(np.hypot(*ab))
        if dist < 1e-12 or dist > 2 * self.L:
            raise OutOfReach(f"elbows {dist:.4f} m apart: no pose")
        h = math.sqrt(max(self.L ** 2 - (dist / 2) ** 2, 0.0))
        normal = np.array([-ab[1], ab[0]]) / dist
        e1, e2 = mid + h * normal, mid - h * normal
        e = e1 if e1[1] >= e2[1] else e2  # the far (larger y) branch, as hAPI picks
        return float(e[0]), float(e[1])

    def jacobian(self, th1: float, th2: float) -> np.ndarray:
        """dE/dth (2x2, metres per radian)."""
        a, b = self.elbows(th1, th2)
        e = np.array(self.forward(th1, th2))
        da = self.l * np.array([-math.sin(th1), math.cos(th1)])
        db = self.l * np.array([-math.sin(th2), math.cos(th2)])
        m = np.array([e - a, e - b])
        dmat = np.diag([(e - a) @ da, (e - b) @ db])
        return np.linalg.solve(m, dmat)

    def torques(self, th1: float, th2: float, fx: float, fy: float) -> tuple[float, float]:
        """Motor torques (N m) that make the handle push with force (fx, fy) newtons."""
        t = self.jacobian(th1, th2).T @ np.array([fx, fy])
        return float(t[0]), float(t[1])

    def force_from_torques(self, th1: float, th2: float, t1: float, t2: float) -> tuple[float, float]:
        """The handle force a pair of motor torques produces (inverse of `torques`)."""
        f = np.linalg.solve(self.jacobian(th1, th2).T, np.array([t1, t2]))
        return float(f[0]), float(f[1])

    def inverse(self, x: float, y: float) -> tuple[float, float]:
        """Motor angles (radians) that put the handle at (x, y): right elbow for motor 1,
        left elbow for motor 2 (the branch `forward` assumes)."""
        def elbow(cx: float, right: bool) -> float:
            px, py = x - cx, y
            r = math.hypot(px, py)
            if r < 1e-12 or r > self.l + self.L or r < abs(self.L - self.l):
                raise OutOfReach(f"({x:.4f}, {y:.4f}) m is out of reach")
            # angle at the motor between the line to E and the proximal link (law of cosines)
            gamma = math.acos((self.l ** 2 + r ** 2 - self.L ** 2) / (2 * self.l * r))
            base = math.atan2(py, px)
            return base - gamma if right else base + gamma
        return elbow(0.0, True), elbow(self.d, False)


#: The Haply 2DIY (generation 2) linkage.
HAPLY_2DIY = Pantograph()
