"""The wind tunnel view: a plain (raster) widget that draws the flow field coloured on the GPU
(app/gui/field_colours.py: an OpenGL context of its own on an offscreen surface, the picture
read back) with QPainter, the overlay (app/gui/overlay.py: body, force arrows, tracers, colour
bar, notes, the polygon editor's handles and the rotation handle) painted on top; and the
mouse: dragging the body, the polygon editor, the rotation handle (app/gui/turn_handle.py) and
the wheel, each a signal to the window. The gl solver runs on the same context (`makeCurrent`).
"""
from __future__ import annotations

import math

import numpy as np
from PySide6.QtCore import QEvent, QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QImage, QPainter, QPolygonF
from PySide6.QtWidgets import QToolTip, QWidget

from feelflow.app.gui import turn_handle
from feelflow.app.gui.cpu_field import BACKGROUND
from feelflow.app.gui.display_modes import COLOUR_BAR_MARGIN, DISPLAY_MODES
from feelflow.app.gui.field_colours import FieldColours
from feelflow.app.gui.overlay import Overlay
from feelflow.app.model.tunnel import TunnelModel
from feelflow.solver import units
WHEEL_DEG_PER_NOTCH = 2.0  # one notch of the mouse wheel (120 eighths of a degree) turns the body this far
MOUSE_HINT = ("Drag the body to move it; drag its round handle or turn the mouse wheel to rotate it "
              "(hold Shift for 15\u00b0 steps).")
HANDLE_HINT = "Drag to rotate the body about its reference point (Shift: 15\u00b0 steps); the mouse wheel rotates it too."


