"""The side panel's wind and viscosity boxes in the units shown (View > Units): m/s and the
fluid's viscosity (read-only: the fluid fixes it) in SI, cells per step in lattice units. The
ranges and words are app/model/side_panel_text.py's; an edit goes back to lattice units, so the
signals always carry the solver's values."""
from __future__ import annotations

import math

from PySide6.QtCore import QObject, Signal
from PySide6.QtWidgets import QAbstractSpinBox, QDoubleSpinBox

from feelflow.app.model import side_panel_text as text
from feelflow.app.model.display_units import DisplayUnits


class ViscosityBox(QDoubleSpinBox):
    """The viscosity box: in physical units it shows the fluid's viscosity (1e-6 m^2/s) in
    scientific notation, which a plain QDoubleSpinBox cannot."""

    scientific = False

    def textFromValue(self, value: float) -> str:
        return f"{value:.4g}" if self.scientific else super().textFromValue(value)

    def valueFromText(self, text: str) -> float:
        if self.scientific:
            try:
                return float(text)
            except ValueError:
                return self.value()
        return super().valueFromText(text)


def configure(box: QDoubleSpinBox, r: text.BoxRange):
    box.setDecimals(r.decimals)
    box.setRange(r.minimum, r.maximum)
    box.setSingleStep(r.step)
    box.setSuffix(r.suffix)


class FlowBoxUnits(QObject):
    """Binds the `wind` and `viscosity` boxes to the units shown. `shown`: the (wind, nu) they
    stand for, lattice units; `windChanged` / `viscosityChanged` carry an edit in lattice units."""

    windChanged = Signal(float)
    viscosityChanged = Signal(float)

    def __init__(self, wind: QDoubleSpinBox, viscosity: ViscosityBox, parent=None):
        super().__init__(parent)
        self.wind, self.viscosity = wind, viscosity
        self.units = DisplayUnits()   # lattice or SI (View > Units; app/model/display_units.py)
        self.shown = (math.nan, math.nan)   # the (wind, nu) the boxes stand for, lattice units
        self._drawn_in = None    # the units the boxes were last drawn in (`_units_key`)
        configure(wind, text.WIND_LATTICE)
        configure(viscosity, text.VISCOSITY_LATTICE)
        wind.valueChanged.connect(self._wind_edited)
        viscosity.valueChanged.connect(self._viscosity_edited)

    def _wind_edited(self, shown: float):
        """The wind box changed: its value back in lattice units (m/s in SI) for the window."""
        wind = self.units.lattice_speed(shown)
        self.shown = (wind, self.shown[1])
        self.windChanged.emit(wind)

    def _viscosity_edited(self, nu: float):
        if self.units.is_si:    # read-only in SI: the fluid fixes it
            return
        self.shown = (self.shown[0], nu)
        self.viscosityChanged.emit(nu)

    def _units_key(self):
        """What the boxes' drawing depends on besides the values: lattice, or the SI scale."""
        u = self.units
        return (u.physical.fluid.name, u.speed(1.0)) if u.is_si else None

    def show(self, wind: float, nu: float):
        """Draw the boxes for lattice (wind, nu) in the units shown (signals blocked)."""
        u = self.units
        boxes = (self.wind, self.viscosity)
        for b in boxes:
            b.blockSignals(True)
        try:
            configure(self.wind, text.wind_range(u))
            self.wind.setValue(u.speed(wind))
            self.wind.setToolTip(text.wind_tip(u, wind))
            self.viscosity.scientific = u.is_si
            self.viscosity.setReadOnly(u.is_si)
            self.viscosity.setButtonSymbols(QAbstractSpinBox.NoButtons if u.is_si else QAbstractSpinBox.UpDownArrows)
            configure(self.viscosity, text.viscosity_range(u))
            self.viscosity.setValue(u.viscosity(nu))
            self.viscosity.setToolTip(text.viscosity_tip(u, nu))
        finally:
            for b in boxes:
                b.blockSignals(False)
        self.shown = (wind, nu)
        self._drawn_in = self._units_key()

    def set_units(self, units: DisplayUnits):
        """Numbers from now on in `units`; the boxes are redrawn only when the units change, so
        that typing is not interrupted."""
        self.units = units
        wind, nu = self.shown
        if self._units_key() != self._drawn_in and math.isfinite(wind) and math.isfinite(nu):
            self.show(wind, nu)
