"""The seed report's plots: pyqtgraph, offscreen, exported as PNG next to the report."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from feelflow.app.reports.plot_images import export_png, offscreen_pyqtgraph
from feelflow.app.reports.seed_analysis import PLOT_SMOOTH_STEPS, fmt, force_series, running_mean
from feelflow.app.reports.seed_runs import MODELS, REFERENCE

COLOURS = {"momentum_exchange": (0, 90, 200), "momentum_exchange_classic": (200, 60, 0),
           "macroscopic": (0, 150, 60), "pressure": (150, 0, 150)}


def _plot(pg, title, xlabel, ylabel, size=(900, 520)):
    w = pg.PlotWidget()
    w.resize(*size)
    w.setTitle(title, size="11pt")
    w.setLabel("bottom", xlabel)
    w.setLabel("left", ylabel)
    w.showGrid(x=True, y=True, alpha=0.3)
    w.addLegend(offset=(10, 10))
    return w


def make_plots(parts: dict, res: dict, folder: Path) -> list[str]:
    pg = offscreen_pyqtgraph()
    folder.mkdir(parents=True, exist_ok=True)
    names = []
    dash = {"d16": pg.QtCore.Qt.PenStyle.SolidLine, "d24": pg.QtCore.Qt.PenStyle.DashLine,
            "d32": pg.QtCore.Qt.PenStyle.DotLine}
    dcol = {"d16": (0, 90, 200), "d24": (200, 60, 0), "d32": (0, 150, 60)}
    if "protocol" in parts:
        runs = parts["protocol"]["runs"]
        for m in MODELS:
            w = _plot(pg, f"{m}: F_x over the seed protocol (stop | with | stop | against), "
                          f"running mean over {PLOT_SMOOTH_STEPS} steps", "step", "F_x (lattice units per step)")
            curves = []
            for key, run in runs.items():
                steps, fx = running_mean(run, m, PLOT_SMOOTH_STEPS)
                curves.append(fx)
                w.plot(steps, fx, pen=pg.mkPen(dcol[key], width=2, style=dash[key]),
                       name=f"D = {run['reference_length']:g}")
            vals = np.concatenate(curves)
            if vals.size:  # the start of each moving phase is a spike: show the plateaus
                lo, hi = np.percentile(vals, [3, 97])
                pad = 0.15 * (hi - lo) + 1e-12
                w.setYRange(lo - pad, hi + pad)
            first = next(iter(runs.values()))
            for b in np.cumsum(first["phases"])[:-1]:
                w.addItem(pg.InfiniteLine(pos=float(b), angle=90,
                                          pen=pg.mkPen((120, 120, 120), style=pg.QtCore.Qt.PenStyle.DashLine)))
            name = f"protocol_{m}.png"
            export_png(w, w.getPlotItem(), folder / name)
            names.append(name)
    if "sweep" in res:
        w = _plot(pg, "Plate drag against speed (log-log), fitted F ~ U^n", "inflow speed U (lattice units)",
                  "|F_x| (lattice units per step)")
        w.setLogMode(True, True)
        for m in MODELS:
            s = res["sweep"][m]
            x, y = np.asarray(s["speeds"]), np.abs(np.asarray(s["drag"]))
            ok = y > 0
            w.plot(x[ok], y[ok], pen=None, symbol="o", symbolBrush=COLOURS[m], symbolPen=COLOURS[m],
                   name=f"{m}: n = {fmt(s['exponent'])}")
            if math.isfinite(s["exponent"]):
                xx = np.linspace(x.min(), x.max(), 20)
                w.plot(xx, s["prefactor"] * xx ** s["exponent"], pen=pg.mkPen(COLOURS[m], width=1))
        export_png(w, w.getPlotItem(), folder / "drag_vs_speed.png")
        names.append("drag_vs_speed.png")
    if "shapes" in res:
        w = _plot(pg, "Drag coefficient per shape (same frontal width 24, Re 200)", "shape",
                  "C_D = 2 F_x / (rho U^2 W)")
        keys = list(res["shapes"][REFERENCE])
        for j, m in enumerate(MODELS):
            cds = [res["shapes"][m][k]["cd"] for k in keys]
            bars = pg.BarGraphItem(x=np.arange(len(keys)) + (j - 1.5) * 0.2, height=cds, width=0.18, brush=COLOURS[m])
            w.addItem(bars)
            w.plotItem.legend.addItem(bars, m)
        w.getAxis("bottom").setTicks([[(i, k) for i, k in enumerate(keys)]])
        export_png(w, w.getPlotItem(), folder / "drag_per_shape.png")
        names.append("drag_per_shape.png")
    if "lift" in parts:
        w = _plot(pg, "Half airfoil, flat side down: lift F_y against time", "step", "F_y (lattice units per step)")
        run = parts["lift"]["runs"]["half_airfoil"]
        for m in MODELS:
            w.plot(run["step"], force_series(run, m)[:, 1], pen=pg.mkPen(COLOURS[m], width=2), name=m)
        export_png(w, w.getPlotItem(), folder / "lift.png")
        names.append("lift.png")
    return names
