"""Invalid geometry is refused with a one-line message naming the problem."""
from __future__ import annotations

import math

import numpy as np
import pytest

from feelflow.shapes import Cylinder, FlatPlate, HalfAirfoil, Polygon, ShapeError, Wedge

SQUARE = [[0, 0], [4, 0], [4, 4], [0, 4]]


def _refused(make, *words):
    with pytest.raises(ShapeError) as err:
        make()
    msg = str(err.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, msg
    return msg


def test_fewer_than_three_vertices():
    _refused(lambda: Polygon([[0, 0], [1, 1]]), "at least 3 vertices", "got 2")


def test_self_intersecting():
    _refused(lambda: Polygon([[0, 0], [4, 4], [4, 0], [0, 4]]).validate(), "self-intersecting")
    _refused(lambda: Polygon([[0, 0], [4, 0], [8, 0], [2, 0], [2, 4]]).validate(), "self-intersecting")


def test_zero_area():
    _refused(lambda: Polygon([[0, 0], [2, 0], [5, 0]]).validate(), "zero area")


def test_repeated_vertex():
    _refused(lambda: Polygon([[0, 0], [4, 0], [4, 0], [0, 4]]).validate(), "repeated vertex")


@pytest.mark.parametrize("make,word", [
    (lambda: Polygon([[0, 0], [4, math.nan], [0, 4]]), "vertex 1 is not finite"),
    (lambda: Cylinder(math.inf), "diameter"),
    (lambda: Cylinder(4, x=math.nan), "cylinder x"),
    (lambda: FlatPlate(4, 1, angle=math.inf), "plate angle"),
    (lambda: Wedge(4, math.nan), "apex_angle"),
    (lambda: HalfAirfoil(10, "thick"), "thickness must be a number"),
])
def test_non_finite_numbers(make, word):
    _refused(make, word)


@pytest.mark.parametrize("make,word", [
    (lambda: Cylinder(0), "cylinder diameter must be positive"),
    (lambda: FlatPlate(-3, 1), "plate length must be positive"),
    (lambda: FlatPlate(5, 0), "plate thickness must be positive"),
    (lambda: Wedge(-1, 1.0), "wedge length must be positive"),
    (lambda: HalfAirfoil(10, -1), "half_airfoil thickness must be positive"),
])
def test_non_positive_sizes(make, word):
    _refused(make, word)


@pytest.mark.parametrize("apex", [0.0, math.pi, -0.5, 4.0])
def test_apex_angle_out_of_range(apex):
    _refused(lambda: Wedge(10, apex), "apex_angle", "between 0 and pi")


def test_wedge_pointing():
    _refused(lambda: Wedge(10, 1.0, "sideways"), "pointing", "sideways")


def test_smaller_than_two_cells():
    _refused(lambda: Cylinder(1.5).validate(), "smaller than 2 cells")
    _refused(lambda: Polygon([[0, 0], [1.5, 0], [0, 1.5]]).validate(), "smaller than 2 cells")
    FlatPlate(2.0, 0.05).validate()                   # thin but 2 cells long: fine


def test_not_inside_the_domain():
    Cylinder(10, x=20, y=20).validate(64, 32)
    _refused(lambda: Cylinder(10, x=20, y=28).validate(64, 32), "not inside the domain", "64x32")
    _refused(lambda: Polygon(SQUARE, x=-1, y=5).validate(64, 32), "not inside the domain")
    _refused(lambda: FlatPlate(20, 1, x=60, y=16, angle=math.pi / 2).validate(64, 32), "not inside the domain")


def test_valid_shapes_pass_and_return_themselves():
    for s in (Cylinder(8, x=20, y=20), Polygon(SQUARE, x=10, y=10), FlatPlate(10, 0.2, x=20, y=20),
              Wedge(10, 1.0, "downstream", x=20, y=20), HalfAirfoil(20, 3, x=20, y=20)):
        assert s.validate(64, 48) is s


@pytest.mark.parametrize("shape", [FlatPlate(10, 0.01), FlatPlate(3, 40), Wedge(10, 0.01), Wedge(10, 3.1),
                                   Wedge(5, 2.0, "downstream"), HalfAirfoil(10, 0.05), HalfAirfoil(300, 30)],
                         ids=lambda s: s.kind)
def test_parametric_bodies_are_simple_polygons(shape):
    """validate() trusts parametric bodies to be simple: check that they are."""
    shape.check_polygon()


def test_many_vertex_polygon_validates():
    th = np.linspace(0, 2 * math.pi, 1001)[:-1]
    Polygon(np.column_stack([100 * np.cos(th), 100 * np.sin(th)])).validate()
    th[500] = th[10]                            # one vertex jumps back across the circle
    with pytest.raises(ShapeError, match="self-intersecting"):
        Polygon(np.column_stack([100 * np.cos(th), 100 * np.sin(th)])).validate()


@pytest.mark.parametrize("direction", [(0, 0), (1, math.nan), "east", (1, 2, 3)])
def test_bad_flow_direction(direction):
    _refused(lambda: Cylinder(8).frontal_area(direction), "flow direction")
    _refused(lambda: FlatPlate(8, 1).frontal_area(direction), "flow direction")
