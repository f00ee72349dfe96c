"""Geometry of the bodies: containment, frontal area, surface elements (closed-surface identities)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from feelflow.shapes import Cylinder, FlatPlate, HalfAirfoil, Polygon, Wedge
from feelflow.shapes.polygon import naca_half_thickness, polygon_area_centroid

ALL = [
    Cylinder(20.0, x=50.0, y=40.0, angle=0.3),
    Polygon([[0, 0], [10, 0], [10, 4], [4, 4], [4, 10], [0, 10]], x=30.0, y=20.0, angle=0.7),  # L shape
    FlatPlate(16.0, 0.2, x=40.0, y=40.0, angle=0.4),
    Wedge(20.0, math.radians(40), "upstream", x=40.0, y=40.0, angle=-0.2),
    Wedge(20.0, math.radians(120), "downstream", x=40.0, y=40.0),
    HalfAirfoil(40.0, 6.0, x=40.0, y=40.0, angle=0.1),
]


def _perimeter(shape):
    if isinstance(shape, Cylinder):
        return math.pi * shape.diameter
    v = shape.world_vertices
    return float(np.hypot(*(np.roll(v, -1, axis=0) - v).T).sum())


def _area(shape):
    return math.pi * shape.diameter**2 / 4 if isinstance(shape, Cylinder) else shape.area


@pytest.mark.parametrize("shape", ALL, ids=lambda s: s.kind)
@pytest.mark.parametrize("spacing", [0.5, 1.7])
def test_surface_elements_close_the_surface(shape, spacing):
    pts, nrm, dl = shape.surface_elements(spacing)
    assert pts.shape == nrm.shape == (len(dl), 2)
    np.testing.assert_allclose(np.hypot(nrm[:, 0], nrm[:, 1]), 1.0)
    assert dl.max() <= spacing + 1e-12
    assert dl.sum() == pytest.approx(_perimeter(shape), rel=1e-12)
    np.testing.assert_allclose((nrm * dl[:, None]).sum(axis=0), 0.0, atol=1e-9 * dl.sum())
    # divergence theorem: area = 1/2 closed-integral of x . n dl
    assert 0.5 * ((pts * nrm).sum(axis=1) * dl).sum() == pytest.approx(_area(shape), rel=1e-9)
    # outward: a point a little along the normal is outside, a little against it inside
    # (skip the plate: 0.2 thick, its inward probe would cross it)
    if not isinstance(shape, FlatPlate):
        assert not shape.contains(*(pts + 1e-3 * nrm).T).any()
        assert shape.contains(*(pts - 1e-3 * nrm).T).all()


def test_frontal_area():
    assert Cylinder(12.0).frontal_area((1, 0)) == 12.0
    assert Cylinder(12.0).frontal_area((0.3, -2.0)) == 12.0
    plate = FlatPlate(10.0, 0.5)
    assert plate.frontal_area((1, 0)) == pytest.approx(10.0)      # normal to the flow at angle 0
    assert plate.moved(angle=math.pi / 2).frontal_area((1, 0)) == pytest.approx(0.5)
    assert plate.frontal_area(math.pi / 2) == pytest.approx(0.5)  # direction as an angle
    # plate at 30 degrees: projection of a rectangle
    th = math.radians(30)
    assert plate.moved(angle=th).frontal_area((1, 0)) == pytest.approx(10 * math.cos(th) + 0.5 * math.sin(th))
    wedge = Wedge(10.0, math.radians(60))
    assert wedge.frontal_area((1, 0)) == pytest.approx(2 * 10 * math.tan(math.radians(30)))
    assert wedge.frontal_area((0, 1)) == pytest.approx(10.0)
    assert HalfAirfoil(30.0, 4.0).frontal_area((1, 0)) == pytest.approx(4.0, rel=1e-3)


def test_parametric_reference_point_is_the_centroid():
    for shape in ALL[2:]:
        area, cx, cy = polygon_area_centroid(shape.world_vertices)
        assert area == pytest.approx(shape.area) and area > 0          # counter-clockwise
        assert (cx, cy) == pytest.approx((shape.x, shape.y), abs=1e-9)


def test_wedge_and_airfoil_orientation():
    up = Wedge(12.0, math.radians(40), "upstream", x=50, y=50)
    down = Wedge(12.0, math.radians(40), "downstream", x=50, y=50)
    apex_up = up.world_vertices[np.argmin(up.world_vertices[:, 0])]
    apex_down = down.world_vertices[np.argmax(down.world_vertices[:, 0])]
    assert apex_up[1] == pytest.approx(50) and apex_down[1] == pytest.approx(50)
    assert apex_up[0] == pytest.approx(50 - 2 / 3 * 12) and apex_down[0] == pytest.approx(50 + 2 / 3 * 12)
    foil = HalfAirfoil(40.0, 6.0, x=0, y=0)
    v = foil.world_vertices
    lower = v[:, 1] == v[:, 1].min()
    assert lower.sum() == 2                                       # flat lower side: one edge
    top = v[np.argmax(v[:, 1])]
    assert top[1] - v[:, 1].min() == pytest.approx(6.0, rel=1e-3)  # max height = thickness
    assert (top[0] - v[:, 0].min()) / 40.0 == pytest.approx(0.3, abs=0.02)  # at 30 % chord (NACA)
    assert naca_half_thickness(np.array([1.0]))[0] == pytest.approx(0.0, abs=1e-12)  # closed TE


def test_bounding_box_and_outline():
    c = Cylinder(10.0, x=20.0, y=30.0)
    assert c.bounding_box() == (15.0, 25.0, 25.0, 35.0)
    o = c.outline()
    assert np.allclose(o[0], o[-1]) and np.allclose(np.hypot(o[:, 0] - 20, o[:, 1] - 30), 5.0)
    p = FlatPlate(10.0, 2.0, x=5.0, y=6.0)
    assert p.bounding_box() == pytest.approx((4.0, 1.0, 6.0, 11.0))
    assert np.allclose(p.outline()[0], p.outline()[-1]) and len(p.outline()) == 5


def test_moved_keeps_shape_and_changes_pose():
    p = HalfAirfoil(30.0, 4.0, x=10, y=10)
    q = p.moved(x=12.5, angle=0.3)
    assert (q.chord, q.thickness, q.x, q.y, q.angle) == (30.0, 4.0, 12.5, 10, 0.3)
    assert q.area == pytest.approx(p.area)


def test_polygon_from_world_puts_reference_at_centroid():
    pts = [[10, 10], [20, 10], [20, 14], [10, 14]]
    p = Polygon.from_world(pts, angle=0.5)
    assert (p.x, p.y) == pytest.approx((15, 12))
    assert sorted(map(tuple, np.round(p.world_vertices, 9))) == sorted(map(tuple, np.array(pts, float)))
