"""Flow configuration: everything a backend needs to set up the lattice, validated.

Units are lattice units (dx = dt = 1). `solver/units.py` converts to what a student reads.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from feelflow.solver.lattice import CS2, RHO0
from feelflow.solver.quiet_inlet import shortest_ramp

X_BOUNDARIES = ("tunnel", "periodic")
Y_BOUNDARIES = ("no_slip", "free_slip", "periodic")
#: bgk, trt, "rr": recursive-regularised BGK (solver/regularised.py), the high-Reynolds operator,
#: and "kbc": entropic KBC (solver/kbc.py; numpy and cpu backends, for comparison)
COLLISIONS = ("bgk", "trt", "rr", "kbc")
#: the equilibrium's velocity terms: rho u (compressible, the seed's eq. 9) or RHO0 u with
#: u = j / RHO0 (incompressible, He & Luo 1997, J. Stat. Phys. 88, 927)
EQUILIBRIA = ("compressible", "incompressible")
PROFILES = ("uniform", "parabolic")
DTYPES = ("float64", "float32")
#: a body force F (Guo et al. 2002) adds F to each node's momentum per step: it may not exceed
#: the Mach limit's speed, and between no-slip walls its steady Poiseuille flow,
#: u_max = F H^2 / (8 nu), may not exceed this many times that speed
BODY_FORCE_SPEED_FACTOR = 2.0


class ConfigError(ValueError):
    """A configuration value is out of range; `key` names it, the message says why."""

    def __init__(self, key: str, message: str):
        super().__init__(f"{key}: {message}")
        self.key = key


@dataclass(frozen=True)
class FlowConfig:
    nx: int
    ny: int
    nu: float = 0.02
    collision: str = "trt"
    trt_magic: float = 3.0 / 16.0
    #: Smagorinsky constant C of the eddy viscosity (collision "rr" only; 0: none)
    smagorinsky: float = 0.0
    equilibrium: str = "compressible"
    dtype: str = "float64"
    x_boundary: str = "tunnel"
    y_boundary: str = "no_slip"
    inflow_speed: float = 0.05
    inflow_profile: str = "uniform"
    inflow_ramp_steps: int = 1000
    body_force: tuple[float, float] = (0.0, 0.0)
    sponge_cells: int = 0
    sponge_strength: float = 10.0
    sponge_absorb: float = 0.0
    inlet_nonreflecting: float = 0.0
    initial_velocity: tuple[float, float] = (0.0, 0.0)
    mach_limit: float = 0.17
    extra: dict = field(default_factory=dict, compare=False)

    @property
    def tau(self) -> float:
        """BGK relaxation time, nu = (tau - 1/2) c_s^2 (seed eq. 5)."""
        return self.nu / CS2 + 0.5

    @property
    def incompressible(self) -> bool:
        """He & Luo's equilibrium (EQUILIBRIA): the velocity is j / RHO0, not j / rho."""
        return self.equilibrium == "incompressible"

    def velocity_divisor(self, rho):
        """What the momentum j is divided by to give the velocity: RHO0 or rho."""
        return RHO0 if self.incompressible else rho

    @property
    def max_speed(self) -> float:
        """Largest speed allowed anywhere (body or inflow): mach_limit * c_s."""
        return self.mach_limit * math.sqrt(CS2)

    def validate(self) -> "FlowConfig":
        def need(ok: bool, key: str, msg: str):
            if not ok:
                raise ConfigError(key, msg)

        for key in ("nx", "ny"):
            v = getattr(self, key)
            need(isinstance(v, int) and 8 <= v <= 8192, key, f"must be an integer in 8..8192, got {v!r}")
        need(math.isfinite(self.nu) and self.nu > 0, "nu", f"must be a positive number, got {self.nu!r}")
        need(self.tau > 0.5 + 1e-6, "nu", "too small: tau = 3 nu + 1/2 must exceed 1/2")
        need(self.tau < 10, "nu", f"too large (tau = {self.tau:.4g} > 10): lower the viscosity or raise the resolution")
        need(self.collision in COLLISIONS, "collision", f"must be one of {COLLISIONS}, got {self.collision!r}")
        need(self.equilibrium in EQUILIBRIA, "equilibrium", f"must be one of {EQUILIBRIA}, got {self.equilibrium!r}")
        need(math.isfinite(self.smagorinsky) and 0.0 <= self.smagorinsky <= 0.5, "smagorinsky",
             f"must be in 0..0.5, got {self.smagorinsky!r}")
        need(self.smagorinsky == 0.0 or self.collision in ("rr", "kbc"), "smagorinsky",
             f"only the rr and kbc collisions take a Smagorinsky constant (collision is {self.collision!r})")
        need(0 < self.trt_magic < 10, "trt_magic", f"must be in (0, 10), got {self.trt_magic!r}")
        need(self.dtype in DTYPES, "dtype", f"must be one of {DTYPES}, got {self.dtype!r}")
        need(self.x_boundary in X_BOUNDARIES, "x_boundary", f"must be one of {X_BOUNDARIES}, got {self.x_boundary!r}")
        need(self.y_boundary in Y_BOUNDARIES, "y_boundary", f"must be one of {Y_BOUNDARIES}, got {self.y_boundary!r}")
        need(self.inflow_profile in PROFILES, "inflow_profile", f"must be one of {PROFILES}, got {self.inflow_profile!r}")
        need(0 < self.mach_limit <= 0.5, "mach_limit", f"must be in (0, 0.5], got {self.mach_limit!r}")
        need(math.isfinite(self.inflow_speed) and abs(self.inflow_speed) <= self.max_speed, "inflow_speed",
             f"{self.inflow_speed:.6g} exceeds the Mach limit: |U| <= {self.max_speed:.4f} (Ma {self.mach_limit})")
        need(isinstance(self.inflow_ramp_steps, int) and self.inflow_ramp_steps >= 0, "inflow_ramp_steps",
             "must be a non-negative integer")
        need(isinstance(self.sponge_cells, int) and 0 <= self.sponge_cells < self.nx // 2, "sponge_cells",
             f"must be an integer in 0..{self.nx // 2 - 1}")
        need(self.sponge_strength >= 1, "sponge_strength", "must be >= 1")
        need(math.isfinite(self.sponge_absorb) and 0.0 <= self.sponge_absorb <= 0.5, "sponge_absorb",
             f"must be in 0..0.5, got {self.sponge_absorb!r}")
        need(math.isfinite(self.inlet_nonreflecting) and 0.0 <= self.inlet_nonreflecting <= 0.1,
             "inlet_nonreflecting", f"must be in 0..0.1, got {self.inlet_nonreflecting!r}")
        if self.inlet_nonreflecting > 0 and self.x_boundary == "tunnel":
            shortest = shortest_ramp(self.nx)
            need(self.inflow_ramp_steps == 0 or self.inflow_ramp_steps >= shortest, "inlet_nonreflecting",
                 f"the quiet inlet needs the wind everywhere from the start (inflow_ramp_steps = 0) or a ramp of "
                 f"at least {shortest} steps at nx = {self.nx} (got {self.inflow_ramp_steps}): a shorter ramp's "
                 f"sound would leave through it as a swing of the inflow")
        for key in ("body_force", "initial_velocity"):
            v = getattr(self, key)
            need(len(v) == 2 and all(math.isfinite(c) for c in v), key, "must be two finite numbers")
        need(math.hypot(*self.initial_velocity) <= self.max_speed, "initial_velocity", "exceeds the Mach limit")
        force = math.hypot(*self.body_force)
        need(force <= self.max_speed, "body_force",
             f"|F| = {force:.3g} is above {self.max_speed:.3g}: it alone would push the flow past the Mach "
             f"limit in a single step")
        if self.y_boundary == "no_slip":   # the steady channel flow it drives: u_max = F H^2 / (8 nu)
            u_max = abs(self.body_force[0]) * self.ny ** 2 / (8 * self.nu)
            need(u_max <= BODY_FORCE_SPEED_FACTOR * self.max_speed, "body_force",
                 f"F_x = {self.body_force[0]:.3g} drives a channel flow of u_max = F H^2 / (8 nu) = {u_max:.3g}, "
                 f"far above the Mach limit's {self.max_speed:.3g}")
        return self
