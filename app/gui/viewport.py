"""The wind tunnel view: a plain (raster) widget that draws the flow field coloured on the GPU
(app/gui/field_colours.py: an OpenGL context of its own on an offscreen surface, the picture
read back) with QPainter, the overlay (app/gui/overlay.py: body, force arrows, tracers, colour
bar, notes, the polygon editor's handles and the rotation handle) painted on top, and the
lattice's place in the widget. The mouse (dragging the body, the polygon editor, the rotation
handle, the wheel) is app/gui/view_mouse.py's; its requests leave as this widget's signals. The
gl solver runs on the same context (`makeCurrent`).
"""
from __future__ import annotations

import math

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QImage, QPainter, QPolygonF
from PySide6.QtWidgets import QWidget

from feelflow.app.gui.cpu_field import BACKGROUND
from feelflow.app.gui.display_modes import COLOUR_BAR_MARGIN, DISPLAY_MODES
from feelflow.app.gui.field_colours import FieldColours
from feelflow.app.gui.overlay import Overlay
from feelflow.app.gui.view_mouse import ViewMouse
from feelflow.app.model.tunnel import TunnelModel
from feelflow.solver import units


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
        self.driver = None             # what else drives the body ("The haptic device"), set by the window
        self.cpu_canvas = None         # without OpenGL 3.3: the cpu_field.CpuCanvas that draws the field
        self.cpu_rgba = None           # and the field it draws, (ny, nx, 4) float32
        self.mouse = ViewMouse(self)   # dragging, the polygon editor, the turn handle, the wheel
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

    def makeCurrent(self):
        """The viewport's GL context current (the gl solver draws with it too)."""
        self.colours.make_current()

    def renderer(self) -> str:
        return self.colours.renderer()

    def upload_field(self, rgba: np.ndarray):
        """numpy path: (ny, nx, 4) float32 (rho, ux, uy, vorticity) to draw."""
        if self.ctx is None:       # no OpenGL 3.3: cpu_field.CpuCanvas colours it on the CPU
            self.cpu_rgba = rgba
            self.cpu_canvas.update()   # a CpuCanvas (first_start.run_on_cpu)
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

    # --- the mouse (app/gui/view_mouse.py) -------------------------------------------------------
    @property
    def edit_preview(self):
        """The polygon's vertices (body frame) while the editor drags one, else None."""
        return self.mouse.edit_preview

    @property
    def turn(self):
        """The handle's drag in progress (turn_handle.Turn), or None."""
        return self.mouse.turn

    @property
    def hover(self):
        """What the pointer is over: "handle", "body" or "near", or None."""
        return self.mouse.hover

    def turn_blocker(self):
        """What drives the body instead of the mouse (a haptic device, a motion script), or None."""
        return self.mouse.turn_blocker()

    def handle_geometry(self):
        """(reference point, knob centre, stalk length) in widget pixels, or None without a body."""
        return self.mouse.handle_geometry()

    def handle_shown(self) -> bool:
        """Whether the turn handle shows (ViewMouse.handle_shown)."""
        return self.mouse.handle_shown()

    def cancel_drag(self):
        """Forget a drag of the body in progress (a replay takes over the view)."""
        self.mouse.cancel_drag()

    def event(self, ev):
        return True if self.mouse.tooltip(ev) else super().event(ev)

    def leaveEvent(self, ev):
        self.mouse.leave()
        super().leaveEvent(ev)

    def mousePressEvent(self, ev):
        self.mouse.press(ev)

    def mouseMoveEvent(self, ev):
        self.mouse.move(ev)

    def mouseReleaseEvent(self, ev):
        self.mouse.release(ev)

    def mouseDoubleClickEvent(self, ev):
        self.mouse.double_click(ev)

    def wheelEvent(self, ev):
        self.mouse.wheel(ev)
