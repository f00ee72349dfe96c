"""The unstable-flow dialog: the flow blew up (non-finite populations or forces); the student
is told why in plain words and asked whether to reset the flow."""
from __future__ import annotations

from PySide6.QtWidgets import QMessageBox, QWidget


def ask_reset(parent: QWidget) -> bool:
    """Tell the student the flow became unstable; True where they ask to reset it."""
    answer = QMessageBox.question(
        parent, "The simulation became unstable",
        "The flow became unstable and stopped (the numbers grew without bound).\n"
        "This happens when the flow is too fast for the grid or the viscosity is too low.\n\n"
        "Reset the flow and continue?", QMessageBox.Reset | QMessageBox.Cancel, QMessageBox.Reset)
    return answer == QMessageBox.Reset
