"""Put a shape on the lattice: solid mask, exact cut fractions q, and the window around them.

docs/science/algorithm.md, 'Links cut by the body': q[i, y, x] in (0, 1] is the fraction of the link
x -> x + c_i up to its first crossing of the true boundary (Bouzidi et al. 2001), for every fluid
node x whose link meets the boundary, including links whose both ends are fluid (thin plates).
Only nodes within sqrt(2) of the boundary can own a cut link, so only those are tested, and only
inside the body's bounding box grown by one cell: the cost grows with the perimeter, not the grid.
"""
from __future__ import annotations

import math

import numpy as np

from feelflow.shapes.base import BodyRaster, Shape
from feelflow.shapes.polygon import BOUNDARY_TOLERANCE, PolygonalShape, edge_crossing_x, edge_distance, link_edge_hit

#: D2Q9 velocities in the order of solver/lattice.py (shapes may not import solver, see
#: pyproject's import contract; tests/test_shapes_raster.py checks the two agree).
LINKS = np.array([[0, 0], [1, 0], [0, 1], [-1, 0], [0, -1], [1, 1], [-1, 1], [-1, -1], [1, -1]],
                 dtype=np.int64)
_BAND = math.sqrt(2.0) + 1e-9
#: node offsets around a boundary piece (length <= 1) that can own a link crossing it:
#: |node - piece midpoint| <= sqrt(2) + 1/2 < 2, so floor(midpoint) + (-2 .. 3) covers them
_STENCIL = np.arange(-2, 4)


def distinct_sorted(keys: np.ndarray) -> np.ndarray:
    """The distinct values of an integer array, sorted (flattened): what np.unique returns, by
    sorting and dropping repeats, which numpy 2.4 does much faster on the few thousand keys of
    a move (the raster's (edge, node) pairs, the force models' stencils, the gl link list)."""
    flat = np.sort(keys, axis=None)
    first = np.ones(flat.size, dtype=bool)
    first[1:] = flat[1:] != flat[:-1]
    return flat[first]


def rasterise(shape: Shape, nx: int, ny: int, margin: int = 2) -> BodyRaster:
    """Solid mask, cut fractions and window of `shape` on an nx x ny lattice (node (ix, iy) at
    position (ix, iy)); work and storage are confined to the body's bounding box grown by one
    cell (BodyRaster.box)."""
    xmin, ymin, xmax, ymax = shape.bounding_box()
    x0, y0 = max(0, math.floor(xmin) - 1), max(0, math.floor(ymin) - 1)
    x1, y1 = min(nx, math.ceil(xmax) + 2), min(ny, math.ceil(ymax) + 2)
    if x0 >= x1 or y0 >= y1:  # entirely outside the lattice
        return BodyRaster(np.zeros((0, 0), bool), np.zeros((len(LINKS), 0, 0)), (0, 0, 0, 0), (nx, ny), (0, 0, 0, 0))

    box = (x0, y0, x1, y1)
    if isinstance(shape, PolygonalShape):
        box_solid, box_q = _polygon_box(shape, box)
    else:
        box_solid, box_q = _generic_box(shape, box)
    _cut_every_link_into_solid(box_solid, box_q)
    return BodyRaster(box_solid, box_q, box, (nx, ny), _window(box_solid, box_q, box, nx, ny, margin))


def _generic_box(shape: Shape, box):
    """Any Shape: classify the box's nodes, test the links of fluid nodes near the boundary."""
    x0, y0, x1, y1 = box
    gx, gy = np.meshgrid(np.arange(x0, x1, dtype=np.float64), np.arange(y0, y1, dtype=np.float64))
    box_solid = shape.contains(gx, gy)
    candidates = ~box_solid
    near = getattr(shape, "boundary_distance", None)
    if near is not None:
        candidates &= near(gx, gy) <= _BAND
    fy, fx = np.nonzero(candidates)
    d = np.repeat(np.arange(1, len(LINKS)), fx.size)
    sx, sy = np.tile(fx, len(LINKS) - 1), np.tile(fy, len(LINKS) - 1)
    t = shape.segment_hit(sx + x0, sy + y0, LINKS[d, 0], LINKS[d, 1])
    box_q = np.zeros((len(LINKS), y1 - y0, x1 - x0))
    box_q[d, sy, sx] = t
    return box_solid, box_q


