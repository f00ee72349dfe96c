"""The wind tunnel view: a QOpenGLWidget whose moderngl context colours the flow field
(shaders/display*.glsl, colormaps from pyqtgraph), with the body, its force arrows, tracers,
the colour bar, the polygon editor's handles and the rotation handle (app/turn_handle.py)
painted on top with QPainter.

GL pitfalls handled here (shared/notes/gl-qt-on-this-machine.md): detect_framebuffer in every
paintGL, enable_only(NOTHING) before any pass, every texture bound before every draw.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import moderngl
import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import QEvent, QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QBrush, QColor, QFont, QLinearGradient, QPainter, QPen, QPolygonF
from PySide6.QtOpenGLWidgets import QOpenGLWidget
from PySide6.QtWidgets import QToolTip

from feelflow.app.gui import turn_handle
from feelflow import SHADER_DIR
from feelflow.solver import units
from feelflow.solver.lattice import glsl_constants



@dataclass(frozen=True)
class DisplayMode:
    label: str
    colormap: str
    shader_mode: int
    range: tuple[float, float]
    unit: str           # what the colour bar's numbers mean


DISPLAY_MODES = {
    "speed": DisplayMode("Speed", "viridis", 0, (0.0, 1.6), "speed\n\u00f7 wind speed"),
    "vorticity": DisplayMode("Vorticity", "CET-D1", 1, (-4.0, 4.0), "vorticity\n\u00d7 D \u00f7 U"),
    "pressure": DisplayMode("Pressure", "CET-D1", 2, (-1.5, 1.5), "pressure\ncoefficient Cp"),
    "tracers": DisplayMode("Tracers", "viridis", 3, (0.0, 1.6), "speed\n\u00f7 wind speed"),
}

BODY_FILL = QColor(225, 225, 225)
BODY_EDGE = QColor(20, 20, 20)
DRAG_COLOUR = QColor(230, 40, 40)
LIFT_COLOUR = QColor(40, 120, 255)
COLOUR_BAR_MARGIN = 132  # pixels on the right kept for the colour bar
#: the dashed line where the outlet zone (the sponge, docs/algorithm.md step 3) begins
OUTLET_LINE = QColor(255, 255, 255, 150)
WHEEL_DEG_PER_NOTCH = 2.0  # one notch of the mouse wheel (120 eighths of a degree) turns the body this far
MOUSE_HINT = ("Drag the body to move it; drag its round handle or turn the mouse wheel to rotate it "
              "(hold Shift for 15\u00b0 steps).")
HANDLE_HINT = "Drag to rotate the body about its reference point (Shift: 15\u00b0 steps); the mouse wheel rotates it too."


def load_shader(name: str) -> str:
    """A GLSL file from shaders/, with the lattice constants injected where `// @LATTICE` stands."""
    return (SHADER_DIR / name).read_text().replace("// @LATTICE", glsl_constants())


class Viewport(QOpenGLWidget):
    """Shows `sim` (an app.simulation.Simulation, set by the window once the context exists)."""

    contextReady = Signal(object)   # the moderngl.Context, once initializeGL ran
    bodyGrabbed = Signal(bool)
    polygonEdited = Signal(object)  # new vertex list (body frame) from the editor handles
    inputRefused = Signal()         # a press or wheel turn while `locked` (a replay shows)
    turnRequested = Signal(float)   # the rotation handle asks for this body angle (degrees, any turns)
    turnFinished = Signal(float, float)   # one drag of the handle: angle before and after (degrees)
    wheelTurned = Signal(float)     # the wheel asks to turn the body by this many degrees
    turnRefused = Signal(str)       # the handle was pressed while this (a device, a script) drives the body

    def __init__(self, parent=None):
        super().__init__(parent)
        self.sim = None
        self.ctx = None
        self.mode = "speed"
        self.show_arrows = True
        self.editing = False
        self.body_edge = None    # a QColor for the body's outline instead of BODY_EDGE, or None
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
        self.setMinimumSize(480, 260)
        self.setMouseTracking(True)    # the handle appears when the pointer comes near the body
        self.setFocusPolicy(Qt.StrongFocus)

    # --- GL ---------------------------------------------------------------------------------
    contextFailed = Signal(str)     # no usable OpenGL 3.3: one line for the user

    def initializeGL(self):
        try:
            self.ctx = moderngl.create_context(require=330)
        except Exception as exc:   # moderngl.Error and friends: say so, never a traceback
            self.ctx = None
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
        if self.ctx is None:
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
        self._paint_overlay(painter)
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

    # --- overlay ------------------------------------------------------------------------------
    def _paint_overlay(self, p: QPainter):
        if self.sim is None:
            return
        p.setRenderHint(QPainter.Antialiasing)
        if self.mode == "tracers" and self.tracers is not None:
            self._paint_tracers(p)
        self._paint_outlet_zone(p)
        self._paint_body(p)
        self._paint_turn_handle(p)
        if self.show_arrows and self.arrow_forces and self.sim.shape is not None:
            self._paint_arrows(p)
        self._paint_colour_bar(p)
        self._paint_notes(p)

    def body_outline_points(self, outline=None):
        """The outline in widget pixels: `to_widget` with the lattice rectangle computed once,
        not once per point (this runs in every paint)."""
        pts = self.sim.shape.outline() if outline is None else outline
        r = self.lattice_rect()
        nx, ny = self.sim.config.nx, self.sim.config.ny
        left, bottom, w, h = r.left(), r.bottom(), r.width(), r.height()
        return QPolygonF([QPointF(left + (x + 0.5) / nx * w, bottom - (y + 0.5) / ny * h) for x, y in pts])

    def _paint_body(self, p: QPainter):
        sim = self.sim
        if sim.shape is None:   # a replayed session that removed its body
            return
        if sim.target is not None and not sim.hold_still:
            a, b = self.to_widget(*sim.pos), self.to_widget(*sim.target)
            p.setPen(QPen(QColor(255, 255, 255, 200), 2, Qt.DashLine))
            p.drawLine(a, b)
            p.setBrush(Qt.NoBrush)
            p.drawEllipse(b, 6, 6)
        # an exercise marks a body that breaks a constraint (app/gui/exercise_controller.py)
        p.setPen(QPen(self.body_edge or BODY_EDGE, 2.5, Qt.DashLine if self.body_edge else Qt.SolidLine))
        p.setBrush(QBrush(BODY_FILL))
        p.drawPolygon(self.body_outline_points())
        if self.editing and sim.polygon is not None:
            verts = self._edit_preview if self._edit_preview is not None else sim.polygon
            world = self.body_to_world(verts)
            p.setPen(QPen(QColor(255, 200, 0), 1.5, Qt.DashLine))
            p.setBrush(Qt.NoBrush)
            p.drawPolygon(self.body_outline_points(world))
            p.setPen(QPen(Qt.black, 1.5))
            p.setBrush(QBrush(QColor(255, 200, 0)))
            for x, y in world:
                c = self.to_widget(x, y)
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
        font = QFont(self.font())
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
        """Drag (along the relative wind) and lift (across it), length = coefficient x size / 2."""
        sim = self.sim
        centre = self.to_widget(*sim.pos)
        px_per_cell = self.lattice_rect().width() / sim.config.nx
        u = max(sim.params.wind, sim.config.max_speed / 2)
        ref = 0.5 * u * u * sim.params.size
        cap = 2.5 * sim.params.size
        for key, colour in (("drag", DRAG_COLOUR), ("lift", LIFT_COLOUR)):
            fx, fy = self.arrow_forces[key]
            coeff_len = math.hypot(fx, fy) / ref * sim.params.size * 0.5
            if coeff_len > cap:
                fx, fy = fx * cap / coeff_len, fy * cap / coeff_len
                coeff_len = cap
            if not math.isfinite(coeff_len):
                continue
            vec = (fx / ref * sim.params.size * 0.5 * px_per_cell, -fy / ref * sim.params.size * 0.5 * px_per_cell)
            self._arrow(p, centre, vec, colour, key)

    def _paint_colour_bar(self, p: QPainter):
        """The colour bar, drawn once per mode and size into a pixmap, then blitted each frame."""
        key = (self.mode, self.width(), self.height(), self.sim.config.nx, self.sim.config.ny)
        if getattr(self, "_bar_key", None) != key:
            from PySide6.QtGui import QPixmap

            pixmap = QPixmap(COLOUR_BAR_MARGIN, self.height())
            pixmap.fill(QColor(41, 43, 48))
            painter = QPainter(pixmap)
            painter.setRenderHint(QPainter.Antialiasing)
            painter.translate(-(self.width() - COLOUR_BAR_MARGIN), 0)
            self._draw_colour_bar(painter)
            painter.end()
            self._bar_pixmap, self._bar_key = pixmap, key
        p.drawPixmap(self.width() - COLOUR_BAR_MARGIN, 0, self._bar_pixmap)

    def _draw_colour_bar(self, p: QPainter):
        mode = DISPLAY_MODES[self.mode]
        r = self.lattice_rect()
        x = self.width() - COLOUR_BAR_MARGIN + 22
        top, bottom = max(40.0, r.top() + 30), min(self.height() - 20.0, r.bottom() - 10)
        if bottom - top < 60:
            top, bottom = 30.0, self.height() - 10.0
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
        font = QFont(self.font())
        font.setPixelSize(15)
        p.setFont(font)
        lo, hi = mode.range
        for v in np.linspace(lo, hi, 5):
            y = bottom - (v - lo) / (hi - lo) * (bottom - top)
            p.drawLine(QPointF(x + 20, y), QPointF(x + 25, y))
            p.drawText(QPointF(x + 28, y + 5), f"{v:g}".replace("-", "\u2212"))
        font.setBold(True)
        p.setFont(font)
        p.drawText(QRectF(x - 22, 4, COLOUR_BAR_MARGIN - 2, top - 8), Qt.AlignLeft | Qt.AlignBottom | Qt.TextWordWrap,
                   mode.unit)

    def outlet_zone_x(self):
        """Widget x where the outlet zone begins, None without one. In the zone (the sponge's last
        `sponge_cells` columns) the fluid is thickened and, with the absorbing layer, drawn
        towards the inflow so that vortices and sound leave the tunnel: the flow there is not
        the test section's, and the line and its label tell a class so."""
        cfg = self.sim.config
        if cfg.x_boundary != "tunnel" or cfg.sponge_cells <= 0:
            return None
        return self.to_widget(cfg.nx - cfg.sponge_cells - 0.5, 0.0).x()

    def _paint_outlet_zone(self, p: QPainter):
        x = self.outlet_zone_x()
        if x is None:
            return
        r = self.lattice_rect()
        p.setPen(QPen(OUTLET_LINE, 1.5, Qt.DashLine))
        p.drawLine(QPointF(x, r.top()), QPointF(x, r.bottom()))
        self._label(p, QPointF(x + 6, r.bottom() - 8), "outlet zone", QColor(230, 230, 230), size=12,
                    box=QColor(0, 0, 0, 110))

    def _paint_notes(self, p: QPainter):
        sim = self.sim
        r = self.lattice_rect()
        notes = [(self.banner, QColor(255, 230, 120))] if self.banner else []
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
            notes.append((f"wind {sim.params.wind:.3f} (speed {stage + 1} of {len(sim.sweep[0])})", QColor(255, 255, 255)))
        for i, (text, colour) in enumerate(notes):
            self._label(p, QPointF(r.left() + 10, r.top() + 24 + 20 * i), text, colour, size=15)

    def _paint_tracers(self, p: QPainter):
        pts, prev = self.tracers
        p.setPen(QPen(QColor(20, 40, 120), 1.6, Qt.SolidLine, Qt.FlatCap))
        r = self.lattice_rect()
        nx, ny = self.sim.config.nx, self.sim.config.ny
        sx, sy = r.width() / nx, r.height() / ny
        x0, y0 = r.left() + 0.5 * sx, r.bottom() - 0.5 * sy
        lines = [QPointF(x0 + a * sx, y0 - b * sy) for a, b in np.stack([prev, pts], 1).reshape(-1, 2).tolist()]
        p.setRenderHint(QPainter.Antialiasing, False)   # ~900 short streaks: plain lines are much cheaper
        p.drawLines(lines)
        p.setRenderHint(QPainter.Antialiasing, True)

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

    def _paint_turn_handle(self, p: QPainter):
        if not self.handle_shown():
            return
        centre, knob, reach = self.handle_geometry()
        turn = self._turn
        if turn is not None and abs(math.radians(turn.target) - self.sim.angle) > 1e-3:
            target = turn_handle.knob_position(centre, reach, math.radians(turn.target))
            turn_handle.paint_turn_target(p, centre, target)
        state = "refused" if self.turn_blocker() else "active" if turn is not None or self._hover == "handle" else "idle"
        turn_handle.paint_handle(p, centre, knob, state)
        if turn is not None:
            shown = (turn.target + 180.0) % 360.0 - 180.0
            ux, uy = (knob.x() - centre.x()) / reach, (knob.y() - centre.y()) / reach
            at = QPointF(knob.x() + 16 * ux - (38 if ux < -0.3 else 0 if ux > 0.3 else 18), knob.y() + 16 * uy + 6)
            self._label(p, at, f"{shown:.0f}\u00b0".replace("-", "\u2212"))   # beyond the knob, off the stalk

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
            self.sim.target = (x + self._grab[0], y + self._grab[1])
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
            self.sim.target = (x + self._grab[0], y + self._grab[1])
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
            self.sim.target = None
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
