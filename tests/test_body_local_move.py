"""A body move works on the body's box only, and the compiled move of the cpu backend
(solver/body_compiled.py) equals the numpy reference (solver/body.py, solver/bouzidi.py,
shapes/raster.py).

- the compiled raster (cylinders, plates, wedges, airfoils, polygons) and links equal the
  reference bit for bit, at poses on and just off a node row, across a cell edge, against the
  domain's edge, and across a periodic seam;
- a move's refill over its window (both poses' raster windows grown by a node) equals the same
  refill over the whole grid, for a sub-cell move, a fast jump of several cells (a window cut
  to the new pose alone would leave the old pose's nodes solid) and beside a wall;
- the compiled boundary-pass node list holds exactly the link nodes with their direction bits.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from feelflow.shapes import Cylinder, FlatPlate, Polygon
from feelflow.shapes.naca import NacaAirfoil
from feelflow.shapes.polygon import HalfAirfoil, Wedge
from feelflow.shapes.raster import rasterise
from feelflow.solver import body_compiled
from feelflow.solver.body import expand_box, make_body_state, move_body, refill, shifted, unshifted
from feelflow.solver.bouzidi import build_links, periodic_wrap
from feelflow.solver.config import FlowConfig
from feelflow.solver.lattice import C, Q, W, equilibrium

NX, NY = 96, 64
#: (x, y, diameter): inside, centred on a node (tangent rows), just either side of a cell edge,
#: cut by the domain's edges, small
POSES = [(40.37, 30.21, 12.0), (40.0, 30.0, 12.0), (40.999999999, 30.5, 12.0), (41.000000001, 30.5, 12.0),
         (6.1, 31.3, 16.0), (90.2, 58.7, 14.0), (20.5, 3.2, 9.0), (50.25, 40.75, 2.3)]
LINK_FIELDS = ("i", "ib", "iy", "ix", "fy", "fx", "q", "uw", "a", "b", "c", "d")


def _random_poses(n=20, seed=7):
    rng = np.random.default_rng(seed)
    return [(rng.uniform(0, NX), rng.uniform(0, NY), rng.uniform(1.0, 24.0)) for _ in range(n)]


@pytest.mark.parametrize("pose", POSES + _random_poses())
def test_compiled_cylinder_raster_and_links_equal_the_reference(pose):
    x, y, d = pose
    shape = Cylinder(d, x=x, y=y)
    ref, fast = rasterise(shape, NX, NY, 0), body_compiled.raster(shape, NX, NY)
    assert (fast.box, fast.window) == (ref.box, ref.window)
    assert np.array_equal(fast.box_solid, ref.box_solid) and np.array_equal(fast.box_q, ref.box_q)
    window = expand_box(ref.window, 2, NX, NY)
    solid, q = ref.crop(window)
    for wrap in ((False, False), (True, True)):
        a = build_links(q, solid, window[0], window[1], (x, y), (-0.04, 0.01), 0.003, wrap)
        b = body_compiled.build_links(q, solid, window[0], window[1], (x, y), (-0.04, 0.01), 0.003, wrap)
        assert len(a) > 0
        for name in LINK_FIELDS:
            assert np.array_equal(getattr(a, name), getattr(b, name)), name


def _polygonal_shapes():
    """Each polygonal kind at random poses and angles, and on node rows and at 45 degrees."""
    rng = np.random.default_rng(11)
    out = [FlatPlate(10.0, 1.0, x=40.0, y=30.0), FlatPlate(10.0, 1.0, x=40.5, y=30.5, angle=np.pi / 4),
           Polygon(np.array([[0, 0], [8, 0], [8, 8], [0, 8]], float), x=40.0, y=30.0),
           Polygon(np.array([[0, 0], [8, 0], [8, 8], [0, 8]], float), x=3.0, y=2.0)]
    for _ in range(4):
        x, y, a = rng.uniform(20, 76), rng.uniform(16, 48), rng.uniform(-3.2, 3.2)
        th = np.sort(rng.uniform(0, 2 * np.pi, 9))
        r = rng.uniform(4, 12, 9)
        out += [FlatPlate(rng.uniform(3, 30), rng.uniform(0.1, 2.0), x=x, y=y, angle=a),
                Wedge(rng.uniform(5, 25), rng.uniform(0.3, 1.5), x=x, y=y, angle=a),
                HalfAirfoil(rng.uniform(10, 30), rng.uniform(0.05, 0.3), x=x, y=y, angle=a),
                NacaAirfoil(rng.uniform(10, 30), 0.12, camber=0.04, x=x, y=y, angle=a),
                Polygon(np.column_stack([r * np.cos(th), r * np.sin(th)]), x=x, y=y, angle=a)]
    return out


@pytest.mark.parametrize("shape", _polygonal_shapes(), ids=lambda s: s.kind)
def test_compiled_polygon_raster_equals_the_reference(shape):
    ref, fast = rasterise(shape, NX, NY, 0), body_compiled.raster(shape, NX, NY)
    assert (fast.box, fast.window) == (ref.box, ref.window)
    assert np.array_equal(fast.box_solid, ref.box_solid) and np.array_equal(fast.box_q, ref.box_q)
    assert ref.box_q.any()


@pytest.mark.parametrize("pose", [(40.999999999, 30.5), (41.000000001, 30.5), (6.1, 31.3), (30.4, 6.3)])
def test_window_links_equal_the_whole_grid_links(pose):
    """The links a move builds on the force window (numpy and compiled) are those of the whole
    grid's mask and cut fractions, node for node, across a cell edge and beside the walls."""
    cfg = FlowConfig(nx=NX, ny=NY)
    shape = Cylinder(12.0, x=pose[0], y=pose[1])
    whole = build_links(rasterise(shape, NX, NY, 0).q, rasterise(shape, NX, NY, 0).solid, 0, 0, (shape.x, shape.y),
                        (0.03, -0.01), 0.002)
    for builders in ({}, dict(links=body_compiled.build_links, rasteriser=body_compiled.raster)):
        body = make_body_state(shape, (0.03, -0.01), 0.002, cfg, 2, **builders)
        L, (x0, y0) = body.links, body.window[:2]
        assert len(L) == len(whole) > 0
        for name in ("i", "q", "uw", "a", "b", "c", "d"):
            assert np.array_equal(getattr(L, name), getattr(whole, name)), name
        assert np.array_equal(L.iy + y0, whole.iy) and np.array_equal(L.ix + x0, whole.ix)
        assert np.array_equal(L.fy + y0, whole.fy) and np.array_equal(L.fx + x0, whole.fx)


