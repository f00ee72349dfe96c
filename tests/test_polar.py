"""The angle-of-attack sweep (app/model/polar.py) and `feelflow polar`."""
from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from feelflow.app.model.polar import (PolarSweep, lift_slope, max_lift, max_lift_fit, naca_zero_lift_angle, run_sweep,
                                      thin_airfoil_cl)

U, CHORD = 0.05, 20.0
Q = 0.5 * U * U * CHORD   # force per unit coefficient


def test_an_angle_settles_when_its_window_means_stop_drifting():
    sweep = PolarSweep((0.0, 5.0), U, CHORD, sample_steps=50, window_chords=1.0, min_chords=2.0, tolerance=0.01)
    assert sweep.window == 8 and sweep.min_steps == 800
    # a transient decaying towards C_L = 0.3, C_D = 0.5: done once it has drifted below the tolerance
    k = 0
    while not sweep.add_sample(Q * (0.5 + 0.5 * math.exp(-k / 5)), Q * (0.3 - 0.3 * math.exp(-k / 5))):
        k += 1
        assert k < 200
    p = sweep.points[0]
    assert p.settled and p.alpha == 0.0 and p.steps >= 800
    assert p.cl == pytest.approx(0.3, abs=0.02) and p.cd == pytest.approx(0.5, abs=0.02)
    assert sweep.angle == 5.0
    # a flow that keeps drifting is recorded unsettled at max_steps
    n = 0
    while not sweep.add_sample(Q * 0.5, Q * 0.003 * n):
        n += 1
    assert not sweep.points[1].settled and sweep.points[1].steps == sweep.max_steps and sweep.done


def test_a_shedding_flow_settles_on_its_mean_and_keeps_its_swing():
    sweep = PolarSweep((12.0,), U, CHORD, sample_steps=50, window_chords=3.0, min_chords=2.0, tolerance=0.01)
    period = 7.3   # samples: not a divisor of the window
    k = 0
    while not sweep.add_sample(Q * 0.6, Q * (0.8 + 0.2 * math.sin(2 * math.pi * k / period))):
        k += 1
    p = sweep.points[0]
    assert p.settled and p.cl == pytest.approx(0.8, abs=0.02) and p.cl_std == pytest.approx(0.2 / math.sqrt(2), rel=0.1)


def test_slope_maximum_and_thin_airfoil_line():
    from feelflow.app.model.polar import PolarPoint

    pts = [PolarPoint(a, 0.1 * a, 0.1, 0.0, 1, True) for a in (-4, -2, 0, 2, 4)] + [PolarPoint(8, 0.6, 0.2, 0.1, 1, True)]
    assert lift_slope(pts) == pytest.approx(0.1 * 180 / math.pi)
    assert max_lift(pts) == (8, 0.6)
    assert max_lift_fit(pts) is None   # the sweep ends at its largest C_L: the maximum is not pinned


def test_the_fitted_maximum_sees_through_the_jitter_of_the_window_means():
    from feelflow.app.model.polar import PolarPoint

    # C_L = 1.2 - 0.002 (alpha - 27)^2 with +-0.1 jitter: the largest single point is at 23 degrees
    jitter = {17: 0.0, 19: -0.05, 21: 0.05, 23: 0.1, 25: -0.1, 27: -0.08, 29: 0.0, 31: -0.1, 33: 0.05, 35: -0.05}
    pts = [PolarPoint(a, 1.2 - 0.002 * (a - 27) ** 2 + d, 0.5, 0.2, 1, True) for a, d in jitter.items()]
    assert max_lift(pts)[0] == 23
    alpha, cl = max_lift_fit(pts, half_width=12.0)
    assert alpha == pytest.approx(27.0, abs=2.0) and cl == pytest.approx(1.2, abs=0.06)
    # still rising at the end of the sweep, or a trough: not pinned
    assert max_lift_fit([PolarPoint(a, 0.05 * a, 0.5, 0.0, 1, True) for a in range(20, 32, 2)]) is None
    assert max_lift_fit([PolarPoint(a, 0.01 * (a - 26) ** 2, 0.5, 0.0, 1, True) for a in range(20, 32, 2)]) is None
    assert thin_airfoil_cl(5.0) == pytest.approx(2 * math.pi * math.radians(5))
    # NACA 4412's mean line: alpha_0 = -4.15 degrees (Abbott & von Doenhoff's thin-airfoil value)
    assert naca_zero_lift_angle(0.04, 0.4) == pytest.approx(-4.15, abs=0.02)


