"""NACA 4-digit sections (shapes/naca.py) against the formulas of Abbott & von Doenhoff (1959,
sec. 6.4): symmetry of the 0012, the 4412's mean line, the area against the closed form, and
the section as a body in files, scenes, the panel's list and exercises."""
from __future__ import annotations

import math

import numpy as np
import pytest

from feelflow.shapes import NacaAirfoil, ShapeError, from_dict, rasterise
from feelflow.shapes.naca import camber_line, stations, surface

#: integral over s in [0, 1] of the closed-trailing-edge thickness polynomial (per unit 5 t):
#: 0.2969 * 2/3 - 0.1260 / 2 - 0.3516 / 3 + 0.2843 / 4 - 0.1036 / 5
HALF_AREA_INTEGRAL = 0.2969 * 2 / 3 - 0.1260 / 2 - 0.3516 / 3 + 0.2843 / 4 - 0.1036 / 5


def test_naca0012_is_symmetric_about_its_chord():
    foil = NacaAirfoil.from_digits("0012", 60.0)
    v = foil.local_vertices
    mirrored = v * [1.0, -1.0]
    # every vertex has its mirror image among the vertices
    d = np.hypot(*(v[:, None, :] - mirrored[None, :, :]).transpose(2, 0, 1)).min(axis=1)
    assert d.max() < 1e-9
    nose, tail = foil.leading_trailing_edges()
    assert nose[1] == pytest.approx(0.0, abs=1e-9) and tail[1] == pytest.approx(0.0, abs=1e-9)
    assert tail[0] - nose[0] == pytest.approx(60.0, rel=1e-12)
    # maximum thickness 12 % of the chord, at 30 % (Abbott & von Doenhoff: x = 0.30 c)
    assert np.ptp(v[:, 1]) == pytest.approx(0.12 * 60.0, rel=2e-3)


def test_naca4412_mean_line_is_midway_between_the_sides():
    s = stations(80.0)
    (xu, yu), (xl, yl) = surface(s, 0.12, 0.04, 0.4)
    yc, _ = camber_line(s, 0.04, 0.4)
    # thickness is laid off normal to the mean line, so the sides' midpoints lie on it
    assert np.allclose(0.5 * (xu + xl), s, atol=1e-12) and np.allclose(0.5 * (yu + yl), yc, atol=1e-12)
    # hand values of y_c / c for m = 0.04, p = 0.4: 0.03 at 0.2 and 0.7, the maximum 0.04 at 0.4
    assert camber_line(np.array([0.2, 0.4, 0.7, 1.0]), 0.04, 0.4)[0] == pytest.approx([0.03, 0.04, 0.03, 0.0])
    # the slope changes sign at the maximum and is continuous there
    _, slope = camber_line(np.array([0.4 - 1e-9, 0.4 + 1e-9]), 0.04, 0.4)
    assert abs(slope).max() < 1e-6
    foil = NacaAirfoil.from_digits("NACA 4412", 80.0)
    assert (foil.thickness, foil.camber, foil.camber_position) == (0.12, 0.04, 0.4) and foil.digits == "4412"


@pytest.mark.parametrize("digits, rel", [("0012", 2e-4), ("0024", 2e-4), ("4412", 5e-3)])
def test_area_against_the_closed_form(digits, rel):
    """Symmetric: A = 2 * 5 t c^2 * integral = 0.6809 t c^2; the camber line moves thickness
    sideways but leaves the area equal to first order in the camber."""
    foil = NacaAirfoil.from_digits(digits, 100.0)
    expected = 10.0 * HALF_AREA_INTEGRAL * foil.thickness * 100.0 ** 2
    assert HALF_AREA_INTEGRAL * 10 == pytest.approx(0.68088, abs=1e-5)
    assert foil.area == pytest.approx(expected, rel=rel)


def test_rasterised_area_and_pose():
    foil = NacaAirfoil.from_digits("4412", 40.0, x=50.3, y=30.2, angle=math.radians(-8))
    r = rasterise(foil, 100, 60)
    assert r.solid.sum() == pytest.approx(foil.area, rel=0.05)
    nose, tail = foil.leading_trailing_edges()
    assert nose[0] < tail[0] and nose[1] > tail[1]   # angle -8 degrees: nose up, 8 degrees of incidence
    assert math.degrees(math.atan2(nose[1] - tail[1], tail[0] - nose[0])) == pytest.approx(8.0, abs=1e-9)


@pytest.mark.parametrize("kwargs, message", [
    ({"thickness": 0.0}, "naca thickness must be between"),
    ({"thickness": 0.5}, "naca thickness must be between"),
    ({"camber": -0.01}, "naca camber must be between"),
    ({"camber": 0.04, "camber_position": 0.0}, "naca camber_position must be between"),
    ({"thickness": "thin"}, "naca thickness must be a number"),
])
def test_bad_parameters_are_one_line(kwargs, message):
    with pytest.raises(ShapeError, match=message):
        NacaAirfoil(40.0, **kwargs)


@pytest.mark.parametrize("digits", ["12", "44x2", "4012"])
def test_bad_designation(digits):
    with pytest.raises(ShapeError):
        NacaAirfoil.from_digits(digits, 40.0)


def test_dict_round_trip_and_defaults():
    foil = NacaAirfoil(40.0, 0.15, 0.02, 0.3, x=60.0, y=40.0, angle=-0.1)
    assert from_dict(foil.to_dict()) == foil
    plain = from_dict({"kind": "naca", "chord": 40.0, "thickness": 0.12, "x": 60.0, "y": 40.0})
    assert plain.camber == 0.0 and plain.digits == "0012"


def test_scene_panel_and_exercise_know_the_kind(tmp_path):
    from feelflow.app.exercises.format import EDIT_KINDS
    from feelflow.app.model.bodies import SHAPE_LABELS, make_shape, params_for_shape
    from feelflow.app.model.scene import load_scene

    scene = tmp_path / "foil.toml"
    scene.write_text('[grid]\nnx = 200\nny = 80\n[flow]\nnu = 0.02\ninflow_speed = 0.05\n'
                     '[body]\nkind = "naca"\nchord = 40\nthickness = 0.12\ncamber = 0.04\ncamber_position = 0.4\n'
                     'x = 60\ny = 40\nangle = -4\n[run]\nsteps = 10\n')
    body = load_scene(scene).body
    assert body.digits == "4412" and body.angle == pytest.approx(math.radians(-4))
    kind, size, _ = params_for_shape(body)
    assert kind == "naca4412" and kind in SHAPE_LABELS and size == 40.0

    from types import SimpleNamespace

    assert make_shape(SimpleNamespace(shape=kind, size=size), None, body.x, body.y, body.angle) == body
    assert "naca" in EDIT_KINDS
    with pytest.raises(ValueError, match="cannot be edited here"):
        params_for_shape(NacaAirfoil(40.0, 0.13))


def test_an_exercise_may_offer_naca_sections():
    import tomllib
    from pathlib import Path

    from feelflow.app.exercises.format import exercise_from_dict

    path = Path(__file__).resolve().parents[1] / "exercises" / "lift_to_drag.toml"
    data = tomllib.loads(path.read_text())
    data["edit"]["kinds"] = ["half_airfoil", "naca"]
    assert list(exercise_from_dict(data, str(path), path).kinds) == ["half_airfoil", "naca"]
