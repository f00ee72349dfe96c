"""The side panel: body (shape, size, angle, hold still, polygon editor), flow (wind speed,
viscosity with live Re and Ma, grid, walls), forces (model, compare all, readouts), display mode
and input (mouse or a haptic device). It only edits values; the window applies them.

In physical units (View > Units) the wind box shows and takes m/s and the viscosity box shows
the fluid's viscosity, read-only; the conversions are app/model/display_units.py's, and the
signals always carry the solver's lattice values.
"""
from __future__ import annotations

import math

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (QAbstractSpinBox, QCheckBox, QComboBox, QDoubleSpinBox, QFormLayout, QGroupBox, QHBoxLayout, QLabel,
                               QPushButton, QScrollArea, QVBoxLayout, QWidget)

from feelflow.app.model.bodies import SHAPE_LABELS
from feelflow.app.model.display_units import DisplayUnits
from feelflow.app.model.simulation import FORCE_MODELS, GRID_PRESETS, WALLS
from feelflow.app.gui.display_modes import DISPLAY_MODES


def _combo(items: dict) -> QComboBox:
    box = QComboBox()
    for key, label in items.items():
        box.addItem(label, key)
    return box


def select_data(box: QComboBox, data) -> None:
    """Select the entry whose data is `data` (no-op if absent)."""
    i = box.findData(data)
    if i >= 0:
        box.setCurrentIndex(i)


def force_pair_text(drag: float, lift: float) -> tuple[str, str]:
    """Drag and lift with the same decimals, four significant digits of the larger: a lift of
    -5.6e-10 beside a drag of 0.58 reads 0.0000, not -5.563e-10 (noise in scientific notation)."""
    scale = max(abs(drag), abs(lift))
    if scale < 1e-9:   # no wind, no force
        return "0", "0"
    decimals = max(0, 3 - math.floor(math.log10(scale)))

    def text(v):
        t = f"{v:.{decimals}f}"
        return t.lstrip("-") if float(t) == 0 else t
    return text(drag), text(lift)


#: what a first-time user needs to know about each control (shown as tooltips)
TOOLTIPS = {
    "shape": "The body in the tunnel; Custom polygon lets you edit its corners",
    "size": "The body's length across the flow, in grid cells (more cells: finer but slower)",
    "hold_still": "Keep the body fixed: the flow pushes on it but it does not move",
    "save_shape": "Save the body's shape to a file",
    "load_shape": "Load a body's shape from a file",
    "wind": "Speed of the incoming air, in grid cells per solver step; "
            "keep the Mach number under its limit for a trustworthy flow",
    "viscosity": "How thick (syrupy) the fluid is, in cells\u00b2 per step: lower viscosity gives a higher "
                 "Reynolds number, with eddies and a swinging wake",
    "grid": "How many cells the tunnel has: a finer grid shows more detail but runs slower",
    "wall": "What the top and bottom of the tunnel are",
    "model": "How the force on the body is computed from the flow (docs/science/force-models.md)",
    "compare_all": "Compute every force model at once and plot them together (dashed lines are lift)",
    "display": "What the colours show: speed, vorticity (spin), pressure, or moving tracer particles",
    "arrows": "Draw the drag (red) and lift (blue) forces on the body",
    "input": "What moves the body: the mouse, or a haptic device you can feel the force with",
}


#: the flow boxes in lattice units: (decimals, minimum, maximum, step, suffix)
WIND_LATTICE = (3, 0.0, 0.09, 0.005, " cells/step")
VISCOSITY_LATTICE = (4, 0.0005, 0.3, 0.002, " cells\u00b2/step")


def _configure(box: QDoubleSpinBox, decimals: int, minimum: float, maximum: float, step: float, suffix: str):
    box.setDecimals(decimals)
    box.setRange(minimum, maximum)
    box.setSingleStep(step)
    box.setSuffix(suffix)


def _decimals_for(maximum: float) -> int:
    """Decimals that give a value near `maximum` four significant digits."""
    return max(0, min(12, 3 - math.floor(math.log10(maximum)))) if maximum > 0 else 3


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


