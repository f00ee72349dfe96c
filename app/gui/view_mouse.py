"""The mouse in the tunnel view (app/gui/viewport.py): dragging the body, the polygon editor's
vertices (drag one, right-click to remove it, double-click to add one), the turn handle (it shows
near the body; one drag is one turn, app/gui/turn_handle.py) and the wheel. It never changes the
model: each request leaves as one of the viewport's signals (`bodyPulled`, `polygonEdited`,
`turnRequested`, `turnFinished`, `wheelTurned`, ...) for the window's controllers; while a replay
shows (`locked`) a press or a wheel turn is refused (`inputRefused`).
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import QEvent, QPointF, Qt
from PySide6.QtWidgets import QToolTip

from feelflow.app.gui import turn_handle

if TYPE_CHECKING:
    from feelflow.app.gui.viewport import Viewport

WHEEL_DEG_PER_NOTCH = 2.0  # one notch of the mouse wheel (120 eighths of a degree) turns the body this far
MOUSE_HINT = ("Drag the body to move it; drag its round handle or turn the mouse wheel to rotate it "
              "(hold Shift for 15\u00b0 steps).")
HANDLE_HINT = "Drag to rotate the body about its reference point (Shift: 15\u00b0 steps); the mouse wheel rotates it too."


class ViewMouse:
    """What the mouse is doing in `view`: a drag of the body (`grab`: offset from the body's
    reference point to the pressed point), of a polygon vertex (`edit_vertex`, with the
    polygon as it would be: `edit_preview`), of the turn handle (`turn`, a turn_handle.Turn),
    and what the pointer is over (`hover`: "handle", "body", "near" or None)."""

    def __init__(self, view: "Viewport"):
        self.view = view
        self.grab = None
        self.edit_vertex = None
        self.edit_preview = None
        self.turn = None
        self.hover = None

    # --- the turn handle ---------------------------------------------------------------------------
    def turn_blocker(self):
        """What drives the body instead of the mouse (a haptic device, a motion script), or None."""
        if self.view.driver:
            return self.view.driver
        sim = self.view.sim
        if sim is not None and sim.runner is not None:
            return "A motion script"
        return None

    def handle_geometry(self):
        """(reference point, knob centre, stalk length) in widget pixels, or None without a body."""
        sim = self.view.sim
        if sim is None or sim.shape is None:
            return None
        centre = self.view.to_widget(*sim.pos)
        reach = turn_handle.handle_reach(centre, self.view.body_outline_points())
        return centre, turn_handle.knob_position(centre, reach, sim.angle), reach

    def handle_shown(self) -> bool:
        """The handle shows while the pointer is near the body or turns it; never during a replay,
        a drag of the body or while the polygon editor drags a vertex."""
        if self.view.locked or self.view.sim is None or self.view.sim.shape is None:
            return False
        if self.grab is not None or self.edit_vertex is not None:
            return False
        return self.turn is not None or self.hover is not None

    def hover_at(self, pos: QPointF):
        """What the pointer is over: the knob, the body, near the body (within the handle's reach)."""
        geometry = self.handle_geometry() if not self.view.locked else None
        if geometry is None:
            return None
        centre, knob, reach = geometry
        if math.hypot(pos.x() - knob.x(), pos.y() - knob.y()) <= turn_handle.KNOB_REACH:
            return "handle"
        if self.view.sim.hit(*self.view.to_lattice(pos)):
            return "body"
        if math.hypot(pos.x() - centre.x(), pos.y() - centre.y()) <= reach + turn_handle.NEAR:
            return "near"
        return None

    def set_hover(self, hover):
        if hover != self.hover:
            self.hover = hover
            self.view.update()
        if self.turn is not None:
            self.view.setCursor(turn_handle.rotate_cursor())
        elif self.grab is not None:
            self.view.setCursor(Qt.ClosedHandCursor)
        elif hover == "handle":
            self.view.setCursor(Qt.ForbiddenCursor if self.turn_blocker() else turn_handle.rotate_cursor())
        elif hover == "body" and not self.view.editing:
            self.view.setCursor(Qt.OpenHandCursor)
        else:
            self.view.unsetCursor()

    def pointer_degrees(self, pos: QPointF) -> float:
        return turn_handle.pointer_degrees(self.view.sim.pos, self.view.to_lattice(pos))

    def leave(self):
        if self.turn is None:
            self.set_hover(None)

    def tooltip(self, ev) -> bool:
        """Tooltips where they help: over the handle, over the body (True: `ev` was a tooltip
        the mouse handled)."""
        view = self.view
        if ev.type() == QEvent.ToolTip and view.sim is not None and not view.locked:
            hover = self.hover_at(QPointF(ev.pos()))
            text = {"handle": HANDLE_HINT, "body": MOUSE_HINT}.get(hover)
            blocker = self.turn_blocker() if hover == "handle" else None
            if blocker:
                text = f"{blocker} drives the body: the handle cannot rotate it now."
            if text:
                QToolTip.showText(ev.globalPos(), text, view)
            else:
                QToolTip.hideText()
            return True
        return False

    def vertex_at(self, pos: QPointF):
        if self.view.sim.polygon is None:
            return None
        for i, (x, y) in enumerate(self.view.body_to_world(self.view.sim.polygon)):
            c = self.view.to_widget(x, y)
            if abs(c.x() - pos.x()) <= 8 and abs(c.y() - pos.y()) <= 8:
                return i
        return None

    # --- the buttons and the wheel --------------------------------------------------------------
    def cancel_drag(self):
        """Forget a drag of the body in progress (a replay takes over the view)."""
        self.grab = None

    def press(self, ev):
        if self.view.sim is None:
            return
        if self.view.locked:
            self.view.inputRefused.emit()
            return
        pos = ev.position()
        x, y = self.view.to_lattice(pos)
        if self.view.probing and ev.button() in (Qt.LeftButton, Qt.RightButton):
            self.view.probeClicked.emit(x, y, ev.button() == Qt.RightButton)
            return
        if self.view.editing and self.view.sim.polygon is not None:
            i = self.vertex_at(pos)
            if i is not None and ev.button() == Qt.RightButton:
                verts = [v for k, v in enumerate(self.view.sim.polygon) if k != i]
                self.view.polygonEdited.emit(verts)
                return
            if i is not None and ev.button() == Qt.LeftButton:
                self.edit_vertex = i
                self.edit_preview = [tuple(v) for v in self.view.sim.polygon]
                return
        hover = self.hover_at(pos)
        if ev.button() == Qt.LeftButton and hover == "handle":
            blocker = self.turn_blocker()
            if blocker:
                self.view.turnRefused.emit(blocker)
                return
            self.turn = turn_handle.Turn(self.pointer_degrees(pos), self.view.sim.target_degrees())
            self.set_hover(hover)
            return
        if ev.button() == Qt.LeftButton and self.view.sim.hit(x, y):
            self.grab = (self.view.sim.pos[0] - x, self.view.sim.pos[1] - y)
            self.view.bodyPulled.emit((x + self.grab[0], y + self.grab[1]))
            self.view.bodyGrabbed.emit(True)
            self.set_hover(hover)
            self.view.update()

    def move(self, ev):
        if self.view.sim is None:
            return
        x, y = self.view.to_lattice(ev.position())
        if self.turn is not None:
            before = self.turn.target
            target = self.turn.follow(self.pointer_degrees(ev.position()), bool(ev.modifiers() & Qt.ShiftModifier))
            if target != before:
                self.view.turnRequested.emit(target)
            self.view.update()
        elif self.edit_vertex is not None:
            self.edit_preview[self.edit_vertex] = self.view.world_to_body(x, y)
            self.view.update()
        elif self.grab is not None:
            self.view.bodyPulled.emit((x + self.grab[0], y + self.grab[1]))
        elif not ev.buttons():
            self.set_hover(self.hover_at(ev.position()))

    def release(self, ev):
        if self.turn is not None:
            turn, self.turn = self.turn, None
            if turn.target != turn.before:
                self.view.turnFinished.emit(turn.before, turn.target)
            self.set_hover(self.hover_at(ev.position()) if self.view.sim is not None else None)
            self.view.update()
        elif self.edit_vertex is not None:
            verts, self.edit_vertex, self.edit_preview = self.edit_preview, None, None
            self.view.polygonEdited.emit(verts)
        elif self.grab is not None:
            self.grab = None
            self.view.bodyPulled.emit(None)
            self.view.bodyGrabbed.emit(False)
            self.set_hover(self.hover_at(ev.position()))

    def double_click(self, ev):
        """Editor: a double click adds a vertex on the nearest edge."""
        if self.view.locked:
            return
        if not (self.view.editing and self.view.sim is not None and self.view.sim.polygon is not None):
            return
        x, y = self.view.to_lattice(ev.position())
        bx, by = self.view.world_to_body(x, y)
        v = np.asarray(self.view.sim.polygon, float)
        a, b = v, np.roll(v, -1, axis=0)
        ab = b - a
        t = np.clip(((bx - a[:, 0]) * ab[:, 0] + (by - a[:, 1]) * ab[:, 1]) / np.maximum((ab ** 2).sum(1), 1e-12), 0, 1)
        d = np.hypot(a[:, 0] + t * ab[:, 0] - bx, a[:, 1] + t * ab[:, 1] - by)
        k = int(np.argmin(d))
        verts = [tuple(p) for p in v]
        verts.insert(k + 1, (bx, by))
        self.view.polygonEdited.emit(verts)

    def wheel(self, ev):
        if self.view.sim is None:
            return
        if self.view.locked:
            self.view.inputRefused.emit()
            ev.accept()
            return
        self.view.wheelTurned.emit(WHEEL_DEG_PER_NOTCH * ev.angleDelta().y() / 120.0)
        ev.accept()
