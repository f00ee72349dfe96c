"""The open exercise's attempts in the window: the work folder they are saved in (remembered in
QSettings, Exercises > Work folder for attempts), the attempts file read when an exercise
opens (a dialog when it cannot be: new attempts are then not saved), each score added to it,
the list shown in the exercise panel, and an attempt's shape read back. The file itself is
app/exercises/attempts.py (Qt-free).
"""
from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import QFileDialog, QMessageBox

from feelflow.app.errors import UserError
from feelflow.shapes.base import ShapeError


class ExerciseAttempts:
    """`record`: the open exercise's `Attempts` (None while none is open or its file is
    unreadable); `panel`: the ExercisePanel that lists them; `parent`: the dialogs' parent."""

    SETTING = "exercises/work_folder"

    def __init__(self, settings, panel, parent):
        self.settings, self.panel, self.parent = settings, panel, parent
        self.exercise = None
        self.record = None

    @property
    def work_folder(self) -> Path:
        default = Path.home() / "FeelFlow" / "exercises"
        return Path(self.settings.value(self.SETTING, str(default)))

    @work_folder.setter
    def work_folder(self, folder):
        self.settings.setValue(self.SETTING, str(folder))

    def choose_work_folder(self, _=False):
        """Exercises > Work folder for attempts: a folder dialog; the open exercise's attempts
        are read again from the new folder."""
        folder = QFileDialog.getExistingDirectory(self.parent, "Work folder for attempts", str(self.work_folder))
        if folder:
            self.work_folder = folder
            if self.exercise is not None:
                self.load(self.exercise)

    def load(self, exercise):
        """Read `exercise`'s attempts file in the work folder and list it."""
        from feelflow.app.exercises.attempts import Attempts

        self.exercise = exercise
        try:
            self.record = Attempts(exercise, self.work_folder)
        except UserError as exc:
            QMessageBox.warning(self.parent, "The attempts file cannot be read",
                                f"{exc}\nNew attempts are not saved until it is fixed or moved away.")
            self.record = None
        self.show()

    def close(self):
        self.exercise = None

    def show(self):
        if self.record is None:
            self.panel.set_attempts([], None, "nowhere: the attempts file is unreadable")
        else:
            self.panel.set_attempts(self.record.items, self.record.best(), str(self.record.path),
                                    self.exercise.objective.uncertainty)

    def add(self, shape, result):
        """Save a scored shape as an attempt (a dialog when the file cannot be written) and list it."""
        if self.record is not None:
            try:
                self.record.add(shape, result)
            except OSError as exc:
                QMessageBox.warning(self.parent, "The attempt could not be saved", str(exc))
        self.show()

    def shape(self, index: int):
        """The shape of attempt `index`, or None (a dialog when its shape cannot be read)."""
        if self.record is None or not 0 <= index < len(self.record.items):
            return None
        try:
            return self.record.items[index].load_shape()
        except ShapeError as exc:
            QMessageBox.warning(self.parent, "This attempt cannot be loaded", str(exc))
            return None
