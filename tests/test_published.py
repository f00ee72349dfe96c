"""Published cylinder values (app/model/published.py) against the papers' tables and each other."""
from __future__ import annotations

import numpy as np
import pytest

from feelflow.app.model import published as pub


def test_tables_hold_the_papers_points():
    re, st = pub.WILLIAMSON_1989.arrays()
    assert len(re) == len(st) == 57 and np.all(np.diff(re) > 0)
    # three rows of Williamson's measured St(Re) (sheardata E1989001 set 2)
    rows = dict(zip(re, st))
    assert rows[49.0] == 0.1183 and rows[100.1] == 0.1604 and rows[177.9] == 0.1865
    assert dict(zip(*pub.DENNIS_CHANG_1970.arrays())) == {20.0: 2.045, 40.0: 1.522}
    assert pub.POSDZIECH_GRUNDMANN_2007_CD.value == (1.325,) and pub.POSDZIECH_GRUNDMANN_2007_ST.value == (0.1644,)


def test_independent_sources_agree_where_they_overlap():
    """Roshko's fit (1954) against Williamson's measurements (1989) within Roshko's range: within
    7 % (they differ by up to 6 % near Re 75: end conditions and oblique shedding); the 2D simulation's St at Re 100
    against Williamson's measurement there (the wake is still two-dimensional at Re 100)."""
    re, st = pub.WILLIAMSON_1989.arrays()
    inside = (re >= pub.ROSHKO_RANGE[0]) & (re <= pub.ROSHKO_RANGE[1])
    assert np.abs(pub.roshko_strouhal(re[inside]) / st[inside] - 1).max() < 0.07
    assert pub.roshko_strouhal(100.0) == pytest.approx(0.167056, abs=1e-6)
    assert np.interp(100.0, re, st) == pytest.approx(0.1644, rel=0.03)


def test_drag_interpolates_between_the_points_and_stays_inside():
    assert pub.published_drag(20.0)[0] == pytest.approx(2.045)
    assert pub.published_drag(40.0) == (pytest.approx(1.522), pub.DENNIS_CHANG_1970.source)
    cd, source = pub.published_drag(60.0)
    assert 1.325 < cd < 1.522 and "Dennis" in source and "Posdziech" in source
    assert pub.published_drag(10.0) is None and pub.published_drag(150.0) is None
    us, fs = pub.published_drag_force([0.01, 0.02, 0.05, 0.2], diameter=20.0, nu=0.02)
    assert list(us) == [0.02, 0.05] and fs[0] == pytest.approx(0.5 * 2.045 * 0.02 ** 2 * 20.0)


def test_the_measured_strouhal_number_of_a_swinging_lift():
    """A lift swinging at St 0.17 for D 20 at U 0.05 (period D / (St U) = 2353 steps), sampled
    every 20 steps: measured back to 1 %; a steady lift has none."""
    t = np.arange(0, 40000, 20.0)
    lift = 0.3 * np.sin(2 * np.pi * t / (20 / (0.17 * 0.05))) + 0.01
    assert pub.measured_strouhal(t, lift, 20.0, 0.05) == pytest.approx(0.17, rel=0.01)
    assert pub.measured_strouhal(t, np.full_like(t, 0.2), 20.0, 0.05) is None
    assert pub.measured_strouhal(t[:100], lift[:100], 20.0, 0.05) is None   # not three periods yet
    assert pub.published_strouhal(100.1) == (0.1604, "Williamson 1989") and pub.published_strouhal(40) is None
