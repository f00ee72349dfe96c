"""A calm first start in a real window under Xvfb: OpenGL 3.3 refused (the requirement raised
past what llvmpipe offers, FEELFLOW_REQUIRE_GL) gives a dialog and a window that runs on the CPU;
a first start opens the lesson chooser, and only the first."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from gui_fixtures import GRID

pytestmark = [pytest.mark.gui,
              pytest.mark.skipif(not os.environ.get("DISPLAY"), reason="needs an X display (run under xvfb-run -a)")]


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
    w.timer.stop()
    w.slow_timer.stop()


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
    assert w.display_mode == PRESETS["lift"].display
    w.timer.stop()
    w.slow_timer.stop()
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
    again.timer.stop()
    again.slow_timer.stop()


def test_selftest_passes_without_gl_on_the_cpu(tmp_path):
    """`feelflow --selftest` end to end where OpenGL 3.3 is refused."""
    env = {**os.environ, "FEELFLOW_REQUIRE_GL": "990"}
    r = subprocess.run([sys.executable, "-m", "feelflow.app", "--selftest", "--seconds", "4"], env=env,
                       capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "renderer no GL, solver backend numpy" in r.stdout
    assert r.stdout.rstrip().endswith("selftest: ok")
