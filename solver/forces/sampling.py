"""Reading the fluid state of a `BodyWindow` at points that are not nodes.

Two ways, one per need:
- `bilinear_stencil`: plain bilinear interpolation of a node field (the macroscopic model samples
  the velocity on a contour a few cells off the wall, where every stencil node is fluid).
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

from feelflow.shapes.raster import distinct_sorted
from feelflow.solver.lattice import C


def moments(window):
    """(rho, ux, uy) of the window's populations f*(t), each (h, w) float64.

    Collision conserves rho and rho u (docs/science/algorithm.md), so these are the moments at t
    (up to the half body-force term, zero unless the scene sets a body force).
    """
    f = np.asarray(window.f, dtype=np.float64)
    rho = f.sum(axis=0)
    per = window.config.velocity_divisor(rho)
    ux = np.tensordot(C[:, 0].astype(np.float64), f, axes=1) / per
    uy = np.tensordot(C[:, 1].astype(np.float64), f, axes=1) / per
    return rho, ux, uy


def _inside(window, ix, iy):
    """Which window indices lie inside the window (it is clipped at the domain's edges, so a
    body near a wall can have sample points beyond it: those are left out, never wrapped)."""
    h, w = window.solid.shape
    return (ix >= 0) & (iy >= 0) & (ix < w) & (iy < h)


class Stencil:
    """Values at k points as fixed linear combinations of node values: v_k = sum_m coef[k, m] *
    field[idx[k, m]] (idx: flat indices into the window's (h, w) arrays). Built once per body
    pose, applied every step. `valid[k]` is False for a point the window could not serve (its
    value is then 0; callers leave it out)."""

    def __init__(self, idx: np.ndarray, coef: np.ndarray, valid: np.ndarray):
        self.idx = idx
        self.coef = coef
        self.valid = valid

    def apply(self, field_flat: np.ndarray) -> np.ndarray:
        return (field_flat[self.idx] * self.coef).sum(axis=1)

    def nodes(self) -> np.ndarray:
        """The distinct flat node indices the stencil reads (for gathering only those), sorted;
        once per move of the body."""
        return distinct_sorted(self.idx)


def bilinear_stencil(window, px, py) -> Stencil:
    """Bilinear interpolation at points (px, py) (world lattice coordinates)."""
    gx = np.asarray(px, dtype=np.float64) - window.x0
    gy = np.asarray(py, dtype=np.float64) - window.y0
    i0 = np.floor(gx).astype(np.int64)
    j0 = np.floor(gy).astype(np.int64)
    valid = _inside(window, i0, j0) & _inside(window, i0 + 1, j0 + 1)
    i0 = np.where(valid, i0, 0)
    j0 = np.where(valid, j0, 0)
    tx = gx - i0
    ty = gy - j0
    w = window.solid.shape[1]
    idx = np.stack([j0 * w + i0, j0 * w + i0 + 1, (j0 + 1) * w + i0, (j0 + 1) * w + i0 + 1], axis=1)
    coef = np.stack([(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty], axis=1) * valid[:, None]
    return Stencil(idx, coef, valid)


def fluid_fit_stencil(window, px, py, radius: float = 2.5) -> Stencil:
    """Value at points (px, py) from a linear least-squares fit to the fluid nodes within
    `radius` of each point (weights (1 - r/radius)^2); solid nodes are never used.

    Points on the body surface thus get the fluid's value extrapolated to the wall. Where fewer
    than three non-collinear fluid nodes lie within the radius, the nearest fluid node's value is
    used instead. The fit is linear in the node values, so it is a fixed stencil per pose.
    """
    px = np.asarray(px, dtype=np.float64)
    py = np.asarray(py, dtype=np.float64)
    fluid = ~np.asarray(window.solid, dtype=bool)
    h, w = fluid.shape
    r = int(np.ceil(radius))
    off = np.arange(-r, r + 2)
    ox, oy = np.meshgrid(off, off)
    ox = ox.ravel()
    oy = oy.ravel()
    bx = np.floor(px - window.x0).astype(np.int64)
    by = np.floor(py - window.y0).astype(np.int64)
    nx_ = bx[:, None] + ox[None, :]  # (k, m) window indices
    ny_ = by[:, None] + oy[None, :]
    inside = _inside(window, nx_, ny_)
    dx = nx_ + window.x0 - px[:, None]
    dy = ny_ + window.y0 - py[:, None]
    dist = np.hypot(dx, dy)
    nx_ = np.where(inside, nx_, 0)
    ny_ = np.where(inside, ny_, 0)
    is_fluid = fluid[ny_, nx_] & inside
    wgt = np.where(is_fluid & (dist < radius), (1.0 - dist / radius) ** 2, 0.0)
    # weighted fit v ~ a + b dx + c dy: a = e0 . (A^T W A)^-1 A^T W v
    basis = np.stack([np.ones_like(dx), dx, dy], axis=-1)  # (k, m, 3)
    ata = np.einsum("km,kmi,kmj->kij", wgt, basis, basis)
    det = np.linalg.det(ata)
    ok = np.abs(det) > 1e-9
    coef = np.zeros(dx.shape)
    if ok.any():
        row = np.linalg.solve(ata[ok], np.broadcast_to(np.array([1.0, 0.0, 0.0]), (int(ok.sum()), 3))[..., None])[..., 0]
        coef[ok] = np.einsum("ki,kmi->km", row, basis[ok]) * wgt[ok]
    valid = ok | is_fluid.any(axis=1)
    if (~ok).any():  # too few fluid nodes: nearest fluid node (none at all: not valid)
        pick = np.argmin(np.where(is_fluid, dist, np.inf)[~ok], axis=1)
        sub = np.zeros((int((~ok).sum()), dx.shape[1]))
        sub[np.arange(pick.size), pick] = valid[~ok]
        coef[~ok] = sub
    return Stencil(ny_ * w + nx_, coef, valid)


def fluid_extrapolate(window, field, px, py, radius: float = 2.5):
    """`fluid_fit_stencil` applied to one (h, w) field."""
    return fluid_fit_stencil(window, px, py, radius).apply(np.asarray(field).ravel())


def moments_at(window, nodes: np.ndarray):
    """(rho, ux, uy) as flat (h*w) arrays, computed only at the flat node indices `nodes`
    (elsewhere zero / one); far cheaper than the whole window's moments."""
    h, w = window.solid.shape
    f = np.asarray(window.f, dtype=np.float64).reshape(9, h * w)[:, nodes]
    rho = np.ones(h * w)
    ux = np.zeros(h * w)
    uy = np.zeros(h * w)
    r = f.sum(axis=0)
    rho[nodes] = r
    per = window.config.velocity_divisor(r)
    ux[nodes] = C[:, 0].astype(np.float64) @ f / per
    uy[nodes] = C[:, 1].astype(np.float64) @ f / per
    return rho, ux, uy
