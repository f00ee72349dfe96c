"""Rasterisation: exact cut fractions against hand computations, and the lattice invariants of
docs/science/algorithm.md ('Links cut by the body')."""
from __future__ import annotations

import math

import numpy as np
import pytest

from feelflow.shapes import Cylinder, FlatPlate, HalfAirfoil, NacaAirfoil, Polygon, Wedge, rasterise
from feelflow.shapes.raster import LINKS
from feelflow.solver.lattice import C, OPP

E, N, W, S, NE, NW, SW, SE = 1, 2, 3, 4, 5, 6, 7, 8


def _circle_poly(r, k=40, **pose):
    th = np.linspace(0.0, 2 * math.pi, k + 1)[:-1]
    return Polygon(np.column_stack([r * np.cos(th), r * np.sin(th)]), **pose)


SHAPES = [
    Cylinder(9.0, x=20.3, y=17.8),
    Cylinder(10.0, x=20.0, y=18.0),             # R = 5: nodes (25, 18), (23, 22) ... on the circle
    _circle_poly(6.5, x=21.7, y=18.2, angle=0.37),
    FlatPlate(12.0, 0.2, x=20.5, y=18.0, angle=0.0),
    FlatPlate(12.0, 0.3, x=20.2, y=17.9, angle=0.6),
    FlatPlate(14.0, 2.5, x=19.6, y=18.3, angle=-1.1),
    Wedge(12.0, math.radians(50), "upstream", x=20.1, y=18.4, angle=0.2),
    Wedge(12.0, math.radians(50), "downstream", x=20.1, y=18.4),
    HalfAirfoil(24.0, 4.0, x=20.4, y=18.3, angle=0.15),
    NacaAirfoil(24.0, 0.12, 0.04, 0.4, x=20.4, y=18.3, angle=-0.2),
    Polygon([[2.0, 3.0], [3.0, 3.0], [3.0, 4.0], [2.0, 4.0]], x=16.0, y=14.0),  # integer-aligned edges
    FlatPlate(10.0, 2.0, x=20.0, y=18.0, angle=math.pi / 2),                   # nodes on edges and corners
    Polygon([[0, 0], [10, 0], [10, 4], [4, 4], [4, 10], [0, 10]], x=15.0, y=12.0),  # concave, on nodes
    Polygon([[0, 0], [6, 3], [0, 6], [3, 3]], x=18.5, y=15.0),                  # arrow: vertices on nodes
]


def test_link_table_matches_solver_lattice():
    assert np.array_equal(LINKS, C)


def test_cylinder_q_axis_and_diagonal_by_hand():
    cyl = Cylinder(4.0, x=10.3, y=10.0)  # R = 2
    r = rasterise(cyl, 24, 20)
    assert not r.solid[10, 8] and r.solid[10, 12] and not r.solid[10, 13]
    assert r.q[E, 10, 8] == pytest.approx(0.3, abs=1e-12)    # wall at x = 10.3 - 2 = 8.3
    assert r.q[W, 10, 13] == pytest.approx(0.7, abs=1e-12)   # wall at x = 12.3
    # x = 10 is 0.3 off the axis: the circle's lower side there is at y = 10 - sqrt(4 - 0.3^2)
    assert r.q[N, 8, 10] == pytest.approx(10.0 - math.sqrt(4 - 0.09) - 8.0, abs=1e-12)
    assert r.q[N, 7, 10] == 0.0
    # NE link from (8, 8): (-2.3 + t)^2 + (-2 + t)^2 = 4  ->  2 t^2 - 8.6 t + 5.29 = 0
    t = (8.6 - math.sqrt(8.6**2 - 8 * 5.29)) / 4
    assert r.q[NE, 8, 8] == pytest.approx(t, abs=1e-12)
    assert r.solid[9, 9]


def test_square_with_fractional_edges_by_hand():
    sq = Polygon([[2.25, 3.4], [6.6, 3.4], [6.6, 7.75], [2.25, 7.75]])
    r = rasterise(sq, 12, 12)
    assert r.q[E, 5, 2] == pytest.approx(0.25)
    assert r.q[W, 5, 7] == pytest.approx(0.4)
    assert r.q[N, 3, 5] == pytest.approx(0.4)
    assert r.q[S, 8, 5] == pytest.approx(0.25)
    assert r.q[NE, 3, 2] == pytest.approx(0.4)     # enters through the bottom edge at (2.4, 3.4)
    assert r.q[SW, 8, 7] == pytest.approx(0.4)     # top-right corner: right edge first at t = 0.4
    assert r.q[N, 3, 7] == 0.0 and r.q[E, 2, 5] == 0.0  # links that miss
    assert r.solid[4:8, 3:7].all() and r.solid.sum() == 16


