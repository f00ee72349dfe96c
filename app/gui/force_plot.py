"""The live force plot (pyqtgraph): drag and lift against time for the force model in use (or
all models), C_D / C_L readouts, and "drag against relative speed" on log-log axes with the
fitted exponent (the U^2 lesson: at low Re, C_D falls as Re grows, so drag grows slower than U^2).
"""
from __future__ import annotations

import math

import numpy as np
import pyqtgraph as pg
import pyqtgraph.exporters
from PySide6.QtCore import Qt
from PySide6.QtWidgets import (QCheckBox, QComboBox, QHBoxLayout, QLabel, QPushButton, QVBoxLayout, QWidget)

from feelflow.app.files import atomic_path, write_text_atomic
from feelflow.app.gui.polar_views import VIEWS as LIFT_VIEWS, LiftViews
from feelflow.app.model.power_law import fit_power_law
from feelflow.app.model import published, readouts
from feelflow.app.model.display_units import DisplayUnits
from feelflow.app.model.readouts import start_pulse_steps
from feelflow.app.model.force_history import History
from feelflow.app.model.simulation import FORCE_MODELS
from feelflow.app.model.tunnel import TunnelModel

MODEL_COLOURS = {"momentum_exchange": ((220, 40, 40), (40, 110, 240)),
                 "macroscopic": ((230, 140, 20), (20, 170, 190)),
                 "pressure": ((150, 60, 190), (40, 160, 60))}


