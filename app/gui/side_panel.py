"""The side panel: body (shape, size, angle, hold still, polygon editor), flow (wind speed,
viscosity with live Re and Ma, grid, walls), forces (model, compare all, readouts), display mode
and input (mouse or a haptic device). It only edits values; the window applies them.

In physical units (View > Units) the wind box shows and takes m/s and the viscosity box shows
the fluid's viscosity, read-only (`FlowBoxUnits`, app/gui/flow_box_units.py); the numbers and
their words are app/model/side_panel_text.py's, and the signals always carry the solver's
lattice values.
"""
from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (QCheckBox, QComboBox, QDoubleSpinBox, QFormLayout, QGroupBox, QHBoxLayout, QLabel,
                               QPushButton, QScrollArea, QVBoxLayout, QWidget)

from feelflow.app.gui.display_modes import DISPLAY_MODES
from feelflow.app.gui.flow_box_units import FlowBoxUnits, ViscosityBox
from feelflow.app.model import side_panel_text
from feelflow.app.model.bodies import SHAPE_LABELS
from feelflow.app.model.display_units import DisplayUnits
from feelflow.app.model.simulation import FORCE_MODELS, GRID_PRESETS, WALLS


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


#: what a first-time user needs to know about each control (shown as tooltips)
TOOLTIPS = {
    "shape": "The body in the tunnel; Custom polygon lets you edit its corners",
    "size": "The body's length across the flow, in grid cells (more cells: finer but slower)",
    "hold_still": "Keep the body fixed: the flow pushes on it but it does not move",
    "save_shape": "Save the body's shape to a file",
    "load_shape": "Load a body's shape from a file",
    "wind": side_panel_text.WIND_TIP,
    "viscosity": side_panel_text.VISCOSITY_TIP,
    "grid": "How many cells the tunnel has: a finer grid shows more detail but runs slower",
    "wall": "What the top and bottom of the tunnel are",
    "model": "How the force on the body is computed from the flow (docs/science/force-models.md)",
    "compare_all": "Compute every force model at once and plot them together (dashed lines are lift)",
    "display": "What the colours show: speed, vorticity (spin), pressure, or moving tracer particles",
    "arrows": "Draw the drag (red) and lift (blue) forces on the body",
    "input": "What moves the body: the mouse, or a haptic device you can feel the force with",
}


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
        self.viscosity = ViscosityBox()
        self.flow_units = FlowBoxUnits(self.wind, self.viscosity, self)   # the two in the units shown
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
        self.flow_units.windChanged.connect(self.windChanged)
        self.flow_units.viscosityChanged.connect(self.viscosityChanged)
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
            self.flow_units.show(params.wind, params.nu)
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

    def show_angle(self, degrees: float):
        """Show the body's angle without emitting angleChanged (the wheel or the handle turned it)."""
        self.angle.blockSignals(True)
        self.angle.setValue(degrees)
        self.angle.blockSignals(False)

    def show_forces(self, drag: float | None, lift: float | None):
        """The force model's mean drag and lift (None: no data yet)."""
        d, l_ = side_panel_text.force_texts(drag, lift, self.units)
        self.drag.setText(d)
        self.lift.setText(l_)

    def show_units(self, units):
        """Numbers from now on in `units` (app.model.display_units.DisplayUnits); in SI the flow's
        physical reading under the Reynolds number."""
        self.units = units
        if units.is_si:
            self.physical.setText(side_panel_text.physical_text(units))
        self.physical.setVisible(units.is_si)
        self.flow_units.set_units(units)

    def show_numbers(self, reynolds: float, mach: float, mach_limit: float):
        self.reynolds.setText(f"Re = {reynolds:.0f}")
        colour = "#c62828" if mach > mach_limit else "black"
        self.mach.setText(f"<span style='color:{colour}'>Ma = {mach:.3f}</span> (limit {mach_limit:.2f})")
