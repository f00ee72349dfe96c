"""The force plot's readout: C_D and C_L large and bold (app/model/readouts.py computes them),
and below them, small, what they are made dimensionless with (the reference length and speed)
and, for a cylinder whose lift swings, its Strouhal number beside the published one."""
from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QLabel, QVBoxLayout, QWidget

from feelflow.app.model import readouts


class CoefficientReadout(QWidget):
    """`value_label`: C_D and C_L; `reference_label`: their reference (and St)."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.value_label = QLabel("C<sub>D</sub> = \u2013   C<sub>L</sub> = \u2013")
        self.value_label.setTextFormat(Qt.RichText)
        font = self.value_label.font()
        font.setPointSizeF(font.pointSizeF() * 1.35)
        font.setBold(True)
        self.value_label.setFont(font)
        self.reference_label = QLabel("")
        small = self.reference_label.font()
        small.setPointSizeF(small.pointSizeF() * 0.85)
        self.reference_label.setFont(small)
        self.reference_label.setWordWrap(True)   # a long reference ("the exercise's ...") wraps, the window keeps its width
        self.reference_label.setToolTip("C = 2 F / (\u03c1 U\u00b2 L): U the relative wind's speed, "
                                        "L the reference length")
        # the widest readout keeps its place: the bar does not shift as the signs change
        self.value_label.setMinimumWidth(
            self.value_label.fontMetrics().horizontalAdvance("CD = -00.00   CL = -00.00"))
        column = QVBoxLayout(self)
        column.setContentsMargins(0, 0, 0, 0)
        column.setSpacing(0)
        column.addWidget(self.value_label)
        column.addWidget(self.reference_label)

    def show_readout(self, readout: readouts.Readout, note: str = ""):
        """`readout`'s coefficients and reference, `note` (St) after it."""
        fmt = readouts.format_coefficient
        self.value_label.setText(f"C<sub>D</sub> = {fmt(readout.cd)} &nbsp; C<sub>L</sub> = {fmt(readout.cl)}")
        self.reference_label.setText(readout.reference_text() + (f"; {note}" if note else ""))
