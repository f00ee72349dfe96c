"""The live force plot (pyqtgraph) below the tunnel: its bar (the view chosen, Pause, Clear,
the exports, the C_D / C_L readout) over one plot that shows the chosen view. Each part is its
own module:

    TimeViews, SpeedView   force_views.py          drag and lift or torque against time; drag against speed
    LiftViews              polar_views.py          the polar, the drag polar, C_p along the surface
    RangeFollower          plot_range.py           the ranges the plot sets until the user zooms
    CoefficientReadout     coefficient_readout.py  C_D and C_L with their reference
    ForceExport            force_export.py         the forces CSV and the plot as PNG

The numbers come from the model (app/model/plot_series.py, readouts.py); widgets only draw.
"""
from __future__ import annotations

import pyqtgraph as pg
from PySide6.QtWidgets import QCheckBox, QComboBox, QHBoxLayout, QPushButton, QVBoxLayout, QWidget

from feelflow.app.gui.coefficient_readout import CoefficientReadout
from feelflow.app.gui.force_export import ForceExport
from feelflow.app.gui.force_views import SpeedView, TimeViews, reset_legend
from feelflow.app.gui.plot_range import RangeFollower
from feelflow.app.gui.polar_views import VIEWS as LIFT_VIEWS, LiftViews
from feelflow.app.model import plot_series, readouts
from feelflow.app.model.display_units import DisplayUnits
from feelflow.app.model.tunnel import TunnelModel


class ForcePlot(QWidget):
    """Shows `sim` (the TunnelModel the window shows, set by the window) in the view chosen in
    `view`; `refresh()` redraws (the window calls it a few times a second)."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.units = DisplayUnits()   # lattice or SI (app/model/display_units.py), set by the window
        self.sim: TunnelModel | None = None   # what the plot shows (the window sets it)
        self.export = ForceExport()   # the window sets its probes: their columns join the CSV
        self.paused = False
        self.view = QComboBox()
        self.view.addItem("Drag and lift against time", "time")
        self.view.addItem("Torque about the body's centre against time", "torque")
        self.view.addItem("Drag against relative speed (log-log)", "speed")
        for key, (label, _, _) in LIFT_VIEWS.items():
            self.view.addItem(label, key)
        self.pause_box = QCheckBox("Pause plot")
        self.clear_button = QPushButton("Clear")
        self.csv_button = QPushButton("Export CSV\u2026")
        self.png_button = QPushButton("Export PNG\u2026")
        self.readout_box = CoefficientReadout()
        bar = QHBoxLayout()
        for w in (self.view, self.pause_box, self.clear_button, self.csv_button, self.png_button):
            bar.addWidget(w)
        bar.addStretch(1)
        bar.addWidget(self.readout_box)

        pg.setConfigOptions(antialias=True, background="w", foreground="k")
        self.plot = pg.PlotWidget()
        self.plot.showGrid(x=False, y=True, alpha=0.3)   # the grid is redrawn with the axes: keep it light
        self.plot.addLegend(offset=(10, 5))
        self._label_axes()
        for ax in ("bottom", "left"):
            self.plot.getAxis(ax).enableAutoSIPrefix(False)
            f = self.plot.getAxis(ax).label.font()
            f.setPointSize(11)
            self.plot.getAxis(ax).label.setFont(f)
        self.ranges = RangeFollower(self.plot)
        self.time_views = TimeViews(self.plot, self.ranges)
        self.speed_view = SpeedView(self.plot, self.ranges)
        self.lift_views = LiftViews(self.plot)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.addLayout(bar)
        layout.addWidget(self.plot, 1)
        self.view.currentIndexChanged.connect(self._switch_view)
        self.pause_box.toggled.connect(self._pause)
        self.clear_button.clicked.connect(self.clear)

    # --- what is shown -----------------------------------------------------------------------
    def _pause(self, on):
        self.paused = on
        if not on:
            self.refresh()

    def clear(self):
        if self.sim is not None:
            self.sim.history.clear()
        self.refresh(force=True)

    def _switch_view(self):
        self.ranges.restart()
        self.plot.clear()
        self.time_views.reset()
        self.lift_views.reset()
        self.plot.getPlotItem().invertY(False)
        reset_legend(self.plot, 1)
        view = self.view.currentData()
        if self.sim is not None:
            self.sim.watch_surface_pressure(view == "cp")   # the wall sampling runs only while C_p is shown
        speed_view = view == "speed"
        self.plot.setLogMode(speed_view, speed_view)
        if speed_view:
            self.speed_view.install()
        self._label_axes()
        self.refresh(force=True)

    def _label_axes(self):
        x, y = self.axis_labels()
        self.plot.getAxis("bottom").setLabel(x)
        self.plot.getAxis("left").setLabel(y)

    def axis_labels(self) -> tuple[str, str]:
        """The (bottom, left) axis labels of the view shown, in the units shown."""
        u = self.units
        view = self.view.currentData()
        if view == "speed":
            return f"relative speed |U - V| ({u.speed_unit})", f"drag ({u.force_unit})"
        if view in LIFT_VIEWS:   # C_p and the polar: dimensionless (app/gui/polar_views.py)
            _, xlabel, ylabel = LIFT_VIEWS[view]
            return xlabel, ylabel
        if view == "torque":
            return f"time ({u.time_unit})", f"torque ({u.torque_unit}), counter-clockwise +"
        return f"time ({u.time_unit})", f"force ({u.force_unit})"

    def set_units(self, units):
        """Show numbers in `units` (app.model.display_units.DisplayUnits) from now on."""
        changed = (units.is_si, units.describe()) != (self.units.is_si, self.units.describe())
        self.units = units
        if changed:
            self._label_axes()
            self.ranges.follow = True
            self.refresh(force=True)

    # --- drawing ---------------------------------------------------------------------------
    def refresh(self, force: bool = False):
        if self.sim is None or (self.paused and not force):
            return
        sim = self.sim
        self.readout_box.show_readout(self.readout(), plot_series.strouhal_note(sim))
        view = self.view.currentData()
        if view == "speed":
            self.speed_view.draw(sim, self.units, self.lift_views)
        elif view == "polar":
            self.lift_views.draw_polar(sim)
        elif view == "drag_polar":
            self.lift_views.draw_drag_polar(sim)
        elif view == "cp":
            self.lift_views.draw_cp(sim.surface_pressure())
        else:
            self.time_views.draw(sim, view, self.units)

    def readout(self, model=None) -> readouts.Readout:
        """The mean drag, lift and coefficients of the last samples, with the reference they use
        (app/model/readouts.py)."""
        sim = self.sim
        return readouts.readout(sim.history, model or sim.params.force_model, sim.reference_length())

    # --- exports ---------------------------------------------------------------------------
    def csv_text(self) -> str:
        """The forces CSV of the model shown, in the units shown (ForceExport)."""
        return self.export.csv_text(self.sim, self.units)

    def export_csv(self, path):
        self.export.write_csv(path, self.sim, self.units)

    def export_png(self, path):
        self.export.write_png(path, self.plot.plotItem)
