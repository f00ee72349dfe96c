"""Physics validation cases (one module each), run by `feelflow validate` and the tests.

`CASES` is the registry: name -> module. Each module has `NAME`, `DEFAULT_RESOLUTION`,
`QUICK_RESOLUTION` and `run(make_solver, resolution=None, quick=False) -> CaseResult`
(solver/validation/base.py); a case whose geometry allows only some resolutions also has
`check_resolution(n)`, which raises ValueError naming why, so that `feelflow validate` refuses
a bad `--resolution` before it runs anything.
"""
from __future__ import annotations

import importlib

CASES: dict[str, str] = {
    "poiseuille": "feelflow.solver.validation.poiseuille",
    "taylor-green": "feelflow.solver.validation.taylor_green",
    "schaefer-turek-2d1": "feelflow.solver.validation.schaefer_turek_2d1",
    "schaefer-turek-2d2": "feelflow.solver.validation.schaefer_turek_2d2",
    "galilean": "feelflow.solver.validation.galilean",
    "mass": "feelflow.solver.validation.mass",
    "stability": "feelflow.solver.validation.stability",
    "strouhal-re100": "feelflow.solver.validation.strouhal",
    "cylinder-re200": "feelflow.solver.validation.cylinder_re200",
    "cylinder-re1000": "feelflow.solver.validation.cylinder_re1000",
    "oscillating-cylinder": "feelflow.solver.validation.oscillating_cylinder",
}


def case_module(name: str):
    """The module of a case by registry name."""
    if name not in CASES:
        raise KeyError(f"unknown validation case {name!r}; choose from {', '.join(CASES)}")
    return importlib.import_module(CASES[name])
