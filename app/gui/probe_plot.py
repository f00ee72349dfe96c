"""The probes' plot beside the forces: each probe's speed, velocity component or pressure
against time, one colour per probe (the colour of its mark in the view). Draws only: the
series are app/model/probes.py's, the units app/model/readouts.py's `Units`."""
from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt
from PySide6.QtGui import QColor
from PySide6.QtWidgets import QComboBox, QHBoxLayout, QLabel, QVBoxLayout, QWidget

#: one colour per probe, in order (the view's marks use the same)
PROBE_COLOURS = ((255, 150, 0), (0, 190, 190), (230, 60, 200), (120, 200, 40))
#: quantity key -> (menu text, what is plotted)
QUANTITIES = {"speed": "Speed |u|", "ux": "Velocity u_x (along the tunnel)", "uy": "Velocity u_y (across)",
              "p": "Pressure p - p\u221e"}


def probe_colour(k: int) -> QColor:
    return QColor(*PROBE_COLOURS[k % len(PROBE_COLOURS)])


class ProbePlot(QWidget):
    """`probes` (app.model.probes.Probes) and `units` (None: lattice units) are set by the window."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.probes = None
        self.units = None
        col = QVBoxLayout(self)
        col.setContentsMargins(0, 0, 0, 0)
        row = QHBoxLayout()
        self.quantity = QComboBox()
        for key, text in QUANTITIES.items():
            self.quantity.addItem(text, key)
        self.quantity.currentIndexChanged.connect(lambda _=0: self.refresh(force=True))
        self.hint = QLabel("View > Place probes, then click in the flow")
        self.hint.setWordWrap(True)
        self.hint.setMinimumWidth(40)
        self.quantity.setMinimumContentsLength(8)
        self.quantity.setSizeAdjustPolicy(QComboBox.AdjustToMinimumContentsLengthWithIcon)
        row.addWidget(self.quantity)
        row.addWidget(self.hint, 1)
        col.addLayout(row)
        self.plot = pg.PlotWidget(background="w")
        self.plot.showGrid(x=True, y=True, alpha=0.3)
        for ax in ("bottom", "left"):
            self.plot.getAxis(ax).enableAutoSIPrefix(False)   # the unit is in the label
        self.legend = self.plot.addLegend(offset=(10, 5))
        col.addWidget(self.plot, 1)
        self._curves = []
        self._key = None
        self.refresh(force=True)

    def axis_labels(self) -> tuple[str, str]:
        key = self.quantity.currentData()
        u = self.units
        if key == "p":
            y = f"pressure p - p\u221e ({u.pressure_unit if u else 'lattice units'})"
        else:
            y = f"{QUANTITIES[key].split(' (')[0].lower()} ({u.speed_unit if u else 'cells/step'})"
        x = f"time ({u.time_unit if u else 'solver steps'})"
        return x, y

    def series(self, probe) -> tuple[np.ndarray, np.ndarray]:
        """(time, values) of one probe for the chosen quantity, in the plot's units."""
        key = self.quantity.currentData()
        t = np.asarray(probe.time, float)
        values = {"speed": probe.speed, "ux": np.asarray(probe.ux, float), "uy": np.asarray(probe.uy, float),
                  "p": np.asarray(probe.p, float)}[key]
        u = self.units
        if u is not None:
            t = u.time(t)
            values = u.pressure(values) if key == "p" else u.speed(values)
        return t, values

    def refresh(self, force: bool = False):
        probes = list(self.probes) if self.probes is not None else []
        key = (len(probes), self.quantity.currentData(), id(self.units))
        if force or key != self._key:
            self.plot.clear()
            self.legend.clear()
            self._curves = [self.plot.plot([], [], pen=pg.mkPen(probe_colour(k), width=2), name=f"probe {k + 1}")
                            for k in range(len(probes))]
            x, y = self.axis_labels()
            self.plot.setLabel("bottom", x)
            self.plot.setLabel("left", y)
            self._key = key
            self.hint.setVisible(not probes)
        for curve, probe in zip(self._curves, probes):
            t, v = self.series(probe)
            curve.setData(t, v, connect="finite")

    def traces(self) -> list:
        """The plotted curves' data (tests): [(x, y)] per probe."""
        return [c.getData() for c in self._curves]
