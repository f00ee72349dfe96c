"""The wind tunnel view: a QOpenGLWidget whose moderngl context colours the flow field
(shaders/display*.glsl, colormaps from pyqtgraph), with the overlay (app/gui/overlay.py: body,
force arrows, tracers, colour bar, notes, the polygon editor's handles and the rotation handle)
painted on top with QPainter; and the mouse: dragging the body, the polygon editor, the
rotation handle (app/gui/turn_handle.py) and the wheel, each a signal to the window.

GL pitfalls handled here: detect_framebuffer in every paintGL, enable_only(NOTHING) before any
pass, every texture bound before every draw.
"""
from __future__ import annotations

import math

import moderngl
import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import QEvent, QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QPainter, QPolygonF
from PySide6.QtOpenGLWidgets import QOpenGLWidget
from PySide6.QtWidgets import QToolTip

from feelflow import SHADER_DIR
from feelflow.app.gui import turn_handle
from feelflow.app.gui.first_start import required_gl
from feelflow.app.gui.display_modes import COLOUR_BAR_MARGIN, DISPLAY_MODES
from feelflow.app.gui.overlay import Overlay
from feelflow.app.model.tunnel import TunnelModel
from feelflow.solver import units
from feelflow.solver.lattice import glsl_constants

WHEEL_DEG_PER_NOTCH = 2.0  # one notch of the mouse wheel (120 eighths of a degree) turns the body this far
MOUSE_HINT = ("Drag the body to move it; drag its round handle or turn the mouse wheel to rotate it "
              "(hold Shift for 15\u00b0 steps).")
HANDLE_HINT = "Drag to rotate the body about its reference point (Shift: 15\u00b0 steps); the mouse wheel rotates it too."


def load_shader(name: str) -> str:
    """A GLSL file from shaders/, with the lattice constants injected where `// @LATTICE` stands."""
    return (SHADER_DIR / name).read_text().replace("// @LATTICE", glsl_constants())


