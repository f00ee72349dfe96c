"""Local grid refinement (solver/refinement.py): a patch of half-size cells in the numpy reference.

Physics checks: the level transfer against a lattice that is twice as fine everywhere (Dupuis &
Chopard 2003's rescaling of the non-equilibrium, per TRT parity), a developed channel flow that
crosses the patch undisturbed, and the drag of Schaefer & Turek's 2D-1 at a coarse resolution
moving towards the finer lattice's.
"""
from __future__ import annotations

import numpy as np
import pytest

from feelflow.solver.config import ConfigError, FlowConfig
from feelflow.solver.lattice import C, OPP, equilibrium
from feelflow.solver.numpy_backend import NumpySolver
from feelflow.solver.refinement import RefinedSolver, _taus, cubic_midpoints, fine_shape, rescale


def test_cubic_midpoints_are_exact_for_cubics():
    x = np.arange(-1, 9, dtype=float)          # 8 nodes and a halo node at each end
    v = np.stack([0.3 * x ** 3 - x ** 2 + 2.0 * x - 5.0, np.cos(x)])
    out = cubic_midpoints(v)
    xf = np.arange(15) / 2.0
    assert np.allclose(out[0], 0.3 * xf ** 3 - xf ** 2 + 2.0 * xf - 5.0, rtol=0, atol=1e-12)
    assert np.allclose(out[1, 0::2], np.cos(xf[0::2]), rtol=0, atol=0)


#: a compressible-equilibrium config for the rescaling's algebra
CONFIG = FlowConfig(nx=8, ny=8)


def _moments(f):
    return f.sum(axis=0), np.tensordot(C[:, 0].astype(float), f, axes=1), np.tensordot(C[:, 1].astype(float), f, axes=1)


def test_rescale_keeps_the_moments_and_inverts():
    rng = np.random.default_rng(3)
    rho = 1.0 + 0.01 * rng.standard_normal((5, 6))
    ux, uy = 0.05 * rng.standard_normal((2, 5, 6))
    f = equilibrium(rho, ux, uy).astype(float) + 1e-4 * rng.standard_normal((9, 5, 6))
    g = rescale(f, 0.43, -0.2, CONFIG)
    for a, b in zip(_moments(f), _moments(g)):
        assert np.allclose(a, b, rtol=0, atol=1e-14)
    assert np.allclose(rescale(g, 1 / 0.43, -1 / 0.2, CONFIG), f, rtol=0, atol=1e-14)
    r, jx, jy = _moments(f)
    feq = equilibrium(r, jx / r, jy / r).astype(float)  # f's own equilibrium
    assert np.allclose(rescale(feq, 0.43, -0.2, CONFIG), feq, rtol=0, atol=1e-15)
    n, m = g - feq, f - feq  # the even part scaled by 0.43, the odd by -0.2
    assert np.allclose(n + n[OPP], 0.43 * (m + m[OPP]), atol=1e-14)
    assert np.allclose(n - n[OPP], -0.2 * (m - m[OPP]), atol=1e-14)


def _shear_box(n, nu, collision):
    cfg = FlowConfig(nx=n, ny=n, nu=nu, collision=collision, x_boundary="periodic", y_boundary="periodic",
                     inflow_speed=0.0, inflow_ramp_steps=0)
    s = NumpySolver(cfg)
    y = np.arange(n)[:, None] / n * np.ones((1, n))
    x = y.T
    ux = 0.05 * np.sin(2 * np.pi * y) * (1 + 0.3 * np.cos(2 * np.pi * x))
    uy = 0.025 * np.sin(2 * np.pi * x)
    s.set_distributions(equilibrium(np.ones_like(ux), ux, uy))
    return s, cfg


def _parts(f):
    rho, jx, jy = _moments(f)
    n = f - equilibrium(rho, jx / rho, jy / rho)
    return 0.5 * (n + n[OPP]), 0.5 * (n - n[OPP])


@pytest.mark.parametrize("collision", ["bgk", "trt"])
def test_the_level_transfer_matches_a_twice_finer_lattice(collision):
    """A decaying shear flow on 32^2 and on 64^2 (nu doubled, twice the steps: the same flow,
    acoustic scaling); the fine run's post-collision populations, rescaled to the coarse level
    at the coincident nodes, carry the coarse run's non-equilibrium, even and odd parts. At
    tau 0.8 the post-collision non-equilibrium changes sign between the levels (fine tau 1.1),
    so a transfer without the rescaling is off by a factor of -4."""
    n, nu = 32, 0.1
    coarse, cc = _shear_box(n, nu, collision)
    fine, cf = _shear_box(2 * n, 2 * nu, collision)
    steps = int(0.1 / (nu * (2 * np.pi / n) ** 2))
    coarse.step(steps)
    fine.step(2 * steps)
    (tpc, tmc), (tpf, tmf) = _taus(cc), _taus(cf)
    restricted = rescale(fine.distributions()[:, ::2, ::2], 2 * (tpc - 1) / (tpf - 1), 2 * (tmc - 1) / (tmf - 1), cc)
    for ours, theirs in zip(_parts(coarse.distributions()), _parts(restricted)):
        assert np.abs(ours - theirs).max() < 0.03 * np.abs(ours).max()
    plain = _parts(fine.distributions()[:, ::2, ::2])[0]
    assert np.abs(plain - _parts(coarse.distributions())[0]).max() > np.abs(_parts(coarse.distributions())[0]).max()


