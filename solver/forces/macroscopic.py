"""The seed's macroscopic drag model (seed eq. 19, fig. 14): the textbook drag equation fed with
the flow sampled on a contour around the body.

    F = 1/2 rho |U| (C_D A U + C_L c |U| e_L),    U = u - V

- u: mean fluid velocity on the contour at distance `distance` (d, default 4 cells, the seed's
  working value; fig. 14) from the body surface, sampled by bilinear interpolation of the
  window's moments at points offset along the outward normals of `shape.surface_elements`,
  each weighted by its element length. rho: the mean density on the same contour.
- V: the body's translational velocity (rotation is ignored).
- A: `shape.frontal_area` for the direction of U.
- C_D, C_L: a table per shape kind (below), textbook values at Re 1e4-1e5
  (C_L is referred to the chord c of the half airfoil, C_D to the frontal width A), from
  White, *Fluid Mechanics* (table 7.2) and Hoerner,
  *Fluid-Dynamic Drag* (1965). e_L is the unit vector normal to U on the side of the body's own
  "up" (its +y axis rotated by its angle).

This model knows nothing of the flow around the body except one mean velocity: its drag grows
like |U|^2 by construction, and it separates shapes only through the coefficients it is given.
Sampling at d -> 0 reads the wall velocity V (no-slip), so U -> 0: the seed's first failure.
The sampling contour must lie inside the body window: `margin` (ceil(d) + 2 cells) tells the
backends how far the window must extend beyond the body. Where the window is clipped by the
domain's edge (a body near a wall), the contour points beyond it are left out.
"""
from __future__ import annotations

import math

import numpy as np

from feelflow.solver.forces.base import BodyWindow, ForceModel
from feelflow.solver.forces.sampling import bilinear_stencil, moments_at
from feelflow.solver.lattice import RHO0

#: kind -> (C_D, source). Wedges depend on which way they face (see `drag_coefficient`).
DRAG_COEFFICIENTS: dict[str, tuple[float, str]] = {
    "cylinder": (1.2, "circular cylinder, Re 1e4-1e5: White, Fluid Mechanics, table 7.2"),
    "plate": (2.0, "flat plate normal to the flow: White table 7.2; Hoerner (1965) ch. 3"),
    "wedge_apex_upstream": (1.55, "equilateral triangle, apex upstream, 1.5-1.6: White table 7.2"),
    "wedge_face_upstream": (2.0, "equilateral triangle, flat face upstream: White table 7.2"),
    "half_airfoil": (0.6, "closest tabulated body: 2:1 ellipse, long axis along the flow: White table 7.2"),
    "polygon": (2.0, "no tabulated value for an arbitrary polygon: the bluff-body value of the flat plate "
                     "(White table 7.2), an upper estimate"),
}

#: kind -> source of the lift coefficient; kinds not listed have C_L = 0 (symmetric bodies in a
#: stream along their axis of symmetry have no lift; the model does not know about angle of attack).
LIFT_SOURCES: dict[str, str] = {
    "half_airfoil": ("thin-airfoil theory at zero incidence, C_L = 4 pi m for a parabolic mean line of "
                     "camber m (Anderson, Fundamentals of Aerodynamics, sec. 4.8); a flat-bottomed body of "
                     "thickness t has m = t / (2 c), so C_L = 2 pi t / c"),
}


def _apex_points_upstream(shape, flow_dir) -> bool:
    """A wedge faces its apex upstream when the apex lies against the flow. In the wedge's own
    frame the apex points to -x ("upstream") or +x ("downstream", shapes.Wedge); turned by its angle."""
    sign = -1.0 if getattr(shape, "pointing", "upstream") == "upstream" else 1.0
    apex_dir = sign * np.array([math.cos(shape.angle), math.sin(shape.angle)])
    return float(np.dot(apex_dir, flow_dir)) < 0.0


def drag_coefficient(shape, flow_dir) -> tuple[float, str]:
    """(C_D, source) of `shape` in a flow along the unit vector `flow_dir` (relative to the body)."""
    kind = getattr(shape, "kind", "polygon")
    if kind == "wedge":
        kind = "wedge_apex_upstream" if _apex_points_upstream(shape, flow_dir) else "wedge_face_upstream"
    return DRAG_COEFFICIENTS.get(kind, DRAG_COEFFICIENTS["polygon"])