def test_rotated_plate_by_hand():
    th = math.radians(30)
    plate = FlatPlate(10.0, 0.2, x=20.3, y=20.1, angle=th)
    n = np.array([math.cos(th), math.sin(th)])      # plate normal at angle th (long side along y at 0)
    r = rasterise(plate, 40, 40)

    def hand(node, c):
        s = n @ (np.array(node, float) - [20.3, 20.1])
        face = -0.1 if s < 0 else 0.1
        return (face - s) / (n @ np.array(c, float))

    assert r.q[E, 20, 20] == pytest.approx(hand((20, 20), (1, 0)), abs=1e-12)
    assert r.q[W, 20, 21] == pytest.approx(hand((21, 20), (-1, 0)), abs=1e-12)
    assert r.q[NE, 19, 20] == pytest.approx(hand((20, 19), (1, 1)), abs=1e-12)
    assert 0 < r.q[E, 20, 20] < 1 and 0 < r.q[W, 20, 21] < 1
    assert not r.solid[20, 20] and not r.solid[20, 21]


def test_thin_plate_cuts_links_both_ways():
    plate = FlatPlate(10.0, 0.2, x=10.5, y=12.0)    # faces at x = 10.4 and 10.6, y in [7, 17]
    r = rasterise(plate, 24, 24)
    assert not r.solid.any()
    span = slice(7, 18)
    np.testing.assert_allclose(r.q[E, span, 10], 0.4)
    np.testing.assert_allclose(r.q[W, span, 11], 0.4)
    np.testing.assert_allclose(r.q[NE, 7:17, 10], 0.4)
    np.testing.assert_allclose(r.q[SW, 8:18, 11], 0.4)
    assert r.q[E, 18, 10] == 0.0 and r.q[E, 6, 10] == 0.0


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: s.kind)
def test_solid_mask_equals_contains_at_nodes(shape):
    nx, ny = 44, 36
    r = rasterise(shape, nx, ny)
    gx, gy = np.meshgrid(np.arange(nx), np.arange(ny))
    assert np.array_equal(r.solid, shape.contains(gx, gy))


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: s.kind)
def test_q_equals_exact_segment_test_on_every_fluid_node(shape):
    """The bounding-box/band shortcut loses nothing: compare with testing every link."""
    nx, ny = 44, 36
    r = rasterise(shape, nx, ny)
    gx, gy = np.meshgrid(np.arange(nx), np.arange(ny))
    for i in range(1, 9):
        full = np.where(r.solid, 0.0, shape.segment_hit(gx, gy, np.full(gx.shape, C[i, 0]), np.full(gx.shape, C[i, 1])))
        tx, ty = gx + C[i, 0], gy + C[i, 1]
        inside = (tx >= 0) & (tx < nx) & (ty >= 0) & (ty < ny)
        target_solid = np.zeros_like(r.solid)
        target_solid[inside] = r.solid[ty[inside], tx[inside]]
        full = np.where(~r.solid & target_solid & (full == 0.0), 1.0, full)
        np.testing.assert_array_equal(r.q[i], full)


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: s.kind)
def test_lattice_invariants(shape):
    nx, ny = 44, 36
    r = rasterise(shape, nx, ny, margin=2)
    assert r.q.shape == (9, ny, nx) and r.q.dtype == np.float64 and r.solid.shape == (ny, nx)
    assert np.all((r.q >= 0) & (r.q <= 1))
    assert not r.q[0].any()
    assert not r.q[:, r.solid].any()                 # only fluid nodes own links
    x0, y0, x1, y1 = r.window
    for i in range(1, 9):
        ys, xs = np.nonzero(~r.solid)
        tx, ty = xs + C[i, 0], ys + C[i, 1]
        ok = (tx >= 0) & (tx < nx) & (ty >= 0) & (ty < ny)
        into_solid = r.solid[ty[ok], tx[ok]]
        assert np.all(r.q[i, ys[ok][into_solid], xs[ok][into_solid]] > 0), "every fluid->solid link is cut"
        cy, cx = np.nonzero(r.q[i])
        for axis, (lo, hi, n, a) in enumerate(((x0, x1, nx, cx), (y0, y1, ny, cy))):
            b = a + C[i, axis]
            assert np.all(np.minimum(a, b) >= lo) and np.all(np.maximum(a, b) < hi)
            assert lo == 0 or np.all(np.minimum(a, b) >= lo + 2)       # margin, unless clipped
            assert hi == n or np.all(np.maximum(a, b) < hi - 2)
    sy, sx = np.nonzero(r.solid)
    assert np.all((sx >= x0 + 2) & (sx < x1 - 2) & (sy >= y0 + 2) & (sy < y1 - 2))
    assert x0 >= 0 and y0 >= 0 and x1 <= nx and y1 <= ny


