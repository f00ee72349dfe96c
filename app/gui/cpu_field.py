"""The flow field drawn without OpenGL 3.3: the window's fallback where the driver offers no
3.3 core context, or no OpenGL at all (app/gui/first_start.py). The same colouring as
shaders/display.glsl, in numpy, painted with QPainter on a plain widget laid over the viewport;
the overlays (body, arrows, colour bar) are the viewport's own.
"""
from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import QEvent, QObject, QRectF, Qt, QTimer
from PySide6.QtGui import QColor, QImage, QPainter
from PySide6.QtWidgets import QApplication, QWidget

from feelflow.solver.lattice import CS2

BACKGROUND = QColor(41, 43, 48)   # display.glsl's clear colour (0.16, 0.17, 0.19)
_luts: dict[str, np.ndarray] = {}


def lut(name: str) -> np.ndarray:
    """256 x 3 uint8 colours of the named pyqtgraph colormap."""
    if name not in _luts:
        _luts[name] = np.ascontiguousarray(pg.colormap.get(name).getLookupTable(0.0, 1.0, 256, alpha=False), np.uint8)
    return _luts[name]


def field_colours(rgba: np.ndarray, mode: int, scale: float, value_range, rho_ref: float, colours) -> np.ndarray:
    """(ny, nx, 4) (rho, ux, uy, vorticity) -> (ny, nx, 3) uint8, as display.glsl colours it:
    mode 0 speed, 1 vorticity, 2 pressure c_s^2 (rho - rho_ref), 3 speed faded (tracers);
    non-finite nodes grey."""
    f = np.asarray(rgba, np.float32)
    if mode == 1:
        v = f[..., 3]
    elif mode == 2:
        v = CS2 * (f[..., 0] - rho_ref)
    else:
        v = np.hypot(f[..., 1], f[..., 2])
    lo, hi = value_range
    with np.errstate(invalid="ignore", over="ignore"):
        s = np.clip((v * scale - lo) / (hi - lo), 0.0, 1.0)
    bad = ~np.isfinite(f).all(axis=-1)
    index = np.where(bad, 0, np.rint(np.nan_to_num(s) * 255)).astype(np.intp)
    out = colours[index].astype(np.float32)
    if mode == 3:
        out = 0.3 * out + 0.7 * 245.0
    out[bad] = 128.0
    return np.rint(out).astype(np.uint8)


def paint(viewport, rgba: np.ndarray | None, device) -> None:
    """Paint the field `rgba` of `viewport` (app.gui.viewport.Viewport) and its overlays on
    `device`, a widget of the viewport's size."""
    from feelflow.app.gui.display_modes import DISPLAY_MODES

    p = QPainter(device)
    p.fillRect(device.rect(), BACKGROUND)
    if viewport.sim is not None and rgba is not None:
        mode = DISPLAY_MODES[viewport.mode]
        rgb = field_colours(rgba, mode.shader_mode, viewport.display_scale(), mode.range, viewport.rho_ref,
                            lut(mode.colormap))
        rgb = np.ascontiguousarray(rgb[::-1])          # lattice row 0 is the bottom of the picture
        ny, nx = rgb.shape[:2]
        image = QImage(rgb.data, nx, ny, 3 * nx, QImage.Format_RGB888)
        p.setRenderHint(QPainter.SmoothPixmapTransform)
        p.drawImage(QRectF(viewport.lattice_rect()), image)
        viewport.overlay.paint(p)
    p.end()
    viewport.frames += 1


class CpuCanvas(QWidget):
    """A raster widget that paints what the viewport's GL would have.

    Over the viewport (`stand_in=False`: Qt has an OpenGL context, below 3.3) it is the
    viewport's child, transparent to the mouse. Where Qt has no OpenGL at all the canvas takes
    the viewport's place (`stand_in=True`, before the window shows, so that the viewport never
    tries to make a context): the viewport leaves the window, hidden, keeps the canvas' size,
    and gets the canvas' mouse, wheel and key events."""

    FORWARD = {QEvent.MouseButtonPress, QEvent.MouseButtonRelease, QEvent.MouseMove, QEvent.MouseButtonDblClick,
               QEvent.Wheel, QEvent.Leave, QEvent.Enter, QEvent.HoverMove, QEvent.KeyPress, QEvent.KeyRelease}

    def __init__(self, viewport, stand_in: bool = False):
        super().__init__(None if stand_in else viewport)
        self.viewport = viewport
        self.stand_in = stand_in
        self.setObjectName("cpu-canvas")
        self.setAttribute(Qt.WA_OpaquePaintEvent)
        viewport.cpu_canvas = self
        if stand_in:
            self.setMinimumSize(viewport.minimumSize())
            self.setMouseTracking(True)
            self.setFocusPolicy(Qt.StrongFocus)
        else:
            self.setAttribute(Qt.WA_TransparentForMouseEvents)
            self._follow = _FollowSize(self)
            viewport.installEventFilter(self._follow)
            self.setGeometry(viewport.rect())
            self.show()
        self._timer = QTimer(self)   # overlays move without a new field (a paused tunnel, editing)
        self._timer.timeout.connect(self.update)
        self._timer.start(50)

    def paintEvent(self, _ev):
        paint(self.viewport, self.viewport.cpu_rgba, self)

    def resizeEvent(self, ev):
        if self.stand_in:
            self.viewport.resize(self.size())
        super().resizeEvent(ev)

    def event(self, ev):
        if self.stand_in and ev.type() in self.FORWARD:
            QApplication.sendEvent(self.viewport, ev)
            self.setCursor(self.viewport.cursor())
            return True
        return super().event(ev)


class _FollowSize(QObject):
    def __init__(self, canvas):
        super().__init__(canvas)
        self.canvas = canvas

    def eventFilter(self, obj, ev):
        if ev.type() == QEvent.Resize:
            self.canvas.setGeometry(obj.rect())
        return False
