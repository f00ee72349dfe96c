"""The flow overlays drawn over the field: the tracers carried by the flow (app/model/tracers.py)
and the drag and lift arrows and the torque arc of this frame's force (app/model/readouts.py).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from feelflow.app.model import readouts
from feelflow.app.model.tracers import Tracers

if TYPE_CHECKING:
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.field_display import FieldDisplay

N_TRACERS = 900


class FlowOverlays:
    """Holds the tracers and sets the viewport's tracers, force arrows and torque arc."""

    def __init__(self, viewport: "Viewport", display: "FieldDisplay"):
        """`display`: the model shown, its display mode and its field."""
        self.viewport, self.display = viewport, display
        self.tracers = Tracers(N_TRACERS)

    def clear(self):
        """No overlay until the next frame (the model shown changed)."""
        vp = self.viewport
        vp.tracers = vp.arrow_forces = vp.torque_arc = None

    def after_frame(self, rgba, n: int, forces):
        """After n steps: the tracers (where shown) and the arrows for this frame's `forces`;
        `rgba`: the field array, or None where it stayed in a texture."""
        if self.display.mode == "tracers":
            self.advance_tracers(rgba, n)
        self.update_arrows(forces)

    def update_arrows(self, forces):
        """The viewport's drag and lift arrows for this frame's force (app/model/readouts.py)."""
        model = self.display.shown
        self.viewport.arrow_forces = readouts.arrows(forces.get(model.params.force_model), model.relative_wind(),
                                                     model.reference_length())
        self.viewport.torque_arc = readouts.torque_arc(model.last_torques.get(model.params.force_model),
                                                       model.params.size, model.config.max_speed)

    def advance_tracers(self, rgba, n: int):
        """Move the viewport's tracers n steps through the field (app/model/tracers.py)."""
        model, vp = self.display.shown, self.viewport
        if rgba is None:
            rgba = self.display.field_array()
        vp.tracers = self.tracers.advance(rgba, n, model.shape, None if vp.tracers is None else vp.tracers[0])
