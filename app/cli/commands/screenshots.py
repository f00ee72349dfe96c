"""`feelflow screenshots --out DIR`: the guide's pictures of the window (app/gui/screenshots.py),
written into DIR (docs/screenshots in a checkout). Needs a display (xvfb-run works)."""
from __future__ import annotations

from feelflow.app.errors import UserError


def add_arguments(parser):
    parser.add_argument("--out", default="docs/screenshots", metavar="DIR",
                        help="folder to write the pictures into (default docs/screenshots)")
    parser.add_argument("--seconds", default="6", metavar="S", help="how long the flow runs before each picture")


def main(args) -> int:
    from feelflow.app.files import check_output_folder
    from feelflow.app.gui.first_start import display_problem

    out = check_output_folder(args.out, "--out")
    try:
        seconds = float(args.seconds)
    except ValueError:
        raise UserError(f"--seconds: must be a number, got {args.seconds!r}") from None
    if not 0 < seconds <= 600:
        raise UserError(f"--seconds: must be in (0, 600], got {args.seconds!r}")
    problem = display_problem()
    if problem is not None:
        raise UserError(problem)
    from feelflow.app.cli.commands.gui import set_surface_format
    from feelflow.app.gui.qt_runtime import make_none_immortal

    make_none_immortal()
    set_surface_format()   # before the QApplication exists, as for the window
    from feelflow.app.gui.screenshots import make_screenshots

    make_screenshots(out, seconds)
    return 0