class Viewport(QOpenGLWidget):
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

    def __init__(self, parent=None):
        super().__init__(parent)
        self.sim: TunnelModel | None = None
        self.ctx = None
        self.mode = "speed"
        self.show_arrows = True
        self.editing = False
        self.body_edge = None    # a QColor for the body's outline instead of the usual, or None
        self.arrow_forces = None       # {"drag": (fx, fy), "lift": (fx, fy)} lattice units
        self.tracers = None
        self.frames = 0
        self.field_texture = None
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
        self.setMinimumSize(480, 260)
        self.setMouseTracking(True)    # the handle appears when the pointer comes near the body
        self.setFocusPolicy(Qt.StrongFocus)

    # --- GL ---------------------------------------------------------------------------------
    contextFailed = Signal(str)     # no usable OpenGL 3.3: one line for the user

    def initializeGL(self):
        try:
            self.ctx = moderngl.create_context(require=required_gl())
        except Exception as exc:   # moderngl.Error and friends: say so, never a traceback
            self.ctx = None        # the window then draws on the CPU (app/gui/cpu_field.py)
            self.contextFailed.emit(f"OpenGL 3.3 is not available here ({str(exc).splitlines()[0]})")
            return
        self._init_programs()

    def _init_programs(self):
        self.program = self.ctx.program(vertex_shader=load_shader("display_vertex.glsl"),
                                        fragment_shader=load_shader("display.glsl"))
        self.vao = self.ctx.vertex_array(self.program, [])
        self._align_texture = self.ctx.texture((1, 1), 4, dtype="f1")
        self._sampler = self.ctx.sampler(filter=(moderngl.LINEAR, moderngl.LINEAR), repeat_x=False, repeat_y=False)
        self._lut = None
        self._lut_name = None
        self.contextReady.emit(self.ctx)

    def renderer(self) -> str:
        return self.ctx.info.get("GL_RENDERER", "?") if self.ctx else "no GL"

    def _ensure_lut(self, name):
        if self._lut_name == name:
            return
        table = pg.colormap.get(name).getLookupTable(0.0, 1.0, 256, alpha=True).astype("u1")
        if self._lut is None:
            self._lut = self.ctx.texture((256, 1), 4, dtype="f1")
            self._lut.repeat_x = self._lut.repeat_y = False
        self._lut.write(np.ascontiguousarray(table).tobytes(), alignment=4)
        self._lut_name = name

    def upload_field(self, rgba: np.ndarray):
        """numpy path: copy (ny, nx, 4) float32 (rho, ux, uy, vorticity) into the field texture."""
        if self.ctx is None:       # no OpenGL 3.3: cpu_field.CpuCanvas colours it on the CPU
            self.cpu_rgba = rgba
            self.cpu_canvas.update()   # set by first_start.run_on_cpu
            return
        ny, nx = rgba.shape[:2]
        tex = self.field_texture
        if tex is None or tex.size != (nx, ny) or getattr(self, "_own_texture", False) is False:
            self._own_texture = True
            self.field_texture = tex = self.ctx.texture((nx, ny), 4, dtype="f4")
            tex.repeat_x = tex.repeat_y = False
        tex.write(np.ascontiguousarray(rgba, np.float32).tobytes(), alignment=4)

    def use_texture(self, texture):
        """gl path: draw the solver's own field texture."""
        self._own_texture = False
        self.field_texture = texture

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

    def paintGL(self):
        if self.ctx is None:       # no OpenGL 3.3: a cpu_field.CpuCanvas paints over the viewport
            return
        painter = QPainter(self)
        painter.beginNativePainting()   # Qt's GL state is saved; moderngl draws the field
        try:
            self._draw_field()
        finally:
            # moderngl leaves GL_UNPACK_ALIGNMENT at 1 after the solver's uploads; Qt's glyph
            # cache assumes the default 4 (garbled text otherwise): a 1-texel write restores it
            self._align_texture.write(b"\0\0\0\0", alignment=4)
            painter.endNativePainting()
        self.overlay.paint(painter)
        painter.end()
        self.frames += 1

    def _draw_field(self):
        ctx = self.ctx
        ctx.enable_only(moderngl.NOTHING)
        fbo = ctx.detect_framebuffer(self.defaultFramebufferObject())
        fbo.use()
        dpr = self.devicePixelRatioF()
        full = (0, 0, int(self.width() * dpr), int(self.height() * dpr))
        ctx.viewport = full
        ctx.clear(0.16, 0.17, 0.19, 1.0)
        if self.sim is None or self.field_texture is None:
            return
        mode = DISPLAY_MODES[self.mode]
        self._ensure_lut(mode.colormap)
        r = self.lattice_rect()
        ctx.viewport = (int(round(r.left() * dpr)), int(round((self.height() - r.bottom()) * dpr)),
                        int(round(r.width() * dpr)), int(round(r.height() * dpr)))
        self.field_texture.use(0)
        self._sampler.use(0)          # smooth, without changing the solver's own texture
        self._lut.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self._lut.use(1)
        self.program["field"] = 0
        self.program["lut"] = 1
        self.program["mode"] = mode.shader_mode
        self.program["scale"] = self.display_scale()
        self.program["range"] = mode.range
        self.program["rho_ref"] = self.rho_ref
        self.vao.render(moderngl.TRIANGLE_STRIP, vertices=4)
        ctx.viewport = full

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
        """The outline in widget pixels: `to_widget` with the lattice rectangle computed once,
        not once per point (this runs in every paint)."""
        pts = self.sim.shape.outline() if outline is None else outline
        r = self.lattice_rect()
        nx, ny = self.sim.config.nx, self.sim.config.ny
        left, bottom, w, h = r.left(), r.bottom(), r.width(), r.height()
        return QPolygonF([QPointF(left + (x + 0.5) / nx * w, bottom - (y + 0.5) / ny * h) for x, y in pts])

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
