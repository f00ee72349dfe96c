"""The polar and the surface pressure as images: pyqtgraph, offscreen, written atomically as PNG.

One image of three panels: C_L against alpha with the thin-airfoil line (labelled for what it
is: inviscid theory, valid at high Re), C_D against alpha, and C_L against C_D (the drag polar).
A second, optional image: C_p against x / c (or theta for a cylinder), upper and lower side, one
curve per angle, drawn with -C_p upwards as aerodynamicists do.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from feelflow.app.model.polar import thin_airfoil_cl
from feelflow.app.reports.plot_images import export_png, offscreen_pyqtgraph

#: colours of successive curves (angles) in the C_p image
PALETTE = [(0, 90, 200), (200, 60, 0), (0, 150, 60), (150, 0, 150), (180, 140, 0), (0, 150, 170),
           (120, 60, 20), (90, 90, 90)]


def _plain_axes(plot_item):
    """Coefficients as they are: no SI prefix (x0.001) on the axes."""
    for name in ("left", "bottom"):
        plot_item.getAxis(name).enableAutoSIPrefix(False)


def polar_image(points, path: Path, title: str, zero_lift_alpha: float = 0.0) -> None:
    """Write the three-panel polar (module docstring) of `points` (app/model/polar.PolarPoint)."""
    pg = offscreen_pyqtgraph()
    win = pg.GraphicsLayoutWidget()
    win.resize(1500, 520)
    win.addLabel(title, row=0, col=0, colspan=3, size="11pt")
    alpha = np.array([p.alpha for p in points])
    cl = np.array([p.cl for p in points])
    cd = np.array([p.cd for p in points])
    std = np.array([p.cl_std for p in points])
    blue, red, grey = (0, 90, 200), (200, 60, 0), (110, 110, 110)

    p1 = win.addPlot(row=1, col=0, title="lift against angle of attack")
    p1.addLegend(offset=(10, 10))
    p1.showGrid(x=True, y=True, alpha=0.3)
    p1.setLabel("bottom", "alpha (degrees)")
    p1.setLabel("left", "C_L")
    _plain_axes(p1)
    if alpha.size:
        a = np.linspace(min(alpha.min(), 0.0), max(alpha.max(), 1.0), 50)
        p1.plot(a, thin_airfoil_cl(a, zero_lift_alpha), pen=pg.mkPen(grey, width=2, style=pg.QtCore.Qt.PenStyle.DashLine),
                name="thin-airfoil theory 2 pi (alpha - alpha_0): inviscid, high Re")
        p1.addItem(pg.ErrorBarItem(x=alpha, y=cl, height=2 * std, pen=pg.mkPen(blue, width=1)))
        p1.plot(alpha, cl, pen=pg.mkPen(blue, width=2), symbol="o", symbolBrush=blue, symbolPen=blue,
                name="measured (bars: C_L's swing, +- 1 std)")

    p2 = win.addPlot(row=1, col=1, title="drag against angle of attack")
    p2.showGrid(x=True, y=True, alpha=0.3)
    p2.setLabel("bottom", "alpha (degrees)")
    p2.setLabel("left", "C_D")
    _plain_axes(p2)
    if alpha.size:
        p2.plot(alpha, cd, pen=pg.mkPen(red, width=2), symbol="o", symbolBrush=red, symbolPen=red)

    p3 = win.addPlot(row=1, col=2, title="drag polar: C_L against C_D")
    p3.showGrid(x=True, y=True, alpha=0.3)
    p3.setLabel("bottom", "C_D")
    p3.setLabel("left", "C_L")
    _plain_axes(p3)
    if alpha.size:
        p3.plot(cd, cl, pen=pg.mkPen(blue, width=2), symbol="o", symbolBrush=blue, symbolPen=blue)
        for a_, x_, y_ in zip(alpha, cd, cl):
            label = pg.TextItem(f"{a_:g} deg", color=grey, anchor=(0, 1))
            label.setPos(float(x_), float(y_))
            p3.addItem(label)
    export_png(win, win.scene(), Path(path), 1500)


def cp_image(curves, path: Path, title: str) -> None:
    """Write C_p along the surface: `curves` is a list of (label, SurfacePressure)."""
    pg = offscreen_pyqtgraph()
    w = pg.PlotWidget()
    w.resize(900, 560)
    w.setTitle(title, size="11pt")
    w.addLegend(offset=(10, 10))
    w.showGrid(x=True, y=True, alpha=0.3)
    coordinate = curves[0][1].coordinate if curves else "x/c"
    w.setLabel("bottom", "theta from the front (degrees)" if coordinate == "theta" else "x / c")
    w.setLabel("left", "C_p (upper side solid, lower side dashed)")
    _plain_axes(w.getPlotItem())
    w.getPlotItem().invertY(coordinate != "theta")   # airfoils: suction (negative C_p) upwards
    for k, (label, cp) in enumerate(curves):
        colour = PALETTE[k % len(PALETTE)]
        for side, style in (("upper", pg.QtCore.Qt.PenStyle.SolidLine), ("lower", pg.QtCore.Qt.PenStyle.DashLine)):
            x, y = getattr(cp, side)
            w.plot(x, y, pen=pg.mkPen(colour, width=2, style=style), name=label if side == "upper" else None)
    export_png(w, w.scene(), Path(path), 900)
