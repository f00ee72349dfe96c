"""The contract every body shape fulfils (geometry in lattice units, angles in radians, CCW).

Implemented by `shapes/cylinder.py` and `shapes/polygon.py`; rasterised by `shapes/raster.py`.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, replace

import numpy as np


class ShapeError(ValueError):
    """Invalid geometry; the message names the problem (one line, for a user)."""


@dataclass(frozen=True)
class Shape(ABC):
    """A rigid body at a pose: reference point (x, y) in lattice units and rotation angle."""

    x: float = 0.0
    y: float = 0.0
    angle: float = 0.0

    kind = "abstract"

    def moved(self, x: float | None = None, y: float | None = None, angle: float | None = None) -> "Shape":
        """The same body at another pose."""
        return replace(self, x=self.x if x is None else x, y=self.y if y is None else y,
                       angle=self.angle if angle is None else angle)

    @abstractmethod
    def contains(self, px: np.ndarray, py: np.ndarray) -> np.ndarray:
        """Boolean array: which points lie inside the body (boundary points count as inside)."""

    @abstractmethod
    def segment_hit(self, px, py, dx, dy) -> np.ndarray:
        """For segments p -> p + d (arrays), the fraction t in (0, 1] of the first crossing of the
        body's boundary, or 0 where the segment does not meet it. Points p are outside the body."""

    @abstractmethod
    def outline(self) -> np.ndarray:
        """(k, 2) closed polygon of the boundary in world coordinates, for drawing."""

    @abstractmethod
    def frontal_area(self, flow_direction) -> float:
        """Width of the body seen along `flow_direction` (2D: area per unit span)."""

    @abstractmethod
    def surface_elements(self, spacing: float = 0.5):
        """(points (k,2), outward unit normals (k,2), lengths (k,)) covering the boundary."""

    @abstractmethod
    def bounding_box(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) in world coordinates."""

    @abstractmethod
    def validate(self, nx: int | None = None, ny: int | None = None) -> "Shape":
        """Raise ShapeError naming the problem; return self when valid (inside the domain if nx, ny)."""

    @abstractmethod
    def to_dict(self) -> dict:
        """JSON-ready description; `shapes.from_dict` reverses it."""


@dataclass(frozen=True)
class BodyRaster:
    """A shape on the lattice (docs/algorithm.md, 'Links cut by the body').

    solid: bool (ny, nx), nodes inside the body.
    q: (9, ny, nx) float64, cut fraction in (0, 1] of the link from fluid node x along c_i, 0 if uncut.
    window: (x0, y0, x1, y1) half-open index box containing every solid node and cut link.
    """

    solid: np.ndarray
    q: np.ndarray
    window: tuple[int, int, int, int]
