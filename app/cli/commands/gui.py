"""`feelflow gui [SESSION] [--exercise FILE]` (the default command) and `feelflow --selftest [--screenshot PATH]
[--seconds S] [--frame-profile]`.

`feelflow gui FILE.ffsession` opens the window and replays that session in it as soon as the live
tunnel runs (what File > Replay session does); the desktop entry's `Exec=... gui %f` uses it, so
double-clicking a session file in the file manager replays it; `feelflow --selftest gui FILE`
measures that replay (frames and session steps per second).

The OpenGL surface format (3.3 core, no depth buffer, no vsync) is set before the QApplication
exists. Without a display there is no window: one line says so and the command exits 2 (try
`feelflow run` for a headless run); app/gui/first_start.py has that check, the CPU fallback
where OpenGL 3.3 is missing, and the lesson chooser a first start opens.
"""
from __future__ import annotations

import os
import sys

from feelflow.app.errors import UserError

DEFAULT_BACKEND = "gl"


def add_arguments(parser):
    parser.add_argument("session", nargs="?", default=None, metavar="SESSION",
                        help="a recorded session file (.ffsession) to replay in the window once it has started")
    parser.add_argument("--backend", choices=("auto", "cpu", "gl", "numpy"), default=None,
                        help="solver backend (default: the Run > Solver backend menu's choice, at first "
                             "'auto': the fastest here, measured on the window's grid and remembered; "
                             f"--selftest: {DEFAULT_BACKEND})")
    parser.add_argument("--fresh", action="store_true", help="ignore remembered settings")
    parser.add_argument("--exercise", default=None, metavar="FILE",
                        help="open this exercise file (exercises/*.toml) once the window runs")


def set_surface_format():
    from PySide6.QtGui import QSurfaceFormat

    fmt = QSurfaceFormat()
    fmt.setVersion(3, 3)
    fmt.setProfile(QSurfaceFormat.CoreProfile)
    fmt.setDepthBufferSize(0)
    fmt.setStencilBufferSize(8)
    fmt.setSwapInterval(0)
    QSurfaceFormat.setDefaultFormat(fmt)


def replay_when_ready(window, path) -> None:
    """Replay the session at `path` once, when the window's live simulation first runs
    (`ReplayController.start`, app/gui/window/replay_controller.py, needs it; a bad file is its one-line dialog)."""
    def start():
        window.simulationReady.disconnect(start)
        window.replays.start(path)
    window.simulationReady.connect(start)


def open_exercise_when_ready(window, path) -> None:
    """Open the exercise at `path` once, when the window's live simulation first runs."""
    def start():
        window.simulationReady.disconnect(start)
        window.exercises.open(path)
    window.simulationReady.connect(start)


def what_opens_first(window, settings, session=None, exercise=None, offer: bool = True) -> None:
    """Once the tunnel runs: replay `session`, or open `exercise`; otherwise (`offer`, and on a
    first start) the lesson chooser. A session or an exercise named on the command line is what
    the user asked for: no chooser covers it (the Presets menu still has it)."""
    if session is not None:
        replay_when_ready(window, session)
    if offer:
        from feelflow.app.gui.first_start import offer_lessons

        offer_lessons(window, settings, first_start=session is None and exercise is None)
    if exercise is not None:
        open_exercise_when_ready(window, exercise)


def main(args) -> int:
    session = getattr(args, "session", None)
    if session is not None and not os.path.isfile(session):
        raise UserError(f"{session}: no such session file")
    exercise = getattr(args, "exercise", None)
    if exercise is not None:   # a bad exercise file is one line and exit 2, before any window
        from feelflow.app.exercises.format import load_exercise

        load_exercise(exercise)
    if getattr(args, "screenshot", None):   # before any window: never a device, a folder or an input
        from feelflow.app.files import check_output

        # the self-test's screenshot is regenerated on every run (as the report's own files)
        check_output(args.screenshot, "--screenshot", inputs=[session, exercise], force=True)
    from feelflow.app.gui.first_start import display_problem

    problem = display_problem()
    if problem is not None:
        raise UserError(problem)
    backend = getattr(args, "backend", None) or DEFAULT_BACKEND
    from feelflow.app.gui.qt_runtime import make_none_immortal

    make_none_immortal()
    set_surface_format()
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QApplication

    from feelflow.app.gui.main_window import MainWindow

    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("FeelFlow")
    app.setOrganizationName("FeelFlow")
    app.setDesktopFileName("feelflow")   # the installed feelflow.desktop: its name and icon (installer/)
    selftest = getattr(args, "selftest", False)
    if selftest or getattr(args, "fresh", False):
        import tempfile

        settings = QSettings(os.path.join(tempfile.mkdtemp(prefix="feelflow-selftest-"), "settings.ini"),
                             QSettings.IniFormat)
    else:
        settings = QSettings()
    from feelflow.app.gui.window.backend_controller import requested_backend

    if not selftest:   # the self-test checks the shader path unless --backend says otherwise
        backend = requested_backend(getattr(args, "backend", None), settings)
    window = MainWindow(backend=backend, settings=settings)
    what_opens_first(window, settings, session, exercise, offer=not selftest)
    if selftest:
        from feelflow.app.gui.selftest import SelfTest

        lesson = getattr(args, "lesson", None)
        from feelflow.app.model.presets import PRESETS

        if lesson is not None and lesson not in PRESETS:
            raise UserError(f"--lesson: one of {', '.join(PRESETS)}, got {lesson!r}")
        views = ("time", "speed", "polar", "drag_polar", "cp")
        if getattr(args, "plot_view", None) not in (None, *views):
            raise UserError(f"--plot-view: one of {', '.join(views)}, got {args.plot_view!r}")
        test = SelfTest(window, seconds=args.seconds, screenshot=args.screenshot, replay=session is not None,
                        frame_profile=getattr(args, "frame_profile", False), lesson=lesson,
                        plot_view=getattr(args, "plot_view", None))
        window.show()
        app.exec()
        if window.startup_error:
            print(f"feelflow: {window.startup_error}", file=sys.stderr)
            return 2
        return test.exit_code
    window.show()
    code = app.exec()
    if window.startup_error:
        print(f"feelflow: {window.startup_error}", file=sys.stderr)
        return 2
    return code
