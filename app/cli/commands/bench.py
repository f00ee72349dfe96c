"""`feelflow bench [solver|accuracy|haptics|operators|motion|streaming]`: speed of the solver backends, their speed
against their error, the haptic loop, the cost per step of each collision operator
(`app/bench/operator_cost.py`), of moving the body (`app/bench/motion_cost.py`), or of the cpu
backend's two streaming patterns (`app/bench/streaming.py`).

The solver bench lives in `app/bench/solver_speed.py`, speed against error in
`app/bench/accuracy.py`, the haptic one in `app/bench/haptic_loop.py`; this module only
dispatches.
"""
from __future__ import annotations

import importlib

from feelflow.app.bench.accuracy import AXES

TARGETS = {"solver": "feelflow.app.bench.solver_speed", "accuracy": "feelflow.app.bench.accuracy",
           "haptics": "feelflow.app.bench.haptic_loop", "operators": "feelflow.app.bench.operator_cost",
           "motion": "feelflow.app.bench.motion_cost", "streaming": "feelflow.app.bench.streaming"}


def add_arguments(parser):
    parser.add_argument("target", nargs="?", default="solver", choices=sorted(TARGETS),
                        help="what to measure (default: solver)")
    parser.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    parser.add_argument("--force", action="store_true", help="replace --json if it exists")
    parser.add_argument("--device", metavar="URL", default="sim://haply2diy",
                        help="haptics: the device to run the loop against (default: a simulator)")
    parser.add_argument("--seconds", type=float, default=None, help="how long to measure")
    parser.add_argument("--rounds", type=int, default=None,
                        help="solver, operators, streaming: alternating rounds (solver: numpy / cpu / gl) per scene, medians reported (default 3; --quick 1)")
    parser.add_argument("--grid", action="append", metavar="NXxNY",
                        help="solver: only this grid (repeatable; default 256x128, 512x256 and 1024x512); motion: default 256x128; "
                             "streaming: default 512x256")
    parser.add_argument("--quick", action="store_true", help="solver, accuracy: fewer steps or points (smoke test)")
    parser.add_argument("--backend", action="append", choices=("numpy", "cpu", "gl"),
                        help="accuracy: only this backend (repeatable; default: numpy float64, numpy float32, gl); "
                             "motion: default all three; operators: only these (default all three)")
    parser.add_argument("--axis", action="append", choices=AXES,
                        help="accuracy: only this axis (repeatable; default: all three)")
    parser.add_argument("--profile", action="store_true",
                        help="solver: where the gl moving tunnel's wall time goes (docs/science/performance.md)")


def main(args) -> int:
    import math

    from feelflow.app.errors import UserError
    from feelflow.app.files import check_output

    if args.seconds is not None and not (math.isfinite(args.seconds) and 0 < args.seconds <= 3600):
        raise UserError(f"--seconds: must be a number in (0, 3600], got {args.seconds!r}")
    if args.rounds is not None and args.rounds > 100:   # (fewer than 1: the solver bench says so)
        raise UserError(f"--rounds: at most 100, got {args.rounds!r}")
    if args.json:   # before the measuring starts
        check_output(args.json, "--json", force=args.force)
    return importlib.import_module(TARGETS[args.target]).main(args)
