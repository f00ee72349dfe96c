"""Physical units (solver/units.py PhysicalUnits, app/model/display_units.py): the lattice flow
read as water or air with the same Reynolds number; every conversion against its formula from
the fluid's properties, the SI columns of a CSV, and `feelflow run --si` as a user meets it."""
from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pytest

from feelflow.app.model.display_units import DisplayUnits, UnitsChoice, parse_si, si_columns
from feelflow.solver.units import FLUIDS, PhysicalUnits, reynolds

ROOT = Path(__file__).resolve().parents[1]


def test_water_past_a_centimetre_body_has_the_lattice_reynolds_number():
    water = FLUIDS["water"]
    assert math.isclose(water.density, 998.0) and math.isclose(water.viscosity, 1.0e-3 / 998.0)
    u = PhysicalUnits(water, size_m=0.01, span_m=0.1, size_cells=24, speed=0.05, nu=0.012)
    re = reynolds(0.05, 24, 0.012)
    assert math.isclose(u.reynolds, re)
    assert math.isclose(u.wind_m_s * 0.01 / water.viscosity, re)            # same Re in water
    assert math.isclose(u.velocity(0.05), u.wind_m_s)                         # the wind converts to it
    assert math.isclose(u.viscosity(0.012), water.viscosity)                  # and nu to water's
    dx, dt = 0.01 / 24, 0.05 * (0.01 / 24) / u.wind_m_s
    assert math.isclose(u.dx, dx) and math.isclose(u.dt, dt) and math.isclose(u.time(1000), 1000 * dt)
    assert math.isclose(u.force(0.02), 0.02 * 998.0 * dx ** 3 * 0.1 / dt ** 2)
    assert math.isclose(u.pressure(0.001), 0.001 * 998.0 * (dx / dt) ** 2)
    assert "water at 1 cm/s past a 1 cm body" in u.describe()
    with pytest.raises(ValueError, match="size_m"):
        PhysicalUnits(water, 0.0, 0.1, 24, 0.05, 0.012)


def test_si_columns_beside_the_lattice_ones():
    u = DisplayUnits(PhysicalUnits(FLUIDS["air"], 0.05, 0.2, 20, 0.05, 0.01))
    head, rows = si_columns(["step", "x", "vx", "fx_momentum_exchange", "ref_length_cells"],
                            [[100, "10", "0.01", "0.002", "20"]], u)
    assert head[5:] == ["time_s", "x_m", "vx_m_s", "fx_momentum_exchange_N"]
    ph = u.physical
    assert [float(v) for v in rows[0][5:]] == pytest.approx([100 * ph.dt, 10 * ph.dx, ph.velocity(0.01),
                                                             ph.force(0.002)], rel=1e-7)
    lattice = DisplayUnits()
    assert lattice.force(3.0) == 3.0 and lattice.force_unit == "lattice units" and not lattice.is_si


def test_parse_si_and_the_choice():
    assert parse_si("water:0.01") == UnitsChoice("water", 0.01, 0.1)
    assert parse_si("oil:0.05:0.3") == UnitsChoice("oil", 0.05, 0.3)
    for bad in ("mud:1", "water", "water:-1", "water:x", "air:1:2:3"):
        with pytest.raises(ValueError, match="--si"):
            parse_si(bad)
    with pytest.raises(ValueError):
        UnitsChoice("mercury")


def test_run_si_bad_value_is_one_line(tmp_path):
    r = subprocess.run([sys.executable, "-m", "feelflow.app", "run", "scenes/default.toml", "--si", "mud:1",
                        "--out", str(tmp_path / "f.csv")], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "--si: give FLUID:SIZE_M" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "f.csv").exists()


def test_a_session_file_checks_its_recorded_units():
    """The optional manifest key `units` (app/sessions/format.py): absent is None; a bad value is
    one SessionError line naming it."""
    from feelflow.app.sessions.format import SessionError, _validate_units

    assert _validate_units(None) is None
    assert _validate_units({"fluid": "air", "size_m": 0.05, "span_m": 1}) == {"fluid": "air", "size_m": 0.05,
                                                                              "span_m": 1.0}
    for bad, what in (({"fluid": "mud", "size_m": 1, "span_m": 1}, "units.fluid"),
                      ({"fluid": "water", "size_m": -1, "span_m": 1}, "units.size_m"),
                      ({"fluid": "water", "size_m": 0.01, "span_m": float("nan")}, "units.span_m"),
                      ({"fluid": "water"}, "exactly"), ("water", "exactly")):
        with pytest.raises(SessionError, match=what):
            _validate_units(bad)


def test_no_wind_still_has_a_cell_and_a_step():
    u = PhysicalUnits(FLUIDS["water"], 0.01, 0.1, 24, 0.0, 0.012)
    assert u.wind_m_s == 0.0 and math.isclose(u.dt, 0.012 * (0.01 / 24) ** 2 / FLUIDS["water"].viscosity)
    assert math.isclose(u.lattice_velocity(u.velocity(0.04)), 0.04)
