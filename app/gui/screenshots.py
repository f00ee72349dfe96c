"""The guide's pictures of the window, made by `feelflow screenshots --out DIR`: the real window
on the numpy solver (fresh settings), set up as a teacher would and saved through the window's
own screenshot (app/gui/window/exports.py, an atomic write):

- feelflow-exercise.png: `exercises/most_lift.toml` opened at 1280 x 800 (the exercise panel
  beside the flow, the tunnel fitted to the view);
- feelflow-probes-units.png: the default tunnel with two probes (upstream and in the wake),
  View > Units set to water past a 1 cm body, the forces and the probes' plot in SI.
"""
from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

#: picture name -> what it shows (the docs link these names)
PICTURES = ("feelflow-exercise.png", "feelflow-probes-units.png")


def make_screenshots(out_dir, seconds: float = 6.0, out=sys.stdout) -> list[Path]:
    from PySide6.QtCore import QSettings, QTimer
    from PySide6.QtWidgets import QApplication

    from feelflow import EXERCISE_DIR
    from feelflow.app.gui.main_window import MainWindow   # the caller set Qt up (feelflow screenshots)
    from feelflow.app.model.display_units import UnitsChoice

    app = QApplication.instance() or QApplication(["feelflow"])
    out_dir = Path(out_dir)
    written: list[Path] = []
    ms = int(1000 * seconds)

    def window():
        settings = QSettings(os.path.join(tempfile.mkdtemp(prefix="feelflow-shots-"), "settings.ini"),
                             QSettings.IniFormat)
        settings.setValue("first_start/lessons_offered", True)
        w = MainWindow(backend="numpy", settings=settings)
        w.resize(1280, 800)
        return w

    def shot(w, name):
        path = out_dir / name
        w.exports.save_screenshot(path)
        written.append(path)
        print(f"{path}: {w.width()} x {w.height()}", file=out, flush=True)

    def exercise(w):
        w.exercises.attempts.work_folder = Path(tempfile.mkdtemp(prefix="feelflow-attempts-"))
        w.exercises.open(EXERCISE_DIR / "most_lift.toml")
        QTimer.singleShot(ms, lambda: (shot(w, PICTURES[0]), w.close(), start(window(), probes)))

    def probes(w):
        x, y = w.sim.pos
        size = w.sim.params.size
        w.probes.add(max(4.0, x - 2.5 * size), y)
        w.probes.add(x + 3.0 * size, y + 0.4 * size)
        w.units.set_choice(UnitsChoice("water", 0.01, 0.1))
        QTimer.singleShot(2 * ms, lambda: (shot(w, PICTURES[1]), w.close(), app.quit()))

    def start(w, then):
        w.simulationReady.connect(lambda: QTimer.singleShot(500, lambda: then(w)))
        w.show()

    start(window(), exercise)
    app.exec()
    return written
