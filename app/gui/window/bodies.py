"""Editing the body: its kind and size, holding it still, the polygon editor (undoable edits on
the window's QUndoStack) and turning it with the viewport's handle, the mouse wheel or the
panel's angle box (each turn one undo step; app/gui/turn_handle.py, app/gui/shape_editor.py).

A turn while the flow runs is body input: it reaches the model as `BodyInput.turn`, and the
body swings there through the angle spring. Paused or held still, the body turns at once, as
an edit of its shape.
"""
from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

from PySide6.QtWidgets import QMessageBox

from feelflow.app.gui.shape_editor import SetPolygon
from feelflow.app.gui.turn_handle import TurnBody
from feelflow.app.model.bodies import default_polygon
from feelflow.app.model.body_input import BodyInput
from feelflow.app.model.simulation import wrap_degrees
from feelflow.shapes.base import ShapeError
from feelflow.solver.config import ConfigError

if TYPE_CHECKING:
    from collections.abc import Callable

    from PySide6.QtGui import QUndoStack
    from PySide6.QtWidgets import QStatusBar, QWidget

    from feelflow.app.gui.side_panel import SidePanel
    from feelflow.app.gui.viewport import Viewport
    from feelflow.app.gui.window.events import WindowEvents
    from feelflow.app.gui.window.flow import FlowController
    from feelflow.app.gui.window.frame_loop import FrameLoop
    from feelflow.app.gui.window.replay_controller import ReplayController
    from feelflow.app.model.simulation import Simulation


