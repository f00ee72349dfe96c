"""The Presets menu: a lesson loads its scene file (scenes/presets/) and sets the window up as
the lesson needs (app/model/presets.py): hold still or not, a wind sweep, the display mode and
the plot's view."""
from __future__ import annotations

from typing import TYPE_CHECKING

from feelflow.app.model.presets import PRESETS
from feelflow.shapes.base import ShapeError
from feelflow.solver.config import ConfigError

if TYPE_CHECKING:
    from collections.abc import Callable

    from PySide6.QtGui import QUndoStack
    from PySide6.QtWidgets import QStatusBar

    from feelflow.app.gui.force_plot import ForcePlot
    from feelflow.app.gui.side_panel import SidePanel
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.bodies import BodyController
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.gui.window.flow import FlowController
    from feelflow.app.gui.window.frame_loop import FrameLoop
    from feelflow.app.gui.window.replay_controller import ReplayController
    from feelflow.app.model.simulation import Simulation


class LessonController:
    """Starts lessons in the live tunnel."""

    def __init__(self, events: "WindowEvents", viewport: "Viewport", loop: "FrameLoop", panel: "SidePanel",
                 plot: "ForcePlot", undo: "QUndoStack", replays: "ReplayController", flow: "FlowController",
                 bodies: "BodyController", status: "QStatusBar", make_current: "Callable[[], None]"):
        self.viewport, self.loop, self.panel, self.plot, self.undo = viewport, loop, panel, plot, undo
        self.replays, self.flow, self.bodies = replays, flow, bodies
        self.status, self.make_current = status, make_current
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        events.liveCreated.connect(self._live_created)

    def _live_created(self, sim):
        self.sim = sim

    def apply(self, key) -> bool:
        """Load the lesson's scene file and set the window up as the lesson needs."""
        from feelflow.app.errors import UserError
        from feelflow.app.model.scene import load_scene

        lesson = PRESETS[key]
        if self.sim is None or self.replays.refuse("lessons run in the live tunnel"):
            return False
        try:
            scene = load_scene(lesson.path)
            self.make_current()
            self.sim.load_scene(scene)
        except (UserError, ConfigError, ShapeError, ValueError) as exc:
            self.flow.refuse_dialog("This lesson cannot run here", exc)
            return False
        self.undo.clear()   # the lesson replaces the body and its pose: earlier edits and turns do not apply
        self.bodies.set_hold_still(lesson.hold_still and self.sim.runner is None)
        if lesson.wind_sweep:
            self.sim.start_sweep(lesson.wind_sweep, lesson.hold_steps)
        if lesson.angle_sweep:
            self.sim.start_polar(lesson.angle_sweep)
        self.loop.display.set_mode(lesson.display)
        self.plot.view.setCurrentIndex(self.plot.view.findData(lesson.plot_view))
        self.viewport.tracers = None
        self.panel.show_params(self.sim.params, self.loop.display.mode)
        self.flow.after_rebuild()
        self.loop.set_paused(False)
        self.status.showMessage(f"{lesson.title}: {lesson.note}", 20000)
        return True
