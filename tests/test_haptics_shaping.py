"""Force shaping, scaling and the virtual coupling against their defining equations."""
import math

import pytest

from feelflow.haptics.virtual_coupling import TunnelMap, VirtualCoupling
from feelflow.haptics.shaping import ForceInterpolator, ForceScale
from feelflow.haptics.timing import Ticker


def test_scale_maps_expected_peak_to_comfort_fraction_of_max():
    s = ForceScale(expected_peak=0.02, comfort_fraction=0.4, device_max=1.5)
    assert 0.02 * s.gain == pytest.approx(0.4 * 1.5)


def test_low_pass_step_response_is_first_order():
    # a held step through y' = wc (x - y): y(tau) = 1 - 1/e at tau = 1 / (2 pi fc)
    fc = 20.0
    f = ForceInterpolator(cutoff_hz=fc)
    f.interval = 1e-9  # make the hold a step
    f.add(1.0, 0.0, arrival=0.0)
    f.evaluate(0.0)
    tau = 1 / (2 * math.pi * fc)
    t, y = 0.0, 0.0
    while t < tau - 1e-12:
        t += 1e-4
        y = f.evaluate(t)[0]
    assert y == pytest.approx(1 - math.exp(-1), abs=0.01)


def test_hold_interpolates_between_samples_without_overshoot():
    f = ForceInterpolator(cutoff_hz=1e6)  # filter out of the way
    for k in range(10):  # samples every 20 ms alternating 0 / 1
        f.add(float(k % 2), 0.0, arrival=0.02 * k)
    # the ramp from the last value towards the new one takes one interval
    f.add(1.0, 0.0, arrival=0.2)
    held = [f.held(0.2 + 0.001 * i)[0] for i in range(0, 30)]
    assert held[0] == pytest.approx(0.0, abs=1e-9) and held[-1] == pytest.approx(1.0)
    assert held[10] == pytest.approx(0.5, abs=0.05)  # half way after half an interval
    assert all(0.0 <= h <= 1.0 for h in held)


def test_tunnel_map_corners_and_flip():
    m = TunnelMap(((-0.05, 0.05), (0.06, 0.14)), (10, 20, 210, 120), flip_y=True)
    assert m.to_tunnel(-0.05, 0.06) == pytest.approx((10, 120))  # near the motors = top
    assert m.to_tunnel(0.05, 0.14) == pytest.approx((210, 20))
    assert m.to_tunnel(1.0, 1.0) == pytest.approx((210, 20))  # clamped to the rectangle
    assert m.vector_to_device(1.0, 2.0) == (1.0, -2.0)
    one = TunnelMap(((-0.04, 0.04), (0.0, 0.0)), (0, 0, 100, 50), dof=1)
    assert one.to_tunnel(0.0, 0.3) == pytest.approx((50, 25))


def test_coupling_step_response_matches_the_spring_damper():
    # x'' = w^2 (u - x) + 2 w (u' - x') (zeta = 1) for a unit step u: Laplace gives
    # x(t) = 1 - exp(-w t) + w t exp(-w t), peaking at 1 + e^-2 when t = 2 / w
    w = 2 * math.pi * 10.0
    c = VirtualCoupling(natural_hz=10.0, damping=1.0, velocity_filter_hz=1e9)
    dt = 1e-5
    c.step((0.0, 0.0), dt)
    t = 0.0
    for _ in range(int(0.3 / dt)):
        (x, _), _ = c.step((1.0, 0.0), dt)
        t += dt
        assert x == pytest.approx(1 - math.exp(-w * t) + w * t * math.exp(-w * t), abs=2e-3)
    assert x == pytest.approx(1.0, abs=1e-3)


def test_coupling_speed_cap():
    capped = VirtualCoupling(natural_hz=10.0, damping=1.0, max_speed=2.0)
    capped.step((0.0, 0.0), 0.001)
    for _ in range(100):
        _, (vx, vy) = capped.step((100.0, 0.0), 0.001)
        assert math.hypot(vx, vy) <= 2.0 + 1e-9


def test_ticker_restarts_after_a_long_stall():
    t = Ticker(1000.0, spin_s=0.0)
    t.wait()
    import time
    time.sleep(0.02)
    t.wait()
    assert t.overruns == 1
