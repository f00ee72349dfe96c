"""What every validation case returns, and the bookkeeping they share."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

from feelflow.solver.backend import Solver
from feelflow.solver.config import FlowConfig

#: builds a solver of the chosen backend for a configuration (the CLI and tests supply it)
SolverFactory = Callable[[FlowConfig], Solver]


@dataclass(frozen=True)
class Check:
    """One target: `quantity` must lie in [low, high] (published interval or reference +- tol)."""

    quantity: str
    low: float
    high: float
    source: str = ""

    def holds(self, value: float) -> bool:
        return bool(math.isfinite(value) and self.low <= value <= self.high)

    def describe(self) -> str:
        return f"{self.low:.6g} .. {self.high:.6g}"


@dataclass
class CaseResult:
    """Measured quantities of one case at one resolution, and whether the targets hold."""

    name: str
    backend: str
    resolution: int
    quantities: dict[str, float] = field(default_factory=dict)
    checks: list[Check] = field(default_factory=list)
    steps: int = 0
    node_updates: int = 0
    wall_seconds: float = 0.0   # in the solver's steps (and the moves of a moving body): MLUPS
    case_seconds: float = 0.0   # the whole case: also set-up, read-backs and analysis (run_case)
    notes: str = ""
    details: dict = field(default_factory=dict)   # case-specific extra data for the JSON (maps, series)

    @property
    def mlups(self) -> float:
        return self.node_updates / self.wall_seconds / 1e6 if self.wall_seconds > 0 else float("nan")

    def check_results(self) -> dict[str, bool]:
        return {c.quantity: c.holds(self.quantities.get(c.quantity, float("nan"))) for c in self.checks}

    @property
    def passed(self) -> bool:
        return all(self.check_results().values())

    def to_dict(self) -> dict:
        def clean(v):
            return v if isinstance(v, (int, str)) or math.isfinite(v) else None

        return {
            "name": self.name, "backend": self.backend, "resolution": self.resolution,
            "quantities": {k: clean(float(v)) for k, v in self.quantities.items()},
            "targets": {c.quantity: {"low": c.low, "high": c.high, "source": c.source,
                                     "met": self.check_results()[c.quantity]} for c in self.checks},
            "passed": self.passed, "steps": self.steps, "wall_seconds": round(self.wall_seconds, 3),
            "case_seconds": round(self.case_seconds, 3), "mlups": clean(round(self.mlups, 3)), "notes": self.notes,
            **({"details": self.details} if self.details else {}),
        }


class Stopwatch:
    """Counts node updates and wall time spent stepping solvers (with the body's moves where a
    case moves it between steps: `timed`)."""

    def __init__(self):
        self.seconds = 0.0
        self.steps = 0
        self.node_updates = 0

    def step(self, solver: Solver, n: int) -> None:
        t0 = time.perf_counter()
        solver.step(n)
        self.seconds += time.perf_counter() - t0
        self.steps += n
        self.node_updates += n * solver.nodes_per_step

    def timed(self, nodes: int, steps: int, advance, *args):
        """Call `advance(*args)` (which runs `steps` steps on `nodes` nodes) and count it."""
        t0 = time.perf_counter()
        out = advance(*args)
        self.seconds += time.perf_counter() - t0
        self.steps += steps
        self.node_updates += steps * nodes
        return out

    def fill(self, result: CaseResult) -> CaseResult:
        result.steps = self.steps
        result.node_updates = self.node_updates
        result.wall_seconds = self.seconds
        return result