class BodyController:
    """Changes the live body; every change is refused while a replay shows."""

    def __init__(self, events: "WindowEvents", viewport: "Viewport", loop: "FrameLoop", panel: "SidePanel",
                 undo: "QUndoStack", replays: "ReplayController", flow: "FlowController", status: "QStatusBar",
                 make_current: "Callable[[], None]", parent: "QWidget"):
        """`make_current`: the viewport's GL context current where the solver draws on it;
        `parent`: the dialogs' parent."""
        self.viewport, self.loop, self.panel, self.undo = viewport, loop, panel, undo
        self.replays, self.flow = replays, flow
        self.status, self.make_current, self.parent = status, make_current, parent
        self.sim: "Simulation | None" = None   # the live tunnel, once it exists (events.liveCreated)
        events.liveCreated.connect(self._live_created)
        events.replayStarted.connect(self._replay_started)

    def _live_created(self, sim):
        self.sim = sim

    def _replay_started(self):
        """A replay takes over: the polygon editor closes and a drag is cancelled."""
        self.set_editing(False)
        self.viewport.cancel_drag()

    def _refused(self) -> bool:
        return self.sim is None or self.replays.refuse("the body follows the recording")

    # --- kind, size, hold still -------------------------------------------------------------------
    def apply_shape(self, **changes) -> bool:
        """`Simulation.set_shape(**changes)`; a shape that cannot be used is a dialog and changes
        nothing."""
        if self._refused():
            return False
        self.make_current()
        try:
            self.sim.set_shape(**changes)
        except (ShapeError, ConfigError, ValueError) as exc:
            self.flow.refuse_dialog("This shape cannot be used", exc)
            return False
        self.panel.show_params(self.sim.params, self.loop.display.mode)
        if self.flow.say_guard():
            self.flow.after_rebuild()
        self.viewport.update()
        return True

    def set_shape_kind(self, kind):
        if self._refused():
            return
        if kind == "polygon" and self.sim.polygon is None:
            self.install_default_polygon()
            return
        self.apply_shape(kind=kind)
        if kind != "polygon":
            self.set_editing(False)

    def install_default_polygon(self):
        verts = default_polygon(self.sim.params.size)
        self.make_current()
        try:
            self.sim.set_shape(kind="polygon", polygon=verts)
        except (ShapeError, ValueError) as exc:
            self.flow.refuse_dialog("This shape cannot be used", exc)
        self.panel.show_params(self.sim.params, self.loop.display.mode)

    def install_loaded_shape(self, shape):
        """A shape read from a file (app/gui/window/exports.py): a polygon is an undoable edit."""
        from feelflow.app.model.bodies import params_for_shape

        sim = self.sim
        kind, size, verts = params_for_shape(shape)
        if kind == "polygon":
            if sim.params.shape != "polygon":
                self.make_current()
                sim.params = replace(sim.params, shape="polygon")
            return self.edit_polygon(verts, "load shape")
        return self.apply_shape(kind=kind, size=size)

    def set_hold_still(self, on):
        if self.replays.refuse("the body follows the recording"):
            return
        if self.sim is not None:
            self.sim.hold_still = bool(on)
        self.panel.hold_still.setChecked(bool(on))

    # --- turning ----------------------------------------------------------------------------------
    def turn_body(self, degrees: float) -> bool:
        """Turn the body to `degrees` (any number of turns). While the flow runs it swings there
        through the angle spring, as with the wheel; paused or held still it turns at once, as
        with the panel's angle box. The panel shows the angle asked for."""
        sim = self.sim
        if self._refused():
            return False
        if self.loop.paused or sim.hold_still:
            if sim.angle != math.radians(wrap_degrees(degrees)):
                self.make_current()
                try:
                    sim.set_shape(angle_deg=wrap_degrees(degrees))
                except (ShapeError, ConfigError, ValueError) as exc:   # no dialog in the middle of a drag
                    self.status.showMessage(f"The body cannot turn there: {exc}", 4000)
                    return False
        else:
            sim.drive(BodyInput.turn(degrees, source="mouse"))
        self.panel.show_angle(sim.params.angle_deg)
        self.viewport.update()
        return True

    def turn_done(self, before: float, after: float):
        """One drag of the handle: one undo step (the body is already at `after`)."""
        if self.sim is not None and self.replays.replay is None:
            self.undo.push(TurnBody(self.turn_body, before, after))

    def _script_refuses_turn(self, how: str) -> bool:
        """A motion script drives the pose (it ignores the angle until it ends, when the body would
        swing to the last asked angle): refuse the turn with a status message."""
        if self.sim is None or self.sim.runner is None:
            return False
        self.turn_refused("A motion script", how)
        return True

    def turn_by_wheel(self, degrees: float) -> bool:
        """The mouse wheel turns the body like the handle does; a burst of notches is one undo step."""
        sim = self.sim
        if sim is None or self._script_refuses_turn("the mouse wheel"):
            return False
        before = sim.target_degrees()
        if not self.turn_body(before + degrees):
            return False
        self.undo.push(TurnBody(self.turn_body, before, before + degrees, "turn the body (wheel)", burst="wheel"))
        return True

    def set_angle(self, degrees: float) -> bool:
        """The panel's angle box turns the body at once; a burst of edits (typed digits, arrow
        steps) is one undo step, whose undo puts the body back at once too."""
        sim = self.sim
        if sim is None:
            return False
        if self._script_refuses_turn("the Angle box"):
            self.panel.show_angle(sim.params.angle_deg)   # the box goes back to the angle the body keeps
            return False
        before = sim.target_degrees()
        if not self._turn_at_once(degrees):
            return False
        self.undo.push(TurnBody(self._turn_at_once, before, degrees, "set the angle", burst="angle box"))
        return True

    def _turn_at_once(self, degrees: float) -> bool:
        return self.apply_shape(angle_deg=wrap_degrees(degrees))

    def turn_refused(self, driver: str, what: str = "the handle"):
        """`driver` (viewport.turn_blocker's words) drives the body, so `what` may not turn it."""
        how = "choose Mouse under Input" if self.viewport.driver is not None \
            else "wait for it to end or reset the flow (R)"
        self.status.showMessage(f"{driver} drives the body: {what} cannot rotate it now ({how}).", 6000)

    # --- polygon editor ---------------------------------------------------------------------------
    def set_editing(self, on):
        if on and self.replays.refuse("the body follows the recording"):
            return
        self.viewport.editing = bool(on) and self.sim is not None and self.sim.params.shape == "polygon"
        self.panel.edit.setChecked(self.viewport.editing)
        if self.viewport.editing:
            self.set_hold_still(True)
            self.status.showMessage(f"Editing the polygon (the body holds still): {self.panel.edit.toolTip()}; "
                                      "Ctrl+Z undoes an edit.", 20000)
        elif on is False and self.status.currentMessage().startswith("Editing the polygon"):
            self.status.clearMessage()
        self.viewport.update()

    def check_polygon(self, verts):
        """Build and validate the polygon without installing it; raises ShapeError."""
        sim = self.sim
        shape = sim.make_shape(replace(sim.params, shape="polygon"), verts, *sim.pos, sim.angle)
        return shape.validate(sim.config.nx, sim.config.ny)

    def edit_polygon(self, verts, text="edit polygon"):
        """Push an undoable polygon edit, or refuse it with a dialog (the previous shape stays)."""
        if self.replays.refuse("the body follows the recording"):
            return False
        try:
            self.check_polygon(verts)
        except (ShapeError, ValueError) as exc:
            QMessageBox.warning(self.parent, "This polygon cannot be used", f"{exc}\nThe previous shape is kept.")
            self.viewport.update()
            return False
        self.undo.push(SetPolygon(self._install_polygon, self.sim.polygon, verts, text))
        return True

    def _install_polygon(self, verts):
        self.make_current()
        self.sim.set_shape(kind="polygon", polygon=[tuple(v) for v in verts])
        self.panel.show_params(self.sim.params, self.loop.display.mode)
        self.viewport.update()