def _polygon_box(shape: PolygonalShape, box):
    """Polygons: scanline parity for the interior, and link/edge tests only between each boundary
    piece and the nodes of its stencil. Same arithmetic as contains()/segment_hit(), so the
    result equals theirs exactly (tests/test_shapes_raster.py compares them)."""
    x0, y0, x1, y1 = box
    h, w = y1 - y0, x1 - x0
    a, e = shape.world_edges
    ax, ay, ex, ey = a[:, 0], a[:, 1], e[:, 0], e[:, 1]

    # interior: node ix is inside when an odd number of crossings lie at x > ix on its row
    rows = np.arange(y0, y1, dtype=np.float64)[:, None]
    straddle, xcross = edge_crossing_x(rows, ax, ay, ex, ey)
    r, k = np.nonzero(straddle)
    last = np.clip(np.ceil(xcross[r, k]).astype(np.int64) - 1 - x0, -1, w - 1)  # nodes j <= last
    keep = last >= 0
    counts = np.bincount(r[keep] * w + last[keep], minlength=h * w).reshape(h, w)
    box_solid = (np.cumsum(counts[:, ::-1], axis=1)[:, ::-1] % 2) == 1

    # nodes near each boundary piece (edge index repeated over the stencil)
    edge, mid, _ = shape.edge_pieces(1.0)
    bx = np.floor(mid[:, 0]).astype(np.int64) - x0
    by = np.floor(mid[:, 1]).astype(np.int64) - y0
    jx = (bx[:, None, None] + _STENCIL[None, None, :]).repeat(len(_STENCIL), axis=1).ravel()
    jy = (by[:, None, None] + _STENCIL[None, :, None]).repeat(len(_STENCIL), axis=2).ravel()
    edge = np.repeat(edge, len(_STENCIL) ** 2)
    ok = (jx >= 0) & (jx < w) & (jy >= 0) & (jy < h)
    # a node lies in the stencils of several pieces of the same edge: test each (edge, node) once
    pair = distinct_sorted((edge[ok] * h + jy[ok]) * w + jx[ok])
    edge, rest = np.divmod(pair, h * w)
    jy, jx = np.divmod(rest, w)
    px, py = (jx + x0).astype(np.float64), (jy + y0).astype(np.float64)

    # boundary points count as inside; only nodes within sqrt(2) of an edge can cut it
    dist = edge_distance(px, py, ax[edge], ay[edge], ex[edge], ey[edge])
    on_edge = dist <= BOUNDARY_TOLERANCE
    box_solid[jy[on_edge], jx[on_edge]] = True

    # links of fluid nodes against the edges near them; the first crossing wins
    fluid = ~box_solid[jy, jx] & (dist <= _BAND)
    jx, jy, edge, px, py = jx[fluid], jy[fluid], edge[fluid], px[fluid], py[fluid]
    n = len(LINKS) - 1
    d = np.repeat(np.arange(1, len(LINKS)), jx.size)
    edge8 = np.tile(edge, n)
    t = link_edge_hit(np.tile(px, n), np.tile(py, n), LINKS[d, 0], LINKS[d, 1],
                      ax[edge8], ay[edge8], ex[edge8], ey[edge8])
    hit = np.isfinite(t)
    first = np.full((len(LINKS), h, w), np.inf)
    np.minimum.at(first, (d[hit], np.tile(jy, n)[hit], np.tile(jx, n)[hit]), np.minimum(t[hit], 1.0))
    return box_solid, np.where(np.isfinite(first), first, 0.0)


def _cut_every_link_into_solid(box_solid, box_q) -> None:
    """A fluid -> solid link always crosses the boundary; if round-off at a vertex lost the
    crossing, put the wall at the solid node (q = 1)."""
    h, w = box_solid.shape
    pad = np.zeros((h + 2, w + 2), dtype=bool)  # beyond the box (grown by a cell) all is fluid
    pad[1:-1, 1:-1] = box_solid
    target = np.stack([pad[1 + cy:1 + cy + h, 1 + cx:1 + cx + w] for cx, cy in LINKS[1:]])
    lost = ~box_solid & target & (box_q[1:] <= 0.0)  # lost[i - 1]: x fluid, x + c_i solid, no cut
    if lost.any():
        box_q[1:][lost] = 1.0


def _window(box_solid, box_q, box, nx, ny, margin):
    """Half-open index box holding every solid node and both ends of every cut link, plus margin."""
    x0, y0 = box[0], box[1]
    d, ys, xs = np.nonzero(box_q)
    sy, sx = np.nonzero(box_solid)
    allx = np.concatenate([xs, xs + LINKS[d, 0], sx])
    ally = np.concatenate([ys, ys + LINKS[d, 1], sy])
    if allx.size == 0:
        return (0, 0, 0, 0)
    return (max(0, int(allx.min()) + x0 - margin), max(0, int(ally.min()) + y0 - margin),
            min(nx, int(allx.max()) + x0 + 1 + margin), min(ny, int(ally.max()) + y0 + 1 + margin))
