"""The exercise panel's "Your shape" box, for exercises on a built-in body: the kind, its
parameters (app/exercises/shape_fields.py `PARAMETERS`: labels, ranges, steps), a wedge's
pointing and the angle. Widgets only: the values go to and from a shape dictionary through
app/exercises/shape_fields.py."""
from __future__ import annotations

from PySide6.QtCore import Signal
from PySide6.QtWidgets import QComboBox, QDoubleSpinBox, QFormLayout, QGroupBox, QLabel

from feelflow.app.exercises.shape_fields import PARAMETERS, FieldValues, field_values, shape_dict


class ShapeFields(QGroupBox):
    """`changed`: the student changed a field (not emitted by `set_parameters`)."""

    changed = Signal()

    def __init__(self, parent=None):
        super().__init__("Your shape", parent)
        form = QFormLayout(self)
        self.kind = QComboBox()
        self.kind.currentIndexChanged.connect(self._kind_changed)
        form.addRow("Kind", self.kind)
        self.spins: dict[str, QDoubleSpinBox] = {}
        self.rows: dict[str, tuple] = {}
        for kind, params in PARAMETERS.items():
            for name, (label, lo, hi, step) in params.items():
                key = f"{kind}.{name}"
                spin = QDoubleSpinBox()
                spin.setRange(lo, hi)
                spin.setSingleStep(step)
                spin.setDecimals(2)
                spin.setKeyboardTracking(False)
                spin.valueChanged.connect(lambda _=0: self.changed.emit())
                self.spins[key] = spin
                lab = QLabel(label)
                form.addRow(lab, spin)
                self.rows[key] = (lab, spin)
        self.pointing = QComboBox()
        self.pointing.addItem("point upstream <", "upstream")
        self.pointing.addItem("point downstream >", "downstream")
        self.pointing.currentIndexChanged.connect(lambda _=0: self.changed.emit())
        self.pointing_label = QLabel("Wedge")
        form.addRow(self.pointing_label, self.pointing)
        self.angle = QDoubleSpinBox()
        self.angle.setRange(-90.0, 90.0)
        self.angle.setDecimals(1)
        self.angle.setSingleStep(1.0)
        self.angle.setKeyboardTracking(False)
        self.angle.valueChanged.connect(lambda _=0: self.changed.emit())
        form.addRow("Angle (degrees, + turns nose down)", self.angle)

    def show_kinds(self, kinds):
        """Offer the exercise's parametric kinds (hidden when it has none)."""
        parametric = [k for k in kinds if k in PARAMETERS]
        self.setVisible(bool(parametric))
        self.kind.blockSignals(True)
        self.kind.clear()
        for k in parametric:
            self.kind.addItem(k.replace("_", " "), k)
        self.kind.blockSignals(False)
        self._show_rows()

    def _kind_changed(self, _=0):
        self._show_rows()
        self.changed.emit()

    def _show_rows(self):
        kind = self.kind.currentData()
        for key, (lab, spin) in self.rows.items():
            on = key.split(".")[0] == kind
            lab.setVisible(on)
            spin.setVisible(on)
        self.pointing.setVisible(kind == "wedge")
        self.pointing_label.setVisible(kind == "wedge")

    def set_parameters(self, shape):
        """Show a built-in body's parameters (angles in degrees) without emitting a change per field."""
        shown = field_values(shape.to_dict())
        widgets = [self.kind, self.pointing, self.angle, *self.spins.values()]
        for w in widgets:
            w.blockSignals(True)
        self.kind.setCurrentIndex(self.kind.findData(shown.kind))
        for name, value in shown.values.items():
            self.spins[f"{shown.kind}.{name}"].setValue(value)
        if shown.pointing is not None:
            self.pointing.setCurrentIndex(self.pointing.findData(shown.pointing))
        self.angle.setValue(shown.angle_deg)
        for w in widgets:
            w.blockSignals(False)
        self._show_rows()

    def parameters(self) -> dict:
        """The shape dictionary (shapes/io.py: radians) the fields describe, at (0, 0)."""
        kind = self.kind.currentData()
        values = {name: self.spins[f"{kind}.{name}"].value() for name in PARAMETERS[kind]}
        return shape_dict(FieldValues(kind, values, self.pointing.currentData(), self.angle.value()))
