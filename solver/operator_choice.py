"""Which collision operator a flow runs: the cheapest one that is stable and accurate for its
wind, viscosity, body size and Mach number, unless the scene names one.

The operators, cheapest first (costs per step: docs/science/collision-operators.md): TRT
(Ginzburg 2008), then recursive-regularised BGK (`rr`, solver/regularised.py). Both keep the
validation results at the Mach numbers the tunnel allows (FlowConfig.mach_limit); what tells
them apart is stability, measured on the hard cases (solver/stability_limit.py): TRT holds
U sqrt(d) / nu <= margin x K, rr the cell Reynolds number U / nu <= margin x its measured limit,
which falls with the body size and, above the wind it was measured at, with the Mach number.
The rule: TRT where it holds, else rr; beyond rr's region the stability guard of the window
(app/model/simulation.py stable_params) raises the viscosity to rr's limit.
"""
from __future__ import annotations

from dataclasses import dataclass

from feelflow.solver.stability_limit import inside, max_cell_reynolds

#: operators the chooser picks from, cheapest first
ORDER = ("trt", "rr")
#: the most stable operator: the window's guard keeps the flow inside its region
MOST_STABLE = "rr"
NAMES = {"trt": "TRT", "bgk": "BGK", "rr": "regularised BGK"}


@dataclass(frozen=True)
class Choice:
    collision: str
    smagorinsky: float
    reason: str          # one line: which operator and why

    @property
    def label(self) -> str:
        name = NAMES.get(self.collision, self.collision)
        return f"{name} + Smagorinsky" if self.smagorinsky else name


def choose(speed: float, nu: float, size: float, mach_limit: float = 0.17, named: str | None = None,
           smagorinsky: float = 0.0) -> Choice:
    """The operator for wind `speed` past a body of `size` cells at viscosity `nu`; `named`: the
    scene's own choice (kept whatever the flow)."""
    re_cell = abs(speed) / nu
    mach = abs(speed) * 3 ** 0.5
    if named is not None:
        reason = f"{NAMES.get(named, named)}: named by the scene (U/nu {re_cell:.1f}, Ma {mach:.2f})"
        return Choice(named, smagorinsky if named == "rr" else 0.0, reason)
    for collision in ORDER:
        if inside(speed, nu, collision, size):
            if collision == ORDER[0]:
                reason = (f"TRT: U/nu {re_cell:.1f} within its stable {max_cell_reynolds('trt', size):.1f} "
                          f"at d {size:g}, Ma {mach:.2f} (cheapest)")
            else:
                reason = (f"{NAMES[collision]}: U/nu {re_cell:.1f} beyond TRT's stable "
                          f"{max_cell_reynolds('trt', size):.1f} at d {size:g}, within its "
                          f"{max_cell_reynolds(collision, size, speed):.0f}, Ma {mach:.2f}")
            return Choice(collision, 0.0, reason)
    return Choice(MOST_STABLE, 0.0, f"{NAMES[MOST_STABLE]}: U/nu {re_cell:.1f} beyond every operator's "
                                    f"stable limit at d {size:g} (the window raises the viscosity)")
