"""The one place that converts between lattice units and what a student reads.

Inside the solver everything is in lattice units (dx = dt = 1, rho_0 = 1). Dimensionless
numbers need a reference length L and a reference velocity U, which the caller states:
- Reynolds number Re = U L / nu; Mach number Ma = |u| / c_s with c_s^2 = 1/3 (seed eq. 5).
- Force coefficients per unit span C_D = 2 F_x / (rho U^2 L), C_L = 2 F_y / (rho U^2 L)
  (Schaefer & Turek 1996).
- Pressure p = c_s^2 rho (ideal LBM equation of state); a pressure difference is made
  dimensionless as dp / (rho U^2).
- Strouhal number St = f L / U.
- Newtons: a lattice force per unit span times `NewtonScale.newtons_per_lattice_force`.

Nothing else in FeelFlow hard-codes a scale.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from feelflow.solver.lattice import CS2, RHO0

#: speed of sound in lattice units
CS = math.sqrt(CS2)


def reynolds(speed: float, length: float, nu: float) -> float:
    """Re = U L / nu."""
    return speed * length / nu


def viscosity_for_reynolds(re: float, speed: float, length: float) -> float:
    """The kinematic viscosity nu = U L / Re that gives Reynolds number `re`."""
    return speed * length / re


def mach(speed: float) -> float:
    """Ma = |u| / c_s."""
    return abs(speed) / CS


def speed_for_mach(ma: float) -> float:
    """The lattice speed with Mach number `ma`."""
    return ma * CS


def tau_for_viscosity(nu: float) -> float:
    """BGK relaxation time: nu = c_s^2 (tau - 1/2) (seed eq. 5)."""
    return nu / CS2 + 0.5


def pressure(rho):
    """Lattice pressure p = c_s^2 rho."""
    return CS2 * rho


def dynamic_pressure(speed: float, rho: float = RHO0) -> float:
    """q = rho U^2 / 2."""
    return 0.5 * rho * speed * speed


def force_coefficient(force: float, speed: float, length: float, rho: float = RHO0) -> float:
    """C = 2 F / (rho U^2 L): drag coefficient for F_x, lift coefficient for F_y."""
    return force / (dynamic_pressure(speed, rho) * length)


def drag_lift_coefficients(force, speed: float, length: float, rho: float = RHO0) -> tuple[float, float]:
    """(C_D, C_L) of a force (F_x, F_y) for a flow along +x."""
    fx, fy = force
    return force_coefficient(fx, speed, length, rho), force_coefficient(fy, speed, length, rho)


def pressure_difference_coefficient(dp: float, speed: float, rho: float = RHO0) -> float:
    """dp / (rho U^2): a pressure difference in units of rho U^2."""
    return dp / (rho * speed * speed)


def strouhal(frequency: float, length: float, speed: float) -> float:
    """St = f L / U (f in 1/steps, L in cells, U in cells per step)."""
    return frequency * length / speed


@dataclass(frozen=True)
class NewtonScale:
    """Lattice force (per unit span, one lattice cell deep) to newtons.

    One factor, `newtons_per_lattice_force`, set from a physical fluid (`physical`). (The gain
    from a lattice force to a haptic device's newtons is `haptics.shaping.ForceScale`.)
    """

    newtons_per_lattice_force: float

    @classmethod
    def physical(cls, dx_m: float, dt_s: float, rho_kg_m3: float, depth_m: float) -> "NewtonScale":
        """The scale of a physical fluid: cell size dx, step dt, density rho, body span depth.

        A lattice cell holds the mass rho dx^2 depth and a lattice acceleration is dx / dt^2,
        so F = F_lattice * rho dx^3 depth / dt^2."""
        for name, value in (("dx_m", dx_m), ("dt_s", dt_s), ("rho_kg_m3", rho_kg_m3), ("depth_m", depth_m)):
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name}: must be a positive number, got {value!r}")
        return cls(rho_kg_m3 * dx_m * dx_m * depth_m * dx_m / (dt_s * dt_s))

    def newtons(self, lattice_force):
        """The force in newtons (scalar, tuple or array)."""
        if isinstance(lattice_force, tuple):
            return tuple(self.newtons_per_lattice_force * c for c in lattice_force)
        return self.newtons_per_lattice_force * lattice_force


# --- physical units: a fluid and a body size, matched to the simulated Reynolds number ----------
@dataclass(frozen=True)
class Fluid:
    """A fluid's name, density rho (kg/m^3) and kinematic viscosity nu (m^2/s)."""

    name: str
    density: float
    viscosity: float


#: fluids at 20 degrees C and 1 atm: density and dynamic viscosity mu from F. M. White, *Fluid
#: Mechanics* (7th ed., 2011), Table 1.4; nu = mu / rho
FLUIDS = {
    "air": Fluid("air", 1.205, 1.80e-5 / 1.205),
    "water": Fluid("water", 998.0, 1.00e-3 / 998.0),
    "oil": Fluid("SAE 30 oil", 891.0, 0.29 / 891.0),
}


@dataclass(frozen=True)
class PhysicalUnits:
    """Lattice units read as a physical flow with the same Reynolds number.

    Given the fluid (rho_f, nu_f), the body's physical size D (metres) and its size in cells L,
    and the simulated flow (wind U and viscosity nu in lattice units): the cell is dx = D / L;
    matching Re = U L / nu = U_f D / nu_f gives the physical wind U_f = Re nu_f / D, and the step
    dt = U dx / U_f (the same as nu dx^2 / nu_f). Then a lattice velocity times dx / dt is in
    m/s, a step is dt seconds, a lattice pressure (rho_0 = 1) times rho_f (dx / dt)^2 is in
    pascals, and a lattice force per unit span times rho_f dx^3 / dt^2 is in newtons per metre of
    span (`NewtonScale.physical`), times `span` (metres) in newtons. Only the Reynolds number is
    simulated: the lattice Mach number is not the physical one (water at 2 cm/s is far slower
    than sound; the lattice flow runs at Ma ~ 0.1 to be fast)."""

    fluid: Fluid
    size_m: float        # the body's size (its reference length) in metres
    span_m: float        # the body's extent across the 2D plane (metres): force per span -> newtons
    size_cells: float    # the same length in cells
    speed: float         # the simulated wind, lattice units
    nu: float            # the simulated viscosity, lattice units

    def __post_init__(self):
        for name in ("size_m", "span_m", "size_cells", "nu"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"{name}: must be a positive number, got {v!r}")
        if not (math.isfinite(self.speed) and self.speed >= 0):   # no wind: still a cell and a step
            raise ValueError(f"speed: must be a number >= 0, got {self.speed!r}")

    @property
    def reynolds(self) -> float:
        return reynolds(self.speed, self.size_cells, self.nu)

    @property
    def dx(self) -> float:
        """Metres per cell."""
        return self.size_m / self.size_cells

    @property
    def wind_m_s(self) -> float:
        """The physical wind speed with the simulated Reynolds number."""
        return self.reynolds * self.fluid.viscosity / self.size_m

    @property
    def dt(self) -> float:
        """Seconds per solver step: U dx / U_f, written as nu dx^2 / nu_f (the same, and defined
        without wind)."""
        return self.nu * self.dx * self.dx / self.fluid.viscosity

    def velocity(self, v):
        """Lattice velocity (cells/step) -> m/s."""
        return v * (self.dx / self.dt)

    def lattice_velocity(self, v_m_s):
        """m/s -> lattice velocity (cells/step): the inverse of `velocity`."""
        return v_m_s / (self.dx / self.dt)

    def time(self, steps):
        """Solver steps -> seconds."""
        return steps * self.dt

    def pressure(self, p):
        """Lattice pressure difference -> pascals."""
        return p * self.fluid.density * (self.dx / self.dt) ** 2

    def viscosity(self, nu):
        """Lattice kinematic viscosity (cells^2/step) -> m^2/s."""
        return nu * self.dx ** 2 / self.dt

    def force_scale(self) -> NewtonScale:
        return NewtonScale.physical(self.dx, self.dt, self.fluid.density, self.span_m)

    def force(self, f):
        """Lattice force (per unit span) -> newtons on a body `span_m` deep."""
        return self.force_scale().newtons(f)

    def describe(self) -> str:
        """'water at 2.0 cm/s past a 1 cm body (10 cm span)': the flow the tunnel simulates."""
        return (f"{self.fluid.name} at {_si(self.wind_m_s, 'm/s')} past a {_si(self.size_m, 'm')} body "
                f"({_si(self.span_m, 'm')} span), Re {self.reynolds:.3g}")


def _si(value: float, unit: str) -> str:
    """A length or speed with a readable prefix (cm, mm; cm/s, mm/s)."""
    for factor, prefix in ((1.0, ""), (1e-2, "c"), (1e-3, "m"), (1e-6, "\u00b5")):
        if abs(value) >= factor or factor == 1e-6:
            return f"{value / factor:.3g} {prefix}{unit}"
    return f"{value:.3g} {unit}"
