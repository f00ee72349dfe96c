"""Qt-free parts of the app: the mouse coupling, the power-law fit of the drag plot, history."""
from __future__ import annotations

import math

import numpy as np
import pytest

from feelflow.app.model.coupling import SpringDamper


def test_spring_damper_settles_on_the_target_without_overshoot():
    """Critical damping: x(t) = T (1 - (1 + w t) e^{-w t}) from rest, never past the target."""
    c = SpringDamper(w0=0.05, max_speed=10.0)
    pos, vel = (0.0, 0.0), (0.0, 0.0)
    xs = []
    for _ in range(200):
        pos, vel, capped = c.advance(pos, vel, (10.0, 0.0), 1)
        xs.append(pos[0])
        assert not capped
    assert max(xs) <= 10.0 + 1e-9
    t = 100
    exact = 10.0 * (1 - (1 + 0.05 * t) * math.exp(-0.05 * t))
    assert xs[t - 1] == pytest.approx(exact, rel=0.05)   # semi-implicit Euler, dt = 1 step
    assert xs[-1] == pytest.approx(10.0, abs=0.05)


def test_spring_damper_caps_the_speed_and_says_so():
    c = SpringDamper(w0=0.05, max_speed=0.05)
    pos, vel, capped = c.advance((0.0, 0.0), (0.0, 0.0), (100.0, 100.0), 50)
    assert capped and math.hypot(*vel) == pytest.approx(0.05)
    assert math.hypot(*pos) <= 0.05 * 50 + 1e-9


@pytest.mark.parametrize("target", [(-100.0, 0.0), (100.0, 0.0), (0.0, 100.0), (-70.0, 70.0)])
def test_the_body_speed_relative_to_the_wind_stays_under_the_cap(target):
    """Pulled against, with and across a wind of 0.09 (the cap 0.098): the body's speed relative
    to the wind and its own speed both stay within the cap; against the wind it may move at
    only 0.008 (relative 0.098), where without the wind it would move at 0.098."""
    cap, wind = 0.098, (0.09, 0.0)
    c = SpringDamper(w0=0.05, max_speed=cap, stream=wind)
    vel = (0.0, 0.0)
    pos = (0.0, 0.0)
    for _ in range(100):
        pos, vel, capped = c.advance(pos, vel, target, 1)
        assert math.hypot(vel[0] - wind[0], vel[1] - wind[1]) <= cap + 1e-12
        assert math.hypot(*vel) <= cap + 1e-12
    assert capped
    if target == (-100.0, 0.0):
        assert vel[0] == pytest.approx(wind[0] - cap)
    if target == (100.0, 0.0):
        assert vel[0] == pytest.approx(cap)


def test_power_law_fit_recovers_the_exponent():
    from feelflow.app.model.power_law import fit_power_law

    rng = np.random.default_rng(0)
    u = np.repeat([0.02, 0.03, 0.045, 0.065, 0.09], 40)
    f = 3.0 * u ** 1.7 * (1 + 0.02 * rng.standard_normal(u.size))
    us, fs, n = fit_power_law(u, f)
    assert len(us) == 5 and n == pytest.approx(1.7, abs=0.03)
    _, _, n = fit_power_law(np.full(50, 0.05), np.full(50, 0.01))
    assert n is None


def test_history_drag_and_lift_are_along_and_across_the_relative_wind():
    from feelflow.app.model.force_history import History

    h = History()
    h.add(1, (0.0, 0.0), (0.05, 0.0), {"m": (2.0, 1.0)})
    h.add(2, (0.0, -0.05), (0.0, 0.05), {"m": (2.0, 1.0)})    # wind from below: drag along +y
    _, drag, lift = h.drag_lift("m")
    assert drag.tolist() == [2.0, 1.0] and lift.tolist() == [1.0, -2.0]


def test_a_turn_follows_the_pointer_across_180_degrees_and_snaps():
    from feelflow.app.model.simulation import wrap_degrees
    from feelflow.app.gui.turn_handle import Turn, pointer_degrees

    assert pointer_degrees((10.0, 10.0), (10.0, 15.0)) == pytest.approx(90.0)   # y up: counter-clockwise
    turn = Turn(pointer_deg=170.0, body_deg=30.0)
    assert turn.follow(-170.0, snapped=False) == pytest.approx(50.0)   # 20 degrees on, not 340 back
    assert turn.follow(-100.0, snapped=False) == pytest.approx(120.0)
    assert turn.follow(-100.0, snapped=True) == 120.0
    assert turn.follow(-93.0, snapped=True) == 120.0                   # 127 -> the nearest 15-degree step
    assert turn.follow(-87.0, snapped=True) == 135.0
    assert turn.before == 30.0 and turn.target == 135.0
    assert [wrap_degrees(a) for a in (190.0, -190.0, 180.0, 725.0)] == [-170.0, 170.0, -180.0, 5.0]
