"""What the force plot draws, as numbers (app/model/plot_series.py, Qt-free): the curves from
the moment a model was switched on, the force axis without the start pulse, the drag against
speed with its fitted power law, the log-log ranges."""
from __future__ import annotations

import math

import numpy as np
import pytest

from feelflow.app.model import plot_series
from feelflow.app.model.display_units import DisplayUnits
from feelflow.app.model.force_history import History
from feelflow.app.model.readouts import start_pulse_steps

ME, MAC = "momentum_exchange", "macroscopic"


def test_force_series_starts_when_the_model_does_and_leaves_the_start_pulse_out_of_the_range():
    size = 10.0
    pulse = start_pulse_steps(size)
    h = History()
    for k in range(200):
        t = 10 * k
        forces = {ME: (50.0 if t < pulse else 0.02, 0.001)}
        if k >= 50:
            forces[MAC] = (0.03, -0.002)
        h.add(t, (0.0, 0.0), (0.05, 0.0), forces)
    s = plot_series.force_series(h, MAC, size, DisplayUnits())
    assert s.t[0] == 500 and len(s.t) == 150                       # from when the model was switched on
    me = plot_series.force_series(h, ME, size, DisplayUnits())
    assert len(me.t) == 200 and np.nanmax(me.curves[0]) == pytest.approx(50.0)   # the pulse is drawn...
    lo, hi = plot_series.force_axis_range(me.settled)
    assert lo == 0.0 and hi == pytest.approx(0.02)                 # ...but the range leaves it out, keeps zero


def test_force_axis_range_without_values_or_with_one_value():
    assert plot_series.force_axis_range([]) is None
    assert plot_series.force_axis_range([math.nan]) is None
    lo, hi = plot_series.force_axis_range([0.0, 0.0])
    assert hi > lo


def test_speed_fit_finds_the_exponent_of_drag_against_speed():
    """Settled samples at five speeds with F = k U^2 give n = 2; one speed gives a point and
    says the fit needs speeds apart; none says to hold a speed."""
    h = History()
    t = 0
    for u in (0.02, 0.03, 0.04, 0.05, 0.06):
        for _ in range(150):
            h.add(t, (0.0, 0.0), (u, 0.0), {ME: (3.0 * u * u, 0.0)})
            t += 10
    fit = plot_series.speed_fit(h, ME, DisplayUnits())
    assert fit.exponent == pytest.approx(2.0, abs=1e-6) and "U<sup>2.00</sup>" in fit.text
    xs, ys = fit.line
    assert np.allclose(ys, 3.0 * xs ** 2)
    (x0, x1), (y0, y1) = plot_series.log_ranges(fit.speeds, fit.drags)
    assert x0 < math.log10(fit.speeds.min()) and x1 > math.log10(fit.speeds.max()) and y0 < y1

    one = History()
    for k in range(200):
        one.add(10 * k, (0.0, 0.0), (0.05, 0.0), {ME: (0.02, 0.0)})
    fit = plot_series.speed_fit(one, ME, DisplayUnits())
    assert len(fit.speeds) == 1 and fit.exponent is None and fit.text.startswith("fit: needs speeds")
    fit = plot_series.speed_fit(History(), ME, DisplayUnits())
    assert len(fit.speeds) == 0 and fit.text == f"fit: hold a speed {History.SETTLE_STEPS} steps"
    assert plot_series.log_ranges([], []) == ((-2.0, -1.0), (-3.0, -1.0))
