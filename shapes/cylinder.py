"""A circular cylinder of given diameter; reference point = centre.

Cut fractions are exact: the link p + t d meets the circle |x - c| = R at the smaller root of
|p - c + t d|^2 = R^2 (Bouzidi, Firdaouss & Lallemand 2001 need the true wall distance).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from feelflow.shapes.base import Shape
from feelflow.shapes.validation import (check_extent, check_in_domain, check_pose, finite_number, positive_number,
                               unit_direction)

#: a link whose chord through the circle is shorter than GRAZE times the radius only touches it
GRAZE = 1e-6


@dataclass(frozen=True, init=False)
class Cylinder(Shape):
    """Circle of `diameter` cells centred at (x, y); `angle` only turns the drawn outline."""

    diameter: float = 1.0

    kind = "cylinder"

    def __init__(self, diameter, x=0.0, y=0.0, angle=0.0):
        object.__setattr__(self, "diameter", positive_number("cylinder diameter", diameter))
        for name, value in (("x", x), ("y", y), ("angle", angle)):
            object.__setattr__(self, name, finite_number(f"cylinder {name}", value))

    @property
    def radius(self) -> float:
        return 0.5 * self.diameter

    def reference_length(self) -> float:
        return float(self.diameter)

    def contains(self, px, py):
        px = np.asarray(px, dtype=np.float64)
        py = np.asarray(py, dtype=np.float64)
        return (px - self.x) ** 2 + (py - self.y) ** 2 <= self.radius ** 2

    def boundary_distance(self, px, py):
        """Unsigned distance from points to the circle."""
        px = np.asarray(px, dtype=np.float64)
        py = np.asarray(py, dtype=np.float64)
        return np.abs(np.hypot(px - self.x, py - self.y) - self.radius)

    def segment_hit(self, px, py, dx, dy):
        rx = np.asarray(px, dtype=np.float64) - self.x
        ry = np.asarray(py, dtype=np.float64) - self.y
        dx = np.asarray(dx, dtype=np.float64)
        dy = np.asarray(dy, dtype=np.float64)
        a = dx * dx + dy * dy
        half_b = rx * dx + ry * dy            # b/2; approaching the circle when negative
        c = rx * rx + ry * ry - self.radius ** 2  # > 0: p outside
        disc = half_b * half_b - a * c
        # a link that only grazes the circle (a chord shorter than GRAZE r, within the rounding of
        # a tangent row's disc = 0) is not cut: rounding would cut it on some steps and not on
        # others as the body moves, and each flip puts a whole population into the force
        ok = (half_b < 0.0) & (disc > (GRAZE * self.radius) ** 2 * a * a) & (c > 0.0)
        with np.errstate(invalid="ignore", divide="ignore"):
            # smaller root t = (-b/2 - sqrt(disc)) / a, written stably as c / (-b/2 + sqrt(disc))
            t = c / (-half_b + np.sqrt(np.where(ok, disc, 0.0)))
        ok &= (t > 0.0) & (t <= 1.0)
        return np.where(ok, t, 0.0)

    def _n_outline(self, spacing: float) -> int:
        return max(16, int(math.ceil(math.pi * self.diameter / spacing)))

    def outline(self) -> np.ndarray:
        k = self._n_outline(0.5)
        phi = self.angle + np.linspace(0.0, 2.0 * math.pi, k + 1)
        return np.column_stack([self.x + self.radius * np.cos(phi), self.y + self.radius * np.sin(phi)])

    def frontal_area(self, flow_direction) -> float:
        unit_direction(flow_direction)
        return self.diameter

    def surface_elements(self, spacing: float = 0.5):
        """k equal arcs: arc midpoints, radial normals, arc lengths (sum = pi D exactly)."""
        spacing = positive_number("surface element spacing", spacing)
        k = self._n_outline(spacing)
        phi = self.angle + (np.arange(k) + 0.5) * (2.0 * math.pi / k)
        normals = np.column_stack([np.cos(phi), np.sin(phi)])
        points = np.array([self.x, self.y]) + self.radius * normals
        lengths = np.full(k, math.pi * self.diameter / k)
        return points, normals, lengths

    def bounding_box(self):
        r = self.radius
        return (self.x - r, self.y - r, self.x + r, self.y + r)

    def validate(self, nx=None, ny=None):
        check_pose(self)
        positive_number("cylinder diameter", self.diameter)
        check_extent(self)
        check_in_domain(self, nx, ny)
        return self

    def to_dict(self) -> dict:
        return {"kind": self.kind, "diameter": self.diameter, "x": self.x, "y": self.y, "angle": self.angle}
