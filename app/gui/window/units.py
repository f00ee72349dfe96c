"""View > Units: lattice units, or SI for a physical fluid (air, water, SAE 30 oil) and body
size, under which the side panel's forces, the force plot, the probes' plot and the forces CSV
read in newtons, metres per second, pascals and seconds for a flow with the simulated Reynolds
number (app/model/display_units.py picks, solver/units.py converts); the side panel's wind box
then reads m/s and its viscosity box the fluid's viscosity. The choice is remembered (QSettings)
and recorded in session files; replaying a session shows it in the units it was recorded in, and
Stop replay returns to the user's own choice. The device's force scaling does not depend on it
(haptics/ scales the lattice force itself)."""
from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import (QComboBox, QDialog, QDialogButtonBox, QDoubleSpinBox, QFormLayout, QLabel,
                               QVBoxLayout)

from feelflow.app.model.display_units import (DEFAULT_SIZE_M, DEFAULT_SPAN_M, LATTICE, DisplayUnits, UnitsChoice,
                                              choice_from_dict, for_model)
from feelflow.solver.units import FLUIDS

if TYPE_CHECKING:
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QStatusBar, QWidget

    from feelflow.app.gui.force_plot import ForcePlot
    from feelflow.app.gui.side_panel import SidePanel
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.gui.window.frame_loop import FrameLoop
    from feelflow.app.gui.window.probes import ProbeController
    from feelflow.app.model.simulation import Simulation
    from feelflow.app.model.tunnel import TunnelModel

REFRESH_MS = 500


class UnitsDialog(QDialog):
    """The fluid (or lattice units), the body's size and its span."""

    def __init__(self, choice: UnitsChoice, parent=None):
        super().__init__(parent)
        self.setWindowTitle("Units")
        self.setObjectName("units-dialog")
        col = QVBoxLayout(self)
        note = QLabel("Only the Reynolds number is simulated: in physical units the tunnel reads as the "
                      "chosen fluid flowing past a body of the chosen size at the speed that gives the "
                      "same Reynolds number. Forces are for a body of the chosen span (2D flow: force per "
                      "metre of span times the span).")
        note.setWordWrap(True)
        col.addWidget(note)
        form = QFormLayout()
        self.fluid = QComboBox()
        self.fluid.addItem("Lattice units (cells, solver steps)", LATTICE)
        for key, f in FLUIDS.items():
            self.fluid.addItem(f"{f.name}: \u03c1 {f.density:g} kg/m\u00b3, \u03bd {f.viscosity:.3g} m\u00b2/s", key)
        self.size = QDoubleSpinBox(decimals=4, minimum=0.0001, maximum=100.0, singleStep=0.005, suffix=" m")
        self.span = QDoubleSpinBox(decimals=4, minimum=0.0001, maximum=100.0, singleStep=0.01, suffix=" m")
        form.addRow("Units", self.fluid)
        form.addRow("Body size (its reference length)", self.size)
        form.addRow("Body span (out of the plane)", self.span)
        col.addLayout(form)
        buttons = QDialogButtonBox(QDialogButtonBox.Ok | QDialogButtonBox.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        col.addWidget(buttons)
        self.fluid.setCurrentIndex(max(0, self.fluid.findData(choice.fluid)))
        self.size.setValue(choice.size_m)
        self.span.setValue(choice.span_m)
        self.fluid.currentIndexChanged.connect(self._fluid_changed)
        self._fluid_changed()

    def _fluid_changed(self, _=0):
        physical = self.fluid.currentData() != LATTICE
        self.size.setEnabled(physical)
        self.span.setEnabled(physical)

    def choice(self) -> UnitsChoice:
        return UnitsChoice(self.fluid.currentData(), self.size.value(), self.span.value())


class UnitsController:
    def __init__(self, events: "WindowEvents", settings: "QSettings", panel: "SidePanel", plot: "ForcePlot",
                 probes: "ProbeController", loop: "FrameLoop", status: "QStatusBar", parent: "QWidget"):
        """`parent`: the dialog's and the timer's parent."""
        self.settings, self.panel, self.plot, self.probes, self.loop = settings, panel, plot, probes, loop
        self.status, self.parent = status, parent
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        events.liveCreated.connect(self._live_created)
        self.choice = self._remembered()
        self.own_choice: UnitsChoice | None = None   # the user's choice while a replay shows the recorded one
        self.units = DisplayUnits()
        events.shownChanged.connect(self.model_changed)
        self.timer = QTimer(parent)     # the physical reading follows the flow (wind, viscosity, body)
        self.timer.setInterval(REFRESH_MS)
        self.timer.timeout.connect(self.refresh)

    def _live_created(self, sim):
        self.sim = sim

    def _remembered(self) -> UnitsChoice:
        s = self.settings
        try:
            return UnitsChoice(str(s.value("units/fluid", LATTICE)), float(s.value("units/size_m", 0.01)),
                               float(s.value("units/span_m", DEFAULT_SPAN_M)))
        except (TypeError, ValueError):
            return UnitsChoice()

    def dialog(self, _=None):
        d = UnitsDialog(self.choice, self.parent)
        self.last_dialog = d
        if d.exec() == QDialog.Accepted:
            self.set_choice(d.choice())

    def set_choice(self, choice: UnitsChoice, remember: bool = True):
        """Show every number in `choice`'s units from now on, and remember it (QSettings) unless
        it is a replayed session's."""
        self.choice = choice
        if remember:
            self.own_choice = None
            s = self.settings
            s.setValue("units/fluid", choice.fluid)
            s.setValue("units/size_m", choice.size_m)
            s.setValue("units/span_m", choice.span_m)
        self.refresh()
        if choice.physical:
            self.timer.start()
        else:
            self.timer.stop()
        self.status.showMessage(f"Units: {self.units.describe()}", 8000)

    def model_changed(self, model: "TunnelModel"):
        """A replay started (its session's recorded units, if it has them) or stopped (back to
        the user's choice)."""
        session = model.replayed_session()
        recorded = choice_from_dict(session.units if session is not None else None)
        if recorded is not None:
            if self.own_choice is None:
                self.own_choice = self.choice
            self.set_choice(recorded, remember=False)
        elif model is self.sim and self.own_choice is not None:
            self.set_choice(self.own_choice)

    def default_size(self, fluid: str) -> float:
        return DEFAULT_SIZE_M.get(fluid, 0.01)

    def refresh(self):
        """The units for the flow shown now, to every widget that shows numbers."""
        units = for_model(self.choice, self.loop.shown)
        self.units = units
        self.plot.set_units(units)
        self.panel.show_units(units)
        self.probes.plot.units = units if units.is_si else None
        self.probes.plot.refresh(force=True)

    def start(self):
        """The tunnel runs: apply the remembered choice."""
        if self.choice.physical:
            self.refresh()
            self.timer.start()
