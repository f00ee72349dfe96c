"""The cylinder at Re 200 (solver/validation/cylinder_high_re.py): `feelflow validate --case cylinder-re200`."""
from __future__ import annotations

from feelflow.solver.validation.base import CaseResult, SolverFactory
from feelflow.solver.validation.cylinder_high_re import (DEFAULT_RESOLUTION, QUICK_RESOLUTION,  # noqa: F401
                                                          format_details, run_ladder)

NAME = "cylinder-re200"
RE = 200.0
#: hours at d = 40: `feelflow validate` runs it only when named with --case
NAMED_ONLY = True


def run(make_solver: SolverFactory, resolution: int | None = None, quick: bool = False,
        backend: str = "numpy") -> CaseResult:
    return run_ladder(NAME, RE, make_solver, resolution, quick, backend)
