"""The flow field drawn without OpenGL 3.3: the window's fallback where the driver offers no
3.3 core context (app/gui/first_start.py). The same colouring as shaders/display.glsl, in numpy,
painted with QPainter; the overlays (body, arrows, colour bar) are the viewport's own.
"""
from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import QRectF
from PySide6.QtGui import QColor, QImage, QPainter

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


def paint(viewport, rgba: np.ndarray | None) -> None:
    """Paint `viewport` (app.gui.viewport.Viewport) with the field `rgba` and its overlays."""
    from feelflow.app.gui.viewport import DISPLAY_MODES

    p = QPainter(viewport)
    p.fillRect(viewport.rect(), BACKGROUND)
    if viewport.sim is not None and rgba is not None:
        mode = DISPLAY_MODES[viewport.mode]
        rgb = field_colours(rgba, mode.shader_mode, viewport.display_scale(), mode.range, viewport.rho_ref,
                            lut(mode.colormap))
        rgb = np.ascontiguousarray(rgb[::-1])          # lattice row 0 is the bottom of the picture
        ny, nx = rgb.shape[:2]
        image = QImage(rgb.data, nx, ny, 3 * nx, QImage.Format_RGB888)
        p.setRenderHint(QPainter.SmoothPixmapTransform)
        p.drawImage(QRectF(viewport.lattice_rect()), image)
        viewport._paint_overlay(p)
    p.end()
    viewport.frames += 1
