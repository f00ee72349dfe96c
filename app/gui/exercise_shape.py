"""The student's shape in an exercise: the polygon edited in the tunnel, or the built-in body
(cylinder, plate, wedge, half airfoil) the exercise panel's parameter fields describe; and
putting a shape (the exercise's start shape, a loaded attempt) into the editor and the tunnel.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, Signal

from feelflow.app.exercises.shape_fields import PARAMETERS
from feelflow.shapes.base import ShapeError

if TYPE_CHECKING:
    from collections.abc import Callable

    from feelflow.app.gui.exercise_panel import ExercisePanel
    from feelflow.app.gui.side_panel import SidePanel
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.gui.window.frame_loop import FrameLoop
    from feelflow.app.model.simulation import Simulation


class StudentShape(QObject):
    """The shape the student has now and how it reaches the live tunnel. `changed`: a shape
    went into the tunnel (the constraints are checked again); `unbuildable(reason)`: the
    parameter fields describe no body."""

    changed = Signal()
    unbuildable = Signal(str)

    def __init__(self, events: "WindowEvents", panel: "ExercisePanel", side_panel: "SidePanel",
                 viewport: "Viewport", loop: "FrameLoop", make_current: "Callable[[], None]", parent=None):
        super().__init__(parent)
        self.panel, self.side_panel, self.viewport, self.loop = panel, side_panel, viewport, loop
        self.make_current = make_current
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        events.liveCreated.connect(self._live_created)
        self.param_shape = None      # the built-in body the parameter fields describe

    def _live_created(self, sim):
        self.sim = sim

    def current(self, exercise):
        """The shape the student has now for `exercise`: the edited polygon, or the parameter
        fields' body (None without an exercise)."""
        if exercise is None:
            return None
        if "polygon" in exercise.kinds and self.sim.params.shape == "polygon":
            return self.sim.shape
        return self.param_shape

    def install(self, shape) -> bool:
        """Put a shape (a start shape, a loaded attempt) into the editor and the tunnel."""
        if shape.kind in PARAMETERS:
            self.panel.shape_box.set_parameters(shape)
            return self.parameters_changed()
        self.make_current()
        self.sim.set_shape(kind="polygon", polygon=[tuple(v) for v in shape.vertices],
                           angle_deg=math.degrees(shape.angle))
        self.param_shape = None
        self._shown()
        return True

    def parameters_changed(self) -> bool:
        """Build the body from the parameter fields and show it in the tunnel (as a polygon with
        the body's exact vertices, or a cylinder)."""
        from feelflow.shapes.io import from_dict

        try:
            shape = from_dict(self.panel.shape_box.parameters())
        except ShapeError as exc:
            self.unbuildable.emit(str(exc).splitlines()[0])
            return False
        self.param_shape = shape
        try:
            self.make_current()
            if shape.kind == "cylinder":
                self.sim.set_shape(kind="cylinder", size=shape.diameter, angle_deg=math.degrees(shape.angle))
            else:
                self.sim.set_shape(kind="polygon", polygon=[tuple(v) for v in shape.local_vertices],
                                   angle_deg=math.degrees(shape.angle))
        except (ShapeError, ValueError):
            pass    # too big for the tunnel: the constraints say so
        self._shown()
        return True

    def _shown(self):
        self.side_panel.show_params(self.sim.params, self.loop.display.mode)
        self.viewport.update()
        self.changed.emit()
