"""The exercise panel beside the flow: goal and instructions, the shape's parameters (for
exercises on a built-in body: `ShapeFields`, app/gui/exercise_shape_fields.py), the constraints
as they stand, Score it with progress and Cancel, the result against the reference solutions,
and the attempts with thumbnails (app/gui/exercise_thumbnail.py).

Widgets only: the words are app/exercises/panel_text.py's and score_text.py's;
app/gui/exercise_controller.py connects the panel to the tunnel and the scoring."""
from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (QHBoxLayout, QLabel, QListWidget, QListWidgetItem, QProgressBar, QPushButton,
                               QTextBrowser, QVBoxLayout, QWidget)

from feelflow.app.exercises import panel_text
from feelflow.app.gui.exercise_shape_fields import ShapeFields
from feelflow.app.gui.exercise_thumbnail import THUMB, thumbnail


class ExercisePanel(QWidget):
    """The panel's widgets, top to bottom; it emits what the student asks for and shows what
    the controller hands it."""

    scoreRequested = Signal()
    cancelRequested = Signal()
    attemptChosen = Signal(int)      # index into the attempts list
    parametersChanged = Signal()
    editToggled = Signal(bool)

    def __init__(self, parent=None):
        super().__init__(parent)
        layout = QVBoxLayout(self)
        self.title = QLabel()
        self.title.setWordWrap(True)
        self.title.setStyleSheet("font-weight: bold; font-size: 14px")
        layout.addWidget(self.title)
        self.instructions = QTextBrowser()
        self.instructions.setMinimumHeight(150)
        layout.addWidget(self.instructions, 2)
        self.goal = QLabel()
        self.goal.setWordWrap(True)
        self.goal.setObjectName("exercise_goal")
        layout.addWidget(self.goal)
        self.references = QLabel()
        self.references.setWordWrap(True)
        self.references.setObjectName("exercise_references")
        layout.addWidget(self.references)
        self.edit = QPushButton("Edit vertices")
        self.edit.setCheckable(True)
        self.edit.setToolTip("Drag the yellow handles; double-click an edge to add a vertex; right-click a handle "
                             "to delete it (the same as the Controls panel's Edit vertices)")
        self.edit.toggled.connect(self.editToggled)
        layout.addWidget(self.edit)

        self.shape_box = ShapeFields()
        self.shape_box.changed.connect(self.parametersChanged)
        layout.addWidget(self.shape_box)

        self.constraints = QLabel()
        self.constraints.setWordWrap(True)
        self.constraints.setTextFormat(Qt.RichText)
        layout.addWidget(self.constraints)

        row = QHBoxLayout()
        self.score_button = QPushButton("Score it")
        self.score_button.clicked.connect(self.scoreRequested)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.clicked.connect(self.cancelRequested)
        self.cancel_button.setEnabled(False)
        row.addWidget(self.score_button)
        row.addWidget(self.cancel_button)
        layout.addLayout(row)
        self.progress = QProgressBar()
        self.progress.setRange(0, 1000)
        self.progress.setTextVisible(True)
        self.progress.setFormat("%p %")
        layout.addWidget(self.progress)
        self.result = QLabel()
        self.result.setWordWrap(True)
        self.result.setTextFormat(Qt.RichText)
        layout.addWidget(self.result)
        #: the live tunnel's coefficients, as the force plot shows them (same reference length)
        self.live = QLabel()
        self.live.setWordWrap(True)
        self.live.setTextFormat(Qt.RichText)
        layout.addWidget(self.live)

        self.attempts_label = QLabel("Attempts")
        self.attempts_label.setWordWrap(True)
        self.attempts_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        layout.addWidget(self.attempts_label)
        self.attempts = QListWidget()
        self.attempts.setIconSize(THUMB)
        self.attempts.setMinimumHeight(120)
        self.attempts.itemDoubleClicked.connect(lambda item: self.attemptChosen.emit(self.attempts.row(item)))
        layout.addWidget(self.attempts, 2)
        self.load_button = QPushButton("Load this attempt into the editor")
        self.load_button.clicked.connect(self._load_clicked)
        layout.addWidget(self.load_button)

    # --- filling in ---------------------------------------------------------------------------
    def show_exercise(self, exercise):
        self.title.setText(exercise.title)
        self.instructions.setPlainText(panel_text.reflow(exercise.instructions))
        self.goal.setText(panel_text.goal_text(exercise))
        self.references.setText(panel_text.references_text(exercise))
        self.edit.setVisible("polygon" in exercise.kinds)
        self.shape_box.show_kinds(exercise.kinds)
        self.result.clear()
        self.progress.setValue(0)

    def show_live(self, readout):
        """The live tunnel's C_D and C_L (an app.model.readouts.Readout) with their reference."""
        self.live.setText(panel_text.live_text(readout))

    def show_result(self, text: str):
        """The scoring run's line, or its verdict (app/exercises/score_text.py words it)."""
        self.result.setText(text)

    def show_editing(self, on: bool):
        """Edit vertices checked or not, as the Controls panel's button is (no editToggled)."""
        self.edit.blockSignals(True)
        self.edit.setChecked(on)
        self.edit.blockSignals(False)

    def set_problems(self, problems: list[str]):
        self.constraints.setText(panel_text.problems_text(problems))
        self.score_button.setEnabled(not problems and not self.cancel_button.isEnabled())

    def set_running(self, running: bool, problems_ok: bool = True):
        self.cancel_button.setEnabled(running)
        self.score_button.setEnabled(not running and problems_ok)
        self.load_button.setEnabled(not running)
        self.shape_box.setEnabled(not running)
        if running:
            self.progress.setValue(0)

    def set_progress(self, fraction: float):
        self.progress.setValue(int(round(1000 * fraction)))

    def set_attempts(self, attempts, best, where: str, uncertainty: float | None = None):
        self.attempts_label.setText(panel_text.attempts_heading(where))
        self.attempts_label.setToolTip(where)
        self.attempts.clear()
        for a in attempts:
            is_best = best is not None and a.number == best.number
            item = QListWidgetItem(thumbnail(a.load_shape().outline(), is_best),
                                   panel_text.attempt_line(a, best, uncertainty))
            item.setToolTip(panel_text.attempt_tip(a))
            self.attempts.addItem(item)
        if attempts:
            self.attempts.setCurrentRow(len(attempts) - 1)

    def _load_clicked(self):
        row = self.attempts.currentRow()
        if row >= 0:
            self.attemptChosen.emit(row)
