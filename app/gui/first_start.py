"""A calm first start: what FeelFlow does when the PC lacks something, and the lessons first.

- no screen (no DISPLAY, or no X server answering it): one line before Qt starts, instead of
  Qt's abort (`display_problem`, used by `feelflow gui`);
- no OpenGL 3.3 core context, or no OpenGL at all (an old driver, a remote desktop): a dialog
  says what is missing and the window runs on the CPU (numpy solver; app/gui/cpu_field.py
  draws the field);
- the first start offers the Presets menu's lessons (`offer_lessons`), not an empty tunnel.
Device permissions have their one-line fixes in feelflow.haptics.permissions.
"""
from __future__ import annotations

import os
import socket
import sys

#: the OpenGL version the viewport and the gl solver need (3.3 core; macOS offers up to 4.1)
REQUIRED_GL = 330
#: environment variable that raises the requirement (for example 990): provokes the CPU
#: fallback on any machine, to see or test it
REQUIRE_GL_ENV = "FEELFLOW_REQUIRE_GL"
SETTINGS_KEY = "first_start/lessons_offered"


def required_gl() -> int:
    value = os.environ.get(REQUIRE_GL_ENV, "")
    return int(value) if value.isdigit() else REQUIRED_GL


# --- display ------------------------------------------------------------------------------------
def _x_server_answers(display: str, timeout: float = 2.0) -> bool:
    """Does an X server listen for DISPLAY ([host]:N[.screen])? Forms not understood count as yes
    (Qt then decides)."""
    host, sep, rest = display.rpartition(":")
    number = rest.split(".")[0]
    if not sep or not number.isdigit() or "/" in host:
        return True
    if host in ("", "unix"):
        path = f"/tmp/.X11-unix/X{number}"
        for address in ("\0" + path, path):   # Linux servers listen on the abstract name too
            with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
                s.settimeout(timeout)
                try:
                    s.connect(address)
                    return True
                except OSError:
                    continue
        if host == "unix":
            return False
        host = "localhost"
    try:
        socket.create_connection((host, 6000 + int(number)), timeout=timeout).close()
        return True
    except OSError:
        return False


def display_problem(environ=None) -> str | None:
    """One line saying why no window can open here, or None where Qt can try."""
    env = os.environ if environ is None else environ
    platform = env.get("QT_QPA_PLATFORM", "")
    headless = "use 'feelflow run' for a headless run, or run under xvfb-run"
    if platform.startswith(("offscreen", "minimal")):
        return f"QT_QPA_PLATFORM={platform} has no screen with OpenGL to open the window on; {headless}"
    if not sys.platform.startswith("linux") or platform.startswith(("wayland", "eglfs", "vnc")):
        return None
    if env.get("WAYLAND_DISPLAY") and not platform.startswith("xcb"):
        return None
    display = env.get("DISPLAY", "")
    if not display:
        return f"no display to open the window on (DISPLAY is not set); {headless}"
    if not _x_server_answers(display):
        return f"no X server answers on DISPLAY={display}; {headless}"
    return None


# --- OpenGL 3.3 missing: the CPU ------------------------------------------------------------------
def no_gl_text(detail: str) -> str:
    return (f"{detail}.\n\nFeelFlow runs on the CPU instead (the numpy solver): everything works, "
            "the flow moves more slowly.\n\nFor the fast solver, update the graphics driver "
            "(OpenGL 3.3 or newer); over a remote desktop, start FeelFlow on the PC itself.")


def watch_gl(window) -> None:
    """Hook (before the window is shown): where the viewport gets no OpenGL 3.3, the window runs
    on numpy and says why. Where Qt has no OpenGL at all the viewport's initializeGL never runs:
    a context made here first finds that out, and a CPU canvas takes the viewport's place."""
    from PySide6.QtCore import QTimer
    from PySide6.QtGui import QOpenGLContext

    window.gl_missing = None
    window.viewport.contextFailed.connect(lambda detail: run_on_cpu(window, detail))
    if QOpenGLContext().create():
        return
    from feelflow.app.gui.cpu_field import CpuCanvas

    viewport = window.takeCentralWidget()   # out of the window, which then needs no OpenGL to show
    viewport.setParent(None)
    window.setCentralWidget(CpuCanvas(viewport, stand_in=True))
    QTimer.singleShot(0, lambda: run_on_cpu(window, "OpenGL is not available here at all "
                                                    "(Qt could not create an OpenGL context)"))


def run_on_cpu(window, detail: str) -> None:
    from PySide6.QtCore import QTimer
    from PySide6.QtWidgets import QMessageBox

    from feelflow.app.gui.cpu_field import CpuCanvas

    if window.gl_missing is not None:
        return
    window.gl_missing = detail
    window.backend = "numpy"
    viewport = window.viewport
    canvas = viewport.cpu_canvas or CpuCanvas(viewport)
    # the window's screenshots read the viewport's framebuffer: the canvas holds the picture now
    viewport.grabFramebuffer = lambda: canvas.grab().toImage()
    box = QMessageBox(QMessageBox.Warning, "FeelFlow runs without OpenGL 3.3", no_gl_text(detail),
                      QMessageBox.Ok, window)
    box.setObjectName("no-gl-dialog")
    window.no_gl_dialog = box
    QTimer.singleShot(0, box.open)   # window-modal, not blocking: the tunnel starts behind it
    window.on_context(None)


# --- the lessons first ----------------------------------------------------------------------------
def add_lessons_action(window) -> None:
    """'Choose a lesson...' at the top of the Presets menu."""
    from PySide6.QtGui import QAction

    for action in window.menuBar().actions():
        menu = action.menu()
        if menu is not None and action.text().replace("&", "") == "Presets":
            first = menu.actions()[0] if menu.actions() else None
            choose = QAction("Choose a lesson\u2026", window)
            choose.triggered.connect(lambda _=False: show_lessons(window))
            menu.insertAction(first, choose)
            if first is not None:
                menu.insertSeparator(first)
            return


def offer_lessons(window, settings, first_start: bool = True) -> None:
    """Hook: 'Choose a lesson...' in the Presets menu, and on the first start (`first_start`, and
    nothing in `settings` says the lessons were offered) the chooser opens once the tunnel runs."""
    add_lessons_action(window)
    if not first_start or settings.value(SETTINGS_KEY, False, type=bool):
        return

    def show():
        window.simulationReady.disconnect(show)
        settings.setValue(SETTINGS_KEY, True)
        settings.sync()
        show_lessons(window)
    window.simulationReady.connect(show)


def show_lessons(window):
    from feelflow.app.gui.lessons_dialog import LessonsDialog

    dialog = LessonsDialog(window)
    window.lessons_dialog = dialog
    dialog.open()
    return dialog
