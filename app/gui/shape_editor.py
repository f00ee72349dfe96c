"""Undoable edits of the custom polygon (QUndoStack): every edit is one command holding the
vertex lists before and after. Invalid polygons never reach the stack: the window checks first."""
from __future__ import annotations

from PySide6.QtGui import QUndoCommand

class SetPolygon(QUndoCommand):
    """Replace the polygon's vertices; `apply` is the window's function that installs a list."""

    def __init__(self, apply, before, after, text="edit polygon"):
        super().__init__(text)
        self.apply, self.before, self.after = apply, [tuple(v) for v in before], [tuple(v) for v in after]

    def redo(self):
        self.apply(self.after)

    def undo(self):
        self.apply(self.before)
