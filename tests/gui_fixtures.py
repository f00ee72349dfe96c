"""What the GUI test files share (a pytest plugin, registered by conftest.py): the real window
fixture and Qt's set-up. Nothing here imports Qt at import time: a run that selects gui tests
sets Qt up after collection (pytest_collection_finish), before pytest-qt makes the QApplication,
and a run without gui tests (the gl process) never does. An EGL standalone context and Qt's GLX
context cannot share a process: see the note in conftest.py."""
from __future__ import annotations

import os

import pytest

GRID = (128, 64)


def pytest_collection_finish(session):
    """The surface format must be the default before pytest-qt creates the QApplication."""
    if os.environ.get("DISPLAY") and any(item.get_closest_marker("gui") for item in session.items):
        from feelflow.app.cli.commands.gui import set_surface_format
        from feelflow.app.gui.qt_runtime import make_none_immortal

        make_none_immortal()
        set_surface_format()


def pytest_runtest_setup(item):
    """A gui test without a display fails, as a gl test without EGL does: a skip would hide a
    broken set-up (installer/run-tests.sh runs the gui tier under xvfb-run)."""
    if item.get_closest_marker("gui") and not os.environ.get("DISPLAY"):
        pytest.fail("no X display for the gui tier: run it under xvfb-run -a (installer/run-tests.sh does)",
                    pytrace=False)


@pytest.fixture
def window(qtbot, tmp_path):
    """The FeelFlow window on the numpy solver and a small grid, running, settings in tmp_path."""
    from PySide6.QtCore import QSettings

    from feelflow.app.gui.main_window import MainWindow
    from feelflow.app.model.simulation import Params

    settings = QSettings(str(tmp_path / "settings.ini"), QSettings.IniFormat)
    w = MainWindow(backend="numpy", settings=settings, params=Params(grid=GRID, size=12))
    qtbot.addWidget(w)
    w.resize(1100, 700)
    w.show()
    qtbot.waitUntil(lambda: w.sim is not None, timeout=20000)
    qtbot.waitUntil(lambda: w.sim.solver.time > 20, timeout=20000)
    yield w
    w.loop.timer.stop()
    w.loop.slow_timer.stop()


def solid_mask(sim):
    """The solver's solid-node mask now (a copy)."""
    return sim.solver.solver.body.solid.copy()


def wheel(window, notches: int):
    """Turn the mouse wheel over the body by `notches` (positive: counter-clockwise)."""
    from PySide6.QtCore import QPoint, Qt
    from PySide6.QtGui import QWheelEvent
    from PySide6.QtWidgets import QApplication

    vp = window.viewport
    pos = vp.to_widget(*window.sim.pos)
    ev = QWheelEvent(pos, vp.mapToGlobal(pos), QPoint(), QPoint(0, 120 * notches), Qt.NoButton, Qt.NoModifier,
                     Qt.NoScrollPhase, False)
    QApplication.sendEvent(vp, ev)