class ForcePlot(QWidget):
    """Shows `sim.history`; `refresh()` redraws (the window calls it a few times a second)."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.probes = None   # app.model.probes.Probes, set by the window: their columns join the CSV
        self.units = DisplayUnits()   # lattice or SI (app/model/display_units.py), set by the window
        self.sim: TunnelModel | None = None   # what the plot shows (the window sets it)
        self.paused = False
        self._frozen = None
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
        self.readout_label = QLabel("C<sub>D</sub> = \u2013   C<sub>L</sub> = \u2013")
        self.readout_label.setTextFormat(Qt.RichText)
        font = self.readout_label.font()
        font.setPointSizeF(font.pointSizeF() * 1.35)
        font.setBold(True)
        self.readout_label.setFont(font)
        # what the coefficients are made dimensionless with, next to them (app/model/readouts.py)
        self.reference_label = QLabel("")
        small = self.reference_label.font()
        small.setPointSizeF(small.pointSizeF() * 0.85)
        self.reference_label.setFont(small)
        self.reference_label.setWordWrap(True)   # a long reference ("the exercise's ...") wraps, the window keeps its width
        self.reference_label.setToolTip("C = 2 F / (\u03c1 U\u00b2 L): U the relative wind's speed, "
                                        "L the reference length")
        bar = QHBoxLayout()
        for w in (self.view, self.pause_box, self.clear_button, self.csv_button, self.png_button):
            bar.addWidget(w)
        # the widest readout keeps its place: the bar does not shift as the signs change
        self.readout_label.setMinimumWidth(
            self.readout_label.fontMetrics().horizontalAdvance("CD = -00.00   CL = -00.00"))
        bar.addStretch(1)
        readout_column = QVBoxLayout()
        readout_column.setSpacing(0)
        readout_column.addWidget(self.readout_label)
        readout_column.addWidget(self.reference_label)
        bar.addLayout(readout_column)

        pg.setConfigOptions(antialias=True, background="w", foreground="k")
        self.plot = pg.PlotWidget()
        self.plot.showGrid(x=False, y=True, alpha=0.3)   # the grid is redrawn with the axes: keep it light
        self.legend = self.plot.addLegend(offset=(10, 5))
        self.plot.getAxis("bottom").setLabel(self.axis_labels()[0])
        self.plot.getAxis("left").setLabel(self.axis_labels()[1])
        for ax in ("bottom", "left"):
            self.plot.getAxis(ax).enableAutoSIPrefix(False)
            f = self.plot.getAxis(ax).label.font()
            f.setPointSize(11)
            self.plot.getAxis(ax).label.setFont(f)
        self.follow_range = True   # the plot sets its ranges until the user zooms or pans
        self.plot.getViewBox().sigRangeChangedManually.connect(self._user_moved_range)
        self.curves = {}
        self.lift_views = LiftViews(self.plot)
        self.scatter = self.fit_line = None
        self.fitted_exponent = None
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.addLayout(bar)
        layout.addWidget(self.plot, 1)
        self.view.currentIndexChanged.connect(self._switch_view)
        self.pause_box.toggled.connect(self._pause)
        self.clear_button.clicked.connect(self.clear)

    # --- state -----------------------------------------------------------------------------
    def _pause(self, on):
        self.paused = on
        if not on:
            self.refresh()

    def clear(self):
        if self.sim is not None:
            self.sim.history.clear()
        self.refresh(force=True)

    def _user_moved_range(self, *_):
        self.follow_range = False

    def _following(self) -> bool:
        """Is the plot to set its own ranges? Yes until the user zooms or pans, and again once
        the user clicks pyqtgraph's auto-range button ("A")."""
        if all(self.plot.getViewBox().autoRangeEnabled()):   # "A" turns both on; a zoom of one axis turns that one off
            self.follow_range = True
        return self.follow_range

    def _switch_view(self):
        self._shown = None
        self.follow_range = True
        self.plot.enableAutoRange()
        self.plot.clear()
        self.curves.clear()
        self.lift_views.reset()
        self.plot.getPlotItem().invertY(False)
        self._reset_legend(1)
        view = self.view.currentData()
        if self.sim is not None and hasattr(self.sim, "watch_surface_pressure"):
            self.sim.watch_surface_pressure(view == "cp")   # the wall sampling runs only while C_p is shown
        speed_view = view == "speed"
        self.plot.setLogMode(speed_view, speed_view)
        if speed_view:   # PlotDataItems: the log mode transforms them (bare scatter items it does not)
            self.scatter = self.plot.plot([], [], pen=None, symbol="o", symbolSize=10,
                                          symbolBrush=pg.mkBrush(220, 40, 40), symbolPen=pg.mkPen("k"),
                                          name="mean drag at one speed")
            self.fit_line = self.plot.plot([], [], pen=pg.mkPen((40, 40, 40), width=2, style=Qt.DashLine),
                                           name="fit")
            self._set_speed_ranges(np.array([]), np.array([]))
        x, y = self.axis_labels()
        self.plot.getAxis("bottom").setLabel(x)
        self.plot.getAxis("left").setLabel(y)
        self.refresh(force=True)

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
            x, y = self.axis_labels()
            self.plot.getAxis("bottom").setLabel(x)
            self.plot.getAxis("left").setLabel(y)
            self.follow_range = True
            self.refresh(force=True)

    def _reset_legend(self, columns: int):
        """The plot keeps one legend across clear(): empty it and set its layout."""
        self.legend = self.plot.addLegend(offset=(10, 5))
        self.legend.clear()
        self.legend.setColumnCount(columns)

    def models_shown(self):
        sim = self.sim
        return list(FORCE_MODELS) if sim.params.compare_all else [sim.params.force_model]

    # --- drawing ---------------------------------------------------------------------------
    def refresh(self, force: bool = False):
        if self.sim is None or (self.paused and not force):
            return
        self._update_readout()
        view = self.view.currentData()
        if view == "speed":
            self._draw_speed_view()
        elif view == "polar":
            self.lift_views.draw_polar(self.sim)
        elif view == "drag_polar":
            self.lift_views.draw_drag_polar(self.sim)
        elif view == "cp":
            self.lift_views.draw_cp(self.surface_pressure())
        elif view == "torque":
            self._draw_torque_view()
        else:
            self._draw_time_view()

    def surface_pressure(self):
        """C_p along the surface now (Simulation.surface_pressure); None where there is none (a
        replay, nothing sampled yet)."""
        take = getattr(self.sim, "surface_pressure", None)
        return take() if take is not None else None

    def readout(self, model=None) -> readouts.Readout:
        """The mean drag, lift and coefficients of the last samples, with the reference they use
        (app/model/readouts.py)."""
        sim = self.sim
        return readouts.readout(sim.history, model or sim.params.force_model, sim.reference_length())

    def coefficients(self, model=None):
        """(C_D, C_L) shown in the readout (app/model/readouts.py's definition)."""
        r = self.readout(model)
        return r.cd, r.cl

    def _update_readout(self):
        r = self.readout()
        fmt = readouts.format_coefficient
        self.readout_label.setText(f"C<sub>D</sub> = {fmt(r.cd)} &nbsp; C<sub>L</sub> = {fmt(r.cl)}")
        self.reference_label.setText(r.reference_text() + self._strouhal_text())

    def _strouhal_text(self) -> str:
        """For a cylinder whose lift swings: its Strouhal number beside the published one
        (app/model/published.py)."""
        sim = self.sim
        shape = getattr(sim, "shape", None)
        if getattr(shape, "kind", None) != "cylinder":
            return ""
        t, _, lift = sim.history.drag_lift(sim.params.force_model)
        text = published.strouhal_text(t, lift, shape.diameter, sim.params.wind, sim.reynolds())
        return f"; {text}" if text else ""

    def _curve(self, key, pen, name):
        if key not in self.curves:
            self.curves[key] = self.plot.plot([], [], pen=pen, name=name)
        return self.curves[key]

    def _draw_time_view(self):
        sim = self.sim
        shown = self.models_shown()
        if getattr(self, "_shown", None) != (tuple(shown), sim.params.compare_all):
            self._shown = (tuple(shown), sim.params.compare_all)
            self.plot.clear()                  # curves and legend rebuilt for the new set of models
            self.curves.clear()
            self._reset_legend(3 if len(shown) > 1 else 1)
        values = []
        for model in shown:
            t, drag, lift = sim.history.drag_lift(model)
            first = int(np.argmax(np.isfinite(drag))) if np.isfinite(drag).any() else len(t)
            t, drag, lift = t[first:], drag[first:], lift[first:]   # from when the model was switched on
            settled = t >= start_pulse_steps(sim.params.size)
            u = self.units
            t, drag, lift = u.time(t), u.force(drag), u.force(lift)
            cd, cl = MODEL_COLOURS.get(model, ((0, 0, 0), (90, 90, 90)))
            self._curve((model, "drag"), pg.mkPen(cd, width=2.5), self._name((model, "drag"))).setData(t, drag, connect="finite")
            self._curve((model, "lift"), pg.mkPen(cl, width=2.5, style=Qt.DashLine if len(shown) > 1 else Qt.SolidLine),
                        self._name((model, "lift"))).setData(t, lift, connect="finite")
            values.append(np.r_[drag[settled], lift[settled]])
        self._set_force_range(np.concatenate(values) if values else np.array([]))

    def _draw_torque_view(self):
        """Each shown model's torque about the body's centre against time (History.torque); the
        macroscopic model's is zero by construction (solver/forces/macroscopic.py)."""
        sim = self.sim
        shown = self.models_shown()
        if getattr(self, "_shown", None) != (tuple(shown), sim.params.compare_all):
            self._shown = (tuple(shown), sim.params.compare_all)
            self.plot.clear()
            self.curves.clear()
            self._reset_legend(3 if len(shown) > 1 else 1)
        values = []
        u = self.units
        for model in shown:
            t, torque = sim.history.torque(model)
            first = int(np.argmax(np.isfinite(torque))) if np.isfinite(torque).any() else len(t)
            t, torque = t[first:], torque[first:]
            settled = t >= start_pulse_steps(sim.params.size)
            t, torque = u.time(t), u.torque(torque)
            cd, _ = MODEL_COLOURS.get(model, ((0, 0, 0), (90, 90, 90)))
            self._curve((model, "torque"), pg.mkPen(cd, width=2.5), self._name((model, "torque"))).setData(
                t, torque, connect="finite")
            values.append(torque[settled])
        self._set_force_range(np.concatenate(values) if values else np.array([]))

    def _set_force_range(self, values):
        """Force axis of the time view: the settled forces and zero, not the start pulse (whose
        curve runs off the top, data unchanged); pyqtgraph's own auto-range until there are
        settled samples."""
        if not self._following():
            return
        values = values[np.isfinite(values)]
        if values.size == 0:
            self.plot.enableAutoRange(y=True)
            return
        lo, hi = min(0.0, float(values.min())), max(0.0, float(values.max()))
        if hi - lo < 1e-12:
            hi = lo + 1e-6
        self.plot.setYRange(lo, hi, padding=0.08)

    def _name(self, key):
        model, what = key
        return f"{what}" if not self.sim.params.compare_all else f"{what}, {FORCE_MODELS[model].split(' (')[0].lower()}"

    def speed_drag(self):
        """(relative wind speed, drag) of the settled samples (History.settled_drag)."""
        return self.sim.history.settled_drag(self.sim.params.force_model)

    def _draw_speed_view(self):
        us, fs, n = fit_power_law(*self.speed_drag())
        u = self.units
        us, fs = np.asarray(u.speed(np.asarray(us, float))), np.asarray(u.force(np.asarray(fs, float)))
        self.scatter.setData(us, fs)
        if n is not None:
            c = np.mean(np.log(fs) - n * np.log(us))
            xs = np.geomspace(us.min(), us.max(), 20)
            self.fit_line.setData(xs, np.exp(c) * xs ** n)
            self._set_fit_text(f"fit: drag \u221d U<sup>{n:.2f}</sup>")
        else:
            self.fit_line.setData([], [])
            self._set_fit_text("fit: needs speeds 1.5\u00d7 apart" if len(us) else
                               f"fit: hold a speed {History.SETTLE_STEPS} steps")
        self.fitted_exponent = n
        self.lift_views.draw_published_drag(self.sim, us)
        self._set_speed_ranges(us, fs)

    def fit_text(self) -> str:
        """The fit's entry in the legend (the exponent, or what the fit still needs)."""
        for sample, label in self.legend.items:
            if sample.item is self.fit_line:
                return label.text
        return ""

    def _set_fit_text(self, text):
        """The fit's result stands in the legend beside its line, not in the bar above the plot
        (there it made the window at least 1175 pixels wide)."""
        for sample, label in self.legend.items:
            if sample.item is self.fit_line and label.text != text:
                label.setText(text, bold=True, size="11pt")

    def _set_speed_ranges(self, us, fs):
        """Log-log ranges around the points (a factor 1.5 in speed, 2 in drag beyond them): with
        one point or none, pyqtgraph's auto-range spans 1e-300 to 1e300."""
        if not self._following():
            return
        us, fs = np.asarray(us, float), np.asarray(fs, float)
        x = (us.min() / 1.5, us.max() * 1.5) if us.size else (0.01, 0.1)
        y = (fs.min() / 2, fs.max() * 2) if fs.size else (1e-3, 1e-1)
        self.plot.setXRange(math.log10(x[0]), math.log10(x[1]), padding=0)   # log mode: log10 values
        self.plot.setYRange(math.log10(y[0]), math.log10(y[1]), padding=0)

    # --- export ---------------------------------------------------------------------------
    def csv_text(self) -> str:
        """The forces CSV (app/model/readouts.py `forces_table`: the probes' columns joined on
        the step, SI columns where the units shown are SI)."""
        sim = self.sim
        return readouts.forces_table(sim.history, FORCE_MODELS, sim.reference_length(), self.probes, self.units)

    def export_csv(self, path):
        write_text_atomic(path, self.csv_text())

    def export_png(self, path):
        exporter = pyqtgraph.exporters.ImageExporter(self.plot.plotItem)
        with atomic_path(path, suffix=".png") as tmp:
            exporter.export(str(tmp))
