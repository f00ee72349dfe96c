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

    def reference_length(self) -> float:
        """The length a section's coefficients are referred to (the polar's C_L and C_D): the
        shape's own size where it has one (a cylinder's diameter, a plate's or wedge's length,
        an airfoil's chord), else the larger side of its bounding box."""
        x0, y0, x1, y1 = self.bounding_box()
        return float(max(x1 - x0, y1 - y0))

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
        """JSON-ready description; `feelflow.shapes.from_dict` reverses it."""


class BodyRaster:
    """A shape on the lattice (docs/science/algorithm.md, 'Links cut by the body').

    Held on `box` (x0, y0, x1, y1), the shape's bounding box grown by a cell and clipped to the
    grid: every solid node and every cut link lies in it, so a move costs the body's size, not
    the grid's. `crop(box)` cuts any window from it; `solid` and `q` are the full-grid arrays,
    built on first use (tests, file export), not on the solver's paths.

    solid: bool (ny, nx), nodes inside the body.
    q: (9, ny, nx) float64, cut fraction in (0, 1] of the link from fluid node x along c_i, 0 if uncut.
    window: (x0, y0, x1, y1) half-open index box containing every solid node and cut link.
    """

    def __init__(self, box_solid: np.ndarray, box_q: np.ndarray, box: tuple[int, int, int, int],
                 grid: tuple[int, int], window: tuple[int, int, int, int]):
        self.box_solid, self.box_q = box_solid, box_q
        self.box, self.grid, self.window = tuple(box), tuple(grid), tuple(window)
        self._full = None

    def crop(self, box) -> tuple[np.ndarray, np.ndarray]:
        """(solid (h, w) bool, q (9, h, w) float64) over box (x0, y0, x1, y1), zero outside `box`."""
        solid, (dst, src) = self._crop_solid(box)
        x0, y0, x1, y1 = box
        q = np.zeros((self.box_q.shape[0], y1 - y0, x1 - x0), dtype=np.float64)
        if dst is not None:
            q[(slice(None),) + dst] = self.box_q[(slice(None),) + src]
        return solid, q

    def crop_solid(self, box) -> np.ndarray:
        """The solid mask (h, w) alone over box, as crop(box)[0] (a move's refill needs no q)."""
        return self._crop_solid(box)[0]

    def _crop_solid(self, box):
        """(solid over box, (dst, src) slices of the overlap with self.box, or (None, None))."""
        x0, y0, x1, y1 = box
        solid = np.zeros((y1 - y0, x1 - x0), dtype=bool)
        bx0, by0, bx1, by1 = self.box
        ox0, oy0, ox1, oy1 = max(x0, bx0), max(y0, by0), min(x1, bx1), min(y1, by1)
        if not (ox0 < ox1 and oy0 < oy1):
            return solid, (None, None)
        dst = (slice(oy0 - y0, oy1 - y0), slice(ox0 - x0, ox1 - x0))
        src = (slice(oy0 - by0, oy1 - by0), slice(ox0 - bx0, ox1 - bx0))
        solid[dst] = self.box_solid[src]
        return solid, (dst, src)

    def _full_arrays(self):
        if self._full is None:
            nx, ny = self.grid
            self._full = self.crop((0, 0, nx, ny))
        return self._full

    @property
    def solid(self) -> np.ndarray:
        return self._full_arrays()[0]

    @property
    def q(self) -> np.ndarray:
        return self._full_arrays()[1]
