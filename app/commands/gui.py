"""`feelflow gui` (the default command) and `feelflow --selftest [--screenshot PATH] [--seconds S]`.

The OpenGL surface format (3.3 core, no depth buffer, no vsync) is set before the QApplication
exists (shared/notes/gl-qt-on-this-machine.md). Without a display there is no window: one line
says so and the command exits 2 (try `feelflow run` for a headless run).
"""
from __future__ import annotations

import os
import sys

from app.cli import UserError

DEFAULT_BACKEND = "gl"


def add_arguments(parser):
    parser.add_argument("--backend", choices=("gl", "numpy"), default=None,
                        help=f"solver backend (default {DEFAULT_BACKEND}; numpy uploads the field every frame)")
    parser.add_argument("--fresh", action="store_true", help="ignore remembered settings")


def has_display() -> bool:
    """Is there a screen Qt can open a window with OpenGL on?"""
    platform = os.environ.get("QT_QPA_PLATFORM", "")
    if platform.startswith("offscreen") or platform.startswith("minimal"):
        return False
    if sys.platform.startswith("linux"):
        return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    return True


def set_surface_format():
    from PySide6.QtGui import QSurfaceFormat

    fmt = QSurfaceFormat()
    fmt.setVersion(3, 3)
    fmt.setProfile(QSurfaceFormat.CoreProfile)
    fmt.setDepthBufferSize(0)
    fmt.setStencilBufferSize(8)
    fmt.setSwapInterval(0)
    QSurfaceFormat.setDefaultFormat(fmt)


def main(args) -> int:
    if not has_display():
        raise UserError("no display to open the window on (DISPLAY is not set); "
                        "use 'feelflow run' for a headless run, or run under xvfb-run")
    backend = getattr(args, "backend", None) or DEFAULT_BACKEND
    from app.qt_runtime import make_none_immortal

    make_none_immortal()
    set_surface_format()
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QApplication

    from app.main_window import MainWindow

    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("FeelFlow")
    app.setOrganizationName("FeelFlow")
    selftest = getattr(args, "selftest", False)
    if selftest or getattr(args, "fresh", False):
        import tempfile

        settings = QSettings(os.path.join(tempfile.mkdtemp(prefix="feelflow-selftest-"), "settings.ini"),
                             QSettings.IniFormat)
    else:
        settings = QSettings()
    window = MainWindow(backend=backend, settings=settings)
    if selftest:
        from app.selftest import SelfTest

        test = SelfTest(window, seconds=args.seconds, screenshot=args.screenshot)
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
