"""The local stability guard in the live tunnel (Qt-free): after each frame, the fastest node
the solver's last physical-range check found is held against the running collision operator's
stable region (solver/local_guard.py, from the operators' linear stability regions); outside
it, the viscosity that brings it back is asked for, keeping the flow. The `Simulation`
(app/model/simulation.py) holds one and sets the viscosity it asks for. Lattice units.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from feelflow.solver import local_guard


@dataclass(frozen=True)
class GuardAction:
    """What the guard found: its verdict (solver/local_guard.py `Verdict`, whose `line` says it
    in one sentence) and the viscosity to set, rounded up to 4 decimals (None: no viscosity on
    the table reaches it, only a slower flow is stable)."""

    verdict: local_guard.Verdict
    nu: float | None


class LocalStabilityGuard:
    """Reads each physical-range check once (`read_at`: the solver step of the last max |u|
    read) and says whether the running flow has left its operator's stable region."""

    def __init__(self):
        self.read_at = None

    def check(self, solver, collision: str, nu: float,
              operator_at: Callable[[float], str]) -> GuardAction | None:
        """None while the last check is read already or found the flow inside the region of
        `collision` at `nu`; else what to do. `operator_at(nu)` is the collision operator the
        chooser picks at another viscosity: its region counts for the one asked for."""
        at = solver.max_speed_at
        if at is None or at == self.read_at:
            return None
        self.read_at = at
        verdict = local_guard.check(collision, nu, solver.max_speed_seen)
        if verdict.inside:
            return None
        if verdict.nu_needed is None:
            return GuardAction(verdict, None)
        nu = verdict.nu_needed
        for _ in range(3):   # the chooser may pick another operator at the new viscosity: its region counts
            again = local_guard.check(operator_at(nu), nu, verdict.max_speed).nu_needed
            if again is None or again <= nu:
                break
            nu = again
        return GuardAction(verdict, math.ceil(nu * 1e4 - 1e-6) / 1e4)
