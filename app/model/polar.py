"""An angle-of-attack sweep (a polar): each angle held until its forces settle, one point per angle.

Qt-free: the command line (`feelflow polar`) and the window's polar lesson feed the same
`PolarSweep` with the force averaged over each sample interval and move the body when it says so.

Coefficients are per unit span on the chord c (not the frontal width): C_D = 2 F_x / (rho U^2 c),
C_L = 2 F_y / (rho U^2 c) (solver/units.py). The angle of attack alpha is the nose-up angle in a
flow along +x, so the body's pose angle (counter-clockwise) is -alpha.

Settling. A sample is the force averaged over `sample_steps` steps. An angle has settled when
the mean C_L and C_D of the last `window` samples and of the `window` samples before them differ
by less than `tolerance` (absolute, in coefficient units) -- the drift of a window mean -- once
`min_steps` steps have passed since the body turned (the start-up transient of a turned body
lasts a few chord-passing times c / U). A window spans `window_chords` chord-passing times, so a
shedding flow is averaged over several of its periods and still settles (its mean does not
drift); its swing is kept as the standard deviation of C_L over the last window (large past
stall). An angle that has not settled after `max_steps` steps is recorded all the same, marked
unsettled.

Reference line: thin-airfoil theory for an inviscid flow, C_L = 2 pi alpha (+ 2 pi alpha_0 for a
cambered mean line; Anderson, Fundamentals of Aerodynamics, sec. 4.7 - 4.8); the lattice's
Reynolds numbers are far below where it holds, and the comparison shows by how much.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from feelflow.solver import units


def thin_airfoil_cl(alpha_deg, zero_lift_alpha_deg: float = 0.0):
    """C_L = 2 pi (alpha - alpha_0), angles in degrees (inviscid thin-airfoil theory)."""
    return 2.0 * math.pi * np.radians(np.asarray(alpha_deg, dtype=np.float64) - zero_lift_alpha_deg)


def naca_zero_lift_angle(camber: float, position: float) -> float:
    """alpha_0 (degrees) of the NACA 4-digit mean line from thin-airfoil theory:
    alpha_0 = -(1/pi) integral_0^pi (dy_c/dx)(cos t0 - 1) dt0 with x = (1 - cos t0) / 2
    (Anderson sec. 4.8, eq. 4.61), integrated numerically."""
    if camber == 0.0:
        return 0.0
    from feelflow.shapes.naca import camber_line

    t0 = np.linspace(0.0, math.pi, 20001)
    _, slope = camber_line(0.5 * (1.0 - np.cos(t0)), camber, position)
    y = slope * (np.cos(t0) - 1.0)
    integral = float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t0)))
    return math.degrees(-integral / math.pi)


@dataclass
class PolarPoint:
    """One angle's settled result: means and C_L's swing over the last window."""

    alpha: float
    cl: float
    cd: float
    cl_std: float
    steps: int
    settled: bool


@dataclass
class PolarSweep:
    """The sweep's state: feed `add_sample(fx, fy)` once per `sample_steps` steps; when it returns
    True the angle is done (its point appended to `points`) and `angle` is the next one (or None
    when the sweep is over)."""

    angles: tuple
    speed: float
    chord: float
    sample_steps: int = 50
    window_chords: float = 3.0
    tolerance: float = 0.01
    min_chords: float = 4.0
    max_chords: float = 40.0
    points: list = field(default_factory=list)

    def __post_init__(self):
        if not self.angles:
            raise ValueError("a polar needs at least one angle")
        if not (self.speed > 0 and self.chord > 0 and self.sample_steps >= 1):
            raise ValueError("a polar needs a positive speed, chord and sample interval")
        self.index = 0
        self._cl: list[float] = []
        self._cd: list[float] = []
        self._steps: list[int] = []
        passing = self.chord / self.speed     # steps for the flow to pass one chord
        self.window = max(4, int(round(self.window_chords * passing / self.sample_steps)))
        self.window_steps = self.window * self.sample_steps
        self.min_steps = int(self.min_chords * passing)
        self.max_steps = max(self.min_steps, int(self.max_chords * passing))

    @property
    def angle(self) -> float | None:
        """The angle being held (degrees), or None when every angle is done."""
        return float(self.angles[self.index]) if self.index < len(self.angles) else None

    @property
    def done(self) -> bool:
        return self.index >= len(self.angles)

    @property
    def steps_at_angle(self) -> int:
        return int(sum(self._steps))

    def coefficients(self, fx: float, fy: float) -> tuple[float, float]:
        """(C_D, C_L) on the chord."""
        return units.drag_lift_coefficients((fx, fy), self.speed, self.chord)

    def live(self) -> tuple[np.ndarray, np.ndarray]:
        """The current angle's (C_L, C_D) samples so far (for a live plot)."""
        return np.array(self._cl), np.array(self._cd)

    def _window(self, end: int):
        """(first index, step-weighted C_L and C_D means, C_L std) of the samples before `end`
        that make up one window (`window_steps` steps), or None if there are not enough."""
        total, first = 0, end
        while first > 0 and total < self.window_steps:
            first -= 1
            total += self._steps[first]
        if total < self.window_steps:
            return None
        w = np.array(self._steps[first:end], dtype=np.float64)
        cl, cd = np.array(self._cl[first:end]), np.array(self._cd[first:end])
        mean_cl = float(np.average(cl, weights=w))
        std = float(np.sqrt(np.average((cl - mean_cl) ** 2, weights=w)))
        return first, mean_cl, float(np.average(cd, weights=w)), std

    def drift(self) -> float | None:
        """max |change of the window mean| of C_L and C_D between the last window and the one
        before it, or None before two windows."""
        last = self._window(len(self._cl))
        if last is None:
            return None
        before = self._window(last[0])
        if before is None:
            return None
        return float(max(abs(last[1] - before[1]), abs(last[2] - before[2])))

    def add_sample(self, fx: float, fy: float, steps: int | None = None) -> bool:
        """Record one sample: the force averaged over `steps` steps (default `sample_steps`);
        True when the angle is done."""
        if self.done:
            raise ValueError("the polar is complete")
        cd, cl = self.coefficients(fx, fy)
        self._cl.append(cl)
        self._cd.append(cd)
        self._steps.append(int(steps or self.sample_steps))
        steps = self.steps_at_angle
        drift = self.drift()
        settled = steps >= self.min_steps and drift is not None and drift < self.tolerance
        if not (settled or steps >= self.max_steps):
            return False
        last = self._window(len(self._cl)) or (0, *self._whole())
        self.points.append(PolarPoint(self.angle, last[1], last[2], last[3], steps, bool(settled)))
        self._cl, self._cd, self._steps = [], [], []
        self.index += 1
        return True

    def _whole(self):
        """(C_L mean, C_D mean, C_L std) of every sample at this angle (fewer than a window)."""
        w = np.array(self._steps, dtype=np.float64)
        cl = np.array(self._cl)
        mean = float(np.average(cl, weights=w))
        return mean, float(np.average(self._cd, weights=w)), float(np.sqrt(np.average((cl - mean) ** 2, weights=w)))

    # --- what the sweep measured -----------------------------------------------------------------
    def rows(self) -> list[list[str]]:
        return [[f"{p.alpha:g}", f"{p.cl:.6g}", f"{p.cd:.6g}", f"{p.cl_std:.4g}", str(p.steps), str(int(p.settled))]
                for p in self.points]

    HEADER = ["alpha_deg", "cl", "cd", "cl_std", "steps", "settled"]


