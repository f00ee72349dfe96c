"""The rotation handle on the body in the viewport: a knob on a short stalk from the body's
reference point (the point it turns about), its geometry in widget pixels, the arithmetic of one
turn (the body follows the change of the pointer's angle about the reference point, unwrapped
across +-180 degrees; Shift snaps to 15-degree steps), the rotate cursor, and the undo command
that makes one drag of the handle one undo step.
"""
from __future__ import annotations

import math
import time

from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QBrush, QColor, QCursor, QPainter, QPainterPath, QPen, QPixmap, QPolygonF, QUndoCommand

from feelflow.app.model.simulation import wrap_degrees

SNAP_DEG = 15.0
KNOB_RADIUS = 7.0     # pixels
KNOB_REACH = 12.0     # a press this close to the knob's centre takes the handle
STALK_BEYOND = 22.0   # the knob sits this far past the body's farthest outline point
NEAR = 18.0           # the handle shows while the pointer is this close to the circle it turns on
BURST_S = 0.8         # wheel notches (angle box edits) closer than this in time are one undo step

KNOB_FILL = QColor(245, 245, 245)
KNOB_ACTIVE = QColor(255, 200, 0)        # the polygon editor's handle colour
KNOB_REFUSED = QColor(150, 150, 150, 200)
STALK = QColor(245, 245, 245, 230)
HALO = QColor(0, 0, 0, 160)


def pointer_degrees(centre, point) -> float:
    """Angle of `point` about `centre`, both in lattice coordinates (y up), counter-clockwise."""
    return math.degrees(math.atan2(point[1] - centre[1], point[0] - centre[0]))


def snap(degrees: float, step: float = SNAP_DEG) -> float:
    return round(degrees / step) * step


class Turn:
    """One drag of the handle: the body's angle (degrees, any number of turns) at the press plus
    how far the pointer has turned about the reference point since."""

    def __init__(self, pointer_deg: float, body_deg: float):
        self.before = body_deg
        self.turned = 0.0
        self._last = pointer_deg
        self.target = body_deg

    def follow(self, pointer_deg: float, snapped: bool) -> float:
        """The body angle the pointer now asks for (a step across +-180 degrees is a small step)."""
        self.turned += (pointer_deg - self._last + 180.0) % 360.0 - 180.0
        self._last = pointer_deg
        angle = self.before + self.turned
        self.target = snap(angle) if snapped else angle
        return self.target


def knob_position(centre: QPointF, reach: float, angle: float) -> QPointF:
    """Where the knob sits (widget pixels, y down): `reach` from the reference point, on the
    body's upstream side at angle 0 (clear of the drag and lift arrows), turning with the body."""
    a = angle + math.pi
    return QPointF(centre.x() + reach * math.cos(a), centre.y() - reach * math.sin(a))


def handle_reach(centre: QPointF, outline: QPolygonF) -> float:
    """Stalk length: past the body's farthest outline point, so the knob is never on the body."""
    far = max((math.hypot(p.x() - centre.x(), p.y() - centre.y()) for p in outline), default=0.0)
    return far + STALK_BEYOND


def paint_handle(p: QPainter, centre: QPointF, knob: QPointF, state: str):
    """Stalk and knob in the overlay's style (light line on a dark halo, like the force arrows);
    `state`: "idle", "active" (hovered or turning) or "refused" (something else drives the body)."""
    p.setBrush(Qt.NoBrush)
    p.setPen(QPen(HALO, 4.5, Qt.SolidLine, Qt.RoundCap))
    p.drawLine(centre, knob)
    p.setPen(QPen(STALK if state != "refused" else KNOB_REFUSED, 2, Qt.SolidLine, Qt.RoundCap))
    p.drawLine(centre, knob)
    p.setPen(QPen(Qt.black, 1.5))
    p.setBrush(QBrush(Qt.black))
    p.drawEllipse(centre, 2.5, 2.5)                 # the reference point it turns about
    fill = {"idle": KNOB_FILL, "active": KNOB_ACTIVE, "refused": KNOB_REFUSED}[state]
    p.setBrush(QBrush(fill))
    p.drawEllipse(knob, KNOB_RADIUS, KNOB_RADIUS)


TORQUE = QColor(120, 220, 255)


