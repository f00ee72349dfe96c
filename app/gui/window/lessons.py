"""The Presets menu: a lesson loads its scene file (scenes/presets/) and sets the window up as
the lesson needs (app/model/presets.py): hold still or not, a wind sweep, the display mode and
the plot's view."""
from __future__ import annotations

from typing import TYPE_CHECKING

from feelflow.app.model.presets import PRESETS
from feelflow.shapes.base import ShapeError
from feelflow.solver.config import ConfigError

if TYPE_CHECKING:
    from feelflow.app.gui.main_window import MainWindow
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.frame_loop import FrameLoop
    from feelflow.app.model.simulation import Simulation


class LessonController:
    """Starts lessons in the live tunnel."""

    def __init__(self, window: "MainWindow", viewport: "Viewport", loop: "FrameLoop"):
        self.w = window
        self.viewport = viewport
        self.loop = loop
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        window.events.liveCreated.connect(self._live_created)

    def _live_created(self, sim):
        self.sim = sim

    def apply(self, key) -> bool:
        """Load the lesson's scene file and set the window up as the lesson needs."""
        from feelflow.app.errors import UserError
        from feelflow.app.model.scene import load_scene

        w = self.w
        lesson = PRESETS[key]
        if self.sim is None or w.replays.refuse("lessons run in the live tunnel"):
            return False
        try:
            scene = load_scene(lesson.path)
            w.make_current()
            self.sim.load_scene(scene)
        except (UserError, ConfigError, ShapeError, ValueError) as exc:
            w.flow.refuse_dialog("This lesson cannot run here", exc)
            return False
        w.undo.clear()   # the lesson replaces the body and its pose: earlier edits and turns do not apply
        w.bodies.set_hold_still(lesson.hold_still and self.sim.runner is None)
        if lesson.wind_sweep:
            self.sim.start_sweep(lesson.wind_sweep, lesson.hold_steps)
        if lesson.angle_sweep:
            self.sim.start_polar(lesson.angle_sweep)
        self.loop.set_display_mode(lesson.display)
        w.plot.view.setCurrentIndex(w.plot.view.findData(lesson.plot_view))
        self.viewport.tracers = None
        w.panel.show_params(self.sim.params, self.loop.display_mode)
        w.flow.after_rebuild()
        self.loop.set_paused(False)
        w.statusBar().showMessage(f"{lesson.title}: {lesson.note}", 20000)
        return True