def test_opposite_links_of_a_thin_plate_meet_the_same_wall():
    """A link cut from both ends by a plate: q_i(x) + q_ib(x + c_i) = 1 - thickness/|c| along x."""
    plate = FlatPlate(10.0, 0.2, x=10.55, y=12.0)
    r = rasterise(plate, 24, 24)
    assert r.q[E, 12, 10] + r.q[OPP[E], 12, 11] == pytest.approx(1.0 - 0.2)


def test_window_clipped_to_domain():
    cyl = Cylinder(6.0, x=3.0, y=3.0)
    r = rasterise(cyl, 20, 20, margin=4)
    assert r.window[0] == 0 and r.window[1] == 0 and r.window[2] <= 20


def _random_star(rng, k):
    th = np.sort(rng.uniform(0, 2 * math.pi, k))
    r = rng.uniform(3.0, 9.0, k)
    return np.column_stack([r * np.cos(th), r * np.sin(th)])


@pytest.mark.parametrize("seed", range(12))
def test_random_polygons_agree_with_exact_tests(seed):
    """Random star polygons at random sub-cell poses (some snapped to nodes and right angles):
    the mask is contains(), every link is the exact first crossing, fluid->solid links are cut."""
    rng = np.random.default_rng(seed)
    verts = _random_star(rng, int(rng.integers(3, 30)))
    if seed % 3 == 0:
        verts = np.round(verts)              # vertices on nodes: the round-off corner cases
        verts = verts[np.any(verts != np.roll(verts, 1, axis=0), axis=1)]
    x, y = rng.uniform(18, 26), rng.uniform(14, 22)
    angle = rng.uniform(-math.pi, math.pi) if seed % 2 else math.pi / 2 * int(rng.integers(4))
    if seed % 3 == 0:
        x, y = round(x), round(y)
    shape = Polygon(verts, x=x, y=y, angle=angle).validate(44, 36)
    test_solid_mask_equals_contains_at_nodes(shape)
    test_q_equals_exact_segment_test_on_every_fluid_node(shape)
    test_lattice_invariants(shape)


@pytest.mark.parametrize("shape", [SHAPES[0], SHAPES[5], SHAPES[11]])
def test_raster_is_held_on_the_body_box_and_crops_like_the_full_grid(shape):
    """A move costs the body's size, not the grid's: the raster keeps its bounding box (grown by a
    cell) only, and crop() of any window, inside, across or outside that box, equals the slice of
    the full-grid arrays (zero where the box does not reach)."""
    nx, ny = 400, 300
    r = rasterise(shape, nx, ny)
    x0, y0, x1, y1 = r.box
    assert (x1 - x0) * (y1 - y0) < 40 * 40 and r.box_q.shape == (9, y1 - y0, x1 - x0)
    for win in [r.window, (0, 0, nx, ny), (x0 - 3, y0 + 2, x1 - 4, y1 + 5), (x1 + 1, y1 + 1, x1 + 9, y1 + 4)]:
        wx0, wy0, wx1, wy1 = max(0, win[0]), max(0, win[1]), min(nx, win[2]), min(ny, win[3])
        solid, q = r.crop((wx0, wy0, wx1, wy1))
        assert np.array_equal(solid, r.solid[wy0:wy1, wx0:wx1])
        assert np.array_equal(q, r.q[:, wy0:wy1, wx0:wx1])
    assert r.solid.shape == (ny, nx) and r.q.shape == (9, ny, nx)
    assert r.solid.sum() == r.box_solid.sum() and np.count_nonzero(r.q) == np.count_nonzero(r.box_q)
