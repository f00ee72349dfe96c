"""`feelflow report seed`: reproduce the seed's experiments with all four force models and write
docs/report-seed.md with PNG plots (the work is in app/seed_report.py).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from app.cli import UserError

TARGETS = ("seed",)


def add_arguments(parser):
    parser.add_argument("target", choices=TARGETS, help="which report (seed: the thesis's experiments)")
    parser.add_argument("--backend", default="numpy", metavar="numpy|gl", help="solver backend (default: numpy)")
    parser.add_argument("--quick", action="store_true",
                        help="a few dozen steps per run: a smoke test of the whole chain, not physics")
    parser.add_argument("--phase-steps", default=None, metavar="N",
                        help="steps per protocol phase instead of the scenes' 15000 (stated in the report)")
    parser.add_argument("--scenes", default="scenes", metavar="DIR", help="folder holding the scenes (default: scenes)")
    parser.add_argument("--out", default="docs", metavar="DIR",
                        help="folder for report-seed.md and report-seed/ (default: docs)")
    parser.add_argument("--replot", action="store_true",
                        help="rebuild text and plots from OUT/report-seed/data.json without running the flow")


def main(args) -> int:
    from app.seed_report import run_all, write_report

    out = Path(args.out)
    if not out.is_dir():
        raise UserError(f"--out: {args.out!r} is not a folder")
    phase_steps = None
    if args.phase_steps is not None:
        try:
            phase_steps = int(args.phase_steps)
        except ValueError:
            phase_steps = 0
        if phase_steps < 1:
            raise UserError(f"--phase-steps: must be a positive integer, got {args.phase_steps!r}")
    command = "feelflow report seed" + (f" --backend {args.backend}" if args.backend != "numpy" else "") \
        + (" --quick" if args.quick else "") + (f" --phase-steps {phase_steps}" if phase_steps else "")
    if args.replot:
        source = out / "report-seed" / "data.json"
        try:
            data = json.loads(source.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise UserError(f"--replot: {source} does not exist (run the report once first)") from None
        except json.JSONDecodeError as exc:
            raise UserError(f"--replot: {source} is not valid JSON ({exc.msg})") from None
        command = data.get("command", command)
    else:
        scenes = Path(args.scenes)
        if not scenes.is_dir():
            raise UserError(f"--scenes: {args.scenes!r} is not a folder")
        print(f"feelflow report seed: running the experiments on {args.backend}", file=sys.stderr)
        data = run_all(scenes, args.backend, args.quick, phase_steps,
                       log=lambda line: print(line, file=sys.stderr, flush=True))
        data["command"] = command
    path = write_report(data, out, command)
    print(f"{path}: written ({data['wall_s'] / 60:.1f} min of runs)")
    return 0
