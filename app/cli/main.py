"""The `feelflow` command line (also `python -m feelflow.app`).

Each sub-command lives in `app/cli/commands/<name>.py` with `add_arguments(parser)` and
`main(args) -> int`. Errors a user can cause are reported as one line on stderr with exit 2;
no tracebacks reach the user.
"""
from __future__ import annotations

import argparse
import importlib
import sys

from feelflow.app.errors import UserError

#: sub-command -> one-line help
COMMANDS = {
    "gui": "open the wind-tunnel window (the default)",
    "run": "run a scene headless and write forces as CSV",
    "validate": "run the physics validation cases and print a table",
    "bench": "measure solver speed (both backends) or the haptic loop",
    "devices": "list haptic devices: serial ports, HID devices, simulators",
    "report": "reports: the seed's experiments (Markdown), how steady the lessons and example scenes are",
    "session": "inspect, replay or export a recorded session file",
    "exercise": "shape-editing exercises: score a class's shapes, check an exercise file",
    "polar": "an angle-of-attack sweep: C_L and C_D against alpha (CSV and image), C_p along the surface",
    "screenshots": "the guide's pictures of the window (exercise, probes and units)",
}


class _Parser(argparse.ArgumentParser):
    """argparse with a bad command line reported like every other user error: one line, exit 2."""

    def error(self, message):
        self.exit(2, f"feelflow: {message.splitlines()[0] if message else 'bad command line'} "
                     f"(see '{self.prog} --help')\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="feelflow", description="FeelFlow: a desktop wind tunnel you can touch")
    parser.add_argument("--selftest", action="store_true",
                        help="open the real window, exercise it and exit 0 only if everything worked")
    parser.add_argument("--screenshot", metavar="PATH", help="with --selftest: save a screenshot")
    parser.add_argument("--seconds", type=float, default=8.0, help="with --selftest: how long to run")
    parser.add_argument("--lesson", default=None, metavar="KEY",
                        help="with --selftest: run this lesson (app/model/presets.py) for --seconds instead of the "
                             "default script (e.g. polar); --screenshot names the picture")
    parser.add_argument("--plot-view", default=None, metavar="VIEW",
                        help="with --selftest --lesson: the force plot's view for the screenshot (time, speed, polar, "
                             "drag_polar, cp)")
    parser.add_argument("--frame-profile", action="store_true",
                        help="with --selftest: also print where a frame's time goes (solver, drawing, plot, Qt)")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, help_ in COMMANDS.items():
        p = sub.add_parser(name, help=help_, description=help_)
        try:
            module = importlib.import_module(f"feelflow.app.cli.commands.{name}")
        except ModuleNotFoundError as exc:  # command not built yet
            if exc.name != f"feelflow.app.cli.commands.{name}":
                raise
            p.set_defaults(missing_command=name)
            continue
        module.add_arguments(p)
        p.set_defaults(command_module=module)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.selftest or args.command is None:
        args.command = "gui"
    if not hasattr(args, "command_module") and not hasattr(args, "missing_command"):
        # no sub-command on the line (`feelflow`, `feelflow --selftest`): the gui's defaults
        try:
            module = importlib.import_module("feelflow.app.cli.commands.gui")
        except ModuleNotFoundError as exc:
            if exc.name != "feelflow.app.cli.commands.gui":
                raise
            args.missing_command = "gui"
        else:
            sub = _Parser()
            module.add_arguments(sub)
            for key, value in vars(sub.parse_args([])).items():
                if not hasattr(args, key):
                    setattr(args, key, value)
            args.command_module = module
    if getattr(args, "missing_command", None):
        print(f"feelflow: '{args.command}' is not available in this version", file=sys.stderr)
        return 2
    try:
        return int(args.command_module.main(args) or 0)
    except UserError as exc:
        print(f"feelflow: {one_line(str(exc))}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    except MemoryError:   # the bounds are checked before the work; this is the last net
        print("feelflow: not enough memory for this command (lower the grid, --scale or --workers)",
              file=sys.stderr)
        return 2


#: longest error line printed (a refusal is one short line; the values in it are cut already)
MAX_LINE = 400


def one_line(text: str) -> str:
    """An error message as one line of at most MAX_LINE characters."""
    text = " ".join(text.split("\n"))
    return text if len(text) <= MAX_LINE else text[:MAX_LINE - 3] + "..."


if __name__ == "__main__":
    sys.exit(main())
