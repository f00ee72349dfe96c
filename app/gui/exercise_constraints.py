"""The exercise's constraints while the student edits: what the shape breaks now
(app/exercises/constraints.py `shape_problems`, Qt-free), named in the exercise panel, and the
body outlined in red in the viewport while anything is broken.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtGui import QColor

from feelflow.app.exercises.constraints import shape_problems

if TYPE_CHECKING:
    from feelflow.app.gui.exercise_panel import ExercisePanel
    from feelflow.app.gui.viewport import Viewport

BROKEN_EDGE = QColor(230, 40, 40)


class ConstraintWatch:
    """`problems`: what the last check found (empty: the shape may be scored)."""

    def __init__(self, panel: "ExercisePanel", viewport: "Viewport"):
        self.panel, self.viewport = panel, viewport
        self.problems: list[str] = []

    def check(self, exercise, shape):
        """Check `shape` (None: none yet) against `exercise`; show what is broken."""
        self.show(shape_problems(exercise, shape))

    def show(self, problems: list[str]):
        if problems != self.problems or not self.panel.constraints.text():
            self.name(problems)
        edge = BROKEN_EDGE if problems else None
        if self.viewport.body_edge != edge:
            self.viewport.body_edge = edge
            self.viewport.update()

    def name(self, problems: list[str]):
        """Name `problems` in the panel (the outline waits for the next check)."""
        self.problems = problems
        self.panel.set_problems(problems)

    def clear(self):
        """The exercise closed: no outline."""
        self.viewport.body_edge = None
