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
    torque_unit = property(lambda self: "N\u00b7m" if self.physical else "lattice units")

    def speed(self, v):
        return self.physical.velocity(v) if self.physical else v

    def lattice_speed(self, v):
        """A speed shown in these units back to the solver's (cells/step)."""
        return self.physical.lattice_velocity(v) if self.physical else v

    def time(self, steps):
        return self.physical.time(steps) if self.physical else steps

    def force(self, f):
        return self.physical.force(f) if self.physical else f

    def torque(self, t):
        """A torque about the body's centre: a force times a lever arm in cells (dx metres each)."""
        return self.physical.force(t) * self.physical.dx if self.physical else t

    def pressure(self, p):
        return self.physical.pressure(p) if self.physical else p

    def viscosity(self, nu):
        return self.physical.viscosity(nu) if self.physical else nu

    def describe(self) -> str:
        return self.physical.describe() if self.physical else "lattice units (cells, solver steps)"


def for_model(choice: UnitsChoice, model) -> DisplayUnits:
    """The units for `model` (a TunnelModel) now: lattice when chosen, or when the flow has no
    body to scale by (then nothing physical can be read)."""
    if not choice.physical or model is None:
        return DisplayUnits()
    p = model.params
    length = model.reference_length().cells
    try:
        return DisplayUnits(PhysicalUnits(FLUIDS[choice.fluid], choice.size_m, choice.span_m, length, p.wind, p.nu))
    except ValueError:
        return DisplayUnits()


def choice_to_dict(choice: UnitsChoice) -> dict:
    """The choice as a session file records it (app/sessions/format.py, manifest "units")."""
    return {"fluid": choice.fluid, "size_m": float(choice.size_m), "span_m": float(choice.span_m)}


def choice_from_dict(d) -> UnitsChoice | None:
    """A session's recorded choice (already checked by app/sessions/format.py); None if absent."""
    if not isinstance(d, dict):
        return None
    return UnitsChoice(d["fluid"], float(d["size_m"]), float(d["span_m"]))


def _column_unit(name: str, units: DisplayUnits):
    """(SI column name, conversion) for a CSV column of lattice values, or None to leave it."""
    if name == "step":
        return "time_s", units.time
    if name.endswith(("_fx", "_fy", "_drag", "_lift")) or name.startswith(("fx_", "fy_")):
        return f"{name}_N", units.force
    if name in ("vx", "vy") or name.startswith(("body_v", "wind_")) or \
            (name.startswith("probe") and name.endswith(("_ux", "_uy", "_speed"))):
        return f"{name}_m_s", units.speed
    if name.startswith("probe") and name.endswith("_p"):
        return f"{name}_Pa", units.pressure
    if name in ("x", "y"):
        return f"{name}_m", lambda v: v * units.physical.dx
    if name.startswith("torque_"):
        return f"{name}_N_m", units.torque
    return None


def si_columns(head: list[str], rows: list[list], units: DisplayUnits) -> tuple[list[str], list[list]]:
    """A CSV table with SI columns added after the lattice ones: `time_s` for the step, `*_N`
    for forces (`*_fx`, `*_fy`, `*_drag`, `*_lift`, `fx_*`, `fy_*`), `*_m_s` for velocities,
    `*_Pa` for probe pressures, `x_m`, `y_m` for positions (solver/units.py PhysicalUnits)."""
    convert = [(i, *c) for i, name in enumerate(head) if (c := _column_unit(name, units)) is not None]
    out_rows = []
    for row in rows:
        extra = []
        for i, _, fn in convert:
            cell = str(row[i]) if i < len(row) else ""
            try:
                extra.append(f"{fn(float(cell)):.8g}" if cell not in ("", "nan") else cell)
            except ValueError:
                extra.append("")
        out_rows.append(list(row) + extra)
    return list(head) + [name for _, name, _ in convert], out_rows


def parse_si(text: str) -> UnitsChoice:
    """`--si FLUID:SIZE_M[:SPAN_M]` (for example water:0.01 or air:0.05:0.2) as a UnitsChoice;
    ValueError (one line) for anything else."""
    parts = str(text).split(":")
    fluids = ", ".join(FLUIDS)
    if len(parts) not in (2, 3) or parts[0] not in FLUIDS:
        raise ValueError(f"--si: give FLUID:SIZE_M[:SPAN_M] with FLUID one of {fluids} (for example water:0.01), "
                         f"got {text!r}")
    try:
        size = float(parts[1])
        span = float(parts[2]) if len(parts) == 3 else DEFAULT_SPAN_M
    except ValueError:
        raise ValueError(f"--si: the body's size and span are lengths in metres, got {text!r}") from None
    if not (size > 0 and span > 0 and size < 1e6 and span < 1e6):
        raise ValueError(f"--si: the body's size and span must be positive lengths in metres, got {text!r}")
    return UnitsChoice(parts[0], size, span)
