"""Momentum exchange on the body links (docs/science/algorithm.md, 'Forces').

Galilean-invariant form: Wen, Zhang, Tu, Wang & Fang, J. Comput. Phys. 266 (2014) 161, per link
(c_ib - u_w) f*_ib(x) - (c_i - u_w) f_i^in(x), plus the cover/uncover impulse J.
Classic form (Ladd 1994; Mei, Yu, Shyy & Luo 2002; the seed): c_ib (f*_ib(x) + f_i^in(x)),
no cover/uncover terms: not Galilean invariant on a moving body, kept to show that.
f_i^in comes from the same `feelflow.solver.bouzidi.incoming` the numpy backend streams with.
"""
from __future__ import annotations

import numpy as np

from feelflow.solver.bouzidi import BodyLinks, build_links, incoming, outgoing, periodic_wrap
from feelflow.solver.forces.base import BodyWindow, ForceModel
from feelflow.solver.lattice import C


def window_links(window: BodyWindow) -> BodyLinks:
    """The window's body links: the backend's, or built from its q and solid."""
    if window.links is not None:
        return window.links
    h, w = window.solid.shape
    box = (window.x0, window.y0, window.x0 + w, window.y0 + h)
    return build_links(window.q, window.solid, window.x0, window.y0,
                       (window.shape.x, window.shape.y), window.velocity, window.omega,
                       wrap=periodic_wrap(window.config, box))


class GalileanMomentumExchange(ForceModel):
    name = "momentum_exchange"
    description = "Galilean-invariant momentum exchange (Wen et al. 2014), with cover/uncover impulse"

    def compute(self, window: BodyWindow) -> tuple[float, float]:
        links = window_links(window)
        jx, jy = window.impulse
        if len(links) == 0:
            return float(jx), float(jy)
        f_out = outgoing(window.f, links)      # f*_ib(x), moving along c_ib
        f_in = incoming(window.f, links, f_out)   # f_i^in(x), moving along c_i
        cx = C[links.i, 0].astype(np.float64)
        cy = C[links.i, 1].astype(np.float64)
        ux, uy = links.uw[:, 0], links.uw[:, 1]
        fx = np.sum((-cx - ux) * f_out - (cx - ux) * f_in)
        fy = np.sum((-cy - uy) * f_out - (cy - uy) * f_in)
        return float(fx + jx), float(fy + jy)

    def torque(self, window: BodyWindow) -> float:
        """sum over the links of r x F_link, r from the body's centre to the link's wall crossing
        x - q c_i (the cover/uncover impulse's moment is left out: booked relative to the body it
        is small, and a turning body of revolution covers nothing)."""
        links = window_links(window)
        if len(links) == 0:
            return 0.0
        f_out = outgoing(window.f, links)
        f_in = incoming(window.f, links, f_out)
        cx = C[links.i, 0].astype(np.float64)
        cy = C[links.i, 1].astype(np.float64)
        ux, uy = links.uw[:, 0], links.uw[:, 1]
        fx = (-cx - ux) * f_out - (cx - ux) * f_in
        fy = (-cy - uy) * f_out - (cy - uy) * f_in
        rx = window.x0 + links.ix - links.q * cx - window.shape.x
        ry = window.y0 + links.iy - links.q * cy - window.shape.y
        return float(np.sum(rx * fy - ry * fx))


class ClassicMomentumExchange(ForceModel):
    name = "momentum_exchange_classic"
    description = "classic momentum exchange (Ladd 1994; the seed): not Galilean invariant"

    def compute(self, window: BodyWindow) -> tuple[float, float]:
        links = window_links(window)
        if len(links) == 0:
            return 0.0, 0.0
        f_out = outgoing(window.f, links)
        s = f_out + incoming(window.f, links, f_out)
        fx = -np.sum(C[links.i, 0] * s)
        fy = -np.sum(C[links.i, 1] * s)
        return float(fx), float(fy)
