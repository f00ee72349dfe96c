"""Probes in the window: View > Place probes turns clicks in the view into probes (left click
places one, right click removes the nearest); each frame the probes sample the field the frame
loop already has (app/model/probes.py), and the probes' plot beside the forces shows their
series (app/gui/probe_plot.py). The forces CSV carries their columns (app/gui/force_export.py)."""
from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import Qt, QTimer
from PySide6.QtWidgets import QDockWidget

from feelflow.app.gui.probe_plot import ProbePlot, probe_colour
from feelflow.app.model import readouts
from feelflow.app.model.probes import Probes

if TYPE_CHECKING:
    from PySide6.QtWidgets import QMainWindow, QStatusBar

    from feelflow.app.gui.force_plot import ForcePlot
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.gui.window.frame_loop import FrameLoop
    from feelflow.app.model.tunnel import TunnelModel

PLOT_REFRESH_MS = 250
PLACING_HINT = "Click in the flow to place a probe (up to 4); right-click one to remove it. View > Place probes ends this."


class ProbeController:
    def __init__(self, events: "WindowEvents", viewport: "Viewport", forces_plot: "ForcePlot",
                 loop: "FrameLoop", status: "QStatusBar", docks: "QMainWindow"):
        """`forces_plot`: the force plot the probes' dock goes beside; `docks`: the main window
        that holds the docks (and the timer)."""
        self.events, self.viewport, self.forces_plot, self.loop = events, viewport, forces_plot, loop
        self.status, self.docks = status, docks
        self.probes = Probes()
        self.plot = ProbePlot()
        self.plot.probes = self.probes
        self.dock = None
        self.timer = QTimer(docks)
        self.timer.setInterval(PLOT_REFRESH_MS)
        self.timer.timeout.connect(self.plot.refresh)
        events.shownChanged.connect(self.model_changed)
        events.fieldShown.connect(self.sample_frame)

    def _ensure_dock(self):
        if self.dock is not None:
            return
        w = self.docks
        self.dock = QDockWidget("Probes", w)
        self.dock.setObjectName("probe_dock")
        self.dock.setWidget(self.plot)
        self.dock.setFeatures(QDockWidget.DockWidgetMovable | QDockWidget.DockWidgetClosable)
        forces = self.forces_plot.parentWidget()
        if isinstance(forces, QDockWidget):
            w.splitDockWidget(forces, self.dock, Qt.Horizontal)   # beside the forces, same height
        else:
            w.addDockWidget(Qt.BottomDockWidgetArea, self.dock)

    # --- placing ------------------------------------------------------------------------------
    def set_placing(self, on: bool):
        self.viewport.probing = bool(on)
        self.events.probesPlacing.emit(bool(on))
        if on:
            self._ensure_dock()
            self.dock.show()
            self.status.showMessage(PLACING_HINT, 20000)
        elif self.status.currentMessage() == PLACING_HINT:
            self.status.clearMessage()
        self.viewport.setCursor(Qt.CrossCursor if on else Qt.ArrowCursor)

    def clicked(self, x: float, y: float, remove: bool):
        model = self.loop.shown
        if model is None:
            return
        if remove:
            self.probes.remove_near(x, y, radius=max(2.0, 12.0 * model.config.nx / max(1, self.viewport.lattice_rect().width())))
        else:
            try:
                self.probes.add(x, y, model.config.nx, model.config.ny)
            except ValueError as exc:
                self.status.showMessage(str(exc), 6000)
                return
        self._ensure_dock()
        self.dock.show()
        self.show_marks()
        self.plot.refresh(force=True)
        self.timer.start()

    def add(self, x: float, y: float):
        """A probe at (x, y) cells, as a click there places it."""
        self.clicked(x, y, False)

    def clear(self):
        self.probes.clear()
        self.show_marks()
        self.plot.refresh(force=True)

    def show_marks(self):
        self.viewport.probe_marks = [(p.x, p.y, probe_colour(k), str(k + 1)) for k, p in enumerate(self.probes)]
        self.viewport.update()

    # --- each frame ---------------------------------------------------------------------------
    def sample_frame(self, field):
        """Sample every probe from this frame's field: `field` is the (ny, nx, 4) array or a
        callable that reads it back (the gl path reads it only when there are probes)."""
        if not len(self.probes):
            return
        model = self.loop.shown
        if model is None:
            return
        rgba = field() if callable(field) else field
        if rgba is None:
            return
        times = model.history.time   # the forces' sample of this frame: the CSV joins on it
        self.probes.sample(times[-1] if times else model.solver.time, rgba, readouts.free_stream_density(rgba))

    def session_arrays(self) -> dict | None:
        """The probes and their series for a session file (None without probes)."""
        return self.probes.to_arrays() if len(self.probes) else None

    def model_changed(self, model: "TunnelModel"):
        """A replay started or stopped: the series start again at its steps; a session that
        was recorded with probes puts them back where they stood."""
        session = model.replayed_session()
        arrays = session.probes if session is not None else None
        if arrays is not None:
            restored = Probes.from_arrays(arrays)
            self.probes.items[:] = restored.items
        self.probes.clear_series()
        self.show_marks()
        if len(self.probes):
            self._ensure_dock()
            self.dock.show()
            self.timer.start()
        self.plot.refresh(force=True)