def test_compiled_links_across_a_periodic_seam():
    """A window that spans the periodic x direction whole takes second nodes across the seam."""
    cfg = FlowConfig(nx=16, ny=32, x_boundary="periodic", y_boundary="periodic")
    ref = make_body_state(Cylinder(14.0, x=7.6, y=16.4), (0.02, 0.0), 0.0, cfg, 2)
    fast = make_body_state(Cylinder(14.0, x=7.6, y=16.4), (0.02, 0.0), 0.0, cfg, 2,
                           links=body_compiled.build_links, rasteriser=body_compiled.raster)
    assert periodic_wrap(cfg, ref.window)[0]
    assert (ref.links.fx != ref.links.ix + C[ref.links.i, 0]).any()   # some second node wraps
    for name in LINK_FIELDS:
        assert np.array_equal(getattr(ref.links, name), getattr(fast.links, name)), name


def _disturbed_state(cfg, seed=3):
    """Full f (9, ny, nx) float64: a stream with noise, so that every node differs."""
    rng = np.random.default_rng(seed)
    rho = 1.0 + 0.01 * rng.standard_normal((cfg.ny, cfg.nx))
    ux = 0.03 + 0.01 * rng.standard_normal((cfg.ny, cfg.nx))
    uy = 0.01 * rng.standard_normal((cfg.ny, cfg.nx))
    return equilibrium(rho, ux, uy).astype(np.float64) + 1e-4 * rng.standard_normal((Q, cfg.ny, cfg.nx))


#: (old pose, new pose): a sub-cell move across a cell edge, a fast jump of several cells, a
#: move beside the wall (the body's box cut by the domain's edge), a turning body's jump
MOVES = [((40.97, 30.3), (41.03, 30.3), 0.0), ((40.3, 30.3), (44.0, 32.1), 0.0), ((7.4, 6.3), (6.6, 6.05), 0.0),
         ((30.2, 20.6), (32.9, 19.1), 0.01)]


