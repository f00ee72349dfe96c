"""A calm first start in a real window under Xvfb: OpenGL 3.3 refused (the requirement raised
past what llvmpipe offers, FEELFLOW_REQUIRE_GL) or no OpenGL at all (Qt's xcb plugin without
GLX and EGL, QT_XCB_GL_INTEGRATION=none) gives a dialog and a window that runs on the CPU; a
first start opens the lesson chooser, and only the first."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from gui_fixtures import GRID

pytestmark = pytest.mark.gui


def make_window(qtbot, settings_path, backend="gl"):
    from PySide6.QtCore import QSettings

    from feelflow.app.gui.main_window import MainWindow
    from feelflow.app.model.simulation import Params

    settings = QSettings(str(settings_path), QSettings.IniFormat)
    w = MainWindow(backend=backend, settings=settings, params=Params(grid=GRID, size=12))
    qtbot.addWidget(w)
    w.resize(1100, 700)
    return w, settings


def test_gl_refused_gives_a_dialog_and_the_window_runs_on_the_cpu(qtbot, tmp_path, monkeypatch):
    from feelflow.app.gui.first_start import REQUIRE_GL_ENV
    from feelflow.app.gui.selftest import field_is_alive

    monkeypatch.setenv(REQUIRE_GL_ENV, "990")   # llvmpipe offers 4.5: this context is refused
    w, _ = make_window(qtbot, tmp_path / "settings.ini", backend="gl")
    w.show()
    qtbot.waitUntil(lambda: w.sim is not None, timeout=20000)
    assert w.startup_error is None and w.viewport.ctx is None
    assert w.backend == "numpy" and w.sim.backend == "numpy"
    assert w.gl_missing.startswith("OpenGL 3.3 is not available here (")
    qtbot.waitUntil(lambda: w.no_gl_dialog.isVisible(), timeout=5000)
    text = w.no_gl_dialog.text()
    assert text.startswith(w.gl_missing) and "runs on the CPU instead (the numpy solver)" in text
    assert "update the graphics driver" in text
    qtbot.waitUntil(lambda: w.sim.solver.time > 300, timeout=60000)
    ok, why = field_is_alive(w)
    assert ok, why
    frames = w.viewport.frames
    qtbot.waitUntil(lambda: w.viewport.frames > frames + 3, timeout=10000)
    assert w.status["renderer"].text() == "no GL, numpy solver"
    # the field is on the screen: the lattice rectangle shows many colours, not the background
    image = w.viewport.grabFramebuffer()
    r = w.viewport.lattice_rect().toRect().adjusted(4, 4, -4, -4)
    pixels = {image.pixel(x, y) for x in range(r.left(), r.right(), 7) for y in range(r.top(), r.bottom(), 7)}
    assert len(pixels) > 20
    w.no_gl_dialog.accept()
    w.loop.timer.stop()
    w.loop.slow_timer.stop()


def test_first_start_offers_the_lessons_once(qtbot, tmp_path):
    from feelflow.app.gui.first_start import offer_lessons
    from feelflow.app.model.presets import PRESETS

    w, settings = make_window(qtbot, tmp_path / "settings.ini", backend="numpy")
    offer_lessons(w, settings)
    w.show()
    qtbot.waitUntil(lambda: getattr(w, "lessons_dialog", None) is not None and w.lessons_dialog.isVisible(),
                    timeout=20000)
    dialog = w.lessons_dialog
    keys = [dialog.list.item(i).data(0x0100) for i in range(dialog.list.count())]
    assert keys == list(PRESETS)
    dialog.list.setCurrentRow(keys.index("lift"))
    dialog.start_button.click()
    assert not dialog.isVisible()
    assert w.statusBar().currentMessage().startswith(PRESETS["lift"].title)
    assert w.loop.display.mode == PRESETS["lift"].display
    w.loop.timer.stop()
    w.loop.slow_timer.stop()
    w.close()

    again, settings2 = make_window(qtbot, tmp_path / "settings.ini", backend="numpy")
    offer_lessons(again, settings2)
    again.show()
    qtbot.waitUntil(lambda: again.sim is not None and again.sim.solver.time > 10, timeout=20000)
    qtbot.wait(300)
    assert getattr(again, "lessons_dialog", None) is None
    presets = next(a.menu() for a in again.menuBar().actions() if a.text() == "&Presets")
    choose = presets.actions()[0]
    assert choose.text() == "Choose a lesson\u2026"
    choose.trigger()
    assert again.lessons_dialog.isVisible()
    shape = again.sim.params.shape
    again.lessons_dialog.explore_button.click()
    assert not again.lessons_dialog.isVisible() and again.sim.params.shape == shape   # the tunnel as it was
    again.loop.timer.stop()
    again.loop.slow_timer.stop()


NO_GL = {"gl 3.3 refused": {"FEELFLOW_REQUIRE_GL": "990"}, "no gl at all": {"QT_XCB_GL_INTEGRATION": "none"}}


@pytest.mark.parametrize("case", list(NO_GL))
def test_selftest_passes_without_gl_on_the_cpu(tmp_path, case):
    """`feelflow --selftest` end to end (the field lives, a drag moves the body)."""
    r = subprocess.run([sys.executable, "-m", "feelflow.app", "--selftest", "--seconds", "4"],
                       env={**os.environ, **NO_GL[case]}, capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "renderer no GL, solver backend numpy" in r.stdout
    assert r.stdout.rstrip().endswith("selftest: ok")


SCREEN_CHECK = """
import sys
from feelflow.app.cli.commands.gui import set_surface_format
from feelflow.app.gui.qt_runtime import make_none_immortal
make_none_immortal(); set_surface_format()
from PySide6.QtCore import QSettings, QTimer
from PySide6.QtWidgets import QApplication
app = QApplication([])
from feelflow.app.gui.main_window import MainWindow
w = MainWindow(backend="gl", settings=QSettings(sys.argv[1], QSettings.IniFormat))
w.resize(1000, 700)
w.show()
def look():
    shown = w.centralWidget()
    r = shown.rect().adjusted(20, 20, -150, -20)
    top_left = shown.mapToGlobal(r.topLeft())
    image = app.primaryScreen().grabWindow(0, top_left.x(), top_left.y(), r.width(), r.height()).toImage()
    colours = {image.pixel(x, y) for x in range(0, image.width(), 9) for y in range(0, image.height(), 9)}
    print(w.backend, w.viewport.frames, len(colours), w.gl_missing)
    app.quit()
QTimer.singleShot(4000, look)
app.exec()
"""


@pytest.mark.parametrize("case", list(NO_GL))
def test_the_cpu_picture_reaches_the_screen(tmp_path, case):
    """The X server's own pixels (QScreen.grabWindow), not the widget's: where Qt has no OpenGL
    a QOpenGLWidget left in the window would keep the whole window black."""
    r = subprocess.run([sys.executable, "-c", SCREEN_CHECK, str(tmp_path / "settings.ini")],
                       env={**os.environ, **NO_GL[case]}, capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    backend, frames, colours, missing = r.stdout.strip().split(" ", 3)
    assert backend == "numpy" and int(frames) > 10
    assert int(colours) > 20, r.stdout            # a coloured flow field, not a black or flat window
    assert missing.startswith("OpenGL 3.3 is not available here (" if case == "gl 3.3 refused"
                              else "OpenGL is not available here at all")
