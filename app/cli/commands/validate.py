"""`feelflow validate`: run the physics validation cases, print a table, optionally write JSON.

Cases live in `solver/validation/` (one module each); the registry is `feelflow.solver.validation.CASES`.
The exit code is 0 when every target is met, 1 otherwise.
"""
from __future__ import annotations

import os
import platform
from dataclasses import replace
from pathlib import Path

from feelflow.app.errors import UserError
from feelflow.app.machine import cpu_name


def add_arguments(parser):
    from feelflow.solver.validation import CASES

    parser.add_argument("--case", action="append", metavar="NAME",
                        help=f"a case to run (repeatable; default: all but the hours-long high-Reynolds "
                             f"ladders, which run when named): {', '.join(CASES)}")
    parser.add_argument("--resolution", default=None, metavar="N",
                        help="cells per diameter (a multiple of 10 for the Schaefer-Turek cases, whose channel "
                             "is 4.1 diameters high; channel width for poiseuille, grid size for taylor-green); "
                             "default: each case's own")
    parser.add_argument("--backend", default="numpy", metavar="numpy|cpu|gl", help="solver backend (default: numpy)")
    parser.add_argument("--collision", default=None, metavar="bgk|trt|rr|kbc",
                        help="run the cases with this collision operator instead of their own (not the stability "
                             "case, which names its operators)")
    parser.add_argument("--smagorinsky", default=0.0, type=float, metavar="C",
                        help="Smagorinsky constant with --collision rr or kbc (default 0: none)")
    parser.add_argument("--json", default=None, metavar="PATH", help="also write the results as JSON")
    parser.add_argument("--force", action="store_true", help="replace --json if it exists")
    parser.add_argument("--quick", action="store_true", help="small grids and short runs (the test-suite versions)")
    parser.add_argument("--refine", action="store_true",
                        help="the Schaefer-Turek cases with the cylinder and its near wake in a patch of twice the "
                             "resolution (numpy only; solver/refinement.py); default cases: those two")


#: the largest --resolution (cells per diameter): the Schaefer-Turek channel is 22 x 4.1
#: diameters, so 400 cells a diameter is already 3.6 million nodes (app/inputs.py's MAX_NODES)
MAX_RESOLUTION = 400


