"""Force models on constructed windows whose answer is known analytically (no solver).

- macroscopic: the drag equation on a uniform field , the contour mean of a linear field
  (the value at the centre, by symmetry), coefficient orientation, lift direction.
- pressure: a field whose equation-of-state pressure is linear, p = g . (x - x_c), gives
  F = - g * (body area) (Gauss; Archimedes' principle), whatever the solid nodes hold.
- stress: a shear flow u_x = a (y - y_c)^2 built from Chapman-Enskog populations gives the
  viscous force 2 rho nu a * area.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from feelflow.shapes import Cylinder, FlatPlate, HalfAirfoil, Wedge
from feelflow.solver.config import FlowConfig
from feelflow.solver.forces import create_model
from feelflow.solver.forces.base import BodyWindow
from feelflow.solver.forces.pressure import BETA_LATTICE
from feelflow.solver.forces.stress import viscous_force
from feelflow.solver.lattice import C, CS2, RHO0, W, equilibrium

CONFIG = FlowConfig(nx=256, ny=128, nu=0.05)


def make_window(shape, rho_fn, u_fn, velocity=(0.0, 0.0), margin=10, solid_rho=RHO0, fneq_fn=None):
    """A BodyWindow around `shape` with equilibrium populations of the given fields (functions of
    world x, y); solid nodes hold f^eq(solid_rho, V) (solid_rho = RHO0 is the contract)."""
    xmin, ymin, xmax, ymax = shape.bounding_box()
    x0, y0 = int(math.floor(xmin)) - margin, int(math.floor(ymin)) - margin
    x1, y1 = int(math.ceil(xmax)) + margin + 1, int(math.ceil(ymax)) + margin + 1
    xs, ys = np.meshgrid(np.arange(x0, x1, dtype=float), np.arange(y0, y1, dtype=float))
    solid = shape.contains(xs, ys)
    rho = np.broadcast_to(rho_fn(xs, ys), xs.shape).astype(float)
    ux, uy = (np.broadcast_to(c, xs.shape).astype(float) for c in u_fn(xs, ys))
    f = equilibrium(rho, ux, uy)
    if fneq_fn is not None:
        f = f + fneq_fn(xs, ys, rho)
    n_solid = int(solid.sum())
    f[:, solid] = equilibrium(np.full(n_solid, solid_rho), np.full(n_solid, velocity[0]), np.full(n_solid, velocity[1]))
    return BodyWindow(x0=x0, y0=y0, f=f, solid=solid, q=np.zeros((9,) + xs.shape), shape=shape,
                      velocity=tuple(velocity), omega=0.0, impulse=(0.0, 0.0), config=CONFIG)


# --- macroscopic ---------------------------------------------------------------------------
def test_macroscopic_equals_the_drag_equation_on_a_uniform_field():
    body = Cylinder(20.0, x=60.3, y=50.6)
    u, rho, v_body = (0.04, 0.015), 1.003, (0.01, -0.005)
    window = make_window(body, lambda x, y: rho, lambda x, y: u, velocity=v_body)
    fx, fy = create_model("macroscopic").compute(window)
    ux, uy = u[0] - v_body[0], u[1] - v_body[1]
    speed = math.hypot(ux, uy)
    # C_D = 1.2 (circular cylinder, White table 7.2), A = diameter
    expect = (0.5 * rho * 20.0 * 1.2 * speed * ux, 0.5 * rho * 20.0 * 1.2 * speed * uy)
    assert fx == pytest.approx(expect[0], rel=1e-9)
    assert fy == pytest.approx(expect[1], rel=1e-9)


@pytest.mark.parametrize("distance", [1.5, 4.0, 6.0])
def test_macroscopic_contour_mean_of_a_linear_field_is_the_centre_value(distance):
    body = Cylinder(16.0, x=40.25, y=33.7)
    a, gx, gy = np.array([0.03, -0.01]), np.array([1e-3, 2e-4]), np.array([-5e-4, 8e-4])
    window = make_window(body, lambda x, y: 1.0 + 0 * x,
                         lambda x, y: (a[0] + gx[0] * (x - body.x) + gy[0] * (y - body.y),
                                       a[1] + gx[1] * (x - body.x) + gy[1] * (y - body.y)))
    model = create_model("macroscopic", distance=distance)
    _, ux, uy = model.sample(window)
    assert (ux, uy) == pytest.approx(tuple(a), abs=1e-12)


def test_macroscopic_margin_and_a_clipped_window():
    """margin = ceil(d) + 2; where the window is too small (clipped at a domain edge) the
    contour points beyond it are left out, and a uniform field still gives the exact formula."""
    model = create_model("macroscopic", distance=4)
    assert model.margin == 6
    assert create_model("macroscopic", distance=7.5).margin == 10
    body = Cylinder(16.0, x=40.0, y=40.0)
    window = make_window(body, lambda x, y: 1.0, lambda x, y: (0.02, 0.0), margin=3)
    fx, fy = model.compute(window)
    assert fx == pytest.approx(0.5 * 1.2 * 16.0 * 0.02 * 0.02, rel=1e-9) and fy == pytest.approx(0.0, abs=1e-15)


def test_macroscopic_wedge_coefficient_follows_the_flow_direction():
    """A wedge pointing upstream ('<') has its apex upstream in a +x stream (C_D 1.55) and its flat
    face upstream when the stream reverses (C_D 2.0): same |U|, same frontal area."""
    wedge = Wedge(length=20.0, apex_angle=math.radians(60), pointing="upstream", x=50.0, y=50.0)
    model = create_model("macroscopic")
    fwd = model.formula(wedge, 1.0, 0.02, 0.0)[0]
    back = -model.formula(wedge, 1.0, -0.02, 0.0)[0]
    assert back / fwd == pytest.approx(2.0 / 1.55, rel=1e-12)


def test_macroscopic_orders_shapes_only_by_its_table():
    """Same frontal area, same U: the force ratios are the table's C_D ratios (the lesson: this
    model cannot tell shapes apart by itself)."""
    model = create_model("macroscopic")
    width = 20.0
    plate = FlatPlate(length=width, thickness=1.0, x=50, y=50)
    cyl = Cylinder(width, x=50, y=50)
    wedge_up = Wedge(length=width * math.sqrt(3) / 2, apex_angle=math.radians(60), pointing="upstream", x=50, y=50)
    forces = {s.kind + getattr(s, "pointing", ""): model.formula(s, 1.0, 0.02, 0.0)[0] for s in (plate, cyl, wedge_up)}
    assert forces["plate"] / forces["cylinder"] == pytest.approx(2.0 / 1.2, rel=1e-6)
    assert forces["wedgeupstream"] / forces["cylinder"] == pytest.approx(1.55 / 1.2, rel=1e-6)


def test_macroscopic_lift_points_to_the_curved_side():
    foil = HalfAirfoil(chord=40.0, thickness=8.0, x=60.0, y=50.0)
    model = create_model("macroscopic")
    for ux in (0.02, -0.02):
        fx, fy = model.formula(foil, 1.0, ux, 0.0)
        assert fy > 0 and np.sign(fx) == np.sign(ux)
        # F_y / F_x = (C_L c) / (C_D A): C_L = 2 pi t / c on the chord, C_D = 0.6 on the frontal width
        area = foil.frontal_area((1.0, 0.0))
        assert fy / abs(fx) == pytest.approx((2 * math.pi * 8.0 / 40.0 * 40.0) / (0.6 * area), rel=1e-9)
    upside_down = foil.moved(angle=math.pi)
    assert model.formula(upside_down, 1.0, 0.02, 0.0)[1] < 0
    assert create_model("macroscopic").formula(Cylinder(10.0, x=50, y=50), 1.0, 0.02, 0.0)[1] == 0.0


# --- pressure --------------------------------------------------------------------------------
@pytest.mark.parametrize("body", [Cylinder(18.0, x=50.3, y=41.8),
                                  HalfAirfoil(chord=40.0, thickness=8.0, x=60.4, y=50.2),
                                  Wedge(length=20.0, apex_angle=math.radians(60), pointing="downstream", x=50.5, y=50.5)],
                         ids=lambda s: s.kind)
def test_pressure_of_a_linear_pressure_field_is_archimedes(body):
    """rho^2 - rho0^2 linear in x, y  =>  p = beta' g . (x - x_c)  =>  F = -beta' g * area.
    Solid nodes filled with an absurd density show that only fluid nodes are read."""
    g = np.array([2e-4, -3e-4])
    rho_fn = lambda x, y: np.sqrt(RHO0**2 + g[0] * (x - 50.0) + g[1] * (y - 45.0))
    window = make_window(body, rho_fn, lambda x, y: (0.0, 0.0), solid_rho=7.0)
    area = math.pi * body.radius**2 if body.kind == "cylinder" else body.area
    fx, fy = create_model("pressure").compute(window)
    beta_p = BETA_LATTICE / RHO0**2
    assert fx == pytest.approx(-beta_p * g[0] * area, rel=2e-3)
    assert fy == pytest.approx(-beta_p * g[1] * area, rel=2e-3)
    tight = make_window(body, rho_fn, lambda x, y: (0.0, 0.0), solid_rho=7.0, margin=1)  # fit clipped at the edge
    assert create_model("pressure").compute(tight) == pytest.approx((fx, fy), rel=2e-2)
    fx50, fy50 = create_model("pressure", gain=50).compute(window)
    assert (fx50, fy50) == pytest.approx((50 * fx, 50 * fy), rel=1e-12)


def test_pressure_default_beta_is_the_lattice_pressure_to_first_order():
    """beta' (rho^2 - rho0^2) with beta = rho0/6 vs c_s^2 (rho - rho0): equal up to (rho-rho0)^2/6."""
    beta_p = create_model("pressure").beta_prime
    for drho in (1e-4, -1e-3, 1e-2):
        rho = RHO0 + drho
        assert abs(beta_p * (rho**2 - RHO0**2) - CS2 * drho) <= drho**2 / 6 + 1e-15