class Viewport(QWidget):
    """Shows `sim`, a `TunnelModel` (the live tunnel or a replay, set by the window once the
    context exists). It never changes the model: the mouse's requests leave as signals
    (`bodyPulled`, `turnRequested`, `wheelTurned`, `polygonEdited`) for the window's
    controllers (app/gui/window/)."""

    contextReady = Signal(object)   # the moderngl.Context, once initializeGL ran
    bodyGrabbed = Signal(bool)
    bodyPulled = Signal(object)     # a drag pulls the body to (x, y) lattice cells; None lets go
    polygonEdited = Signal(object)  # new vertex list (body frame) from the editor handles
    inputRefused = Signal()         # a press or wheel turn while `locked` (a replay shows)
    turnRequested = Signal(float)   # the rotation handle asks for this body angle (degrees, any turns)
    turnFinished = Signal(float, float)   # one drag of the handle: angle before and after (degrees)
    wheelTurned = Signal(float)     # the wheel asks to turn the body by this many degrees
    turnRefused = Signal(str)       # the handle was pressed while this (a device, a script) drives the body
    probeClicked = Signal(float, float, bool)   # while `probing`: a click at (x, y) cells; True = right button

    def __init__(self, parent=None):
        super().__init__(parent)
        self.sim: TunnelModel | None = None
        self.colours = FieldColours(self)   # the GL context and the field's colouring pass
        self.mode = "speed"
        self.show_arrows = True
        self.editing = False
        self.body_edge = None    # a QColor for the body's outline instead of the usual, or None
        self.probing = False     # clicks place (left) and remove (right) probes instead of moving the body
        self.probe_marks = []    # [(x, y, QColor, label)] probes to draw (app/gui/window/probes.py)
        self.arrow_forces = None       # {"drag": (x, y), "lift": (x, y)} cells (app/model/readouts.py arrows)
        self.torque_arc = None         # degrees of the turn handle's torque arc (readouts.torque_arc)
        self.tracers = None
        self.frames = 0
        self.rho_ref = 1.0             # free-stream density for the pressure view (set by the window)
        self.locked = False            # True while a replay shows: the mouse does not move the body
        self.banner = None             # a line painted over the field (the replay's progress)
        self._grab = None              # offset from body centre to the pressed point
        self._edit_vertex = None       # index of the vertex being dragged
        self._edit_preview = None
        self.driver = None             # what else drives the body ("The haptic device"), set by the window
        self._turn = None              # the handle's drag in progress (turn_handle.Turn)
        self._hover = None             # "handle", "body" or "near" (the handle shows), or None
        self.overlay = Overlay(self)
        self._gl_tried = False
        self._outline_cache = None     # (shape, lattice rectangle, QPolygonF) of body_outline_points
        self.setAttribute(Qt.WA_OpaquePaintEvent)   # paintEvent fills every pixel
        self.setMinimumSize(480, 260)
        self.setMouseTracking(True)    # the handle appears when the pointer comes near the body
        self.setFocusPolicy(Qt.StrongFocus)

    # --- GL ---------------------------------------------------------------------------------
    contextFailed = Signal(str)     # no usable OpenGL 3.3: one line for the user

    def showEvent(self, ev):
        super().showEvent(ev)
        if not self._gl_tried:      # the context once, when the window first shows
            self._gl_tried = True
            self.initializeGL()

    def initializeGL(self):
        """The GL context (FieldColours.create); contextFailed where there is none of OpenGL
        3.3, else the display program and contextReady."""
        try:
            self.colours.create()
        except Exception as exc:   # moderngl.Error and friends: say so, never a traceback
            self.colours.ctx = None   # the window then draws on the CPU (app/gui/cpu_field.py)
            self.contextFailed.emit(f"OpenGL 3.3 is not available here ({str(exc).splitlines()[0]})")
            return
        self.colours.prepare()
        self.contextReady.emit(self.ctx)

    @property
    def ctx(self):
        """The moderngl context (FieldColours), or None before it exists or without OpenGL 3.3."""
        return self.colours.ctx

    @property
    def field_texture(self):
        """The texture drawn: the numpy path's upload or the gl solver's own, or None."""
        return self.colours.field_texture

    @property
    def edit_preview(self):
        """The polygon's vertices (body frame) while the editor drags one, else None."""
        return self._edit_preview

    @property
    def turn(self):
        """The handle's drag in progress (turn_handle.Turn), or None."""
        return self._turn

    @property
    def hover(self):
        """What the pointer is over: "handle", "body" or "near", or None."""
        return self._hover

    def makeCurrent(self):
        """The viewport's GL context current (the gl solver draws with it too)."""
        self.colours.make_current()

    def renderer(self) -> str:
        return self.colours.renderer()

    def upload_field(self, rgba: np.ndarray):
        """numpy path: (ny, nx, 4) float32 (rho, ux, uy, vorticity) to draw."""
        if self.ctx is None:       # no OpenGL 3.3: cpu_field.CpuCanvas colours it on the CPU
            self.cpu_rgba = rgba
            self.cpu_canvas.update()   # set by first_start.run_on_cpu
            return
        self.colours.upload(rgba)

    def use_texture(self, texture):
        """gl path: draw the solver's own field texture."""
        self.colours.use_texture(texture)

    def lattice_rect(self) -> QRectF:
        """Where the lattice is drawn (logical pixels), aspect ratio kept, colour bar beside it."""
        if self.sim is None:
            return QRectF(0, 0, self.width(), self.height())
        nx, ny = self.sim.config.nx, self.sim.config.ny
        w, h = max(1, self.width() - COLOUR_BAR_MARGIN), max(1, self.height())
        s = min(w / nx, h / ny)
        return QRectF((w - s * nx) / 2, (h - s * ny) / 2, s * nx, s * ny)

    def to_lattice(self, p: QPointF):
        r = self.lattice_rect()
        nx, ny = self.sim.config.nx, self.sim.config.ny
        return (-0.5 + (p.x() - r.left()) / r.width() * nx, -0.5 + (r.bottom() - p.y()) / r.height() * ny)

    def to_widget(self, x, y) -> QPointF:
        r = self.lattice_rect()
        nx, ny = self.sim.config.nx, self.sim.config.ny
        return QPointF(r.left() + (x + 0.5) / nx * r.width(), r.bottom() - (y + 0.5) / ny * r.height())

    def paintEvent(self, _ev):
        painter = QPainter(self)
        painter.fillRect(self.rect(), BACKGROUND)
        if self.ctx is None:       # not yet shown, or no OpenGL 3.3: a cpu_field.CpuCanvas paints over it
            painter.end()
            return
        field = self.field_image()
        if field is not None:
            image, where = field
            painter.setRenderHint(QPainter.SmoothPixmapTransform)
            painter.drawImage(where, image)
        self.overlay.paint(painter)
        painter.end()
        self.frames += 1

    def grabFramebuffer(self) -> QImage:
        """What the viewport shows (the field and its overlay), for screenshots."""
        return self.grab().toImage()

    def field_image(self):
        """(image, where): the field coloured by display.glsl into a QImage (top row first), at
        the lattice's own size or the lattice rectangle's size in device pixels, whichever is
        smaller, read back; `where` is the rectangle (logical pixels) to draw it in. The window
        stays a plain raster window, which Qt updates by copying the changed pixels only (a GL
        widget makes Qt composite the whole window on every frame), and a picture no larger
        than the lattice is cheap to colour and read back on a machine without a GPU: QPainter
        scales it up, smoothly. None before there is a field."""
        if self.sim is None or self.field_texture is None:
            return None
        dpr = self.devicePixelRatioF()
        r = self.lattice_rect()
        nx, ny = self.sim.config.nx, self.sim.config.ny
        size = (max(1, min(nx, int(round(r.width() * dpr)))), max(1, min(ny, int(round(r.height() * dpr)))))
        return self.colours.image(size, DISPLAY_MODES[self.mode], self.display_scale(), self.rho_ref), r

    def display_scale(self) -> float:
        """Lattice value -> the colour bar's unit (reference speed: the wind, or half the cap)."""
        sim = self.sim
        u = sim.params.wind if sim.params.wind > 0.005 else sim.config.max_speed / 2
        mode = DISPLAY_MODES[self.mode].shader_mode
        if mode == 1:
            return sim.params.size / u
        if mode == 2:
            return 1.0 / units.dynamic_pressure(u)   # C_p = (p - p0) / (rho U^2 / 2)
        return 1.0 / u

    # --- geometry the overlay and the mouse share -----------------------------------------------
    def body_outline_points(self, outline=None):
        """The outline in widget pixels, computed with numpy; the body's own (`outline` None) is
        kept until the body or the lattice rectangle changes (this runs in every paint)."""
        shape = self.sim.shape
        r = self.lattice_rect()
        nx, ny = self.sim.config.nx, self.sim.config.ny
        key = (r.left(), r.bottom(), r.width(), r.height(), nx, ny)
        if outline is None and self._outline_cache is not None and self._outline_cache[0] is shape \
                and self._outline_cache[1] == key:
            return self._outline_cache[2]
        pts = np.asarray(shape.outline() if outline is None else outline, float).reshape(-1, 2)
        left, bottom, w, h = key[:4]
        xs = (left + (pts[:, 0] + 0.5) * (w / nx)).tolist()
        ys = (bottom - (pts[:, 1] + 0.5) * (h / ny)).tolist()
        polygon = QPolygonF([QPointF(x, y) for x, y in zip(xs, ys)])
        if outline is None:
            self._outline_cache = (shape, key, polygon)
        return polygon

    def outlet_zone_x(self):
        """Widget x where the outlet zone begins, None without one. In the zone (the sponge's last
        `sponge_cells` columns) the fluid is thickened and, with the absorbing layer, drawn
        towards the inflow so that vortices and sound leave the tunnel: the flow there is not
        the test section's, and the line and its label tell a class so."""
        cfg = self.sim.config
        if cfg.x_boundary != "tunnel" or cfg.sponge_cells <= 0:
            return None
        return self.to_widget(cfg.nx - cfg.sponge_cells - 0.5, 0.0).x()

    # --- rotation handle ------------------------------------------------------------------------
    def turn_blocker(self):
        """What drives the body instead of the mouse (a haptic device, a motion script), or None."""
        if self.driver:
            return self.driver
        if getattr(self.sim, "runner", None) is not None:
            return "A motion script"
        return None

    def handle_geometry(self):
        """(reference point, knob centre, stalk length) in widget pixels, or None without a body."""
        sim = self.sim
        if sim is None or sim.shape is None:
            return None
        centre = self.to_widget(*sim.pos)
        reach = turn_handle.handle_reach(centre, self.body_outline_points())
        return centre, turn_handle.knob_position(centre, reach, sim.angle), reach

    def handle_shown(self) -> bool:
        """The handle shows while the pointer is near the body or turns it; never during a replay,
        a drag of the body or while the polygon editor drags a vertex."""
        if self.locked or self.sim is None or self.sim.shape is None:
            return False
        if self._grab is not None or self._edit_vertex is not None:
            return False
        return self._turn is not None or self._hover is not None

    def _hover_at(self, pos: QPointF):
        """What the pointer is over: the knob, the body, near the body (within the handle's reach)."""
        geometry = self.handle_geometry() if not self.locked else None
        if geometry is None:
            return None
        centre, knob, reach = geometry
        if math.hypot(pos.x() - knob.x(), pos.y() - knob.y()) <= turn_handle.KNOB_REACH:
            return "handle"
        if self.sim.hit(*self.to_lattice(pos)):
            return "body"
        if math.hypot(pos.x() - centre.x(), pos.y() - centre.y()) <= reach + turn_handle.NEAR:
            return "near"
        return None

    def _set_hover(self, hover):
        if hover != self._hover:
            self._hover = hover
            self.update()
        if self._turn is not None:
            self.setCursor(turn_handle.rotate_cursor())
        elif self._grab is not None:
            self.setCursor(Qt.ClosedHandCursor)
        elif hover == "handle":
            self.setCursor(Qt.ForbiddenCursor if self.turn_blocker() else turn_handle.rotate_cursor())
        elif hover == "body" and not self.editing:
            self.setCursor(Qt.OpenHandCursor)
        else:
            self.unsetCursor()

    def _pointer_degrees(self, pos: QPointF) -> float:
        return turn_handle.pointer_degrees(self.sim.pos, self.to_lattice(pos))

    def leaveEvent(self, ev):
        if self._turn is None:
            self._set_hover(None)
        super().leaveEvent(ev)

    def event(self, ev):
        """Tooltips where they help: over the handle, over the body."""
        if ev.type() == QEvent.ToolTip and self.sim is not None and not self.locked:
            hover = self._hover_at(QPointF(ev.pos()))
            text = {"handle": HANDLE_HINT, "body": MOUSE_HINT}.get(hover)
            blocker = self.turn_blocker() if hover == "handle" else None
            if blocker:
                text = f"{blocker} drives the body: the handle cannot rotate it now."
            if text:
                QToolTip.showText(ev.globalPos(), text, self)
            else:
                QToolTip.hideText()
            return True
        return super().event(ev)

    # --- editor geometry ------------------------------------------------------------------------
    def body_to_world(self, verts):
        sim = self.sim
        c, s = math.cos(sim.angle), math.sin(sim.angle)
        v = np.asarray(verts, float)
        return np.c_[sim.pos[0] + c * v[:, 0] - s * v[:, 1], sim.pos[1] + s * v[:, 0] + c * v[:, 1]]

    def world_to_body(self, x, y):
        sim = self.sim
        c, s = math.cos(sim.angle), math.sin(sim.angle)
        dx, dy = x - sim.pos[0], y - sim.pos[1]
        return (c * dx + s * dy, -s * dx + c * dy)

    def _vertex_at(self, pos: QPointF):
        if self.sim.polygon is None:
            return None
        for i, (x, y) in enumerate(self.body_to_world(self.sim.polygon)):
            c = self.to_widget(x, y)
            if abs(c.x() - pos.x()) <= 8 and abs(c.y() - pos.y()) <= 8:
                return i
        return None

    # --- mouse --------------------------------------------------------------------------------
    def cancel_drag(self):
        """Forget a drag of the body in progress (a replay takes over the view)."""
        self._grab = None

    def mousePressEvent(self, ev):
        if self.sim is None:
            return
        if self.locked:
            self.inputRefused.emit()
            return
        pos = ev.position()
        x, y = self.to_lattice(pos)
        if self.probing and ev.button() in (Qt.LeftButton, Qt.RightButton):
            self.probeClicked.emit(x, y, ev.button() == Qt.RightButton)
            return
        if self.editing and self.sim.polygon is not None:
            i = self._vertex_at(pos)
            if i is not None and ev.button() == Qt.RightButton:
                verts = [v for k, v in enumerate(self.sim.polygon) if k != i]
                self.polygonEdited.emit(verts)
                return
            if i is not None and ev.button() == Qt.LeftButton:
                self._edit_vertex = i
                self._edit_preview = [tuple(v) for v in self.sim.polygon]
                return
        hover = self._hover_at(pos)
        if ev.button() == Qt.LeftButton and hover == "handle":
            blocker = self.turn_blocker()
            if blocker:
                self.turnRefused.emit(blocker)
                return
            self._turn = turn_handle.Turn(self._pointer_degrees(pos), self.sim.target_degrees())
            self._set_hover(hover)
            return
        if ev.button() == Qt.LeftButton and self.sim.hit(x, y):
            self._grab = (self.sim.pos[0] - x, self.sim.pos[1] - y)
            self.bodyPulled.emit((x + self._grab[0], y + self._grab[1]))
            self.bodyGrabbed.emit(True)
            self._set_hover(hover)
            self.update()

    def mouseMoveEvent(self, ev):
        if self.sim is None:
            return
        x, y = self.to_lattice(ev.position())
        if self._turn is not None:
            before = self._turn.target
            target = self._turn.follow(self._pointer_degrees(ev.position()), bool(ev.modifiers() & Qt.ShiftModifier))
            if target != before:
                self.turnRequested.emit(target)
            self.update()
        elif self._edit_vertex is not None:
            self._edit_preview[self._edit_vertex] = self.world_to_body(x, y)
            self.update()
        elif self._grab is not None:
            self.bodyPulled.emit((x + self._grab[0], y + self._grab[1]))
        elif not ev.buttons():
            self._set_hover(self._hover_at(ev.position()))

    def mouseReleaseEvent(self, ev):
        if self._turn is not None:
            turn, self._turn = self._turn, None
            if turn.target != turn.before:
                self.turnFinished.emit(turn.before, turn.target)
            self._set_hover(self._hover_at(ev.position()) if self.sim is not None else None)
            self.update()
        elif self._edit_vertex is not None:
            verts, self._edit_vertex, self._edit_preview = self._edit_preview, None, None
            self.polygonEdited.emit(verts)
        elif self._grab is not None:
            self._grab = None
            self.bodyPulled.emit(None)
            self.bodyGrabbed.emit(False)
            self._set_hover(self._hover_at(ev.position()))

    def mouseDoubleClickEvent(self, ev):
        """Editor: a double click adds a vertex on the nearest edge."""
        if self.locked:
            return
        if not (self.editing and self.sim is not None and self.sim.polygon is not None):
            return
        x, y = self.to_lattice(ev.position())
        bx, by = self.world_to_body(x, y)
        v = np.asarray(self.sim.polygon, float)
        a, b = v, np.roll(v, -1, axis=0)
        ab = b - a
        t = np.clip(((bx - a[:, 0]) * ab[:, 0] + (by - a[:, 1]) * ab[:, 1]) / np.maximum((ab ** 2).sum(1), 1e-12), 0, 1)
        d = np.hypot(a[:, 0] + t * ab[:, 0] - bx, a[:, 1] + t * ab[:, 1] - by)
        k = int(np.argmin(d))
        verts = [tuple(p) for p in v]
        verts.insert(k + 1, (bx, by))
        self.polygonEdited.emit(verts)

    def wheelEvent(self, ev):
        if self.sim is None:
            return
        if self.locked:
            self.inputRefused.emit()
            ev.accept()
            return
        self.wheelTurned.emit(WHEEL_DEG_PER_NOTCH * ev.angleDelta().y() / 120.0)
        ev.accept()