def lift_slope(points, max_abs_alpha: float = 4.0) -> float | None:
    """dC_L/dalpha per radian from a least-squares line through the points with |alpha| <=
    max_abs_alpha (at least two), or None."""
    sel = [(p.alpha, p.cl) for p in points if abs(p.alpha) <= max_abs_alpha + 1e-9]
    if len(sel) < 2:
        return None
    a, cl = np.radians([s[0] for s in sel]), np.array([s[1] for s in sel])
    return float(np.polyfit(a, cl, 1)[0])


def max_lift(points) -> tuple[float, float] | None:
    """(alpha in degrees, C_L) of the largest C_L, or None."""
    if not points:
        return None
    best = max(points, key=lambda p: p.cl)
    return best.alpha, best.cl


def max_lift_fit(points, half_width: float = 8.0) -> tuple[float, float] | None:
    """(alpha in degrees, C_L) at the vertex of a least-squares parabola through the points within
    `half_width` degrees of the largest C_L, or None when the maximum is not pinned.

    Past stall the window means jitter by about +-0.1 from angle to angle (the shed vortices'
    lift swings by +-0.2 to +-0.4 and a window holds only a few of its periods), so the largest
    single point is a noisy estimate of where C_L peaks; the parabola averages over the
    neighbours. Not pinned: fewer than four points in the range, points on only one side of the
    largest C_L (the sweep ends there), a parabola that opens upwards, or a vertex outside the
    fitted range."""
    if not points:
        return None
    top = max(points, key=lambda p: p.cl)
    sel = [(p.alpha, p.cl) for p in points if abs(p.alpha - top.alpha) <= half_width + 1e-9]
    alphas = np.array([s[0] for s in sel], dtype=np.float64)
    if len(sel) < 4 or not (alphas.min() < top.alpha < alphas.max()):
        return None
    a, b, c = np.polyfit(alphas, [s[1] for s in sel], 2)
    if a >= 0:
        return None
    vertex = -b / (2 * a)
    if not alphas.min() <= vertex <= alphas.max():
        return None
    return float(vertex), float(c - b * b / (4 * a))


def chord_of(shape) -> float:
    """The length the coefficients are referred to (shapes' `reference_length`: a section's
    chord, a cylinder's diameter, a plate's length)."""
    return shape.reference_length()


def run_sweep(solver, shape, sweep: PolarSweep, model: str = "momentum_exchange", probe=None,
              on_sample=None, on_point=None):
    """Drive `solver` (a body-free or body-holding solver with `model` enabled) through the sweep:
    the body `shape` turned to each angle (pose angle -alpha), held until the sweep says the angle
    is done. With `probe` (a SurfacePressureProbe added to the solver) the C_p of each angle is
    taken over its last window and handed to `on_point(point, surface_pressure or None)`.
    `on_sample(sweep)` is called after every sample. Raises the solver's SolverDiverged."""
    from feelflow.solver.forces.surface_pressure import distribution, free_stream_density

    while not sweep.done:
        solver.set_body(shape.moved(angle=-math.radians(sweep.angle)))
        full = None   # the probe's mean over the last complete window of samples
        if probe is not None:
            probe.take()
        while True:
            solver.step(sweep.sample_steps)
            fx, fy = solver.forces()[model]
            if probe is not None and probe.steps >= sweep.window * sweep.sample_steps:
                full = probe.take()
            finished = sweep.add_sample(fx, fy)
            if on_sample is not None:
                on_sample(sweep)
            if finished:
                break
        solver.check_physical()
        cp = None
        if probe is not None:
            half = probe.steps >= sweep.window * sweep.sample_steps // 2
            taken = probe.take() if half or full is None else full
            if taken is not None:
                body, pts, normals, _, rho, valid = taken
                rho_ref = free_stream_density(solver.macroscopic()[0], body)
                cp = distribution(body, pts, normals, rho, valid, rho_ref, sweep.speed)
        if on_point is not None:
            on_point(sweep.points[-1], cp)
    return sweep.points
