"""The force plot's own views, drawn with pyqtgraph (the numbers come from
app/model/plot_series.py): each shown force model's drag and lift, or torque, against time; and
the settled drag against relative speed on log-log axes with the fitted power law in the legend
(the U^2 lesson: at low Re, C_D falls as Re grows, so drag grows slower than U^2). The lift
views are app/gui/polar_views.py."""
from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt

from feelflow.app.model import plot_series
from feelflow.app.model.simulation import FORCE_MODELS

MODEL_COLOURS = {"momentum_exchange": ((220, 40, 40), (40, 110, 240)),
                 "macroscopic": ((230, 140, 20), (20, 170, 190)),
                 "pressure": ((150, 60, 190), (40, 160, 60))}
OTHER_COLOURS = ((0, 0, 0), (90, 90, 90))


def reset_legend(plot, columns: int):
    """The plot keeps one legend across clear(): empty it and set its layout."""
    legend = plot.addLegend(offset=(10, 5))
    legend.clear()
    legend.setColumnCount(columns)
    return legend


class TimeViews:
    """Curves against time in `plot`: drag and lift ("time") or torque ("torque") of each
    shown model; `curves` maps (model, "drag" | "lift" | "torque") to its curve."""

    def __init__(self, plot, ranges):
        self.plot, self.ranges = plot, ranges
        self.curves = {}
        self._shown = None     # (models, compare all) the curves and legend were made for

    def reset(self):
        self.curves.clear()
        self._shown = None

    def draw(self, sim, view: str, units):
        shown = plot_series.models_shown(sim.params)
        compare = sim.params.compare_all
        if self._shown != (tuple(shown), compare):
            self._shown = (tuple(shown), compare)
            self.plot.clear()                  # curves and legend rebuilt for the new set of models
            self.curves.clear()
            reset_legend(self.plot, 3 if len(shown) > 1 else 1)
        settled = []
        for model in shown:
            drag_colour, lift_colour = MODEL_COLOURS.get(model, OTHER_COLOURS)
            if view == "torque":
                s = plot_series.torque_series(sim.history, model, sim.params.size, units)
                self._curve(model, "torque", pg.mkPen(drag_colour, width=2.5), compare).setData(
                    s.t, s.curves[0], connect="finite")
            else:
                s = plot_series.force_series(sim.history, model, sim.params.size, units)
                drag, lift = s.curves
                self._curve(model, "drag", pg.mkPen(drag_colour, width=2.5), compare).setData(
                    s.t, drag, connect="finite")
                lift_style = Qt.DashLine if len(shown) > 1 else Qt.SolidLine
                self._curve(model, "lift", pg.mkPen(lift_colour, width=2.5, style=lift_style), compare).setData(
                    s.t, lift, connect="finite")
            settled.append(s.settled)
        self.ranges.set_y(plot_series.force_axis_range(np.concatenate(settled) if settled else []))

    def _curve(self, model, what, pen, compare_all):
        key = (model, what)
        if key not in self.curves:
            name = what if not compare_all else f"{what}, {FORCE_MODELS[model].split(' (')[0].lower()}"
            self.curves[key] = self.plot.plot([], [], pen=pen, name=name)
        return self.curves[key]


class SpeedView:
    """The log-log view of the settled drag against relative speed: `scatter` (the points),
    `fit_line`, and the fit's words in the legend beside its line; `fitted_exponent` is the
    last fit's n (None until the speeds span a factor 1.5)."""

    def __init__(self, plot, ranges):
        self.plot, self.ranges = plot, ranges
        self.scatter = self.fit_line = None
        self.fitted_exponent = None

    def install(self):
        """Make the view's items, in the plot's legend (PlotDataItems: the log mode transforms
        them, bare scatter items it does not)."""
        self.scatter = self.plot.plot([], [], pen=None, symbol="o", symbolSize=10,
                                      symbolBrush=pg.mkBrush(220, 40, 40), symbolPen=pg.mkPen("k"),
                                      name="mean drag at one speed")
        self.fit_line = self.plot.plot([], [], pen=pg.mkPen((40, 40, 40), width=2, style=Qt.DashLine),
                                       name="fit")
        self.ranges.set_log(*plot_series.log_ranges([], []))

    def draw(self, sim, units, lift_views):
        fit = plot_series.speed_fit(sim.history, sim.params.force_model, units)
        self.scatter.setData(fit.speeds, fit.drags)
        self.fit_line.setData(*fit.line)
        self._set_fit_text(fit.text)
        self.fitted_exponent = fit.exponent
        lift_views.draw_published_drag(sim, fit.speeds)
        self.ranges.set_log(*plot_series.log_ranges(fit.speeds, fit.drags))

    def fit_text(self) -> str:
        """The fit's entry in the legend (the exponent, or what the fit still needs)."""
        for sample, label in self._legend_items():
            if sample.item is self.fit_line:
                return label.text
        return ""

    def _legend_items(self):
        legend = self.plot.getPlotItem().legend
        return legend.items if legend is not None else []

    def _set_fit_text(self, text):
        """The fit's result stands in the legend beside its line, not in the bar above the plot
        (there it made the window at least 1175 pixels wide)."""
        for sample, label in self._legend_items():
            if sample.item is self.fit_line and label.text != text:
                label.setText(text, bold=True, size="11pt")