@pytest.mark.parametrize("old_pose, new_pose, omega", MOVES)
@pytest.mark.parametrize("impulse", ["relative", "absolute"])
def test_a_local_move_equals_a_whole_grid_refill(old_pose, new_pose, omega, impulse):
    """The move's window, numpy and compiled, against `refill` over the whole grid."""
    cfg = FlowConfig(nx=NX, ny=NY, dtype="float64")
    old = make_body_state(Cylinder(12.0, x=old_pose[0], y=old_pose[1]), (0.03, -0.01), omega, cfg, 2)
    new = make_body_state(Cylinder(12.0, x=new_pose[0], y=new_pose[1]), (0.03, -0.01), omega, cfg, 2)
    f0 = unshifted(shifted(_disturbed_state(cfg)).astype(np.float32))  # the cpu backend's float32 storage
    assert (old.solid & ~new.solid).any() and (new.solid & ~old.solid).any()

    whole = f0.copy()
    j_whole, _ = refill(whole, old.solid, new.solid, new.shape, new.velocity, new.omega, 0, 0, impulse=impulse)

    local = f0.copy()

    def read_window(x0, y0, x1, y1):
        return local[:, y0:y1, x0:x1].copy()

    def write_nodes(x0, y0, f, changed):
        h, w = changed.shape
        local[:, y0:y0 + h, x0:x0 + w][:, changed] = f[:, changed]

    j_local = move_body(old, new, cfg, read_window, write_nodes, impulse=impulse)
    g = shifted(f0).astype(np.float32)
    j_fast = body_compiled.move_body(old, new, cfg, g, impulse)

    assert np.abs(whole - f0).max() > 1e-3    # the move wrote something
    np.testing.assert_allclose(local, whole, rtol=0, atol=1e-14)
    np.testing.assert_allclose(g, shifted(whole).astype(np.float32), rtol=0, atol=1e-8)  # float32 rounding
    np.testing.assert_allclose(j_local, j_whole, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(j_fast, j_whole, rtol=1e-12, atol=1e-15)


def test_compiled_node_list_holds_the_link_nodes_and_their_bits():
    cfg = FlowConfig(nx=NX, ny=NY)
    body = make_body_state(Cylinder(12.0, x=30.4, y=6.3), (0.03, 0.0), 0.0, cfg, 2)
    L = body.links
    x0, y0 = body.window[:2]
    edge_grid = np.zeros((NY, NX), np.int64)
    edge_grid[0, :] = 0b1100100   # the lower wall's bits (2, 5, 6), under some link nodes
    ey, ex = np.nonzero(edge_grid)
    edge = (ey, ex, edge_grid[ey, ex])
    (ry, rx, rbits), arrays = body_compiled.redo_nodes(edge, edge_grid, L, body.window)
    want = {}
    for i, iy, ix in zip(L.i, L.iy + y0, L.ix + x0):
        want[(iy, ix)] = want.get((iy, ix), int(edge_grid[iy, ix])) | (1 << int(i))
    bare = [(y, x) not in want for y, x in zip(ey, ex)]   # edge nodes that own no link come first
    ne = int(np.sum(bare))
    assert ne < ey.size   # the body reaches the wall row: those nodes come only with the links
    assert np.array_equal(ry[:ne], ey[bare]) and np.array_equal(rx[:ne], ex[bare])
    assert np.array_equal(rbits[:ne], edge[2][bare])
    got = {(int(y), int(x)): int(b) for y, x, b in zip(ry[ne:], rx[ne:], rbits[ne:])}
    assert got == want and len(ry) == ne + len(want)
    assert any(y == 0 for y, _ in got)   # bits merged there
    assert len(set(zip(ry.tolist(), rx.tolist()))) == len(ry)   # each node once: the pass is parallel
    li, gy, gx, gfy, gfx = arrays[:5]
    assert np.array_equal(gy, L.iy + y0) and np.array_equal(gx, L.ix + x0)
    assert np.array_equal(gfy, L.fy + y0) and np.array_equal(gfx, L.fx + x0)
    assert np.array_equal(arrays[9], L.uw[:, 0]) and np.array_equal(arrays[10], L.uw[:, 1])
    assert np.array_equal(arrays[11], L.ix + x0 - L.q * C[L.i, 0])   # the wall crossings (torque)
    assert np.array_equal(arrays[12], L.iy + y0 - L.q * C[L.i, 1])


def test_cpu_equals_numpy_for_a_body_jumping_cells_beside_a_wall():
    """The cpu backend's compiled move against the numpy reference's, stepping between moves
    (the default tier's kernel variant: TRT, float32)."""
    from feelflow.solver.backend import create_solver

    cfg = dataclasses.replace(FlowConfig(nx=64, ny=40, dtype="float32", collision="trt",
                                         initial_velocity=(0.03, 0.0)), inflow_ramp_steps=0)
    solvers = [create_solver(b, cfg) for b in ("numpy", "cpu")]
    poses = [(30.2, 9.1), (30.9, 8.4), (33.6, 7.2), (33.1, 7.9), (29.4, 8.8), (29.45, 8.8)]
    forces = [[], []]
    for j, s in enumerate(solvers):
        s.enable_force_models(["momentum_exchange"])
        for x, y in poses:
            s.set_body(Cylinder(12.0, x=x, y=y), velocity=(0.02, -0.01), omega=0.004)
            s.step(2)
            forces[j].append(s.forces()["momentum_exchange"])
    ref, cpu = (s.distributions() for s in solvers)
    assert np.abs(cpu - ref).max() / np.abs(ref - W[:, None, None]).max() < 1e-5
    ref_f, cpu_f = np.array(forces[0]), np.array(forces[1])
    assert np.abs(cpu_f - ref_f).max() / np.abs(ref_f).max() < 1e-4