def _channel(d=10):
    from feelflow.solver.validation.schaefer_turek import Geometry

    geo = Geometry(d, 20.0)
    return geo, geo.config()


def test_a_developed_channel_flow_crosses_the_patch():
    """Schaefer-Turek's channel without the cylinder, started from its developed profile: with a
    patch in mid-channel, the coarse field and the fine lattice's (at the coincident nodes and,
    cubically interpolated, between them) stay those of the plain lattice to 0.2 % of U_m."""
    geo, cfg = _channel()
    x0, y0, x1, y1 = 40, 10, 100, 30
    plain, refined = NumpySolver(cfg), RefinedSolver(cfg, (x0, y0, x1, y1))
    assert refined.nodes_per_step == 220 * 41 + 2 * 121 * 41  # what validation's MLUPS count
    for s in (plain, refined):
        s.set_distributions(geo.initial_populations())
        s.step(3000)
    (_, u0, v0), (_, u1, v1) = plain.macroscopic(), refined.macroscopic()
    tol = 2e-3 * geo.u_max
    assert np.abs(u1 - u0).max() < tol and np.abs(v1 - v0).max() < tol
    _, uf, vf = refined.fine.macroscopic()
    box = u0[y0 - 1:y1 + 2, x0 - 1:x1 + 2]  # the plain field on the patch, to the fine nodes
    rows = cubic_midpoints(box.T).T
    plain_fine = cubic_midpoints(rows)
    assert np.abs(uf - plain_fine).max() < tol
    assert np.abs(uf[::2, ::2] - u0[y0:y1 + 1, x0:x1 + 1]).max() < tol


@pytest.mark.slow
def test_a_refined_patch_takes_2d1_towards_the_finer_lattice():
    """2D-1 at 10 cells per diameter: C_D is 0.53 % above the reference on the plain lattice
    (docs/science/data/accuracy-numpy.json), 0.13 % above at 20 cells and -0.04 % at 40. With the
    cylinder and its near wake (1 D ahead, 3 D behind, 1 D each side) at 20 cells the error
    must be at most half the plain lattice's."""
    from feelflow.solver.validation import schaefer_turek_2d1 as case

    d = 10
    plain = case.run(NumpySolver, resolution=d)
    refined = case.run(NumpySolver, resolution=d, refine=True)
    assert refined.quantities["cells_per_d_at_body"] == 20 and "refined patch (9, 9, 50, 30)" in refined.notes
    assert plain.quantities["cd_rel_error"] > 0.004
    assert abs(refined.quantities["cd_rel_error"]) < 0.5 * plain.quantities["cd_rel_error"]


def test_fine_shape_is_the_same_body_at_twice_the_size():
    from feelflow.shapes.cylinder import Cylinder
    from feelflow.shapes.polygon import Wedge

    for shape in (Cylinder(diameter=8.0, x=30.3, y=20.7), Wedge(length=12.0, apex_angle=0.7, x=31.0, y=19.5, angle=0.3)):
        fine = fine_shape(shape, 20, 10)
        px, py = np.meshgrid(np.linspace(20, 45, 60), np.linspace(10, 30, 50))
        assert np.array_equal(shape.contains(px, py), fine.contains(2 * (px - 20), 2 * (py - 10)))


def test_bad_patches_and_bodies_are_refused_with_the_reason():
    from feelflow.shapes.cylinder import Cylinder

    _, cfg = _channel()
    with pytest.raises(ConfigError, match="refine: the patch"):
        RefinedSolver(cfg, (1, 10, 100, 30))
    with pytest.raises(ConfigError, match="reaches into the outlet sponge"):
        RefinedSolver(FlowConfig(**{**cfg.__dict__, "sponge_cells": 40}), (10, 10, 190, 30))
    s = RefinedSolver(cfg, (10, 10, 50, 30))
    with pytest.raises(ConfigError, match="must stay 3 cells inside"):
        s.set_body(Cylinder(diameter=10.0, x=15.0, y=20.0))
    with pytest.raises(ConfigError, match="holds a fixed body"):
        s.set_body(Cylinder(diameter=10.0, x=30.0, y=20.0), velocity=(0.01, 0.0))
    one = FlowConfig(nx=64, ny=32, nu=1.0 / 6.0, collision="bgk", x_boundary="periodic", y_boundary="periodic",
                     inflow_speed=0.0)
    with pytest.raises(ConfigError, match="relaxation time of 1"):
        RefinedSolver(one, (10, 5, 40, 25))
