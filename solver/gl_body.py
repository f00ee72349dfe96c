"""The body as the gl backend's step shader sees it: a node mask and the link fractions q.

The step's BODY variant applies, per cut link (x, ib) of a fluid node x, the interpolated
bounce-back of Bouzidi, Firdaouss & Lallemand (Phys. Fluids 13 (2001) 3452) with the
moving-wall term, the same rule as solver/bouzidi.py, and gives every solid node the
equilibrium at the body's velocity. It reads per node:
- MASK (R32UI): bit 0 solid; bit i (1..8) when q[OPP[i], x] > 0 (the link from x along c_ib
  crosses the wall, so f_i^in(x) comes from the wall rule); bit 8+i when that link takes the
  two-node interpolation;
- QA, QB (RGBA32F): q[1..4, x] and q[5..8, x].
They are written at a move only, and only over the union of the old and new body windows; the
wall velocity comes from uniforms (velocity, angular velocity, centre).
"""
from __future__ import annotations

import numpy as np

from feelflow.solver.lattice import OPP, Q


def node_mask(solid: np.ndarray, q: np.ndarray, box, links=None, window=None) -> np.ndarray:
    """The shader's node mask over box (x0, y0, x1, y1), uint32 (h, w), from `solid` (h, w) and
    `q` (9, h, w) cut to that box (BodyRaster.crop).

    bit 0: solid; bit i (1..8): q[OPP[i], x] > 0 (the wall rule gives f_i^in); bit 8+i: the link
    takes the two-node interpolation (q < 1/2 and a fluid second node x + c_i): set from the
    body's `links` (solver.bouzidi, built on the force `window` (x0, y0, ...)), so that both
    backends make the same choice, across a periodic seam too (the shader takes the second
    node's population as streamed, which wraps there).
    """
    x0, y0, x1, y1 = box
    cut = (q[OPP[1:]] > 0) & ~solid  # cut[i - 1]: bit i
    mask = solid.astype(np.uint32) | np.bitwise_or.reduce(
        cut.astype(np.uint32) << np.arange(1, Q, dtype=np.uint32)[:, None, None], axis=0)
    if links is not None and len(links):
        two = links.b != 0
        ys, xs = links.iy[two] + window[1] - y0, links.ix[two] + window[0] - x0
        inside = (ys >= 0) & (ys < y1 - y0) & (xs >= 0) & (xs < x1 - x0)
        bits = np.left_shift(np.uint32(1), (8 + links.i[two][inside]).astype(np.uint32))
        np.bitwise_or.at(mask, (ys[inside], xs[inside]), bits)
    return mask


def upload_raster(mask_tex, qa_tex, qb_tex, body, box) -> None:
    """Node mask and q of `body` (None: no body) over box (x0, y0, x1, y1), into their textures."""
    x0, y0, x1, y1 = box
    h, w = y1 - y0, x1 - x0
    if body is None:
        mask = np.zeros((h, w), np.uint32)
        q = np.zeros((Q, h, w), np.float32)
    else:
        solid, q = body.raster.crop(box)
        mask = node_mask(solid, q, box, body.links, body.window)
        q = q.astype(np.float32)
    viewport = (x0, y0, w, h)
    mask_tex.write(np.ascontiguousarray(mask).tobytes(), viewport=viewport)
    qa_tex.write(np.ascontiguousarray(np.moveaxis(q[1:5], 0, -1)).tobytes(), viewport=viewport)
    qb_tex.write(np.ascontiguousarray(np.moveaxis(q[5:9], 0, -1)).tobytes(), viewport=viewport)