def machine_description() -> str:
    return (f"{cpu_name()} ({os.cpu_count()} logical CPUs), {platform.system()} {platform.release()}, "
            f"Python {platform.python_version()}")


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def format_table(results) -> str:
    """A Markdown table: one row per measured quantity that has a target, plus speed."""
    lines = ["| case | N | quantity | value | target | met | steps | wall s | MLUPS |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in results:
        met = r.check_results()
        checked = {c.quantity: c for c in r.checks}
        first = True
        for name, value in r.quantities.items():
            target = checked[name].describe() if name in checked else ""
            ok = ("yes" if met[name] else "**no**") if name in checked else ""
            speed = [str(r.steps), f"{r.wall_seconds:.1f}", f"{r.mlups:.1f}"] if first else ["", "", ""]
            lines.append(f"| {r.name if first else ''} | {r.resolution if first else ''} | {name} | {_fmt(value)} "
                         f"| {target} | {ok} | " + " | ".join(speed) + " |")
            first = False
    return "\n".join(lines)


def write_json_atomic(path: Path, data) -> None:
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        raise UserError(f"--json: directory {str(directory)!r} does not exist")
    from feelflow.app import files

    files.save_json(path, data, "--json")


def refinable(name: str) -> bool:
    """Whether a case's `run` takes `refine` (it has a body to refine around)."""
    import inspect

    from feelflow.solver.validation import case_module

    return "refine" in inspect.signature(case_module(name).run).parameters


def run_case(name: str, factory, resolution, quick: bool, backend: str, refine: bool = False):
    """One case; a flow that blows up is a failed case (stable = 0), not a traceback."""
    import time
    import warnings

    import numpy as np

    from feelflow.solver import backend as backends
    from feelflow.solver.validation import case_module
    from feelflow.solver.validation.base import CaseResult, Check

    module = case_module(name)
    t0 = time.perf_counter()
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            extra = {"refine": True} if refine else {}
            result = module.run(factory, resolution=resolution, quick=quick, backend=backend, **extra)
    except ValueError as exc:   # ConfigError, ShapeError: the resolution gives an impossible grid
        raise UserError(f"--resolution: {name}: {str(exc).splitlines()[0]}") from None
    except backends.SolverDiverged as exc:
        n = resolution or (module.QUICK_RESOLUTION if quick else module.DEFAULT_RESOLUTION)
        result = CaseResult(name, backend, n, quantities={"stable": 0.0, "diverged_at_step": float(exc.step)},
                            checks=[Check("stable", 1.0, 1.0, "the flow must not blow up")])
        result.notes = str(exc)
    result.case_seconds = time.perf_counter() - t0
    return result


def operator_override(args) -> dict:
    """{collision, smagorinsky} from --collision / --smagorinsky ({} when not given); UserError
    naming the option when the pair is invalid."""
    from feelflow.solver.config import COLLISIONS, ConfigError, FlowConfig

    collision = getattr(args, "collision", None)
    smagorinsky = float(getattr(args, "smagorinsky", 0.0) or 0.0)
    if collision is None:
        if smagorinsky:
            raise UserError("--smagorinsky: needs --collision rr or kbc")
        return {}
    if collision not in COLLISIONS:
        raise UserError(f"--collision: must be one of {', '.join(COLLISIONS)}, got {collision!r}")
    try:
        FlowConfig(nx=16, ny=16, collision=collision, smagorinsky=smagorinsky).validate()
    except ConfigError as exc:
        raise UserError(f"--{exc.key}: {str(exc).split(': ', 1)[1]}") from None
    return {"collision": collision, "smagorinsky": smagorinsky}


def main(args) -> int:
    from feelflow.app.cli.commands.run import positive_int_option
    from feelflow.app.headless import make_solver
    from feelflow.solver.validation import CASES, case_module

    refine = bool(getattr(args, "refine", False))
    for name in args.case or []:
        if name not in CASES:
            raise UserError(f"--case: unknown case {name!r}; choose from {', '.join(CASES)}")
    names = args.case or [name for name in CASES if (refinable(name) or not refine)
                          and not getattr(case_module(name), "NAMED_ONLY", False)]
    if refine:
        if args.backend != "numpy":
            raise UserError(f"--refine: the refined patch runs on the numpy backend only, not {args.backend!r}")
        for name in names:
            if not refinable(name):
                raise UserError(f"--refine: case {name!r} has no body to refine around; "
                                f"choose from {', '.join(n for n in CASES if refinable(n))}")
    resolution = positive_int_option("--resolution", args.resolution) if args.resolution is not None else None
    for name in names:
        check = getattr(case_module(name), "check_resolution", None)
        if resolution is not None and check is not None:
            try:
                check(resolution)
            except ValueError as exc:
                raise UserError(f"--resolution: {name}: {exc}") from None
    if resolution is not None and resolution > MAX_RESOLUTION:
        raise UserError(f"--resolution: at most {MAX_RESOLUTION} cells per diameter (a larger grid would not "
                        f"fit this machine's memory), got {resolution}")
    if args.json is not None:   # before the cases run
        from feelflow.app.files import check_output

        check_output(args.json, "--json", force=args.force)

    operator = operator_override(args)

    def factory(config):
        return make_solver(args.backend, config)

    def factory_with_operator(config):
        return make_solver(args.backend, replace(config, **operator).validate())

    results = []
    for name in names:
        print(f"running {name} ...", flush=True)
        own = not operator or name == "stability"
        result = run_case(name, factory if own else factory_with_operator, resolution, args.quick, args.backend, refine)
        results.append(result)
        print(f"  {name}: {'targets met' if result.passed else 'TARGETS NOT MET'} "
              f"({result.steps} steps, {result.wall_seconds:.1f} s stepping, {result.case_seconds:.1f} s in all)",
              flush=True)
    machine = machine_description()
    op = f", collision {operator['collision']} (Smagorinsky C {operator['smagorinsky']:g})" if operator else ""
    print(f"\nFeelFlow validation, backend {args.backend}{', refined patch' if refine else ''}{op}, on {machine}\n")
    print(format_table(results))
    for r in results:   # a case may add its own tables (e.g. the stability map)
        details = getattr(case_module(r.name), "format_details", None)
        if details is not None and details(r):
            print("\n" + details(r))
    failed = [r.name for r in results if not r.passed]
    print(f"\n{len(results) - len(failed)} of {len(results)} cases meet their targets"
          + (f"; not met: {', '.join(failed)}" if failed else ""))
    if args.json:
        write_json_atomic(Path(args.json), {"machine": machine, "backend": args.backend, "refine": refine,
                                            "operator": operator or None,
                                            "cases": [r.to_dict() for r in results]})
    return 0 if not failed else 1
