"""`feelflow gui SESSION`: what the desktop entry's `Exec=... gui %f` runs when a teacher
double-clicks a `.ffsession` file. The real command line, the real window (Xvfb, numpy solver):
the window opens and replays that file; a missing file is one line and exit 2."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_a_missing_session_file_is_one_line_and_exit_2(tmp_path):
    missing = tmp_path / "gone.ffsession"
    r = subprocess.run([sys.executable, "-m", "feelflow.app", "gui", str(missing)], cwd=ROOT,
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2
    assert r.stderr.strip() == f"feelflow: {missing}: no such session file"


@pytest.mark.gui
@pytest.mark.skipif(not os.environ.get("DISPLAY"), reason="needs an X display (run under xvfb-run -a)")
def test_gui_with_a_session_file_opens_the_window_replaying_it(qapp, tmp_path, monkeypatch):
    from PySide6.QtCore import QTimer

    from feelflow.app.cli.main import main
    from feelflow.app.gui.main_window import MainWindow
    from feelflow.app.sessions import SessionRecorder, SessionSolver
    from session_scenes import MODELS, drive_moving_cylinder, small_config, start_body
    from feelflow.solver.backend import create_solver

    cfg = small_config()
    rec = SessionRecorder(cfg, start_body(), MODELS)
    drive_moving_cylinder(SessionSolver(create_solver("numpy", cfg), rec), steps=25)
    path = rec.save(tmp_path / "lesson.ffsession")

    seen = {}
    # Only the window this command opens is looked at: a window an earlier test of the same
    # process left for Qt to delete may still be listed among the top-level widgets, and
    # touching it can crash the process.
    opened = []
    init = MainWindow.__init__

    def remember(self, *args, **kwargs):
        init(self, *args, **kwargs)
        opened.append(self)

    monkeypatch.setattr(MainWindow, "__init__", remember)

    def watch():
        """Once the window replays, note what it shows and close it (app.exec() then returns)."""
        for w in opened:
            if w.isVisible():
                if w.replays.replay is not None:
                    seen.update(label=w.replays.label.text(), shown=w.viewport.sim is w.replays.replay,
                                live=w.sim is not None)
                    w.close()
                elif w.startup_error:
                    seen["error"] = w.startup_error

    def give_up():
        seen.setdefault("timeout", True)
        for w in opened:
            w.close()

    poll = QTimer()
    poll.timeout.connect(watch)
    poll.start(50)
    QTimer.singleShot(60000, give_up)
    try:
        code = main(["gui", "--backend", "numpy", "--fresh", str(path)])
    finally:
        poll.stop()
    assert "timeout" not in seen and "error" not in seen, seen
    assert code == 0
    assert seen["live"] and seen["shown"]
    assert seen["label"].startswith("Replaying lesson.ffsession: step ")
