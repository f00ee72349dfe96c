"""The units the window shows numbers in: lattice units, or SI for a physical flow with the
simulated Reynolds number (solver/units.py `PhysicalUnits` converts; this module only names the
units and picks the conversion). Qt-free: the force plot, the probes' plot, the side panel and
the CSV export ask a `DisplayUnits` for their numbers and axis labels.

The physical reading depends on the flow now (wind, viscosity and the body's size in cells set
the Reynolds number, and so the physical speed and the length of a step): `for_model` makes it
for the model shown, each time it is needed.
"""
from __future__ import annotations

from dataclasses import dataclass

from feelflow.solver.units import FLUIDS, PhysicalUnits

LATTICE = "lattice"
#: the body sizes offered (metres) and the default span (the body's extent out of the plane)
DEFAULT_SIZE_M = {"air": 0.05, "water": 0.01, "oil": 0.05}
DEFAULT_SPAN_M = 0.1


@dataclass(frozen=True)
class UnitsChoice:
    """What the user chose: `fluid` LATTICE or a key of solver/units.py FLUIDS, the body's size
    and span in metres."""

    fluid: str = LATTICE
    size_m: float = 0.01
    span_m: float = DEFAULT_SPAN_M

    @property
    def physical(self) -> bool:
        return self.fluid != LATTICE

    def __post_init__(self):
        if self.fluid != LATTICE and self.fluid not in FLUIDS:
            raise ValueError(f"units: {self.fluid!r} is not one of lattice, {', '.join(FLUIDS)}")
        if self.physical and not (self.size_m > 0 and self.span_m > 0):
            raise ValueError("units: the body's size and span must be positive lengths in metres")


class DisplayUnits:
    """Conversions and unit names for what is shown: identity and lattice names without
    `physical`, SI with it."""

    def __init__(self, physical: PhysicalUnits | None = None):
        self.physical = physical

    @property
    def is_si(self) -> bool:
        return self.physical is not None

    speed_unit = property(lambda self: "m/s" if self.physical else "cells/step")
    time_unit = property(lambda self: "s" if self.physical else "solver steps")
    force_unit = property(lambda self: "N" if self.physical else "lattice units")
    pressure_unit = property(lambda self: "Pa" if self.physical else "lattice units")
    viscosity_unit = property(lambda self: "m\u00b2/s" if self.physical else "cells\u00b2/step")

    def speed(self, v):
        return self.physical.velocity(v) if self.physical else v

    def time(self, steps):
        return self.physical.time(steps) if self.physical else steps

    def force(self, f):
        return self.physical.force(f) if self.physical else f

    def pressure(self, p):
        return self.physical.pressure(p) if self.physical else p

    def viscosity(self, nu):
        return self.physical.viscosity(nu) if self.physical else nu

    def describe(self) -> str:
        return self.physical.describe() if self.physical else "lattice units (cells, solver steps)"


def for_model(choice: UnitsChoice, model) -> DisplayUnits:
    """The units for `model` (a TunnelModel) now: lattice when chosen, or when the flow has no
    wind or no body to scale by (then nothing physical can be read)."""
    if not choice.physical or model is None:
        return DisplayUnits()
    p = model.params
    length = model.reference_length().cells
    try:
        return DisplayUnits(PhysicalUnits(FLUIDS[choice.fluid], choice.size_m, choice.span_m, length, p.wind, p.nu))
    except ValueError:
        return DisplayUnits()
