"""What the force plot draws, as numbers (Qt-free; app/gui/force_views.py draws them): each
force model's drag and lift, or torque, against time from the moment the model was switched on,
in the units shown; the force axis's range (the settled forces and zero, without the start
pulse: readouts.start_pulse_steps); the settled drag against relative speed with the fitted
power law F ~ U^n (app/model/power_law.py); the log-log ranges around those points; and a
cylinder's Strouhal number beside the published one (app/model/published.py).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from feelflow.app.model import published
from feelflow.app.model.force_history import History
from feelflow.app.model.power_law import fit_power_law
from feelflow.app.model.readouts import start_pulse_steps
from feelflow.app.model.simulation import FORCE_MODELS


def models_shown(params) -> list[str]:
    """Every force model when the panel compares them all, else the one in use."""
    return list(FORCE_MODELS) if params.compare_all else [params.force_model]


@dataclass
class TimeSeries:
    """One model's curves against time (units shown) and its settled values (for the range)."""

    t: np.ndarray
    curves: tuple[np.ndarray, ...]
    settled: np.ndarray


def _from_switch_on(t, first_curve, *rest):
    """The samples from the first finite one of `first_curve` (when the model was switched on)."""
    finite = np.isfinite(first_curve)
    first = int(np.argmax(finite)) if finite.any() else len(t)
    return (t[first:], first_curve[first:]) + tuple(c[first:] for c in rest)


def force_series(history, model: str, size_cells: float, units) -> TimeSeries:
    """Drag and lift of `model` against time; settled: both after the start pulse."""
    t, drag, lift = _from_switch_on(*history.drag_lift(model))
    settled = t >= start_pulse_steps(size_cells)
    t, drag, lift = units.time(t), units.force(drag), units.force(lift)
    return TimeSeries(t, (drag, lift), np.r_[drag[settled], lift[settled]])


def torque_series(history, model: str, size_cells: float, units) -> TimeSeries:
    """The torque of `model` about the body's centre against time (History.torque)."""
    t, torque = _from_switch_on(*history.torque(model))
    settled = t >= start_pulse_steps(size_cells)
    t, torque = units.time(t), units.torque(torque)
    return TimeSeries(t, (torque,), torque[settled])


def force_axis_range(values) -> tuple[float, float] | None:
    """The force axis's (low, high): the finite `values` and zero; None without any."""
    values = np.asarray(values, float)
    values = values[np.isfinite(values)]
    if values.size == 0:
        return None
    lo, hi = min(0.0, float(values.min())), max(0.0, float(values.max()))
    if hi - lo < 1e-12:
        hi = lo + 1e-6
    return lo, hi


@dataclass
class SpeedFit:
    """Drag against relative speed: the points (units shown), the fitted exponent (None until
    the speeds span a factor 1.5), the fit's line and the words beside it."""

    speeds: np.ndarray
    drags: np.ndarray
    exponent: float | None
    line: tuple[np.ndarray, np.ndarray]
    text: str


def speed_fit(history, model: str, units) -> SpeedFit:
    """The settled samples' drag against relative speed (History.settled_drag), binned and
    fitted with F ~ U^n (fit_power_law)."""
    us, fs, n = fit_power_law(*history.settled_drag(model))
    us, fs = np.asarray(units.speed(np.asarray(us, float))), np.asarray(units.force(np.asarray(fs, float)))
    if n is None:
        text = "fit: needs speeds 1.5\u00d7 apart" if len(us) else f"fit: hold a speed {History.SETTLE_STEPS} steps"
        return SpeedFit(us, fs, None, (np.array([]), np.array([])), text)
    c = np.mean(np.log(fs) - n * np.log(us))
    xs = np.geomspace(us.min(), us.max(), 20)
    return SpeedFit(us, fs, n, (xs, np.exp(c) * xs ** n), f"fit: drag \u221d U<sup>{n:.2f}</sup>")


def log_ranges(speeds, drags) -> tuple[tuple[float, float], tuple[float, float]]:
    """log10 ranges around the points (a factor 1.5 in speed, 2 in drag beyond them), or a
    decade without points: with one point or none, an auto-range would span 1e-300 to 1e300."""
    us, fs = np.asarray(speeds, float), np.asarray(drags, float)
    x = (us.min() / 1.5, us.max() * 1.5) if us.size else (0.01, 0.1)
    y = (fs.min() / 2, fs.max() * 2) if fs.size else (1e-3, 1e-1)
    return (math.log10(x[0]), math.log10(x[1])), (math.log10(y[0]), math.log10(y[1]))


def strouhal_note(sim) -> str:
    """For a cylinder whose lift swings: its Strouhal number beside the published one ("" for
    any other body, or before the lift swings)."""
    shape = sim.shape
    if shape is None or shape.kind != "cylinder":
        return ""
    t, _, lift = sim.history.drag_lift(sim.params.force_model)
    return published.strouhal_text(t, lift, shape.diameter, sim.params.wind, sim.reynolds())
