"""The side panel's numbers in the units shown (app/model/display_units.py), Qt-free: the
wind and viscosity boxes' ranges, steps, suffixes and tooltips in lattice units or SI, the
drag and lift readouts, and the physical reading of the flow under the Reynolds number.
app/gui/side_panel.py and app/gui/flow_box_units.py draw them."""
from __future__ import annotations

import math
from typing import NamedTuple

from feelflow.app.model.display_units import DisplayUnits


class BoxRange(NamedTuple):
    """A number box's decimals, minimum, maximum, step and suffix."""

    decimals: int
    minimum: float
    maximum: float
    step: float
    suffix: str


#: the flow boxes in lattice units
WIND_LATTICE = BoxRange(3, 0.0, 0.09, 0.005, " cells/step")
VISCOSITY_LATTICE = BoxRange(4, 0.0005, 0.3, 0.002, " cells\u00b2/step")
#: the viscosity box in SI: the fluid's value, read-only, in scientific notation
VISCOSITY_SI = BoxRange(12, 0.0, 1.0, 0.0, " m\u00b2/s")

WIND_TIP = ("Speed of the incoming air, in grid cells per solver step; "
            "keep the Mach number under its limit for a trustworthy flow")
VISCOSITY_TIP = ("How thick (syrupy) the fluid is, in cells\u00b2 per step: lower viscosity gives a higher "
                 "Reynolds number, with eddies and a swinging wake")


def decimals_for(maximum: float) -> int:
    """Decimals that give a value near `maximum` four significant digits."""
    return max(0, min(12, 3 - math.floor(math.log10(maximum)))) if maximum > 0 else 3


def wind_range(units: DisplayUnits) -> BoxRange:
    """The wind box in the units shown: the lattice range, or the same speeds in m/s."""
    if not units.is_si:
        return WIND_LATTICE
    top = units.speed(WIND_LATTICE.maximum)
    return BoxRange(decimals_for(top), 0.0, top, units.speed(WIND_LATTICE.step), " m/s")


def viscosity_range(units: DisplayUnits) -> BoxRange:
    return VISCOSITY_SI if units.is_si else VISCOSITY_LATTICE


def wind_tip(units: DisplayUnits, wind: float) -> str:
    """The wind box's tooltip; in SI it names the lattice speed `wind` the solver runs."""
    if not units.is_si:
        return WIND_TIP
    return (f"Speed of the incoming {units.physical.fluid.name}, in m/s for the chosen body size "
            f"(View > Units); the solver runs the same Reynolds number at {wind:.4g} cells per step")


def viscosity_tip(units: DisplayUnits, nu: float) -> str:
    """The viscosity box's tooltip; in SI it says why the box is read-only and names the
    lattice viscosity `nu` the solver runs."""
    if not units.is_si:
        return VISCOSITY_TIP
    return (f"{units.physical.fluid.name}'s kinematic viscosity: the fluid fixes it, so it cannot "
            f"be changed here (change the Reynolds number with the wind speed, or "
            f"set the solver's viscosity in lattice units, View > Units); the "
            f"solver runs {nu:.4g} cells\u00b2 per step")


def force_pair_text(drag: float, lift: float) -> tuple[str, str]:
    """Drag and lift with the same decimals, four significant digits of the larger: a lift of
    -5.6e-10 beside a drag of 0.58 reads 0.0000, not -5.563e-10 (noise in scientific notation)."""
    scale = max(abs(drag), abs(lift))
    if scale < 1e-9:   # no wind, no force
        return "0", "0"
    decimals = max(0, 3 - math.floor(math.log10(scale)))

    def text(v):
        t = f"{v:.{decimals}f}"
        return t.lstrip("-") if float(t) == 0 else t
    return text(drag), text(lift)


def force_texts(drag: float | None, lift: float | None, units: DisplayUnits) -> tuple[str, str]:
    """The Drag and Lift readouts with their unit: newtons to four significant digits in SI
    (forces of micronewtons in water), lattice units as `force_pair_text`; a dash without data."""
    if drag is None or lift is None or not (math.isfinite(drag) and math.isfinite(lift)):
        return "\u2013", "\u2013"
    if units.is_si:
        d, l_ = f"{units.force(drag):.4g}", f"{units.force(lift):.4g}"
    else:
        d, l_ = force_pair_text(drag, lift)
    unit = "N" if units.is_si else "lattice units"
    return f"{d} ({unit})", f"{l_} ({unit})"


def physical_text(units: DisplayUnits) -> str:
    """What the flow simulates in SI (rich text): the body, wind, fluid, a step and a cell, and
    the lattice values the solver runs; empty in lattice units."""
    if not units.is_si:
        return ""
    ph = units.physical
    return (f"<i>Simulates {ph.describe()}: wind {ph.wind_m_s:.3g} m/s, "
            f"ν {ph.fluid.viscosity:.3g} m²/s, ρ {ph.fluid.density:g} kg/m³; "
            f"a step is {ph.dt:.3g} s, a cell {ph.dx:.3g} m. The solver runs wind "
            f"{ph.speed:.4g} cells/step, ν {ph.nu:.4g} cells²/step.</i>")