def test_angles_parse():
    from feelflow.app.cli.commands.polar import parse_angles
    from feelflow.app.errors import UserError

    assert parse_angles("-4:4:2") == (-4, -2, 0, 2, 4)
    assert parse_angles("0, 3.5") == (0.0, 3.5)
    for bad in ("", "a,b", "4:0:1", "0:10:0", "100", "0:1000:1"):
        with pytest.raises(UserError):
            parse_angles(bad)


TINY = """[grid]
nx = 80
ny = 40
[flow]
nu = 0.004
inflow_speed = 0.05
inflow_ramp_steps = 0
initial_velocity = [0.05, 0.0]
walls = "free_slip"
sponge_cells = 8
sponge_absorb = 0.1
[body]
kind = "naca"
chord = 10
thickness = 0.12
camber = {camber}
camber_position = 0.4
x = 25
y = 20
[run]
steps = 100
"""


@pytest.mark.parametrize("camber", [0.0, 0.04])
def test_cli_writes_the_polar_and_cp(tmp_path, camber, capsys):
    """A NACA 0012 and a NACA 4412 on a tiny grid (Re 125 on a 10-cell chord): the CSV, the images,
    the C_p file; the symmetric section has no lift at 0 degrees, the cambered one lifts there
    (its C_p lower on top than below)."""
    from feelflow.app.cli.main import main

    scene = tmp_path / "foil.toml"
    scene.write_text(TINY.format(camber=camber))
    out, cp = tmp_path / "polar.csv", tmp_path / "cp.csv"
    assert main(["polar", str(scene), "--angles", "0", "--out", str(out), "--cp", str(cp)]) == 0
    rows = list(csv.DictReader(out.open()))
    assert [float(r["alpha_deg"]) for r in rows] == [0.0] and rows[0]["settled"] == "1"
    cl0 = float(rows[0]["cl"])
    if camber:
        assert cl0 > 0.05
    else:
        assert abs(cl0) < 0.02
    assert (tmp_path / "polar.png").stat().st_size > 1000 and (tmp_path / "cp.png").stat().st_size > 1000
    cps = list(csv.DictReader(cp.open()))
    assert {r["side"] for r in cps} == {"upper", "lower"} and {r["alpha_deg"] for r in cps} == {"0"}
    upper = np.array([float(r["cp"]) for r in cps if r["side"] == "upper"])
    lower = np.array([float(r["cp"]) for r in cps if r["side"] == "lower"])
    if camber:   # the cambered section's lift: less pressure on top than below, on average
        assert upper.mean() < lower.mean()
    else:
        assert upper.mean() == pytest.approx(lower.mean(), abs=0.02)
    # an existing output is refused without --force
    assert main(["polar", str(scene), "--angles", "0", "--out", str(out)]) == 2
    assert "exists" in capsys.readouterr().err


def test_live_polar_turns_the_body_when_an_angle_settles(tmp_path):
    """The window's polar (app/model/live_polar.py) in a headless Simulation: an angle is held
    until it settles, then the body turns to the next (pose angle -alpha); each angle keeps its
    C_p, and the probe's force never reaches the force history."""
    from feelflow.app.model.scene import load_scene
    from feelflow.app.model.simulation import Simulation

    scene = tmp_path / "foil.toml"
    scene.write_text(TINY.format(camber=0.0))
    sim = Simulation(backend="numpy")
    sim.load_scene(load_scene(scene))
    sim.start_polar((0.0, 4.0), window_chords=1.0, min_chords=1.0)
    assert sim.hold_still and sim.angle == pytest.approx(0.0)
    while not sim.polar.sweep.points:
        sim.advance(50)
        assert sim.solver.time < 20000
    assert sim.angle == pytest.approx(math.radians(-4.0)) and sim.polar.sweep.angle == 4.0
    alpha, cp = sim.polar.cp[0]
    assert alpha == 0.0 and cp.coordinate == "x/c" and len(cp.upper[0]) > 10
    assert "surface_pressure" not in sim.history.forces
    sim.advance(50)
    assert sim.polar.live_cp(sim) is not None
    sim.reset_flow()
    assert sim.polar is None
