"""The shared tail of the throwaway wall-rule probes (docs/bench/s19/probe_quadratic_bouzidi.py,
docs/bench/s21/probe_cli_bouzidi.py; not product code): run one Schaefer-Turek case on the numpy
backend, with whatever rule the probe patched in, and print its quantities, steps and seconds.

    argv: 2d2 D   or   2d1 D [U_m]   (U_m default 0.075)
"""
import json
import time


def run_case(argv) -> None:
    from solver.backend import create_solver
    from solver.validation import case_module

    case, d = argv[1], int(argv[2])
    u = float(argv[3]) if len(argv) > 3 else 0.075
    kwargs = {"resolution": d} if case == "2d2" else {"resolution": d, "u_max": u}
    t0 = time.time()
    r = case_module({"2d1": "schaefer-turek-2d1", "2d2": "schaefer-turek-2d2"}[case]).run(
        lambda c: create_solver("numpy", c), **kwargs)
    print(case, d, json.dumps(r.quantities), r.steps, round(time.time() - t0), "s")
