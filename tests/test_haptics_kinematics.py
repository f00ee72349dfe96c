"""Pantograph kinematics of the Haply 2DIY against hand-computed poses, and the Jacobian against
finite differences and virtual work."""
import math

import numpy as np
import pytest

from feelflow.haptics.kinematics import HAPLY_2DIY, OutOfReach, Pantograph

L_, l_ = 0.09, 0.07


def test_symmetric_pose_arms_straight_out():
    # th1 = 0, th2 = 180 deg: elbows at (+-0.07, 0); handle on the y axis at sqrt(L^2 - l^2)
    x, y = HAPLY_2DIY.forward(0.0, math.pi)
    assert x == pytest.approx(0.0, abs=1e-12)
    assert y == pytest.approx(math.sqrt(L_ ** 2 - l_ ** 2), rel=1e-12)


def test_symmetric_pose_60_120():
    # elbows at (+-0.035, 0.0606..); handle straight above their midpoint by sqrt(L^2 - 0.035^2)
    x, y = HAPLY_2DIY.forward(math.radians(60), math.radians(120))
    assert x == pytest.approx(0.0, abs=1e-12)
    assert y == pytest.approx(l_ * math.sin(math.radians(60)) + math.sqrt(L_ ** 2 - 0.035 ** 2), rel=1e-12)


def test_asymmetric_pose_by_hand():
    # th1 = 90 deg (A = (0, 0.07)), th2 = 180 deg (B = (-0.07, 0)): E is at distance L from both.
    x, y = HAPLY_2DIY.forward(math.radians(90), math.radians(180))
    assert math.hypot(x - 0.0, y - 0.07) == pytest.approx(L_, rel=1e-12)
    assert math.hypot(x + 0.07, y) == pytest.approx(L_, rel=1e-12)
    # the two circles' far intersection, solved by hand: E lies on the line y = -x (the
    # perpendicular bisector of AB), so x^2 + (x + 0.07)^2 ... take the far (larger y) root
    # of 2 x^2 + 0.14 x + 0.0049 - 0.0081 = 0
    xr = (-0.14 - math.sqrt(0.14 ** 2 - 4 * 2 * (0.0049 - 0.0081))) / 4
    assert x == pytest.approx(xr, rel=1e-12) and y == pytest.approx(-xr, rel=1e-12)


@pytest.mark.parametrize("x,y", [(0.0, 0.10), (0.03, 0.08), (-0.04, 0.12), (0.05, 0.13)])
def test_inverse_then_forward_round_trips(x, y):
    th = HAPLY_2DIY.inverse(x, y)
    assert HAPLY_2DIY.forward(*th) == pytest.approx((x, y), abs=1e-12)


def test_out_of_reach_is_an_error():
    with pytest.raises(OutOfReach):
        HAPLY_2DIY.inverse(0.0, 0.2)


@pytest.mark.parametrize("mech", [HAPLY_2DIY, Pantograph(0.05, 0.07, 0.02)])
def test_jacobian_matches_finite_differences(mech):
    th = mech.inverse(0.012, 0.09) if mech is HAPLY_2DIY else (math.radians(70), math.radians(110))
    j = mech.jacobian(*th)
    h = 1e-7
    for k in range(2):
        d = [0.0, 0.0]
        d[k] = h
        plus = np.array(mech.forward(th[0] + d[0], th[1] + d[1]))
        minus = np.array(mech.forward(th[0] - d[0], th[1] - d[1]))
        assert j[:, k] == pytest.approx((plus - minus) / (2 * h), rel=1e-6, abs=1e-9)


def test_torques_do_the_same_virtual_work_as_the_force():
    th = HAPLY_2DIY.inverse(-0.02, 0.11)
    f = np.array([0.7, -0.4])
    tau = np.array(HAPLY_2DIY.torques(*th, *f))
    dth = np.array([1e-6, -2e-6])
    de = HAPLY_2DIY.jacobian(*th) @ dth
    assert tau @ dth == pytest.approx(f @ de, rel=1e-12)
    assert HAPLY_2DIY.force_from_torques(*th, *tau) == pytest.approx(tuple(f), rel=1e-9)
