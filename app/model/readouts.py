"""The physics the window shows, in one Qt-free place: the force along and across the relative
wind (drag and lift), the force coefficients with the reference they use, the force arrows, the
forces CSV and the pressure view's free-stream density. The widgets (force plot, overlay, side
panel, exercise panel) only draw what these functions return.

One definition of the coefficients everywhere (solver/units.py, Schaefer & Turek 1996, per unit
span):

    C_D = 2 D / (rho_0 U^2 L),   C_L = 2 L_f / (rho_0 U^2 L)

- D, L_f: the force along and across the *relative* wind (the inflow less the body's velocity),
  lift positive to the left of the wind (+y for a wind along +x);
- U: the speed of the relative wind (for a body held still, the inflow speed);
- L: the reference length, stated next to every coefficient shown: the body's size (cylinder
  diameter, plate length, wedge length, airfoil chord, the polygon's scale; app/model/bodies.py)
  in the free tunnel, the exercise's `reference_length` while an exercise is open (the length its
  score uses, app/exercises/scoring.py).

Lattice units throughout (docs/science/algorithm.md).
"""
from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass

import numpy as np

from feelflow.app.model.display_units import si_columns
from feelflow.solver import units
from feelflow.solver.lattice import CS2

#: samples (frames) the readouts average over: about half a second of the window's frames
READOUT_SAMPLES = 30
#: below this relative wind speed (lattice units) a coefficient is not defined (shown as a dash)
MIN_COEFFICIENT_SPEED = 0.005
#: the impulsive start's pressure pulse (the flow begins at full speed around a body that was not
#: there) has passed once it crossed the body twice at the speed of sound: 2 D / c_s steps
START_PULSE_CROSSINGS = 2.0
#: a force arrow is as long as its coefficient times half the reference length, at most this
#: many reference lengths
ARROW_CAP_LENGTHS = 2.5

BODY_SIZE = "body size"
EXERCISE_LENGTH = "the exercise's reference length"


@dataclass(frozen=True)
class ReferenceLength:
    """The length the coefficients are made dimensionless with, and what it is."""

    cells: float
    name: str = BODY_SIZE


@dataclass(frozen=True)
class Readout:
    """Mean drag and lift (lattice units) of the last samples and their coefficients, with the
    reference length and speed they use. NaN where there is no data or no wind."""

    drag: float
    lift: float
    cd: float
    cl: float
    length: ReferenceLength
    speed: float

    @property
    def has_forces(self) -> bool:
        return math.isfinite(self.drag) and math.isfinite(self.lift)

    def reference_text(self) -> str:
        """'L = 24 cells (body size), U = 0.050': what the coefficients are made dimensionless with."""
        speed = f"{self.speed:.3f}" if math.isfinite(self.speed) else "\u2013"
        return f"L = {self.length.cells:g} cells ({self.length.name}), U = {speed}"


def format_coefficient(value: float, digits: int = 2) -> str:
    """A coefficient as the window shows it ('\u2013' when undefined, never '-0.00')."""
    if not math.isfinite(value):
        return "\u2013"
    text = f"{value + 0.0:.{digits}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def drag_direction(wind):
    """Unit vectors along the relative wind ((n, 2); +x where the relative wind is ~0)."""
    w = np.atleast_2d(np.asarray(wind, float))
    s = np.hypot(w[:, 0], w[:, 1])
    out = np.tile([1.0, 0.0], (len(w), 1))
    ok = s > 1e-9
    out[ok] = w[ok] / s[ok, None]
    return out


def drag_lift(forces, wind):
    """(drag, lift) arrays of forces (n, 2) against the relative wind (n, 2): the component along
    the wind, and across it (positive to the wind's left)."""
    f = np.atleast_2d(np.asarray(forces, float))
    along = drag_direction(wind)
    drag = (f * along).sum(axis=1)
    lift = f[:, 1] * along[:, 0] - f[:, 0] * along[:, 1]
    return drag, lift


def coefficients(drag: float, lift: float, speed: float, length: ReferenceLength,
                 min_speed: float = MIN_COEFFICIENT_SPEED) -> tuple[float, float]:
    """(C_D, C_L) of a drag and lift at relative wind speed `speed` (module docstring); NaN below
    `min_speed` (a measured wind near zero; a stated speed such as an exercise's passes 0)."""
    if not (math.isfinite(speed) and speed > 0 and speed >= min_speed):
        return math.nan, math.nan
    return (units.force_coefficient(drag, speed, length.cells),
            units.force_coefficient(lift, speed, length.cells))


def readout(history, force_model: str, length: ReferenceLength, last: int = READOUT_SAMPLES) -> Readout:
    """The mean drag, lift and coefficients of `force_model` over the last `last` samples of a
    force history (app/model/simulation.py History): what the plot, the side panel and the
    exercise panel show."""
    t, drag, lift = history.drag_lift(force_model)
    if len(t) == 0 or force_model not in history.forces:
        return Readout(math.nan, math.nan, math.nan, math.nan, length, math.nan)
    d, l_ = drag[-last:], lift[-last:]
    if not np.isfinite(d).any():
        return Readout(math.nan, math.nan, math.nan, math.nan, length, math.nan)
    w = np.asarray(history.wind[-last:], float).reshape(-1, 2)
    speed = float(np.hypot(w[:, 0], w[:, 1]).mean())
    mean_d, mean_l = float(np.nanmean(d)), float(np.nanmean(l_))
    cd, cl = coefficients(mean_d, mean_l, speed, length)
    return Readout(mean_d, mean_l, cd, cl, length, speed)


