"""The window's solver backend in a real window under Xvfb: "auto" measures the backends on the
window's grid once the OpenGL context exists, runs the fastest and says so in the status bar;
the next start takes the remembered choice without measuring; the menu's choice waits for the
next start."""
from __future__ import annotations


import pytest

from gui_fixtures import GRID

pytestmark = pytest.mark.gui


def started_window(qtbot, settings, backend):
    from feelflow.app.gui.main_window import MainWindow
    from feelflow.app.model.simulation import Params

    w = MainWindow(backend=backend, settings=settings, params=Params(grid=GRID, size=12))
    qtbot.addWidget(w)
    w.resize(1100, 700)
    with qtbot.waitSignal(w.simulationReady, timeout=180000):   # a first cpu compile can be slow
        w.show()
    return w


def test_auto_measures_runs_the_fastest_and_remembers_it(qtbot, tmp_path):
    from PySide6.QtCore import QSettings

    from feelflow.app.model.backend_choice import CANDIDATES

    settings = QSettings(str(tmp_path / "settings.ini"), QSettings.IniFormat)
    w = started_window(qtbot, settings, "auto")
    assert w.backend in CANDIDATES and w.sim.backend == w.backend
    assert w.backends.measured > 0
    assert "steps/s measured" in w.status["renderer"].text() and f"{w.backend} solver" in w.status["renderer"].text()
    for name in CANDIDATES:   # the tooltip names every backend's measured rate
        assert name in w.status["renderer"].toolTip()
    first = w.backend
    w.loop.timer.stop()
    w.close()

    again = started_window(qtbot, QSettings(str(tmp_path / "settings.ini"), QSettings.IniFormat), "auto")
    assert again.backend == first and again.backends.measured is None   # remembered, not measured
    assert "measured before" in again.status["renderer"].toolTip()
    again.loop.timer.stop()
    again.close()


def test_the_menus_choice_waits_for_the_next_start(qtbot, tmp_path):
    from PySide6.QtCore import QSettings

    from feelflow.app.gui.window.backend_controller import requested_backend

    settings = QSettings(str(tmp_path / "settings.ini"), QSettings.IniFormat)
    w = started_window(qtbot, settings, "gl")
    w.backends.set_requested("numpy")
    assert w.backend == "gl" and w.sim.backend == "gl"   # never switched while running
    assert requested_backend(None, settings) == "numpy"
    assert requested_backend("cpu", settings) == "cpu"   # --backend wins over the menu
    w.backends.remeasure()
    assert requested_backend(None, settings) == "auto"
    w.loop.timer.stop()
    w.close()