class SidePanel(QScrollArea):
    """Signals carry the new value; the window applies it and calls `show_*` with the result."""

    shapeChanged = Signal(str)
    sizeChanged = Signal(float)
    angleChanged = Signal(float)
    holdStillToggled = Signal(bool)
    editToggled = Signal(bool)
    windChanged = Signal(float)
    viscosityChanged = Signal(float)
    gridChanged = Signal(tuple)
    wallChanged = Signal(str)
    forceModelChanged = Signal(str)
    compareAllToggled = Signal(bool)
    displayModeChanged = Signal(str)
    arrowsToggled = Signal(bool)
    inputChanged = Signal(str)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.units = DisplayUnits()   # lattice or SI (View > Units; app/model/display_units.py)
        self.flow_shown = (math.nan, math.nan)   # the (wind, nu) the flow boxes stand for, lattice units
        self._flow_units = None    # the units the flow boxes were last drawn in (`_flow_key`)
        inner = QWidget()
        col = QVBoxLayout(inner)
        col.setSpacing(6)
        col.setContentsMargins(4, 4, 4, 4)
        self.setWidget(inner)
        self.setWidgetResizable(True)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarAlwaysOff)

        # body
        self.shape = _combo(SHAPE_LABELS)
        self.size = QDoubleSpinBox(decimals=0, minimum=6, maximum=80, singleStep=2, suffix=" cells")
        self.angle = QDoubleSpinBox(decimals=0, minimum=-180, maximum=180, singleStep=5, suffix="\u00b0")
        self.angle.setWrapping(True)
        self.angle.setToolTip("The body's angle; on the view, drag the round handle beside the body "
                              "or turn the mouse wheel over it")
        self.hold_still = QCheckBox("Hold still")
        self.edit = QPushButton("Edit vertices")
        self.edit.setCheckable(True)
        self.edit.setToolTip("Drag the yellow handles; double-click an edge to add a vertex; right-click a handle to delete it")
        self.save_shape = QPushButton("Save\u2026")
        self.load_shape = QPushButton("Load\u2026")
        body = QFormLayout()
        body.addRow("Shape", self.shape)
        body.addRow("Size", self.size)
        body.addRow("Angle", self.angle)
        body.addRow(self.hold_still)
        row = QHBoxLayout()
        for w in (self.edit, self.save_shape, self.load_shape):
            row.addWidget(w)
        body.addRow(row)
        col.addWidget(self._group("Body", body))

        # flow
        self.wind = QDoubleSpinBox()
        _configure(self.wind, *WIND_LATTICE)
        self.viscosity = ViscosityBox()
        _configure(self.viscosity, *VISCOSITY_LATTICE)
        self.reynolds = QLabel()
        self.mach = QLabel()
        for label in (self.reynolds, self.mach):
            f = label.font()
            f.setBold(True)
            label.setFont(f)
        self.grid = QComboBox()
        for label, size in GRID_PRESETS.items():
            self.grid.addItem(label, f"{size[0]}x{size[1]}")
        self.wall = _combo(WALLS)
        flow = QFormLayout()
        flow.addRow("Wind speed", self.wind)
        flow.addRow("Viscosity", self.viscosity)
        flow.addRow("Reynolds number", self.reynolds)
        flow.addRow("Mach number", self.mach)
        self.physical = QLabel()   # the SI reading of the flow (View > Units), hidden in lattice units
        self.physical.setWordWrap(True)
        self.physical.setObjectName("physical_flow")
        self.physical.hide()
        flow.addRow(self.physical)
        flow.addRow("Grid", self.grid)
        flow.addRow("Walls", self.wall)
        col.addWidget(self._group("Flow", flow))

        # forces
        self.model = _combo(FORCE_MODELS)
        self.compare_all = QCheckBox("Compute and plot all models")
        self.drag = QLabel("\u2013")
        self.lift = QLabel("\u2013")
        forces = QFormLayout()
        forces.addRow("Model", self.model)
        forces.addRow(self.compare_all)
        forces.addRow("Drag", self.drag)
        forces.addRow("Lift", self.lift)
        col.addWidget(self._group("Forces", forces))

        # display and input
        self.display = _combo({k: m.label for k, m in DISPLAY_MODES.items()})
        self.arrows = QCheckBox("Force arrows")
        self.arrows.setChecked(True)
        self.input = QComboBox()
        self.input.addItem("Mouse", "mouse")
        self.input_note = QLabel("")
        self.input_note.setWordWrap(True)
        view = QFormLayout()
        view.addRow("Show", self.display)
        view.addRow(self.arrows)
        view.addRow("Input", self.input)
        view.addRow(self.input_note)
        col.addWidget(self._group("Display and input", view))
        col.addStretch(1)

        self.shape.currentIndexChanged.connect(lambda: self.shapeChanged.emit(self.shape.currentData()))
        self.size.valueChanged.connect(self.sizeChanged)
        self.angle.valueChanged.connect(self.angleChanged)
        self.hold_still.toggled.connect(self.holdStillToggled)
        self.edit.toggled.connect(self.editToggled)
        self.wind.valueChanged.connect(self._wind_edited)
        self.viscosity.valueChanged.connect(self._viscosity_edited)
        self.grid.currentIndexChanged.connect(lambda: self.gridChanged.emit(tuple(int(v) for v in self.grid.currentData().split("x"))))
        self.wall.currentIndexChanged.connect(lambda: self.wallChanged.emit(self.wall.currentData()))
        self.model.currentIndexChanged.connect(lambda: self.forceModelChanged.emit(self.model.currentData()))
        self.compare_all.toggled.connect(self.compareAllToggled)
        self.display.currentIndexChanged.connect(lambda: self.displayModeChanged.emit(self.display.currentData()))
        self.arrows.toggled.connect(self.arrowsToggled)
        self.input.currentIndexChanged.connect(lambda: self.inputChanged.emit(self.input.currentData() or "mouse"))
        for name, tip in TOOLTIPS.items():
            getattr(self, name).setToolTip(tip)
        self.setMinimumWidth(inner.sizeHint().width() + 24)

    @staticmethod
    def _group(title, layout):
        layout.setVerticalSpacing(4)      # compact: every group fits a 800-pixel-high screen
        layout.setContentsMargins(8, 4, 8, 4)
        box = QGroupBox(title)
        box.setLayout(layout)
        return box

    def show_params(self, params, display_mode):
        """Set every control from `params` without emitting signals."""
        widgets = (self.shape, self.size, self.angle, self.wind, self.viscosity, self.grid, self.wall,
                   self.model, self.compare_all, self.display)
        for w in widgets:
            w.blockSignals(True)
        try:
            select_data(self.shape, params.shape)
            self.size.setValue(params.size)
            self.angle.setValue(params.angle_deg)
            self._show_flow(params.wind, params.nu)
            key = f"{params.grid[0]}x{params.grid[1]}"
            if self.grid.findData(key) < 0:   # a grid from a scene or settings, not a preset
                self.grid.addItem(f"{params.grid[0]} x {params.grid[1]}", key)
            select_data(self.grid, key)
            select_data(self.wall, params.wall)
            select_data(self.model, params.force_model)
            self.compare_all.setChecked(params.compare_all)
            select_data(self.display, display_mode)
        finally:
            for w in widgets:
                w.blockSignals(False)
        self.edit.setEnabled(params.shape == "polygon")
        self.save_shape.setEnabled(True)

    # --- the flow boxes in the units shown ----------------------------------------------------
    def _wind_edited(self, shown: float):
        """The wind box changed: its value back in lattice units (m/s in SI) for the window."""
        wind = self.units.lattice_speed(shown)
        self.flow_shown = (wind, self.flow_shown[1])
        self.windChanged.emit(wind)

    def _viscosity_edited(self, nu: float):
        if self.units.is_si:    # read-only in SI: the fluid fixes it
            return
        self.flow_shown = (self.flow_shown[0], nu)
        self.viscosityChanged.emit(nu)

    def _flow_key(self):
        """What the flow boxes' drawing depends on besides the values: lattice, or the SI scale."""
        u = self.units
        return (u.physical.fluid.name, u.speed(1.0)) if u.is_si else None

    def _show_flow(self, wind: float, nu: float):
        """Draw the flow boxes for lattice (wind, nu) in the units shown (signals blocked)."""
        u = self.units
        boxes = (self.wind, self.viscosity)
        for b in boxes:
            b.blockSignals(True)
        try:
            if u.is_si:
                fluid = u.physical.fluid
                top = u.speed(WIND_LATTICE[2])
                _configure(self.wind, _decimals_for(top), 0.0, top, u.speed(WIND_LATTICE[3]), " m/s")
                self.wind.setValue(u.speed(wind))
                self.wind.setToolTip(f"Speed of the incoming {fluid.name}, in m/s for the chosen body size "
                                     f"(View > Units); the solver runs the same Reynolds number at "
                                     f"{wind:.4g} cells per step")
                self.viscosity.scientific = True
                _configure(self.viscosity, 12, 0.0, 1.0, 0.0, " m\u00b2/s")
                self.viscosity.setValue(u.viscosity(nu))
                self.viscosity.setReadOnly(True)
                self.viscosity.setButtonSymbols(QAbstractSpinBox.NoButtons)
                self.viscosity.setToolTip(f"{fluid.name}'s kinematic viscosity: the fluid fixes it, so it cannot "
                                          f"be changed here (change the Reynolds number with the wind speed, or "
                                          f"set the solver's viscosity in lattice units, View > Units); the "
                                          f"solver runs {nu:.4g} cells\u00b2 per step")
            else:
                _configure(self.wind, *WIND_LATTICE)
                self.wind.setValue(wind)
                self.wind.setToolTip(TOOLTIPS["wind"])
                self.viscosity.scientific = False
                self.viscosity.setReadOnly(False)
                self.viscosity.setButtonSymbols(QAbstractSpinBox.UpDownArrows)
                _configure(self.viscosity, *VISCOSITY_LATTICE)
                self.viscosity.setValue(nu)
                self.viscosity.setToolTip(TOOLTIPS["viscosity"])
        finally:
            for b in boxes:
                b.blockSignals(False)
        self.flow_shown = (wind, nu)
        self._flow_units = self._flow_key()

    def show_angle(self, degrees: float):
        """Show the body's angle without emitting angleChanged (the wheel or the handle turned it)."""
        self.angle.blockSignals(True)
        self.angle.setValue(degrees)
        self.angle.blockSignals(False)

    def show_forces(self, drag: float | None, lift: float | None):
        """The force model's mean drag and lift (None: no data yet)."""
        if drag is None or lift is None or not (math.isfinite(drag) and math.isfinite(lift)):
            self.drag.setText("\u2013")
            self.lift.setText("\u2013")
            return
        u = self.units
        if u.is_si:   # newtons: four significant digits (forces of micronewtons in water)
            d, l_ = f"{u.force(drag):.4g}", f"{u.force(lift):.4g}"
        else:
            d, l_ = force_pair_text(drag, lift)
        self.drag.setText(f"{d} ({'N' if u.is_si else 'lattice units'})")
        self.lift.setText(f"{l_} ({'N' if u.is_si else 'lattice units'})")

    def show_units(self, units):
        """Numbers from now on in `units` (app.model.display_units.DisplayUnits); in SI the flow's
        physical reading under the Reynolds number."""
        self.units = units
        if units.is_si:
            ph = units.physical
            self.physical.setText(f"<i>Simulates {ph.describe()}: wind {ph.wind_m_s:.3g} m/s, "
                                  f"ν {ph.fluid.viscosity:.3g} m²/s, ρ {ph.fluid.density:g} kg/m³; "
                                  f"a step is {ph.dt:.3g} s, a cell {ph.dx:.3g} m. The solver runs wind "
                                  f"{ph.speed:.4g} cells/step, ν {ph.nu:.4g} cells²/step.</i>")
        self.physical.setVisible(units.is_si)
        wind, nu = self.flow_shown
        if self._flow_key() != self._flow_units and math.isfinite(wind) and math.isfinite(nu):
            self._show_flow(wind, nu)   # redrawn only when the units change: typing is not interrupted

    def show_numbers(self, reynolds: float, mach: float, mach_limit: float):
        self.reynolds.setText(f"Re = {reynolds:.0f}")
        colour = "#c62828" if mach > mach_limit else "black"
        self.mach.setText(f"<span style='color:{colour}'>Ma = {mach:.3f}</span> (limit {mach_limit:.2f})")
