"""Reading the fluid state of a `BodyWindow` at points that are not nodes.

Two ways, one per need:
- `bilinear`: plain bilinear interpolation of a node field (the macroscopic model samples the
  velocity on a contour a few cells off the wall, where every stencil node is fluid).
- `fluid_extrapolate`: a weighted least-squares linear fit to the *fluid* nodes around a point,
  evaluated at the point (the pressure model needs the density on the wall itself, where a
  bilinear stencil would mix in solid nodes, which hold rho_0 and not the fluid's density).
  Moving least squares as in Lancaster & Salkauskas (1981); the linear fit makes the
  extrapolation exact for linear fields and second-order accurate for smooth ones.

Coordinates are lattice positions: node (ix, iy) sits at (ix, iy); window arrays are
[.., iy - y0, ix - x0] (solver/forces/base.py).
"""
from __future__ import annotations

import numpy as np

from solver.lattice import C


def moments(window):
    """(rho, ux, uy) of the window's populations f*(t), each (h, w) float64.

    Collision conserves rho and rho u (docs/algorithm.md), so these are the moments at t
    (up to the half body-force term, zero unless the scene sets a body force).
    """
    f = np.asarray(window.f, dtype=np.float64)
    rho = f.sum(axis=0)
    ux = np.tensordot(C[:, 0].astype(np.float64), f, axes=1) / rho
    uy = np.tensordot(C[:, 1].astype(np.float64), f, axes=1) / rho
    return rho, ux, uy


def _check_inside(window, ix, iy, what):
    h, w = window.solid.shape
    if ix.size and (ix.min() < 0 or iy.min() < 0 or ix.max() >= w or iy.max() >= h):
        raise ValueError(
            f"{what}: sample points reach outside the body window ({w}x{h} at {window.x0},{window.y0}); "
            "the backend must widen the window by the model's `margin`")


def bilinear(window, fields, px, py):
    """Bilinear interpolation of node fields at points (px, py) (world lattice coordinates).

    fields: sequence of (h, w) arrays on the window. Returns a list of (k,) arrays.
    """
    gx = np.asarray(px, dtype=np.float64) - window.x0
    gy = np.asarray(py, dtype=np.float64) - window.y0
    i0 = np.floor(gx).astype(np.int64)
    j0 = np.floor(gy).astype(np.int64)
    _check_inside(window, np.concatenate([i0, i0 + 1]), np.concatenate([j0, j0 + 1]), "bilinear")
    tx = gx - i0
    ty = gy - j0
    w00 = (1 - tx) * (1 - ty)
    w10 = tx * (1 - ty)
    w01 = (1 - tx) * ty
    w11 = tx * ty
    out = []
    for a in fields:
        out.append(w00 * a[j0, i0] + w10 * a[j0, i0 + 1] + w01 * a[j0 + 1, i0] + w11 * a[j0 + 1, i0 + 1])
    return out


def fluid_extrapolate(window, field, px, py, radius: float = 2.5):
    """Value of `field` at points (px, py) from a linear least-squares fit to the fluid nodes
    within `radius` of each point (weights (1 - r/radius)^2); solid nodes are never used.

    Points on the body surface thus get the fluid's value extrapolated to the wall. Where fewer
    than three non-collinear fluid nodes lie within the radius, the nearest fluid node's value is
    used instead.
    """
    px = np.asarray(px, dtype=np.float64)
    py = np.asarray(py, dtype=np.float64)
    fluid = ~np.asarray(window.solid, dtype=bool)
    r = int(np.ceil(radius))
    off = np.arange(-r, r + 2)
    ox, oy = np.meshgrid(off, off)
    ox = ox.ravel()
    oy = oy.ravel()
    bx = np.floor(px - window.x0).astype(np.int64)
    by = np.floor(py - window.y0).astype(np.int64)
    nx_ = bx[:, None] + ox[None, :]  # (k, m) window indices
    ny_ = by[:, None] + oy[None, :]
    _check_inside(window, nx_.ravel(), ny_.ravel(), "fluid_extrapolate")
    dx = nx_ + window.x0 - px[:, None]
    dy = ny_ + window.y0 - py[:, None]
    dist = np.hypot(dx, dy)
    wgt = np.where(fluid[ny_, nx_] & (dist < radius), (1.0 - dist / radius) ** 2, 0.0)
    vals = field[ny_, nx_]
    # normal equations of the weighted fit  v ~ a + b dx + c dy
    basis = np.stack([np.ones_like(dx), dx, dy], axis=-1)  # (k, m, 3)
    ata = np.einsum("km,kmi,kmj->kij", wgt, basis, basis)
    atb = np.einsum("km,kmi,km->ki", wgt, basis, vals)
    det = np.linalg.det(ata)
    ok = np.abs(det) > 1e-9
    result = np.empty(px.shape, dtype=np.float64)
    if ok.any():
        result[ok] = np.linalg.solve(ata[ok], atb[ok][..., None])[:, 0, 0]
    if (~ok).any():  # too few fluid nodes: nearest fluid node
        dmask = np.where(fluid[ny_, nx_], dist, np.inf)[~ok]
        pick = np.argmin(dmask, axis=1)
        result[~ok] = vals[~ok][np.arange(pick.size), pick]
    return result
