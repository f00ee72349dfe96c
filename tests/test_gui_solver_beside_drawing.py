"""The window on the compiled cpu backend runs each frame's solver steps in a worker thread
while the viewport repaints (app/gui/window/frame_loop.py `_advance_beside_drawing`): the steps
run there, every frame still draws, no timer or input event of the window is handled while
steps are in flight (so no controller changes the simulation under them), a drag still moves
the body, and the switch turns it off. The window's cpu kernel is the default tier's TRT
float32 variant (tests/test_cpu_vs_numpy.py): no extra compile."""
from __future__ import annotations

import threading

import pytest

from gui_fixtures import GRID

pytestmark = pytest.mark.gui


@pytest.fixture
def cpu_window(qtbot, tmp_path):
    from PySide6.QtCore import QSettings

    from feelflow.app.gui.main_window import MainWindow
    from feelflow.app.model.simulation import Params

    settings = QSettings(str(tmp_path / "settings.ini"), QSettings.IniFormat)
    w = MainWindow(backend="cpu", settings=settings, params=Params(grid=GRID, size=12))
    qtbot.addWidget(w)
    w.resize(1100, 700)
    w.show()
    qtbot.waitUntil(lambda: w.sim is not None and w.sim.solver.time > 20, timeout=120000)
    yield w
    w.loop.stop()


class StepSpy:
    """Wraps the backend's step: which thread ran it, and whether steps are in flight."""

    def __init__(self, backend):
        self.backend, self.step = backend, backend.step
        self.threads, self.busy = [], False
        backend.step = self

    def __call__(self, n):
        self.busy = True
        self.threads.append(threading.current_thread().name)
        try:
            return self.step(n)
        finally:
            self.busy = False

    def remove(self):
        del self.backend.step


def test_the_steps_run_beside_the_repaint_and_no_event_is_handled_under_them(cpu_window, qtbot):
    from PySide6.QtCore import QEvent, QObject
    from PySide6.QtWidgets import QApplication

    from feelflow.app.gui.selftest import drag_body

    w = cpu_window
    spy = StepSpy(w.sim.solver.solver)
    seen = {"during steps": 0, "events": 0}
    kinds = {QEvent.Timer, QEvent.MouseButtonPress, QEvent.MouseMove, QEvent.MouseButtonRelease, QEvent.KeyPress,
             QEvent.Wheel}

    class Watch(QObject):
        def eventFilter(self, obj, ev):
            if ev.type() in kinds:
                seen["events"] += 1
                seen["during steps"] += spy.busy
            return False

    watch = Watch()
    QApplication.instance().installEventFilter(watch)
    try:
        frames, t0 = w.viewport.frames, w.sim.solver.time
        before = w.sim.pos
        for _ in drag_body(w, 15, 6, moves=6, hold_ticks=4):
            qtbot.wait(60)
        qtbot.wait(300)
    finally:
        QApplication.instance().removeEventFilter(watch)
        spy.remove()
    assert w.viewport.frames > frames + 3 and w.sim.solver.time > t0
    assert spy.threads and all(name.startswith("feelflow-steps") for name in spy.threads), set(spy.threads)
    assert seen["events"] > 10 and seen["during steps"] == 0, seen
    assert abs(w.sim.pos[0] - before[0]) > 5   # the drag reached the body between frames


def test_the_switch_runs_the_steps_in_the_window_thread(cpu_window, qtbot, monkeypatch):
    from feelflow.app.gui.window import frame_loop

    w = cpu_window
    monkeypatch.setattr(frame_loop, "SOLVER_BESIDE_DRAWING", False)
    spy = StepSpy(w.sim.solver.solver)
    frames = w.viewport.frames
    qtbot.wait(300)
    spy.remove()
    assert spy.threads and set(spy.threads) == {threading.main_thread().name}
    assert w.viewport.frames > frames + 3
