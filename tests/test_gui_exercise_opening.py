"""An exercise opens as an exercise (Xvfb, the real window): `feelflow gui --exercise FILE` on a
first start shows no lesson chooser over it; the exercise panel is readable at the default
window size and at 1280 x 800 (no wrapped line squeezed under its neighbour, the attempts file's
folder shown whole); the exercise's wide, low tunnel fills the viewport."""
from __future__ import annotations

import pathlib

import pytest

pytestmark = pytest.mark.gui

ROOT = pathlib.Path(__file__).resolve().parents[1]
MOST_LIFT = ROOT / "exercises" / "most_lift.toml"


def _window(qtbot, tmp_path, size):
    from PySide6.QtCore import QSettings

    from feelflow.app.cli.commands.gui import what_opens_first
    from feelflow.app.gui.main_window import MainWindow

    settings = QSettings(str(tmp_path / "settings.ini"), QSettings.IniFormat)   # a first start
    settings.setValue("exercises/work_folder", str(tmp_path / "a folder with a long name" / "for the attempts"))
    w = MainWindow(backend="numpy", settings=settings)
    qtbot.addWidget(w)
    what_opens_first(w, settings, exercise=str(MOST_LIFT))
    if size is not None:
        w.resize(*size)
    w.show()
    qtbot.waitUntil(lambda: w.exercises.exercise is not None, timeout=20000)
    qtbot.wait(1200)  # the docks settle, the tunnel is fitted, the readouts show the exercise's reference
    return w


def _fully_shown(label) -> bool:
    """A word-wrapped label has at least the height its text needs at its width."""
    return label.isVisible() and label.height() >= label.heightForWidth(label.width())


@pytest.mark.parametrize("size", [None, (1280, 800)], ids=["default size", "1280x800"])
def test_exercise_opens_readable_without_the_lesson_chooser(qtbot, tmp_path, size):
    w = _window(qtbot, tmp_path, size)
    try:
        assert getattr(w, "lessons_dialog", None) is None     # no chooser over the exercise
        panel = w.exercises.panel
        assert w.exercises.dock.isVisible() and not w.exercises.dock.visibleRegion().isEmpty()
        # the lines wrap, none is cut or squeezed, and no two overlap
        for label in (panel.title, panel.goal, panel.references, panel.attempts_label):
            assert _fully_shown(label), label.objectName() or label.text()
        shown = [x for x in (panel.title, panel.instructions, panel.goal, panel.references, panel.edit,
                             panel.constraints, panel.score_button, panel.progress, panel.result,
                             panel.attempts_label, panel.attempts) if x.isVisible()]
        for a, b in zip(shown, shown[1:]):
            assert a.geometry().bottom() < b.geometry().top() or a.y() == b.y(), (a, b)
        assert "for the attempts" in panel.attempts_label.text().replace("\u200b", "")
        # the scores to the digits the grid uncertainty supports (most_lift: 0.05), ties said
        assert "1.11" in panel.references.text() and "1.1086" not in panel.references.text()
        assert "\u00b10.05" in panel.goal.text() and "tie" in panel.goal.text()
        # the instructions read as paragraphs, not the file's line breaks
        assert "area between 60 and 80" in panel.instructions.toPlainText()
        # the 192 x 64 tunnel fills the viewport: its full width (less the colour bar) and most of its height
        from feelflow.app.gui.display_modes import COLOUR_BAR_MARGIN

        vp = w.viewport
        r = vp.lattice_rect()
        assert r.width() >= 0.97 * (vp.width() - COLOUR_BAR_MARGIN)
        assert r.height() >= 0.85 * vp.height(), (r, vp.size())
        assert vp.width() >= 0.6 * w.width()
        if size is not None:   # the panel fits: the window keeps the size it was given
            assert (w.width(), w.height()) == size
    finally:
        w.loop.timer.stop()
        w.loop.slow_timer.stop()
        w.close()


def test_first_start_without_an_exercise_still_offers_the_lessons(qtbot, tmp_path):
    from PySide6.QtCore import QSettings

    from feelflow.app.cli.commands.gui import what_opens_first
    from feelflow.app.gui.main_window import MainWindow

    settings = QSettings(str(tmp_path / "settings.ini"), QSettings.IniFormat)
    w = MainWindow(backend="numpy", settings=settings)
    qtbot.addWidget(w)
    what_opens_first(w, settings)
    w.show()
    try:
        qtbot.waitUntil(lambda: getattr(w, "lessons_dialog", None) is not None and w.lessons_dialog.isVisible(),
                        timeout=20000)
    finally:
        w.lessons_dialog.close()
        w.loop.timer.stop()
        w.loop.slow_timer.stop()
        w.close()


def test_another_exercise_waits_for_a_running_score(qtbot, tmp_path, monkeypatch):
    """While a score runs, opening an exercise says so in one dialog and changes nothing."""
    from PySide6.QtWidgets import QMessageBox

    w = _window(qtbot, tmp_path, None)
    try:
        said = []
        monkeypatch.setattr(QMessageBox, "information", lambda *a, **k: said.append(a[1]))
        exercise = w.exercises.exercise
        w.exercises.scoring.worker = object()   # a score running
        assert not w.exercises.open(MOST_LIFT)
        assert said == ["Scoring is running"] and w.exercises.exercise is exercise
    finally:
        w.exercises.scoring.worker = None
        w.loop.timer.stop()