# --- viscous stress (the split of the reference) ---------------------------------------------
def test_viscous_force_of_a_parabolic_shear_flow():
    """u_x = a (y - yc)^2: sigma'_xy = 2 rho nu a (y - yc), so sum sigma'.n dA = 2 rho nu a * area.
    Populations carry the Chapman-Enskog non-equilibrium part of that flow, post-collision."""
    body = Cylinder(16.0, x=40.2, y=40.6)
    a, rho0 = 2e-5, 1.0
    tau = CONFIG.tau
    yc = 40.0

    def fneq(x, y, rho):  # post-collision: (1 - 1/tau) * (-w_i tau rho / cs2 * 2 c_x c_y S_xy)
        sxy = a * (y - yc)
        out = np.empty((9,) + x.shape)
        for i in range(9):
            out[i] = (1 - 1 / tau) * (-W[i] * tau * rho / CS2) * 2 * C[i, 0] * C[i, 1] * sxy
        return out

    window = make_window(body, lambda x, y: rho0, lambda x, y: (a * (y - yc) ** 2, 0.0 * y), fneq_fn=fneq)
    fx, fy = viscous_force(window)
    assert fx == pytest.approx(2 * rho0 * CONFIG.nu * a * math.pi * body.radius**2, rel=2e-3)
    assert abs(fy) < 1e-3 * abs(fx)
