"""Put a shape on the lattice: solid mask, exact cut fractions q, and the window around them.

docs/algorithm.md, 'Links cut by the body': q[i, y, x] in (0, 1] is the fraction of the link
x -> x + c_i up to its first crossing of the true boundary (Bouzidi et al. 2001), for every fluid
node x whose link meets the boundary, including links whose both ends are fluid (thin plates).
Only nodes within sqrt(2) of the boundary can own a cut link, so only those are tested.
"""
from __future__ import annotations

import math

import numpy as np

from shapes.base import BodyRaster, Shape

#: D2Q9 velocities in the order of solver/lattice.py (shapes may not import solver, see
#: pyproject's import contract; tests/test_shapes_raster.py checks the two agree).
LINKS = np.array([[0, 0], [1, 0], [0, 1], [-1, 0], [0, -1], [1, 1], [-1, 1], [-1, -1], [1, -1]],
                 dtype=np.int64)
_BAND = math.sqrt(2.0) + 1e-9


def rasterise(shape: Shape, nx: int, ny: int, margin: int = 2) -> BodyRaster:
    """Solid mask, cut fractions and window of `shape` on an nx x ny lattice (node (ix, iy) at
    position (ix, iy)); work is confined to the body's bounding box grown by one cell."""
    solid = np.zeros((ny, nx), dtype=bool)
    q = np.zeros((len(LINKS), ny, nx), dtype=np.float64)
    xmin, ymin, xmax, ymax = shape.bounding_box()
    x0, y0 = max(0, math.floor(xmin) - 1), max(0, math.floor(ymin) - 1)
    x1, y1 = min(nx, math.ceil(xmax) + 2), min(ny, math.ceil(ymax) + 2)
    if x0 >= x1 or y0 >= y1:  # entirely outside the lattice
        return BodyRaster(solid=solid, q=q, window=(0, 0, 0, 0))

    gx, gy = np.meshgrid(np.arange(x0, x1, dtype=np.float64), np.arange(y0, y1, dtype=np.float64))
    box_solid = shape.contains(gx, gy)
    solid[y0:y1, x0:x1] = box_solid

    fluid = ~box_solid
    near = getattr(shape, "boundary_distance", None)
    if near is not None:
        fluid &= near(gx, gy) <= _BAND
    fy, fx = np.nonzero(fluid)                       # box-relative indices of candidate nodes
    links = LINKS[1:]
    cx = np.repeat(links[:, 0], fx.size)
    cy = np.repeat(links[:, 1], fx.size)
    sx = np.tile(fx, len(links))
    sy = np.tile(fy, len(links))
    t = shape.segment_hit(sx + x0, sy + y0, cx, cy)

    # every fluid -> solid link is cut: round-off at a vertex must not lose one
    tx, ty = sx + cx, sy + cy
    inside = (tx >= 0) & (tx < x1 - x0) & (ty >= 0) & (ty < y1 - y0)
    to_solid = np.zeros_like(inside)
    to_solid[inside] = box_solid[ty[inside], tx[inside]]
    t = np.where(to_solid & (t <= 0.0), 1.0, t)

    cut = t > 0.0
    idir = np.repeat(np.arange(1, len(LINKS)), fx.size)
    q[idir[cut], sy[cut] + y0, sx[cut] + x0] = t[cut]

    # window: every solid node and both ends of every cut link, plus margin
    xs = [sx[cut], tx[cut]]
    ys = [sy[cut], ty[cut]]
    sy_all, sx_all = np.nonzero(box_solid)
    xs.append(sx_all)
    ys.append(sy_all)
    allx = np.concatenate(xs)
    ally = np.concatenate(ys)
    if allx.size == 0:
        return BodyRaster(solid=solid, q=q, window=(0, 0, 0, 0))
    window = (max(0, int(allx.min()) + x0 - margin), max(0, int(ally.min()) + y0 - margin),
              min(nx, int(allx.max()) + x0 + 1 + margin), min(ny, int(ally.max()) + y0 + 1 + margin))
    return BodyRaster(solid=solid, q=q, window=window)
