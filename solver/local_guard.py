"""The local stability guard: is the flow, where it is fastest, inside the region in which its
collision operator is stable? Read from the field the physical-range check already reads
(max |u| over the grid, `Solver.check_physical`), not from a law in the wind and body size
fitted on one grid, so the same limit holds for any grid and body size.

The region is the operator's linear (von Neumann) stability region, measured by
solver/validation/linear_stability.py on the numpy reference operators: a uniform flow at
speed |u| and viscosity nu is stable when no disturbance of any wavelength grows, along every
direction of the flow (0, 22.5 and 45 degrees; 22.5 is the weakest for TRT, 45 for rr).
`LINEAR_LIMIT` holds, per operator, the largest such |u| at each tabulated viscosity (an
operator without a row, KBC, whose entropic gamma is not linearisable at equilibrium, gets BGK's)
(`python -m feelflow.solver.local_guard` prints and checks the table). A flow whose fastest node
moves faster than `MARGIN` x that limit at its viscosity has left the region there: the guard
asks for the smallest tabulated-and-interpolated viscosity whose limit covers it.

How this relates to the hard cases (docs/science/collision-operators.md, 'Local guard'): TRT's
linear limit is a cell Reynolds number, |u| = 16.6 nu; the stability scan's TRT failures
start at a wind U / nu of about 9 - 11, where the flow near the body runs at about twice the
wind. rr's limit is a Mach number (|u| 0.25 - 0.4 for nu 0.0005 - 0.05): its failures on the
scan are the runs whose max |u| passed 0.35.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from feelflow.solver.lattice import CS2

#: the fraction of the linear limit the guard lets the fastest node reach
MARGIN = 0.9

#: operator -> ((nu, largest linearly stable |u| over the directions 0, 22.5, 45 degrees), ...),
#: measured by solver/validation/linear_stability.py (48 x 48 wave vectors, bisection to 0.001)
LINEAR_LIMIT: dict[str, tuple[tuple[float, float], ...]] = {
    "trt": ((0.0005, 0.0078), (0.001, 0.0166), (0.002, 0.0342), (0.004, 0.0693),
            (0.007, 0.1230), (0.01, 0.1787), (0.02, 0.2637), (0.05, 0.3418)),
    "bgk": ((0.0005, 0.1084), (0.001, 0.1172), (0.002, 0.1426), (0.004, 0.1807),
            (0.007, 0.2070), (0.01, 0.2217), (0.02, 0.2412), (0.05, 0.2979)),
    "rr": ((0.0005, 0.2256), (0.001, 0.2725), (0.002, 0.3193), (0.004, 0.3496),
            (0.007, 0.3750), (0.01, 0.3965), (0.02, 0.4209), (0.05, 0.4219)),
}


def speed_limit(collision: str, nu: float) -> float:
    """Largest |u| inside `collision`'s linear region at viscosity nu: linear interpolation in
    the table; below its smallest viscosity, proportional to nu (a cell Reynolds number, TRT's
    law and below rr's); above its largest, the last value."""
    table = LINEAR_LIMIT[collision]
    nu = float(nu)
    if nu <= table[0][0]:
        return table[0][1] * nu / table[0][0]
    for (n0, u0), (n1, u1) in zip(table, table[1:]):
        if nu <= n1:
            return u0 + (u1 - u0) * (nu - n0) / (n1 - n0)
    return table[-1][1]


def viscosity_for(collision: str, speed: float) -> float | None:
    """The smallest viscosity at which `speed` lies inside MARGIN x the linear limit (None when
    no tabulated viscosity reaches it: only a slower flow is stable)."""
    need = float(speed) / MARGIN
    table = LINEAR_LIMIT[collision]
    if need <= table[0][1]:
        return table[0][0] * need / table[0][1]
    for (n0, u0), (n1, u1) in zip(table, table[1:]):
        if need <= u1:
            return n0 + (n1 - n0) * (need - u0) / (u1 - u0) if u1 > u0 else n1
    return None


@dataclass(frozen=True)
class Verdict:
    """What the guard found: `inside` the region, else the viscosity that brings the flow back
    (`nu_needed`, None when none does), and the numbers behind it."""

    collision: str
    nu: float
    max_speed: float
    limit: float
    nu_needed: float | None

    @property
    def inside(self) -> bool:
        return self.max_speed <= MARGIN * self.limit

    @property
    def mach(self) -> float:
        return self.max_speed / math.sqrt(CS2)

    def line(self, name: str, nu_set: float | None = None) -> str:
        """One sentence for the status bar or the terminal."""
        where = (f"the flow reached |u| {self.max_speed:.3f} (Ma {self.mach:.2f}) where it is fastest, beyond "
                 f"{MARGIN * self.limit:.3g}, what {name} keeps stable at viscosity {self.nu:.4g}")
        if nu_set is not None:
            return f"Viscosity raised to {nu_set:.4f}: {where}."
        if self.nu_needed is None:
            return f"{where[0].upper()}{where[1:]}; no viscosity keeps it stable: lower the wind or the body's speed."
        return f"{where[0].upper()}{where[1:]}; viscosity {self.nu_needed:.4f} or more keeps it inside."


def check(collision: str, nu: float, max_speed: float) -> Verdict:
    """The verdict for a flow of `collision` at viscosity nu whose fastest node moves at max_speed."""
    base = "bgk" if collision not in LINEAR_LIMIT else collision
    limit = speed_limit(base, nu)
    needed = None
    if max_speed > MARGIN * limit:
        needed = viscosity_for(base, max_speed)
        if needed is not None:
            needed = max(needed, float(nu))
    return Verdict(collision, float(nu), float(max_speed), limit, needed)


def main(argv=None) -> int:
    """Print the table against a fresh analysis at each tabulated viscosity (slow: minutes)."""
    from feelflow.solver.validation.linear_stability import max_stable_speed

    for collision, table in LINEAR_LIMIT.items():
        for nu, u in table:
            fresh = min(max_stable_speed(collision, nu, a) for a in (0.0, 22.5, 45.0))
            print(f"{collision:4s} nu {nu:<7g} table {u:.4f}  analysis {fresh:.4f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
