"""Interpolated bounce-back on the body links (docs/science/algorithm.md, rule 1a).

Bouzidi, Firdaouss & Lallemand, Phys. Fluids 13 (2001) 3452, linear scheme, with the
moving-wall term of Lallemand & Luo, J. Comput. Phys. 184 (2003) 406 (seed eqs. 13-17).

`build_links` turns a window's q/solid into a flat list of body links with the coefficients of
    f_i^in(x) = a f*_ib(x) + b f*_ib(x + c_i) + c f*_i(x) + d
and `incoming` evaluates it on a window of f* (full f, or shifted g = f - w RHO0: a + b + c = 1,
so the same rule holds for g). The numpy backend's streaming and the momentum-exchange force both
call `incoming`, so both compute identical numbers.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from feelflow.solver.lattice import C, OPP, RHO0, W


@dataclass(frozen=True)
class BodyLinks:
    """Body links (x, ib) of a window: fluid node x whose link towards x + c_ib is cut.

    i: direction of the incoming population f_i^in(x); ib = OPP[i].
    iy, ix: window-local node of x; fy, fx: the second node x + c_i (x itself when unused).
    q: cut fraction q[ib, x]; uw: (n, 2) wall velocity at x + q c_ib.
    a, b, c, d: coefficients of the rule (d: moving-wall term, includes w_i RHO0).
    """

    i: np.ndarray
    ib: np.ndarray
    iy: np.ndarray
    ix: np.ndarray
    fy: np.ndarray
    fx: np.ndarray
    q: np.ndarray
    uw: np.ndarray
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray

    def __len__(self) -> int:
        return len(self.i)


def wall_velocity(px, py, center, velocity, omega):
    """Rigid-body velocity at points (px, py): (V_x - Omega (y - Y), V_y + Omega (x - X))."""
    cx, cy = center
    return (velocity[0] - omega * (np.asarray(py) - cy), velocity[1] + omega * (np.asarray(px) - cx))


def periodic_wrap(config, window) -> tuple[bool, bool]:
    """(x, y): whether the window (x0, y0, x1, y1) spans a periodic direction of the domain
    whole, so that a second node across the periodic seam is the window's other edge."""
    x0, y0, x1, y1 = window
    return (config.x_boundary == "periodic" and x0 == 0 and x1 == config.nx,
            config.y_boundary == "periodic" and y0 == 0 and y1 == config.ny)


def second_nodes(q: np.ndarray, solid: np.ndarray, i, iy, ix, wrap: tuple[bool, bool] = (False, False)):
    """The second node x + c_i of each link (i: incoming direction, (iy, ix): the fluid node x,
    window-local), wrapped across a periodic seam the window spans whole (`wrap`), and whether
    an interpolation may use it: inside the window, fluid, and its own link along c_ib not cut.
    Returns (fy, fx, usable)."""
    h, w = solid.shape
    fy, fx = iy + C[i, 1], ix + C[i, 0]
    if wrap[0]:
        fx = fx % w
    if wrap[1]:
        fy = fy % h
    inside = (fy >= 0) & (fy < h) & (fx >= 0) & (fx < w)
    fyc, fxc = np.clip(fy, 0, h - 1), np.clip(fx, 0, w - 1)
    return fy, fx, inside & ~solid[fyc, fxc] & (q[i, iy, ix] == 0)


def build_links(q: np.ndarray, solid: np.ndarray, x0: int, y0: int, center, velocity, omega,
                wrap: tuple[bool, bool] = (False, False)) -> BodyLinks:
    """All body links of a window (q: (9, h, w), solid: (h, w), lower-left node (x0, y0)).

    The window must reach one node beyond every cut link inside the domain: a second node
    outside the window counts as outside the domain (half-way rule), except across a periodic
    seam the window spans whole (`wrap`, from `periodic_wrap`): there it is the node at the
    window's other edge, where periodic streaming takes it from.
    """
    mask = (q[OPP] > 0) & ~solid         # mask[i]: the link of x along c_ib is cut
    mask[0] = False
    i, iy, ix = np.nonzero(mask)
    ib = OPP[i]
    qq = q[ib, iy, ix].astype(np.float64)
    cx, cy = C[i, 0], C[i, 1]
    fy, fx, second = second_nodes(q, solid, i, iy, ix, wrap)
    # wall velocity at the crossing x + q c_ib = x - q c_i (world coordinates)
    ux, uy = wall_velocity(x0 + ix - qq * cx, y0 + iy - qq * cy, center, velocity, omega)
    ux = np.broadcast_to(np.asarray(ux, dtype=np.float64), qq.shape)
    uy = np.broadcast_to(np.asarray(uy, dtype=np.float64), qq.shape)
    cu = W[i] * RHO0 * (cx * ux + cy * uy)
    small = qq < 0.5
    lin = small & second          # 2q f*_ib(x) + (1-2q) f*_ib(xf) + 6 w (c.u_w)
    big = ~small                  # 1/(2q) f*_ib(x) + (2q-1)/(2q) f*_i(x) + 3/q w (c.u_w)
    a = np.where(lin, 2 * qq, np.where(big, 0.5 / qq, 1.0))   # else half-way: f*_ib(x) + 6 w (c.u_w)
    b = np.where(lin, 1 - 2 * qq, 0.0)
    c = np.where(big, (2 * qq - 1) / (2 * qq), 0.0)
    d = np.where(big, (3.0 / qq) * cu, 6.0 * cu)
    return BodyLinks(i, ib, iy, ix, np.where(lin, fy, iy), np.where(lin, fx, ix), qq,
                     np.stack([ux, uy], axis=1), a, b, c, d)


def incoming(f: np.ndarray, links: BodyLinks, f_ib: np.ndarray | None = None) -> np.ndarray:
    """f_i^in(x) for every body link, from a window f of post-collision populations (9, h, w).

    Evaluated in float64 whatever f's dtype, in the order a f_ib(x) + b f_ib(xf) + c f_i(x) + d.
    `f_ib`: `outgoing(f, links)` where the caller has it already (the momentum exchange: one
    gather of f*_ib(x) instead of two).
    """
    if f_ib is None:
        f_ib = outgoing(f, links)
    f_ib2 = f[links.ib, links.fy, links.fx].astype(np.float64)
    f_i = f[links.i, links.iy, links.ix].astype(np.float64)
    return links.a * f_ib + links.b * f_ib2 + links.c * f_i + links.d


def outgoing(f: np.ndarray, links: BodyLinks) -> np.ndarray:
    """f*_ib(x): the population leaving x towards the body on each link."""
    return f[links.ib, links.iy, links.ix].astype(np.float64)
