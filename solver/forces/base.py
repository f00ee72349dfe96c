"""The interface every force model shares: a model sees only the body's neighbourhood.

Both backends hand the same `BodyWindow` (numpy arrays) to the same model code, so forces agree
between backends by construction (docs/science/algorithm.md, 'Forces'). The one exception: where the
momentum exchanges are the only models, the gl backend sums their links on the GPU
(shaders/link_sums.glsl) to the same formulas; a test holds it to the window's numbers.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from feelflow.solver.config import FlowConfig


@dataclass
class BodyWindow:
    """The state around the body at the start of a step (before t -> t+1).

    x0, y0: grid index of the window's lower-left node; arrays are [.., iy - y0, ix - x0].
    f: (9, h, w) full post-collision populations f*(t), float64.
    solid, q: the body raster cut to the window (q as in shapes.BodyRaster).
    shape: the body (a shapes.Shape at its current pose); velocity (vx, vy); omega.
    impulse: (Jx, Jy) cover/uncover momentum booked for this step.
    config: the flow configuration (inflow, viscosity, boundaries).
    links: the window's Bouzidi body links (solver.bouzidi.BodyLinks) when the backend has
        them already, else None (models build them with solver.bouzidi.build_links).
    fluid_in_domain: (h, w) bool, True for fluid nodes (False for solid and nothing else:
        the window never extends outside the domain; the body is kept away from its edges).
    """

    x0: int
    y0: int
    f: np.ndarray
    solid: np.ndarray
    q: np.ndarray
    shape: object
    velocity: tuple[float, float]
    omega: float
    impulse: tuple[float, float]
    config: FlowConfig
    links: object = None

    @property
    def fluid(self) -> np.ndarray:
        return ~self.solid


class ForceModel(ABC):
    """A way to compute the force of the fluid on the body, lattice units per step."""

    name: str = "abstract"
    description: str = ""

    @abstractmethod
    def compute(self, window: BodyWindow) -> tuple[float, float]:
        """(F_x, F_y) on the body for this step."""

    def torque(self, window: BodyWindow) -> float:
        """The torque of the fluid on the body about its centre (shape.x, shape.y), counter-
        clockwise positive, lattice units per step; a model without a moment gives 0."""
        return 0.0

    def evaluate(self, window: BodyWindow) -> tuple[float, float, float]:
        """(F_x, F_y, torque) for this step: what the backends call each step (a model that
        shares work between its force and its torque overrides it)."""
        fx, fy = self.compute(window)
        return fx, fy, self.torque(window)
