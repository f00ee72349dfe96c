"""The pressure coefficient along the body's surface, from the pressure model's own sampling.

    C_p = (p_wall - p_ref) / (rho_0 U^2 / 2),   p = c_s^2 rho   (solver/units.py),

with rho on the wall extrapolated from the fluid side exactly as the pressure model does it
(`PressureIntegration.wall_density`: the surface elements of `shape.surface_elements` and a
linear least-squares fit to the fluid nodes within 2.5 cells, `sampling.fluid_fit_stencil`).
Summing -p n dA over the same elements gives the pressure model's force, so the C_p plot and the
pressure force are one measurement.

`SurfacePressureProbe` is a force model (it returns the pressure force) that also sums the wall
density of every step it sees; `take()` returns the mean since the last take (a time average
over the steps, the way a pressure tap's reading is averaged) and starts a new one. A pose
change starts a new average, since the surface points moved.

`distribution(...)` lays the samples out the way they are plotted: for a cylinder against the
angle theta from the front stagnation point (0 upstream, 180 downstream), upper and lower side;
for every other body against x / c along its chord (leading edge 0, trailing edge 1), upper and
lower side by the side the surface faces in the body's own frame.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from feelflow.solver.forces.pressure import PressureIntegration
from feelflow.solver.lattice import CS2, RHO0


class SurfacePressureProbe(PressureIntegration):
    """The pressure model, recording the wall density of every step for a time-mean C_p."""

    name = "surface_pressure"
    description = "the pressure model's surface sampling, averaged over time for C_p along the surface"

    def __init__(self, **options):
        super().__init__(**options)
        self._sum = None
        self._count = 0
        self._pose = None

    def wall_density(self, window):
        """As the pressure model's, and summed into the time mean (every force or torque of a
        step reads it once)."""
        pts, normals, lengths, rho = super().wall_density(window)
        pose = (window.shape, window.x0, window.y0)
        if pose != self._pose or self._sum is None or self._sum.shape != rho.shape:
            self._pose, self._sum, self._count = pose, np.zeros_like(rho), 0
        self._sum += rho
        self._count += 1
        self._last = (window.shape, pts, normals, lengths, self._geom[3].valid)
        return pts, normals, lengths, rho

    @property
    def steps(self) -> int:
        """Steps summed since the last `take()`."""
        return self._count

    def peek(self):
        """What `take()` would return, without starting a new average."""
        if not self._count:
            return None
        shape, pts, normals, lengths, valid = self._last
        return shape, pts, normals, lengths, self._sum / self._count, valid

    def take(self):
        """(shape, points (k, 2), normals (k, 2), lengths (k,), mean wall rho (k,), valid (k,)) over
        the steps since the last take, or None before the first step; starts a new average."""
        taken = self.peek()
        if taken is not None:
            self._sum, self._count = np.zeros_like(self._sum), 0
        return taken


@dataclass(frozen=True)
class SurfacePressure:
    """C_p along the surface, split into the upper and the lower side.

    coordinate: "theta" (degrees from the front stagnation point, cylinder) or "x/c".
    upper, lower: (coordinate (k,), C_p (k,)) sorted by coordinate.
    points, cp: every surface element's world position and C_p, in the surface's own order.
    speed, rho_ref: the U and the free-stream density C_p is referred to; steps: steps averaged.
    """

    coordinate: str
    upper: tuple
    lower: tuple
    points: np.ndarray
    cp: np.ndarray
    side: np.ndarray
    position: np.ndarray
    speed: float
    rho_ref: float
    steps: int = 1

    def rows(self):
        """CSV rows: side, coordinate, C_p, x, y (lattice units), upper side first."""
        order = np.lexsort((self.position, self.side != "upper"))
        return [[str(self.side[i]), f"{self.position[i]:.6g}", f"{self.cp[i]:.6g}",
                 f"{self.points[i, 0]:.6g}", f"{self.points[i, 1]:.6g}"] for i in order]

    @property
    def header(self) -> list[str]:
        return ["side", "theta_deg" if self.coordinate == "theta" else "x_over_c", "cp", "x", "y"]

    def value_at(self, side: str, where: float) -> float:
        """C_p on `side` at `where` (theta in degrees or x / c), linear between samples."""
        x, cp = self.upper if side == "upper" else self.lower
        return float(np.interp(where, x, cp))


def pressure_coefficient(rho_wall, rho_ref: float, speed: float):
    """C_p = c_s^2 (rho_wall - rho_ref) / (rho_0 U^2 / 2)."""
    return CS2 * (np.asarray(rho_wall, dtype=np.float64) - rho_ref) / (0.5 * RHO0 * speed * speed)


def _chord_frame(shape):
    """(leading edge, unit chord vector, chord length) in world coordinates."""
    edges = getattr(shape, "leading_trailing_edges", None)
    if edges is not None:
        nose, tail = edges()
    else:   # the body's own x axis: from its most upstream to its most downstream local point
        local = shape.outline() - [shape.x, shape.y]
        c, s = math.cos(shape.angle), math.sin(shape.angle)
        along = local @ np.array([c, s])
        nose, tail = shape.outline()[int(np.argmin(along))], shape.outline()[int(np.argmax(along))]
    d = np.asarray(tail, dtype=np.float64) - np.asarray(nose, dtype=np.float64)
    length = float(math.hypot(*d))
    return np.asarray(nose, dtype=np.float64), d / length, length


def distribution(shape, points, normals, rho_wall, valid, rho_ref: float, speed: float,
                 flow_direction=(1.0, 0.0), steps: int = 1) -> SurfacePressure:
    """Lay the wall densities out as C_p on the upper and lower side (module docstring).
    Points the fit could not serve (`valid` False) are left out."""
    keep = np.asarray(valid, dtype=bool)
    pts, nrm = np.asarray(points)[keep], np.asarray(normals)[keep]
    cp = pressure_coefficient(np.asarray(rho_wall)[keep], rho_ref, speed)
    if getattr(shape, "kind", None) == "cylinder":
        u = np.asarray(flow_direction, dtype=np.float64)
        u = u / np.hypot(*u)
        # the angle of the outward normal from the upstream direction -u: positive on the side
        # to the left of the flow (the upper side for a flow along +x)
        cross = u[0] * nrm[:, 1] - u[1] * nrm[:, 0]
        dot = -(u[0] * nrm[:, 0] + u[1] * nrm[:, 1])
        theta = np.degrees(np.arctan2(cross, dot))
        side = np.where(theta >= 0.0, "upper", "lower")
        position = np.abs(theta)
        coordinate = "theta"
    else:
        nose, along, length = _chord_frame(shape)
        position = (pts - nose) @ along / length
        normal_up = np.array([-along[1], along[0]])
        side = np.where(nrm @ normal_up >= 0.0, "upper", "lower")
        coordinate = "x/c"

    def one(name):
        sel = side == name
        order = np.argsort(position[sel])
        return position[sel][order], cp[sel][order]
    return SurfacePressure(coordinate, one("upper"), one("lower"), pts, cp, side, position,
                           float(speed), float(rho_ref), int(steps))


def free_stream_density(rho_field: np.ndarray, shape) -> float:
    """The free-stream density: the mean over the middle half of the column half-way between
    the inlet (after the inlet's own layer) and the body's upstream edge."""
    ny, nx = rho_field.shape
    x0, _, _, _ = shape.bounding_box()
    column = int(max(2, min(nx - 3, round(0.5 * x0))))
    return float(np.mean(rho_field[ny // 4: 3 * ny // 4 + 1, column]))
