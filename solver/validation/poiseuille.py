"""Plane Poiseuille flow between walls at fractional positions: second-order convergence.

A channel periodic in x, driven by a uniform body force g (Guo, Zheng & Shi 2002), between two
walls that are two rectangles (`feelflow.shapes.Polygon`) seen by the solver as one body
(`ChannelWalls`); the walls sit a fraction q of a link away from the last fluid nodes
(q = Q_BOTTOM, Q_TOP: not 1/2), so the interpolated bounce-back (Bouzidi et al. 2001) is what
places them. Steady solution u(y) = g / (2 nu) (y - y_b)(y_t - y). Diffusive scaling: tau and
the peak speed stay fixed as the width H grows, so the relative L2 error must fall like H^-2
(target: order 2 +- 0.2 over at least three resolutions).

Q_BOTTOM < 1/2 and Q_TOP > 1/2, so both branches of the linear rule are checked. With q < 1/2
the rule needs the node x + c_i, which for the diagonal links of the first and last column lies
across the periodic seam: the walls' window spans the periodic width, and the backends take
that node from the other edge (docs/science/algorithm.md rule 1a; falling back to the half-way rule there
instead gives order 1.1 at q = 0.3 and a flow that varies along x).
Each run starts from the analytic profile and runs until the field changes by less than
`STEADY_TOL` (relative) over a block: the discrete steady state, whatever the start.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from feelflow.shapes.base import Shape, ShapeError
from feelflow.shapes.polygon import Polygon
from feelflow.solver.config import FlowConfig
from feelflow.solver.lattice import C, equilibrium
from feelflow.solver.validation.base import CaseResult, Check, SolverFactory, Stopwatch

NAME = "poiseuille"
RESOLUTIONS = (8, 16, 32, 64)
QUICK_RESOLUTIONS = (8, 16, 32)
#: float32 storage (the gl backend) stops at 32 rows: at 64 the body force per step (9.5e-7)
#: is a few ulp of the stored populations, and float32 round-off moves the steady error by
#: about 1e-4, half the scheme's own 2.0e-4 (docs/science/validation.md: gl 3.3e-4 at 64 rows with
#: `feelflow validate --backend gl --case poiseuille --resolution 64`, numpy float64 2.0e-4)
RESOLUTIONS_FLOAT32 = QUICK_RESOLUTIONS
DEFAULT_RESOLUTION = RESOLUTIONS[-1]
QUICK_RESOLUTION = QUICK_RESOLUTIONS[-1]
Q_BOTTOM = 0.3
Q_TOP = 0.6
NU = 0.1
U_PEAK = 0.05
NX = 8
PAD = 3  # solid rows below and above the channel
STEADY_TOL = 1e-10
#: the same for float32 storage (the gl backend, or dtype float32): its rounding noise in u is
#: ~1e-7 U_PEAK, so 1e-10 would never be met
STEADY_TOL_FLOAT32 = 1e-6


@dataclass(frozen=True, init=False)
class ChannelWalls(Shape):
    """The union of several polygons as one body (the solver holds one body). Its parts may
    reach beyond the domain in the periodic direction; only its finiteness is validated."""

    parts: tuple = ()

    kind = "channel_walls"

    def __init__(self, parts):
        object.__setattr__(self, "parts", tuple(parts))
        object.__setattr__(self, "x", 0.0)
        object.__setattr__(self, "y", 0.0)
        object.__setattr__(self, "angle", 0.0)

    def contains(self, px, py):
        return np.logical_or.reduce([p.contains(px, py) for p in self.parts])

    def segment_hit(self, px, py, dx, dy):
        hits = np.stack([np.broadcast_to(p.segment_hit(px, py, dx, dy), np.broadcast(px, py, dx, dy).shape)
                         for p in self.parts])
        first = np.where(hits > 0, hits, np.inf).min(axis=0)
        return np.where(np.isfinite(first), first, 0.0)

    def outline(self):
        return np.vstack([p.outline() for p in self.parts])

    def frontal_area(self, flow_direction) -> float:
        return sum(p.frontal_area(flow_direction) for p in self.parts)

    def surface_elements(self, spacing: float = 0.5):
        elems = [p.surface_elements(spacing) for p in self.parts]
        return tuple(np.concatenate(e) for e in zip(*elems))

    def bounding_box(self):
        boxes = np.array([p.bounding_box() for p in self.parts])
        return (boxes[:, 0].min(), boxes[:, 1].min(), boxes[:, 2].max(), boxes[:, 3].max())

    def validate(self, nx=None, ny=None):
        if not self.parts:
            raise ShapeError("channel walls need at least one part")
        return self

    def to_dict(self) -> dict:
        return {"kind": self.kind, "parts": [p.to_dict() for p in self.parts]}


def rectangle(x0, y0, x1, y1) -> Polygon:
    return Polygon.from_world([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])


class Channel:
    """The channel of `n` fluid rows: walls at y_b = PAD - Q_BOTTOM, y_t = PAD + n - 1 + Q_TOP."""

    def __init__(self, n: int, nu: float = NU, u_peak: float = U_PEAK):
        self.n = n
        self.ny = n + 2 * PAD
        self.y_bottom = PAD - Q_BOTTOM
        self.y_top = PAD + n - 1 + Q_TOP
        self.height = self.y_top - self.y_bottom
        self.nu = nu
        self.g = 8 * nu * u_peak / self.height ** 2

    def walls(self) -> ChannelWalls:
        x0, x1 = -3.0, NX + 2.0
        return ChannelWalls([rectangle(x0, -3.0, x1, self.y_bottom), rectangle(x0, self.y_top, x1, self.ny + 2.0)])

    def config(self) -> FlowConfig:
        return FlowConfig(nx=NX, ny=self.ny, nu=self.nu, x_boundary="periodic", y_boundary="periodic",
                          inflow_speed=0.0, inflow_ramp_steps=0, body_force=(self.g, 0.0))

    def exact(self, y):
        return np.clip(self.g / (2 * self.nu) * (y - self.y_bottom) * (self.y_top - y), 0.0, None)

    def fluid_rows(self) -> slice:
        return slice(PAD, PAD + self.n)


def velocity_x(solver) -> np.ndarray:
    """u_x from the stored post-collision populations: (sum c_x f* - F_x / 2) / rho, since
    collision with the Guo source adds F/2 to the momentum of f^in + F/2 (docs/science/algorithm.md)."""
    f = solver.distributions()
    rho = f.sum(axis=0)
    return (np.tensordot(C[:, 0].astype(float), f, axes=1) - 0.5 * solver.config.body_force[0]) / rho


def l2_error(make_solver: SolverFactory, n: int, watch: Stopwatch, max_steps: int | None = None) -> tuple[float, bool]:
    """Relative L2 error of the steady velocity over the fluid rows of an n-row channel."""
    ch = Channel(n)
    solver = make_solver(ch.config())
    try:
        y = np.arange(ch.ny, dtype=float)
        ux = np.repeat(ch.exact(y)[:, None], NX, axis=1)
        solver.set_distributions(equilibrium(np.ones_like(ux), ux, np.zeros_like(ux)))
        solver.set_body(ch.walls())
        rows = ch.fluid_rows()
        block = max(100, n * n // 4)
        max_steps = max_steps or int(20 * ch.height ** 2 / ch.nu)
        prev = velocity_x(solver)[rows]
        single = solver.name == "gl" or solver.config.dtype == "float32"
        tol = STEADY_TOL_FLOAT32 if single else STEADY_TOL
        steady = False
        u = prev
        while not steady and solver.time < max_steps:
            watch.step(solver, block)
            u = velocity_x(solver)[rows]
            steady = float(np.abs(u - prev).max()) < tol * U_PEAK
            prev = u
        exact = ch.exact(y[rows])[:, None]
        return float(np.sqrt(((u - exact) ** 2).sum() / (exact ** 2 * NX).sum())), steady
    finally:
        solver.close()


def run(make_solver: SolverFactory, resolution: int | None = None, quick: bool = False,
        backend: str = "numpy", resolutions=None) -> CaseResult:
    """`resolution`: the finest channel width; the three or four before it halve it."""
    if resolutions is None:
        base = QUICK_RESOLUTIONS if quick else RESOLUTIONS_FLOAT32 if backend == "gl" else RESOLUTIONS
        if resolution:
            k = len(base)
            resolutions = tuple(resolution // 2 ** (k - 1 - j) for j in range(k))
        else:
            resolutions = base
    watch = Stopwatch()
    errors, steady = [], []
    for n in resolutions:
        e, s = l2_error(make_solver, n, watch)
        errors.append(e)
        steady.append(s)
    heights = np.array([Channel(n).height for n in resolutions])
    order = -np.polyfit(np.log(heights), np.log(errors), 1)[0]
    quantities = {f"l2_error_{n}": e for n, e in zip(resolutions, errors)}
    for (n0, e0, h0), (n1, e1, h1) in zip(zip(resolutions, errors, heights), zip(resolutions[1:], errors[1:], heights[1:])):
        quantities[f"order_{n0}_{n1}"] = math.log(e0 / e1) / math.log(h1 / h0)
    quantities["order"] = float(order)
    quantities["steady"] = float(all(steady))
    result = CaseResult(NAME, backend, resolutions[-1], quantities=quantities)
    result.checks += [Check("order", 1.8, 2.2, "target: L2 error order 2 +- 0.2"),
                      Check("steady", 1.0, 1.0, f"steady within {STEADY_TOL:g} U per block")]
    result.notes = (f"widths {', '.join(f'{h:g}' for h in heights)} cells, q = {Q_BOTTOM} / {Q_TOP}, "
                    f"nu = {NU}, U_peak = {U_PEAK}, TRT, Guo forcing, periodic x ({NX} columns)")
    return watch.fill(result)