def lift_coefficient(shape) -> tuple[float, float]:
    """(C_L, reference length) of the shape's kind: (0, 0) where LIFT_SOURCES has no entry.
    The half airfoil's thin-airfoil C_L is referred to its chord, not to its frontal width."""
    if getattr(shape, "kind", None) == "half_airfoil":
        chord = float(getattr(shape, "chord"))
        thickness = float(getattr(shape, "thickness"))
        return 2.0 * math.pi * thickness / chord, chord
    return 0.0, 0.0


class MacroscopicDrag(ForceModel):
    """F = 1/2 rho |U| (C_D A U + C_L c |U| e_L) with U sampled on a contour (seed eq. 19, fig. 14)."""

    name = "macroscopic"
    description = "drag equation with C_D from a table, fluid velocity sampled d cells off the wall (seed)"

    def __init__(self, distance: float = 4.0, spacing: float = 0.5,
                 drag_coefficient: float | None = None, lift_coefficient: float | None = None):
        if not (math.isfinite(distance) and distance >= 0):
            raise ValueError(f"distance must be a number >= 0, got {distance!r}")
        if not (math.isfinite(spacing) and spacing > 0):
            raise ValueError(f"spacing must be a positive number, got {spacing!r}")
        self.distance = float(distance)
        self.spacing = float(spacing)
        self.cd_override = drag_coefficient
        self.cl_override = lift_coefficient
        #: cells the body window must extend beyond the body (contour plus bilinear stencil)
        self.margin = int(math.ceil(self.distance)) + 2

    def sample(self, window: BodyWindow):
        """(rho, ux, uy): length-weighted means on the contour at `distance` from the surface."""
        key = (window.shape, window.x0, window.y0, window.solid.shape)
        if getattr(self, "_key", None) != key:  # rebuilt only when the pose changes
            pts, normals, lengths = window.shape.surface_elements(self.spacing)
            pts = np.asarray(pts, dtype=np.float64)
            normals = np.asarray(normals, dtype=np.float64)
            lengths = np.asarray(lengths, dtype=np.float64)
            stencil = bilinear_stencil(window, pts[:, 0] + self.distance * normals[:, 0],
                                       pts[:, 1] + self.distance * normals[:, 1])
            weight = lengths * stencil.valid  # points beyond a clipped window are left out
            self._geom = (stencil, stencil.nodes(), weight / weight.sum() if weight.sum() > 0 else None)
            self._key = key
        stencil, nodes, weight = self._geom
        if weight is None:  # the whole contour lies beyond the domain: nothing to sample
            return RHO0, window.velocity[0], window.velocity[1]
        rho, ux, uy = moments_at(window, nodes)
        return tuple(float(np.dot(stencil.apply(a), weight)) for a in (rho, ux, uy))

    def compute(self, window: BodyWindow) -> tuple[float, float]:
        rho, ux, uy = self.sample(window)
        return self.formula(window.shape, rho, ux - window.velocity[0], uy - window.velocity[1])

    def torque(self, window: BodyWindow) -> float:
        """0: the drag equation is a control-volume law for the force through the body's centre.
        A moment would need a moment coefficient per shape and a relative angular velocity,
        and neither the seed nor the drag tables give one (the torque on a turning cylinder is
        viscous, mu Omega R^2, not a |U|^2 law); the contour's mean velocity, which is all this
        model reads, carries no moment. Use `momentum_exchange` for the torque."""
        return 0.0

    def formula(self, shape, rho: float, ux: float, uy: float) -> tuple[float, float]:
        """The drag equation for relative velocity U = (ux, uy) and density rho."""
        speed = math.hypot(ux, uy)
        if speed == 0.0:
            return 0.0, 0.0
        direction = np.array([ux / speed, uy / speed])
        area = float(shape.frontal_area(direction))
        cd = self.cd_override if self.cd_override is not None else drag_coefficient(shape, direction)[0]
        cl, lift_length = lift_coefficient(shape)
        if self.cl_override is not None:
            cl, lift_length = self.cl_override, (lift_length or area)
        fx = 0.5 * rho * area * speed * cd * ux
        fy = 0.5 * rho * area * speed * cd * uy
        if cl:
            up = np.array([-math.sin(shape.angle), math.cos(shape.angle)])
            e_lift = np.array([-direction[1], direction[0]])
            if float(np.dot(e_lift, up)) < 0:
                e_lift = -e_lift
            fx += 0.5 * rho * lift_length * speed * speed * cl * e_lift[0]
            fy += 0.5 * rho * lift_length * speed * speed * cl * e_lift[1]
        return float(fx), float(fy)
