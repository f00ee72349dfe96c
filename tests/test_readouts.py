"""The physics the window shows (app/model/readouts.py): drag and lift against the relative
wind, one definition of C_D and C_L with the reference it uses, the arrows and the forces CSV
built from the same numbers."""
from __future__ import annotations

import csv
import io
import math

import numpy as np
import pytest

from feelflow.app.model import readouts
from feelflow.app.model.readouts import EXERCISE_LENGTH, ReferenceLength
from feelflow.app.model.force_history import History
from feelflow.app.model.tracers import Tracers


def test_drag_and_lift_follow_the_relative_wind():
    # a wind along +y: drag is the y force, lift the force to the wind's left (-x)
    drag, lift = readouts.drag_lift([(0.3, 2.0)], [(0.0, 0.05)])
    assert drag[0] == pytest.approx(2.0) and lift[0] == pytest.approx(-0.3)
    # no relative wind: drag along +x
    drag, lift = readouts.drag_lift([(1.0, 0.5)], [(0.0, 0.0)])
    assert (drag[0], lift[0]) == (1.0, 0.5)


def test_coefficients_use_the_stated_reference():
    length = ReferenceLength(24.0, EXERCISE_LENGTH)
    cd, cl = readouts.coefficients(0.0228, -0.001, 0.05, length)
    assert cd == pytest.approx(2 * 0.0228 / (0.05 ** 2 * 24.0))
    assert cl == pytest.approx(2 * -0.001 / (0.05 ** 2 * 24.0))
    assert all(math.isnan(c) for c in readouts.coefficients(0.1, 0.1, 0.001, length))   # no wind: undefined
    assert readouts.coefficients(0.1, 0.0, 0.001, length, min_speed=0.0)[0] == pytest.approx(2 * 0.1 / (1e-6 * 24))


def history(n=40, wind=(0.05, 0.0), seed=0):
    rng = np.random.default_rng(seed)
    h = History()
    for k in range(n):
        h.add(10 * k, (0.0, 0.0), wind, {"momentum_exchange": tuple(rng.normal([0.02, 0.001], 0.002))})
    return h


def test_readout_csv_and_arrows_agree():
    """The readout (plot, side panel, exercise panel), the CSV rows and the arrows give the
    same coefficient for the same samples."""
    h = history()
    length = ReferenceLength(20.0)
    r = readouts.readout(h, "momentum_exchange", length)
    rows = list(csv.DictReader(io.StringIO(readouts.forces_csv(h, ["momentum_exchange"], length))))
    assert len(rows) == len(h) and rows[-1]["ref_length_cells"] == "20"
    csv_cd = np.mean([float(row["momentum_exchange_cd"]) for row in rows[-readouts.READOUT_SAMPLES:]])
    assert r.cd == pytest.approx(csv_cd, rel=1e-6)
    last = h.forces["momentum_exchange"][-1]
    a = readouts.arrows(last, h.wind[-1], length)
    assert readouts.arrow_coefficient(a["drag"], length) == pytest.approx(abs(float(rows[-1]["momentum_exchange_cd"])),
                                                                          rel=1e-6)
    assert readouts.arrow_coefficient(a["lift"], length) == pytest.approx(abs(float(rows[-1]["momentum_exchange_cl"])),
                                                                          rel=1e-6)
    assert "L = 20 cells (body size), U = 0.050" == r.reference_text()


def test_arrows_are_capped_and_absent_without_wind():
    length = ReferenceLength(10.0)
    a = readouts.arrows((5.0, 0.0), (0.05, 0.0), length)
    assert math.hypot(*a["drag"]) == pytest.approx(readouts.ARROW_CAP_LENGTHS * 10.0)
    assert readouts.arrows((0.01, 0.0), (0.0, 0.0), length) is None
    assert readouts.arrows((math.nan, 0.0), (0.05, 0.0), length) is None


def test_tracers_move_with_the_flow_and_restart_at_the_inlet():
    rgba = np.zeros((20, 40, 4), np.float32)
    rgba[..., 1] = 0.5
    t = Tracers(50)
    pts, tails = t.advance(rgba, 4)
    moved, _ = t.advance(rgba, 4, points=pts.copy())
    inside = pts[:, 0] + 2.0 <= 39
    assert np.allclose(moved[inside, 0], pts[inside, 0] + 2.0)
    assert (moved[~inside, 0] <= 3.0).all()                 # left the tunnel: back at the inlet
    assert np.allclose(tails, pts - rgba[0, 0, 1:3] * 30)


def test_format_coefficient():
    assert readouts.format_coefficient(-0.001) == "0.00"
    assert readouts.format_coefficient(math.nan) == "\u2013"
    assert readouts.format_coefficient(0.7620, 4) == "0.7620"


def test_the_torque_arc_follows_the_torque_and_is_capped():
    from feelflow.app.model.readouts import TORQUE_ARC_CAP_DEG, TORQUE_ARC_DEG, torque_arc
    from feelflow.solver import units

    reference = units.dynamic_pressure(0.1) * 16.0 ** 2
    assert torque_arc(-0.5 * reference, 16.0, 0.1) == pytest.approx(-0.5 * TORQUE_ARC_DEG)   # clockwise
    assert torque_arc(100 * reference, 16.0, 0.1) == TORQUE_ARC_CAP_DEG
    assert torque_arc(float("nan"), 16.0, 0.1) is None and torque_arc(None, 16.0, 0.1) is None


def test_forces_table_joins_the_probes_on_the_step():
    """The window's forces CSV (readouts.forces_table): the lattice table as it is without
    probes or SI units; a probe's columns on the rows of the steps it sampled, blank elsewhere
    (the SI columns: tests/test_gui_units.py)."""
    from feelflow.app.model.display_units import DisplayUnits
    from feelflow.app.model.probes import Probes

    h, length = history(n=4), ReferenceLength(20.0)
    plain = readouts.forces_csv(h, ["momentum_exchange"], length)
    assert readouts.forces_table(h, ["momentum_exchange"], length, Probes(), DisplayUnits()) == plain
    probes = Probes()
    probes.add(2.0, 2.0, 8, 8)
    field = np.zeros((8, 8, 4))
    field[..., 0], field[..., 1] = 1.0, 0.03
    probes.sample(10, field, 1.0)   # the second sample's step only
    rows = list(csv.DictReader(io.StringIO(readouts.forces_table(h, ["momentum_exchange"], length, probes))))
    assert [row["probe1_ux"] for row in rows] == ["", "0.03", "", ""]
    assert rows[1]["momentum_exchange_cd"] == list(csv.DictReader(io.StringIO(plain)))[1]["momentum_exchange_cd"]


def test_settled_drag_keeps_only_the_samples_held_long_enough():
    """History.settled_drag: the drag-against-speed view fits settled samples only."""
    h = History()
    for k in range(30):
        h.add(100 * k, (0.0, 0.0), (0.05, 0.0), {"momentum_exchange": (0.02, 0.0)})
    speed, drag = h.settled_drag("momentum_exchange")
    assert len(speed) == sum(h.settled) > 0 and len(speed) < len(h)
    assert np.allclose(speed, 0.05) and np.allclose(drag, 0.02)
