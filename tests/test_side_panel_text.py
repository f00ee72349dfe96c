"""The side panel's numbers in the units shown, Qt-free (app/model/side_panel_text.py)."""
import math

import pytest

from feelflow.app.model import side_panel_text as text
from feelflow.app.model.display_units import DisplayUnits
from feelflow.solver.units import FLUIDS, PhysicalUnits

LATTICE = DisplayUnits()
WATER = DisplayUnits(PhysicalUnits(FLUIDS["water"], 0.01, 0.1, 20.0, 0.05, 0.02))


def test_force_pair_has_one_precision_and_no_noise_in_scientific_notation():
    assert text.force_pair_text(0.5812, -5.6e-10) == ("0.5812", "0.0000")
    assert text.force_pair_text(12.345, 0.02) == ("12.35", "0.02")
    assert text.force_pair_text(0.0, 1e-12) == ("0", "0")
    assert text.force_texts(0.5812, -0.1, LATTICE) == ("0.5812 (lattice units)", "-0.1000 (lattice units)")
    assert text.force_texts(None, 0.1, LATTICE) == ("\u2013", "\u2013")
    assert text.force_texts(math.nan, 0.1, WATER) == ("\u2013", "\u2013")


def test_forces_in_si_are_newtons_to_four_digits():
    d, l_ = text.force_texts(0.5, 0.25, WATER)
    assert d == f"{WATER.force(0.5):.4g} (N)" and l_ == f"{WATER.force(0.25):.4g} (N)"
    assert WATER.force(0.5) != 0.5


def test_flow_boxes_in_lattice_units_and_si():
    assert text.wind_range(LATTICE) == text.WIND_LATTICE and text.viscosity_range(LATTICE) == text.VISCOSITY_LATTICE
    assert text.wind_tip(LATTICE, 0.05) == text.WIND_TIP and text.viscosity_tip(LATTICE, 0.02) == text.VISCOSITY_TIP
    r = text.wind_range(WATER)
    assert r.suffix == " m/s" and r.maximum == pytest.approx(WATER.speed(0.09))
    assert r.step == pytest.approx(WATER.speed(0.005))
    assert 3 - math.floor(math.log10(r.maximum)) == r.decimals or r.decimals in (0, 12)
    assert text.viscosity_range(WATER) == text.VISCOSITY_SI
    assert "water" in text.wind_tip(WATER, 0.05) and "0.05 cells per step" in text.wind_tip(WATER, 0.05)
    assert "fixes it" in text.viscosity_tip(WATER, 0.02) and "0.02 cells\u00b2 per step" in text.viscosity_tip(WATER, 0.02)


def test_decimals_for_give_four_significant_digits():
    assert text.decimals_for(0.09) == 5 and text.decimals_for(2.5) == 3 and text.decimals_for(1234.0) == 0
    assert text.decimals_for(0.0) == 3 and text.decimals_for(1e-20) == 12


def test_physical_reading_names_the_fluid_and_the_lattice_values():
    assert text.physical_text(LATTICE) == ""
    t = text.physical_text(WATER)
    assert "water" in t and "0.05 cells/step" in t and "0.02 cells²/step" in t
