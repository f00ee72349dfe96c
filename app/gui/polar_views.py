"""The force plot's lift views (widgets draw; the numbers come from app/model/live_polar.py and
app/model/published.py): the polar (C_L and C_D against the angle of attack, with the
thin-airfoil line), the drag polar (C_L against C_D), C_p along the surface, and the published
2D-simulation drag beside the measured drag against speed for a cylinder."""
from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt

from feelflow.app.model.polar import thin_airfoil_cl
from feelflow.app.model.published import DRAG, published_drag_force

#: view key -> (label in the view list, x axis, y axis)
VIEWS = {
    "polar": ("Polar: lift and drag against angle of attack", "angle of attack alpha (degrees)", "C_L, C_D"),
    "drag_polar": ("Drag polar: lift against drag", "C_D", "C_L"),
    "cp": ("Pressure along the surface (C_p)", "x / c (theta from the front for a cylinder)", "C_p"),
}
LIFT, DRAG_COLOUR, THEORY, LIVE = (40, 110, 240), (220, 40, 40), (120, 120, 120), (0, 160, 90)


class LiftViews:
    """Draws the lift views into `plot` (a pyqtgraph PlotWidget the force plot owns)."""

    def __init__(self, plot):
        self.plot = plot
        self.items = {}

    def reset(self):
        self.items = {}

    def _item(self, key, **style):
        if key not in self.items:
            self.items[key] = self.plot.plot([], [], **style)
        return self.items[key]

    # --- the polar --------------------------------------------------------------------------
    def draw_polar(self, sim):
        polar = sim.polar
        points = polar.sweep.points if polar is not None else []
        alpha = np.array([p.alpha for p in points])
        cl = np.array([p.cl for p in points])
        cd = np.array([p.cd for p in points])
        angles = np.asarray(polar.sweep.angles if polar is not None else (0.0, 10.0), dtype=np.float64)
        a = np.linspace(min(0.0, angles.min()), max(1.0, angles.max()), 40)
        a0 = polar.zero_lift_alpha if polar is not None else 0.0
        self._item("theory", pen=pg.mkPen(THEORY, width=2, style=Qt.DashLine),
                   name="thin-airfoil theory 2\u03c0(\u03b1 - \u03b1\u2080): inviscid, high Re").setData(
            a, thin_airfoil_cl(a, a0))
        self._item("cl", pen=pg.mkPen(LIFT, width=2.5), symbol="o", symbolBrush=LIFT, symbolPen=LIFT,
                   name="C_L measured").setData(alpha, cl)
        self._item("cd", pen=pg.mkPen(DRAG_COLOUR, width=2.5), symbol="s", symbolBrush=DRAG_COLOUR,
                   symbolPen=DRAG_COLOUR, name="C_D measured").setData(alpha, cd)
        live_a, live_cl, live_cd = self._live(polar)
        self._item("live", pen=None, symbol="o", symbolSize=7, symbolBrush=pg.mkBrush(*LIVE, 90),
                   symbolPen=None, name="now (settling)").setData(live_a, live_cl)
        self._item("live_cd", pen=None, symbol="s", symbolSize=7, symbolBrush=pg.mkBrush(*LIVE, 90),
                   symbolPen=None).setData(live_a, live_cd)

    @staticmethod
    def _live(polar):
        """The angle being held: its latest samples, at its angle."""
        if polar is None or polar.done:
            return np.array([]), np.array([]), np.array([])
        cl, cd = polar.sweep.live()
        cl, cd = cl[-20:], cd[-20:]
        return np.full(len(cl), polar.sweep.angle), cl, cd

    def draw_drag_polar(self, sim):
        polar = sim.polar
        points = polar.sweep.points if polar is not None else []
        self._item("polar", pen=pg.mkPen(LIFT, width=2.5), symbol="o", symbolBrush=LIFT, symbolPen=LIFT,
                   name="C_L against C_D, one point per angle").setData(
            np.array([p.cd for p in points]), np.array([p.cl for p in points]))
        _, live_cl, live_cd = self._live(polar)
        self._item("live", pen=None, symbol="o", symbolSize=7, symbolBrush=pg.mkBrush(*LIVE, 90),
                   symbolPen=None, name="now (settling)").setData(live_cd, live_cl)

    # --- C_p ----------------------------------------------------------------------------------
    def draw_cp(self, cp):
        """`cp`: a SurfacePressure or None (nothing sampled yet)."""
        empty = np.array([])
        upper = cp.upper if cp is not None else (empty, empty)
        lower = cp.lower if cp is not None else (empty, empty)
        self._item("upper", pen=pg.mkPen(LIFT, width=2.5), name="upper side").setData(*upper)
        self._item("lower", pen=pg.mkPen(DRAG_COLOUR, width=2.5, style=Qt.DashLine), name="lower side").setData(*lower)
        airfoil = cp is not None and cp.coordinate == "x/c"
        self.plot.getPlotItem().invertY(airfoil)   # airfoils: suction (negative C_p) upwards, as in aerodynamics
        self.plot.getAxis("bottom").setLabel("x / c" if cp is None or airfoil else "theta from the front (degrees)")

    # --- published drag against speed -----------------------------------------------------------
    def draw_published_drag(self, sim, speeds):
        """The published 2D C_D(Re) as drag at the measured speeds' range (cylinders only)."""
        item = self._item("published", pen=pg.mkPen((60, 60, 60), width=2, style=Qt.DotLine),
                          name="2D simulations: " + "; ".join(s.label.split(" (")[0] for s in DRAG))
        if sim.shape is None or sim.shape.kind != "cylinder" or len(speeds) == 0:
            item.setData([], [])
            return
        u = np.geomspace(max(min(speeds) / 1.5, 1e-4), max(speeds) * 1.5, 40)
        us, fs = published_drag_force(u, sim.shape.diameter, sim.config.nu)
        item.setData(us, fs)
