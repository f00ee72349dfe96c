"""What the viewport paints over the flow field with QPainter: the tracers, the outlet zone's
line, the body (and the polygon editor's handles), the rotation handle (app/gui/turn_handle.py),
the drag and lift arrows, the colour bar and the notes (replay progress, speed limit, holding
still, scripted motion, wind sweep). It only reads: the viewport's geometry and state, and the
`TunnelModel` it shows."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QBrush, QColor, QFont, QLinearGradient, QPainter, QPen, QPixmap, QPolygonF

from feelflow.app.gui import turn_handle
from feelflow.app.gui.display_modes import COLOUR_BAR_MARGIN, DISPLAY_MODES

if TYPE_CHECKING:
    from feelflow.app.gui.viewport import Viewport

BODY_FILL = QColor(225, 225, 225)
BODY_EDGE = QColor(20, 20, 20)
DRAG_COLOUR = QColor(230, 40, 40)
LIFT_COLOUR = QColor(40, 120, 255)
#: the dashed line where the outlet zone (the sponge, docs/science/algorithm.md step 3) begins
OUTLET_LINE = QColor(255, 255, 255, 150)


class Overlay:
    """Paints `view`'s overlay; keeps the colour bar drawn once per mode and size."""

    def __init__(self, view: "Viewport"):
        self.view = view
        self._bar_key = None
        self._bar_pixmap = None

    def paint(self, p: QPainter):
        v = self.view
        if v.sim is None:
            return
        p.setRenderHint(QPainter.Antialiasing)
        if v.mode == "tracers" and v.tracers is not None:
            self._paint_tracers(p)
        self._paint_outlet_zone(p)
        self._paint_body(p)
        self._paint_turn_handle(p)
        if v.show_arrows and v.arrow_forces and v.sim.shape is not None:
            self._paint_arrows(p)
        if v.probe_marks:
            self._paint_probes(p)
        self._paint_colour_bar(p)
        self._paint_notes(p)

    def _paint_probes(self, p: QPainter):
        """Each probe: a ring with a cross in its plot colour, and its number."""
        v = self.view
        for x, y, colour, label in v.probe_marks:
            c = v.to_widget(x, y)
            p.setPen(QPen(QColor(0, 0, 0, 160), 4))
            p.drawEllipse(c, 6, 6)
            p.setPen(QPen(colour, 2))
            p.setBrush(Qt.NoBrush)
            p.drawEllipse(c, 6, 6)
            p.drawLine(c.x() - 9, c.y(), c.x() + 9, c.y())
            p.drawLine(c.x(), c.y() - 9, c.x(), c.y() + 9)
            p.drawText(c.x() + 8, c.y() - 8, label)

    def _paint_body(self, p: QPainter):
        v = self.view
        sim = v.sim
        if sim.shape is None:   # a replayed session that removed its body
            return
        if sim.target is not None and not sim.hold_still:
            a, b = v.to_widget(*sim.pos), v.to_widget(*sim.target)
            p.setPen(QPen(QColor(255, 255, 255, 200), 2, Qt.DashLine))
            p.drawLine(a, b)
            p.setBrush(Qt.NoBrush)
            p.drawEllipse(b, 6, 6)
        # an exercise marks a body that breaks a constraint (app/gui/exercise_constraints.py)
        edge = self.view.body_edge
        p.setPen(QPen(edge or BODY_EDGE, 2.5, Qt.DashLine if edge else Qt.SolidLine))
        p.setBrush(QBrush(BODY_FILL))
        p.drawPolygon(v.body_outline_points())
        if v.editing and sim.polygon is not None:
            verts = v.edit_preview if v.edit_preview is not None else sim.polygon
            world = v.body_to_world(verts)
            p.setPen(QPen(QColor(255, 200, 0), 1.5, Qt.DashLine))
            p.setBrush(Qt.NoBrush)
            p.drawPolygon(v.body_outline_points(world))
            p.setPen(QPen(Qt.black, 1.5))
            p.setBrush(QBrush(QColor(255, 200, 0)))
            for x, y in world:
                c = v.to_widget(x, y)
                p.drawRect(QRectF(c.x() - 5, c.y() - 5, 10, 10))

    def _arrow(self, p, start: QPointF, vec, colour, label):
        length = math.hypot(*vec)
        if length < 3:
            return
        end = QPointF(start.x() + vec[0], start.y() + vec[1])
        p.setPen(QPen(QColor(0, 0, 0, 160), 7, Qt.SolidLine, Qt.RoundCap))
        p.drawLine(start, end)
        p.setPen(QPen(colour, 4, Qt.SolidLine, Qt.RoundCap))
        p.drawLine(start, end)
        ux, uy = vec[0] / length, vec[1] / length
        head = min(16.0, 0.45 * length)
        tip = QPolygonF([end, QPointF(end.x() - head * ux + 0.6 * head * uy, end.y() - head * uy - 0.6 * head * ux),
                         QPointF(end.x() - head * ux - 0.6 * head * uy, end.y() - head * uy + 0.6 * head * ux)])
        p.setPen(QPen(Qt.black, 1.5))
        p.setBrush(QBrush(colour))
        p.drawPolygon(tip)
        if length < 30:   # too short to carry a label without covering the body
            return
        self._label(p, QPointF(end.x() + 10 * ux - 4, end.y() + 10 * uy + (16 if uy > 0.5 else -8 if uy < -0.5 else 5)),
                    label, QColor(255, 255, 255), box=colour.darker(130))

    def _label(self, p, at: QPointF, text, colour=QColor(255, 255, 255), size=15, box=QColor(0, 0, 0, 160)):
        """Bold text on a dark translucent box, readable on any colour of the field."""
        v = self.view
        font = QFont(v.font())
        font.setPixelSize(size)
        font.setBold(True)
        p.setFont(font)
        rect = p.fontMetrics().boundingRect(text).adjusted(-4, -2, 4, 2).translated(int(at.x()), int(at.y()))
        p.setPen(Qt.NoPen)
        p.setBrush(box)
        p.drawRoundedRect(QRectF(rect), 4, 4)
        p.setPen(colour)
        p.drawText(at, text)

    def _paint_arrows(self, p: QPainter):
        """Drag (along the relative wind) and lift (across it), as app/model/readouts.py `arrows`
        sized them (coefficient x half the reference length, in cells)."""
        v = self.view
        centre = v.to_widget(*v.sim.pos)
        px_per_cell = v.lattice_rect().width() / v.sim.config.nx
        for key, colour in (("drag", DRAG_COLOUR), ("lift", LIFT_COLOUR)):
            x, y = v.arrow_forces[key]
            self._arrow(p, centre, (x * px_per_cell, -y * px_per_cell), colour, key)

    def _paint_colour_bar(self, p: QPainter):
        """The colour bar, drawn once per mode and size into a pixmap, then blitted each frame."""
        v = self.view
        key = (v.mode, v.width(), v.height(), v.sim.config.nx, v.sim.config.ny)
        if self._bar_key != key:
            pixmap = QPixmap(COLOUR_BAR_MARGIN, v.height())
            pixmap.fill(QColor(41, 43, 48))
            painter = QPainter(pixmap)
            painter.setRenderHint(QPainter.Antialiasing)
            painter.translate(-(v.width() - COLOUR_BAR_MARGIN), 0)
            self._draw_colour_bar(painter)
            painter.end()
            self._bar_pixmap, self._bar_key = pixmap, key
        p.drawPixmap(v.width() - COLOUR_BAR_MARGIN, 0, self._bar_pixmap)

    def _draw_colour_bar(self, p: QPainter):
        v = self.view
        mode = DISPLAY_MODES[v.mode]
        r = v.lattice_rect()
        x = v.width() - COLOUR_BAR_MARGIN + 22
        top, bottom = max(40.0, r.top() + 30), min(v.height() - 20.0, r.bottom() - 10)
        if bottom - top < 60:
            top, bottom = 30.0, v.height() - 10.0
        bar = QRectF(x, top, 20, bottom - top)
        grad = QLinearGradient(0, bottom, 0, top)
        table = pg.colormap.get(mode.colormap).getLookupTable(0.0, 1.0, 17, alpha=False)
        for k, (r_, g_, b_) in enumerate(table.tolist()):
            if mode.shader_mode == 3:  # the faded speed map of the tracer view (display.glsl)
                r_, g_, b_ = (int(0.7 * 245 + 0.3 * c) for c in (r_, g_, b_))
            grad.setColorAt(k / 16.0, QColor(int(r_), int(g_), int(b_)))
        p.setPen(QPen(QColor(230, 230, 230), 1))
        p.setBrush(QBrush(grad))
        p.drawRect(bar)
        font = QFont(v.font())
        font.setPixelSize(15)
        p.setFont(font)
        lo, hi = mode.range
        for tick in np.linspace(lo, hi, 5):
            y = bottom - (tick - lo) / (hi - lo) * (bottom - top)
            p.drawLine(QPointF(x + 20, y), QPointF(x + 25, y))
            p.drawText(QPointF(x + 28, y + 5), f"{tick:g}".replace("-", "\u2212"))
        font.setBold(True)
        p.setFont(font)
        p.drawText(QRectF(x - 22, 4, COLOUR_BAR_MARGIN - 2, top - 8), Qt.AlignLeft | Qt.AlignBottom | Qt.TextWordWrap,
                   mode.unit)

    def _paint_outlet_zone(self, p: QPainter):
        v = self.view
        x = v.outlet_zone_x()
        if x is None:
            return
        r = v.lattice_rect()
        p.setPen(QPen(OUTLET_LINE, 1.5, Qt.DashLine))
        p.drawLine(QPointF(x, r.top()), QPointF(x, r.bottom()))
        self._label(p, QPointF(x + 6, r.bottom() - 8), "outlet zone", QColor(230, 230, 230), size=12,
                    box=QColor(0, 0, 0, 110))

    def _paint_notes(self, p: QPainter):
        v = self.view
        sim = v.sim
        r = v.lattice_rect()
        notes = [(v.banner, QColor(255, 230, 120))] if v.banner else []
        if sim.capped:
            notes.append(("speed limit reached (Mach %.2f)" % sim.config.mach_limit, QColor(255, 170, 40)))
        if sim.hold_still:
            notes.append(("holding still", QColor(255, 255, 255)))
        phase = sim.script_phase()
        if phase is not None:
            k, count, words = phase
            notes.append((f"scripted motion: {words} (phase {k + 1} of {count})", QColor(255, 255, 255)))
        stage = sim.sweep_stage()
        if stage is not None:
            notes.append((f"wind {sim.params.wind:.3f} (speed {stage + 1} of {len(sim.sweep.speeds)})", QColor(255, 255, 255)))
        for i, (text, colour) in enumerate(notes):
            self._label(p, QPointF(r.left() + 10, r.top() + 24 + 20 * i), text, colour, size=15)

    def _paint_tracers(self, p: QPainter):
        v = self.view
        pts, prev = v.tracers
        p.setPen(QPen(QColor(20, 40, 120), 1.6, Qt.SolidLine, Qt.FlatCap))
        r = v.lattice_rect()
        nx, ny = v.sim.config.nx, v.sim.config.ny
        sx, sy = r.width() / nx, r.height() / ny
        x0, y0 = r.left() + 0.5 * sx, r.bottom() - 0.5 * sy
        lines = [QPointF(x0 + a * sx, y0 - b * sy) for a, b in np.stack([prev, pts], 1).reshape(-1, 2).tolist()]
        p.setRenderHint(QPainter.Antialiasing, False)   # ~900 short streaks: plain lines are much cheaper
        p.drawLines(lines)
        p.setRenderHint(QPainter.Antialiasing, True)

    def _paint_turn_handle(self, p: QPainter):
        v = self.view
        if not v.handle_shown():
            return
        centre, knob, reach = v.handle_geometry()
        turn = v.turn
        if turn is not None and abs(math.radians(turn.target) - v.sim.angle) > 1e-3:
            target = turn_handle.knob_position(centre, reach, math.radians(turn.target))
            turn_handle.paint_turn_target(p, centre, target)
        state = "refused" if v.turn_blocker() else "active" if turn is not None or v.hover == "handle" else "idle"
        if v.torque_arc:
            turn_handle.paint_torque_arc(p, centre, reach, v.sim.angle, v.torque_arc)
        turn_handle.paint_handle(p, centre, knob, state)
        if turn is not None:
            shown = (turn.target + 180.0) % 360.0 - 180.0
            ux, uy = (knob.x() - centre.x()) / reach, (knob.y() - centre.y()) / reach
            at = QPointF(knob.x() + 16 * ux - (38 if ux < -0.3 else 0 if ux > 0.3 else 18), knob.y() + 16 * uy + 6)
            self._label(p, at, f"{shown:.0f}\u00b0".replace("-", "\u2212"))   # beyond the knob, off the stalk
