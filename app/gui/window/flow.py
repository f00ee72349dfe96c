"""The flow's settings from the side panel: wind, viscosity, walls, grid and force models, and
Reset flow. Values outside the measured stable region are moved inside it by the model
(app/model/flow_choice.py `stable_params`), and the status bar says what changed.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtWidgets import QMessageBox

from feelflow.shapes.base import ShapeError
from feelflow.solver.config import ConfigError

if TYPE_CHECKING:
    from collections.abc import Callable

    from PySide6.QtWidgets import QStatusBar, QWidget

    from feelflow.app.gui.force_plot import ForcePlot
    from feelflow.app.gui.side_panel import SidePanel
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.gui.window.frame_loop import FrameLoop
    from feelflow.app.gui.window.replay_controller import ReplayController
    from feelflow.app.model.simulation import Simulation


class FlowController:
    """Changes the live tunnel's flow; refused while a replay shows."""

    def __init__(self, events: "WindowEvents", viewport: "Viewport", loop: "FrameLoop", panel: "SidePanel",
                 plot: "ForcePlot", replays: "ReplayController", status: "QStatusBar",
                 make_current: "Callable[[], None]", parent: "QWidget"):
        """`make_current`: the viewport's GL context current where the solver draws on it;
        `parent`: the dialogs' parent."""
        self.events, self.viewport, self.loop, self.panel, self.plot = events, viewport, loop, panel, plot
        self.replays, self.status, self.make_current, self.parent = replays, status, make_current, parent
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        events.liveCreated.connect(self._live_created)
        events.replayStopped.connect(self._replay_stopped)
        events.guardActed.connect(self._guard_acted)
        events.resetAsked.connect(self.reset)

    def _live_created(self, sim):
        self.sim = sim

    def _replay_stopped(self, _paused: bool):
        """Back on the live tunnel: the panel shows its parameters, the status bar its operator."""
        self.panel.show_params(self.sim.params, self.loop.display.mode)
        self.after_rebuild()

    def _guard_acted(self):
        """The local stability guard raised the viscosity: the status bar says so, the panel
        shows it, and the tunnel's followers follow."""
        self.say_guard()
        self.panel.show_params(self.sim.params, self.loop.display.mode)
        self.after_rebuild()

    def apply(self, **changes):
        """`Simulation.set_flow(**changes)` (wind, nu, wall); a bad value is a dialog."""
        if self.sim is None or self.replays.refuse("the flow follows the recording"):
            return
        self.make_current()
        try:
            self.sim.set_flow(**changes)
        except ConfigError as exc:
            self.refuse_dialog("This flow setting cannot be used", exc)
            return
        if self.say_guard():
            self.panel.show_params(self.sim.params, self.loop.display.mode)
        self.after_rebuild()

    def set_grid(self, grid):
        if self.sim is None or self.replays.refuse("the grid is the recording's"):
            return
        self.make_current()
        try:
            self.sim.set_grid(grid)
        except (ConfigError, ShapeError) as exc:
            self.refuse_dialog("This grid cannot be used", exc)
            return
        self.viewport.tracers = None
        self.after_rebuild()

    def set_force_models(self, selected=None, compare_all=None):
        if self.sim is not None and not self.replays.refuse("the scene cannot be changed"):
            self.make_current()
            self.sim.set_force_models(selected=selected, compare_all=compare_all)
            self.loop.readouts.refresh()
            self.plot.refresh(force=True)

    def reset(self, _=None):
        """Reset flow (R): the flow from its initial state, the body where it is."""
        if self.sim is None or self.replays.refuse("the flow follows the recording"):
            return
        self.make_current()
        self.sim.reset_flow()
        self.viewport.tracers = None
        self.events.flowChanged.emit()

    def say_guard(self) -> bool:
        """Show in the status bar what the stability guard changed (app/model/flow_choice.py stable_params)."""
        note = self.sim.guard_note if self.sim is not None else None
        if note:
            self.status.showMessage(note, 10000)
        return bool(note)

    def after_rebuild(self):
        """After the tunnel changed: `window.events.flowChanged` (the device's workspace, the
        field, the readouts, a redraw follow it)."""
        self.events.flowChanged.emit()

    def refuse_dialog(self, title, exc):
        """A change the model refused: one-line dialog, the panel back at the model's values."""
        QMessageBox.warning(self.parent, title, str(exc))
        self.panel.show_params(self.sim.params, self.loop.display.mode)
