"""Tracers for the window's tracer view: massless particles carried by the flow's velocity
(explicit Euler over the frame's steps, the nearest node's velocity), restarted at the inlet
when they leave the tunnel or enter the body. Qt-free; the overlay draws what `advance` returns.
Lattice units (cells, cells per step)."""
from __future__ import annotations

import numpy as np

#: how far back a tracer's streak reaches (steps at its present velocity)
STREAK_STEPS = 30
#: tracers restart within this many cells of the inlet
RESTART_CELLS = 3.0


class Tracers:
    """`count` tracers with their own random stream (the same sequence on every run)."""

    def __init__(self, count: int, seed: int = 1):
        self.count = count
        self.rng = np.random.default_rng(seed)

    def advance(self, rgba, steps: int, shape=None, points=None):
        """Move `points` ((count, 2) cells; None or another count: scattered afresh over the
        tunnel) `steps` steps through the field `rgba` ((ny, nx, 4): rho, ux, uy, vorticity).
        Returns (points, tails): where they are and where they were STREAK_STEPS steps ago."""
        ny, nx = rgba.shape[:2]
        rng = self.rng
        if points is None or len(points) != self.count:
            points = np.c_[rng.uniform(0, nx - 1, self.count), rng.uniform(0, ny - 1, self.count)]
        ix = np.clip(np.rint(points[:, 0]).astype(int), 0, nx - 1)
        iy = np.clip(np.rint(points[:, 1]).astype(int), 0, ny - 1)
        u = rgba[iy, ix, 1:3].astype(float)
        pts = points + u * steps
        bad = (pts[:, 0] < 0) | (pts[:, 0] > nx - 1) | (pts[:, 1] < 0) | (pts[:, 1] > ny - 1) \
            | ~np.isfinite(pts).all(axis=1)
        if shape is not None:
            bad |= shape.contains(pts[:, 0], pts[:, 1])
        k = int(bad.sum())
        if k:
            pts[bad] = np.c_[rng.uniform(0, RESTART_CELLS, k), rng.uniform(0, ny - 1, k)]
        return pts, pts - u * STREAK_STEPS