def arrows(force, wind, length: ReferenceLength) -> dict | None:
    """The drag and lift arrows of one frame's force: {"drag": (x, y), "lift": (x, y)} in cells,
    each along its direction (drag along the relative wind, lift across it) and as long as its
    coefficient times half the reference length, at most ARROW_CAP_LENGTHS reference lengths;
    None without a finite force or a relative wind to scale it by."""
    if force is None or not all(math.isfinite(v) for v in force):
        return None
    speed = math.hypot(*wind)
    (ax, ay), = drag_direction(wind)
    drag, lift = (float(v[0]) for v in drag_lift(force, wind))
    cd, cl = coefficients(drag, lift, speed, length)
    if not (math.isfinite(cd) and math.isfinite(cl)):
        return None
    half, cap = 0.5 * length.cells, ARROW_CAP_LENGTHS * length.cells
    out = {}
    for key, c, (ux, uy) in (("drag", cd, (ax, ay)), ("lift", cl, (-ay, ax))):
        n = min(abs(c) * half, cap)
        out[key] = (math.copysign(n, c) * ux, math.copysign(n, c) * uy)
    return out


#: the turn handle's torque arc: degrees of arc per reference torque, and its most
TORQUE_ARC_DEG = 180.0
TORQUE_ARC_CAP_DEG = 150.0


def torque_arc(torque, size: float, max_speed: float) -> float | None:
    """The turn handle's torque arc for one frame's torque about the body's centre: degrees,
    counter-clockwise positive like the torque, TORQUE_ARC_DEG per reference torque
    q(max_speed) size^2 (the dynamic pressure at the Mach limit on the body's size, at a lever arm
    of its size: what a turn the tunnel allows can reach), at most TORQUE_ARC_CAP_DEG; None
    without a finite torque. Lattice units."""
    if torque is None or not math.isfinite(torque) or size <= 0:
        return None
    reference = units.dynamic_pressure(max_speed) * size * size
    return math.copysign(min(abs(torque) / reference * TORQUE_ARC_DEG, TORQUE_ARC_CAP_DEG), torque)


def arrow_coefficient(vector, length: ReferenceLength) -> float:
    """The coefficient an arrow of `arrows` shows: its length over half the reference length."""
    return math.hypot(*vector) / (0.5 * length.cells)


def start_pulse_steps(size_cells: float) -> float:
    """Solver steps after the flow (re)starts during which the forces show the start pulse, a
    spike tens of times the steady drag; the time plot's force range leaves them out."""
    return START_PULSE_CROSSINGS * size_cells / math.sqrt(CS2)


def free_stream_density(rgba) -> float:
    """Median density of the fluid in a (ny, nx, 4) field (rho, ux, uy, vorticity): the reference
    of the pressure view (the lattice's mean density drifts by a fraction of a percent, which
    alone is C_p ~ 1 at U = 0.05)."""
    rho = np.asarray(rgba)[::2, ::2, 0]
    rho = rho[np.isfinite(rho)]
    return float(np.median(rho)) if rho.size else 1.0


def forces_csv(history, force_models, length: ReferenceLength) -> str:
    """The forces CSV the plot exports: one row per sample (step, body velocity, relative wind),
    and for each force model in the history Fx, Fy, drag, lift, C_D, C_L (this module's
    definition; the reference length in the `ref_length_cells` column)."""
    h = history
    models = [m for m in force_models if m in h.forces]
    out = io.StringIO()
    w = csv.writer(out)
    w.writerow(["step", "body_vx", "body_vy", "wind_x", "wind_y", "ref_length_cells"]
               + [f"{m}_{q}" for m in models for q in ("fx", "fy", "drag", "lift", "cd", "cl")])
    n = len(h)
    wind = np.asarray(h.wind, float).reshape(n, 2)
    speed = np.hypot(wind[:, 0], wind[:, 1])
    cols = []
    for m in models:
        _, drag, lift = h.drag_lift(m)
        f = np.full((n, 2), np.nan)
        s = np.asarray(h.forces[m], float).reshape(-1, 2)
        f[n - len(s):] = s[-n:] if len(s) else s
        c = np.array([coefficients(d, l_, u, length) for d, l_, u in zip(drag, lift, speed)]).reshape(n, 2)
        cols.append(np.c_[f, drag, lift, c])
    for i in range(n):
        row = [h.time[i], *h.body_velocity[i], *h.wind[i], f"{length.cells:g}"]
        for c in cols:
            row += [f"{v:.8g}" for v in c[i]]
        w.writerow(row)
    return out.getvalue()


def forces_table(history, force_models, length: ReferenceLength, probes=None, units=None) -> str:
    """The forces CSV the window exports: `forces_csv`, with the probes' columns
    (app/model/probes.py `Probes`) joined on the step where there are probes, and SI columns
    beside the lattice ones where `units` (app/model/display_units.py `DisplayUnits`) is SI."""
    text = forces_csv(history, force_models, length)
    probes = probes if probes is not None and len(probes) else None
    si = units is not None and units.is_si
    if probes is None and not si:
        return text
    rows = list(csv.reader(io.StringIO(text)))
    head = rows[0] + (probes.columns() if probes else [])
    body = [row + (probes.values_at(int(float(row[0]))) if probes else []) for row in rows[1:]]
    if si:   # SI columns beside the lattice ones
        head, body = si_columns(head, body, units)
    out = io.StringIO()
    w = csv.writer(out)
    w.writerow(head)
    w.writerows(body)
    return out.getvalue()
