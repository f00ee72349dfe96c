"""solver/units.py against hand computations."""
import math

import pytest

from feelflow.solver import units


def test_reynolds_and_viscosity_are_inverse():
    nu = units.viscosity_for_reynolds(100.0, 0.05, 20.0)
    assert nu == pytest.approx(0.01)
    assert units.reynolds(0.05, 20.0, nu) == pytest.approx(100.0)


def test_mach_uses_lattice_sound_speed():
    assert units.mach(1 / math.sqrt(3)) == pytest.approx(1.0)
    assert units.speed_for_mach(0.17) == pytest.approx(0.17 / math.sqrt(3))


def test_tau_from_viscosity_seed_eq5():
    assert units.tau_for_viscosity(1 / 6) == pytest.approx(1.0)


def test_force_coefficients_schaefer_turek_definition():
    # C_D = 2 F / (rho U^2 D): F = 0.5 * 1 * 0.04 * 0.1 * C
    cd, cl = units.drag_lift_coefficients((0.5 * 0.04 * 0.1 * 5.58, 0.5 * 0.04 * 0.1 * 0.0106), 0.2, 0.1)
    assert cd == pytest.approx(5.58)
    assert cl == pytest.approx(0.0106)


def test_pressure_difference_coefficient_and_pressure():
    assert units.pressure(1.03) == pytest.approx(1.03 / 3)
    assert units.pressure_difference_coefficient(0.1175, 0.2) == pytest.approx(0.1175 / 0.04)


def test_strouhal():
    assert units.strouhal(1 / 2000, 20, 0.05) == pytest.approx(0.2)


def test_newton_scale_of_a_physical_fluid():
    s = units.NewtonScale.physical(dx_m=0.001, dt_s=0.01, rho_kg_m3=1000.0, depth_m=0.1)
    # one cell of water 1 mm x 1 mm x 0.1 m (1e-4 kg) accelerated by 1 mm / (0.01 s)^2 = 10 m/s^2
    assert s.newtons(1.0) == pytest.approx(1e-3)
    assert s.newtons((2.0, -1.0)) == pytest.approx((2e-3, -1e-3))
    with pytest.raises(ValueError, match="dx_m"):
        units.NewtonScale.physical(dx_m=-1, dt_s=1, rho_kg_m3=1, depth_m=1)