def paint_torque_arc(p: QPainter, centre: QPointF, reach: float, angle: float, degrees: float):
    """The torque the fluid puts on the body (app/model/readouts.py torque_arc): an arc on the
    knob's circle from the knob, `degrees` long (counter-clockwise positive, as the torque turns
    the body), with an arrowhead at its end; the body turned against the fluid shows it pulling
    back."""
    start = math.degrees(angle) + 180.0   # the knob's direction (knob_position)
    rect = QRectF(centre.x() - reach, centre.y() - reach, 2 * reach, 2 * reach)
    path = QPainterPath()
    path.arcMoveTo(rect, start)
    path.arcTo(rect, start, degrees)     # Qt's angles run counter-clockwise on screen (y down)
    p.setBrush(Qt.NoBrush)
    p.setPen(QPen(HALO, 6, Qt.SolidLine, Qt.RoundCap))
    p.drawPath(path)
    p.setPen(QPen(TORQUE, 3, Qt.SolidLine, Qt.RoundCap))
    p.drawPath(path)
    end = math.radians(start + degrees)
    tip = QPointF(centre.x() + reach * math.cos(end), centre.y() - reach * math.sin(end))
    sense = 1.0 if degrees > 0 else -1.0   # the tangent along the arc's direction, on screen
    tx, ty = -math.sin(end) * sense, -math.cos(end) * sense
    nx, ny = -ty, tx
    head = QPolygonF([tip + QPointF(8 * tx, 8 * ty), tip + QPointF(5 * nx, 5 * ny), tip - QPointF(5 * nx, 5 * ny)])
    p.setPen(QPen(HALO, 1.5))
    p.setBrush(QBrush(TORQUE))
    p.drawPolygon(head)


def paint_turn_target(p: QPainter, centre: QPointF, knob: QPointF):
    """Where the pointer asks the body to turn: dashed, like the drag's target line."""
    p.setPen(QPen(QColor(255, 255, 255, 200), 2, Qt.DashLine))
    p.setBrush(Qt.NoBrush)
    p.drawLine(centre, knob)
    p.drawEllipse(knob, KNOB_RADIUS - 1, KNOB_RADIUS - 1)


_cursor = None


def rotate_cursor() -> QCursor:
    """A circular arrow (Qt has no rotate cursor shape), white on a black outline; built once."""
    global _cursor
    if _cursor is None:
        pix = QPixmap(32, 32)
        pix.fill(Qt.transparent)
        p = QPainter(pix)
        p.setRenderHint(QPainter.Antialiasing)
        arc = QPainterPath()
        box = QRectF(7, 7, 18, 18)
        arc.arcMoveTo(box, 120)
        arc.arcTo(box, 120, 270)
        end = math.radians(120 + 270)                    # the arc's end, heading counter-clockwise
        ex, ey = 16 + 9 * math.cos(end), 16 - 9 * math.sin(end)
        dx, dy = -math.sin(end), -math.cos(end)          # tangent, widget y down
        head = QPolygonF([QPointF(ex + 5 * dx, ey + 5 * dy), QPointF(ex - 5 * dy - dx, ey + 5 * dx - dy),
                          QPointF(ex + 5 * dy - dx, ey - 5 * dx - dy)])
        for colour, width in ((Qt.black, 5.0), (Qt.white, 2.2)):
            p.setPen(QPen(colour, width, Qt.SolidLine, Qt.RoundCap, Qt.RoundJoin))
            p.setBrush(Qt.NoBrush)
            p.drawPath(arc)
            p.setBrush(QBrush(colour))
            p.setPen(QPen(colour, width - 1.5, Qt.SolidLine, Qt.RoundCap, Qt.RoundJoin))
            p.drawPolygon(head)
        p.end()
        _cursor = QCursor(pix, 16, 16)
    return _cursor


class TurnBody(QUndoCommand):
    """One turn of the body: its angle before and after (degrees, any number of turns); `apply`
    is the window's function that turns the body. The window turns the body first and pushes the
    command only when that worked, so the push's own redo does nothing (the body is there).

    `burst` names a source whose quick successive turns make one undo step ("wheel", "angle
    box"): a command of the same burst that follows within BURST_S seconds of the last one merges
    into it (QUndoStack calls mergeWith). A drag of the handle (burst None) never merges."""

    BURSTS = ("wheel", "angle box")

    def __init__(self, apply, before: float, after: float, text="turn the body", burst=None, at=None):
        super().__init__(text)
        self.apply, self.before, self.after = apply, before, after
        self.burst = burst
        self.turned = after - before   # degrees turned by this command and those merged into it
        self._pushed = False
        self.at = time.monotonic() if at is None else at   # when the last turn of the burst came

    def id(self) -> int:
        return self.BURSTS.index(self.burst) + 1 if self.burst is not None else -1

    def mergeWith(self, other) -> bool:
        # the next turn starts where this one ended: the same angle, but paused the body turns
        # at once and keeps only the wrapped angle (181 comes back as -179)
        if other.id() != self.id() or other.at - self.at > BURST_S \
                or wrap_degrees(other.before) != wrap_degrees(self.after):
            return False
        self.after, self.at = other.after, other.at
        # turned back to where it began, notch for notch: no undo step (paused, the angles come back
        # wrapped, so 179 -> 181 -> 179 reads 179 -> -181: the sum of the turns says it is none)
        self.turned += other.after - other.before
        self.setObsolete(abs(self.turned) < 1e-9)
        return True

    def redo(self):
        if self._pushed:
            self.apply(self.after)
        self._pushed = True

    def undo(self):
        self.apply(self.before)
