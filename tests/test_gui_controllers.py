"""The window's controllers are built from their parts, without the window (Xvfb, real Qt
widgets, the numpy solver): the frame loop, the replay, probe, units and flow controllers made
from the events, the widgets and one another, as MainWindow makes them; the live tunnel reaches
them through `events.liveCreated`, and a change of the flow through the flow controller
reaches the model and the others through the events alone."""
from __future__ import annotations

import pytest

pytestmark = pytest.mark.gui


def test_the_flow_controller_works_without_the_window(qtbot, tmp_path):
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QLabel, QMainWindow, QStatusBar

    from feelflow.app.gui.force_plot import ForcePlot
    from feelflow.app.gui.side_panel import SidePanel
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.gui.window.flow import FlowController
    from feelflow.app.gui.window.field_display import FieldDisplay
    from feelflow.app.gui.window.flow_overlays import FlowOverlays
    from feelflow.app.gui.window.frame_loop import FrameLoop
    from feelflow.app.gui.window.frame_rates import FrameRates
    from feelflow.app.gui.window.frame_readouts import FrameReadouts
    from feelflow.app.gui.window.probes import ProbeController
    from feelflow.app.gui.window.replay_controller import ReplayController
    from feelflow.app.gui.window.units import UnitsController
    from feelflow.app.model.simulation import Params, Simulation

    host = QMainWindow()   # the parent of the dialogs, timers and the probes' dock; holds the viewport
    qtbot.addWidget(host)
    events, viewport, panel, plot, status = WindowEvents(host), Viewport(), SidePanel(), ForcePlot(), QStatusBar()
    labels = {k: QLabel() for k in ("steps", "mlups", "fps", "re", "ma", "operator")}
    params = Params(grid=(96, 48), size=8.0)
    display = FieldDisplay(viewport, panel, lambda: params, lambda: None)
    rates = FrameRates()
    loop = FrameLoop(events, viewport, plot, display, FlowOverlays(viewport, display),
                     FrameReadouts(events, panel, plot, labels, display, rates), rates, status, lambda: None, host)
    probes = ProbeController(events, viewport, plot, loop, status, host)
    units = UnitsController(events, QSettings(str(tmp_path / "s.ini"), QSettings.IniFormat), panel, plot, probes,
                            loop, status, host)
    replays = ReplayController(events, viewport, loop, panel, probes, units, status, lambda: None, lambda: "numpy",
                               host)
    flow = FlowController(events, viewport, loop, panel, plot, replays, status, lambda: None, host)
    changed = []
    events.flowChanged.connect(lambda: changed.append(True))

    flow.apply(wind=0.06)   # before the tunnel exists: nothing happens
    assert changed == []
    host.setCentralWidget(viewport)
    host.show()   # the viewport makes its GL context when it first shows
    qtbot.waitUntil(lambda: viewport.ctx is not None, timeout=20000)
    sim = Simulation(params)
    events.liveCreated.emit(sim)
    events.shownChanged.emit(sim)
    assert flow.sim is sim and replays.shown is sim and loop.shown is sim and plot.sim is sim
    flow.apply(wind=0.06)
    assert sim.params.wind == pytest.approx(0.06) and changed == [True]
    sim.advance(4)
    loop.readouts.refresh()   # the panel, the plot and the status bar's numbers from the model
    assert labels["re"].text() == f"Re {sim.reynolds():.0f}" and labels["operator"].text() == sim.operator_line()
