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


def link_forces(window: BodyWindow, galilean: bool = True):
    """Each body link's force on the body this step, (fx, fy) arrays, and its wall crossing
    x - q c_i relative to the body's centre, (rx, ry) arrays; Galilean-invariant form or the
    classic one (module docstring). None where the window has no link."""
    links = window_links(window)
    if len(links) == 0:
        return None
    f_out = outgoing(window.f, links)      # f*_ib(x), moving along c_ib
    f_in = incoming(window.f, links, f_out)   # f_i^in(x), moving along c_i
    cx = C[links.i, 0].astype(np.float64)
    cy = C[links.i, 1].astype(np.float64)
    if galilean:
        ux, uy = links.uw[:, 0], links.uw[:, 1]
        fx = (-cx - ux) * f_out - (cx - ux) * f_in
        fy = (-cy - uy) * f_out - (cy - uy) * f_in
    else:
        fx = -cx * (f_out + f_in)
        fy = -cy * (f_out + f_in)
    rx = window.x0 + links.ix - links.q * cx - window.shape.x
    ry = window.y0 + links.iy - links.q * cy - window.shape.y
    return fx, fy, rx, ry


def link_torque(window: BodyWindow, galilean: bool = True) -> float:
    """sum over the links of r x F_link about the body's centre (counter-clockwise positive)."""
    parts = link_forces(window, galilean)
    if parts is None:
        return 0.0
    fx, fy, rx, ry = parts
    return float(np.sum(rx * fy - ry * fx))


class GalileanMomentumExchange(ForceModel):
    name = "momentum_exchange"
    description = "Galilean-invariant momentum exchange (Wen et al. 2014), with cover/uncover impulse"

    def compute(self, window: BodyWindow) -> tuple[float, float]:
        jx, jy = window.impulse
        parts = link_forces(window, galilean=True)
        if parts is None:
            return float(jx), float(jy)
        fx, fy = parts[0], parts[1]
        return float(np.sum(fx) + jx), float(np.sum(fy) + jy)

    def torque(self, window: BodyWindow) -> float:
        """sum over the links of r x F_link, r from the body's centre to the link's wall crossing
        x - q c_i (the cover/uncover impulse's moment is left out: booked relative to the body it
        is small, and a turning body of revolution covers nothing)."""
        return link_torque(window, galilean=True)

    def evaluate(self, window: BodyWindow) -> tuple[float, float, float]:
        jx, jy = window.impulse
        parts = link_forces(window, galilean=True)
        if parts is None:
            return float(jx), float(jy), 0.0
        fx, fy, rx, ry = parts
        return float(np.sum(fx) + jx), float(np.sum(fy) + jy), float(np.sum(rx * fy - ry * fx))


class ClassicMomentumExchange(ForceModel):
    name = "momentum_exchange_classic"
    description = "classic momentum exchange (Ladd 1994; the seed): not Galilean invariant"

    def compute(self, window: BodyWindow) -> tuple[float, float]:
        parts = link_forces(window, galilean=False)
        if parts is None:
            return 0.0, 0.0
        return float(np.sum(parts[0])), float(np.sum(parts[1]))

    def torque(self, window: BodyWindow) -> float:
        """sum over the links of r x F_link of the classic form (as the Galilean-invariant one;
        like its force, wrong on a moving body)."""
        return link_torque(window, galilean=False)

    def evaluate(self, window: BodyWindow) -> tuple[float, float, float]:
        parts = link_forces(window, galilean=False)
        if parts is None:
            return 0.0, 0.0, 0.0
        fx, fy, rx, ry = parts
        return float(np.sum(fx)), float(np.sum(fy)), float(np.sum(rx * fy - ry * fx))
