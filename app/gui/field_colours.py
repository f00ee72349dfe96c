"""The flow field coloured on the GPU for the viewport (app/gui/viewport.py): an OpenGL context
of its own on an offscreen surface, the moderngl context on it (the gl solver runs on the same
one), the field texture (the numpy path's upload, or the gl solver's own texture), and
display.glsl colouring it through a pyqtgraph colormap into a picture read back as a QImage.

Why read back instead of a QOpenGLWidget: with one in the window, Qt composites the whole window
through OpenGL on every frame; on a machine without a GPU (llvmpipe) that took half or more of
each frame (docs/science/performance.md, "The window"). Reading back the coloured field (a few
MB a frame) costs far less, and on a GPU the frame already waits for the solver's own read-back.

GL rules kept here: enable_only(NOTHING) before any pass, every texture bound before every draw.
"""
from __future__ import annotations

import sys

import moderngl
import numpy as np
import pyqtgraph as pg
from PySide6.QtGui import QImage, QOffscreenSurface, QOpenGLContext

from feelflow.app.gui.first_start import required_gl
from feelflow.solver.gl_programs import create_program

LITTLE_ENDIAN = sys.byteorder == "little"


def display_program(ctx):
    """The display program (shaders/display_vertex.glsl + display.glsl) on `ctx`, loaded as
    every shader is (solver/gl_programs.py: the lattice constants injected, the driver's line
    numbers kept, a compile error a ShaderError naming the file and line)."""
    return create_program(ctx, "display_vertex.glsl", "display.glsl")


class FieldColours:
    """The GL side of the viewport: its context (`ctx`, None until `create` or where there is
    no OpenGL 3.3), the field texture drawn (`field_texture`), and the colouring pass."""

    def __init__(self, owner):
        self._owner = owner            # the QObject the Qt context and surface belong to
        self.ctx = None
        self.field_texture = None
        self._own_texture = False      # the texture is ours (numpy path), not the gl solver's
        self._gl = self._surface = None   # the QOpenGLContext and its offscreen surface
        self._program = self._vao = self._sampler = None
        self._lut = None
        self._lut_name = None
        self._image_fbo = None         # where display.glsl colours the field
        self._pixels = None

    def create(self):
        """An OpenGL context on an offscreen surface (the default surface format,
        app/cli/commands/gui.py) and the moderngl context on it; raises (RuntimeError,
        moderngl.Error) where there is none of OpenGL 3.3, leaving `ctx` None. Then `prepare`."""
        gl = QOpenGLContext(self._owner)
        surface = QOffscreenSurface(None, self._owner)
        if not gl.create():
            raise RuntimeError("Qt could not create an OpenGL context")
        surface.setFormat(gl.format())
        surface.create()
        if not gl.makeCurrent(surface):
            raise RuntimeError("Qt could not make its OpenGL context current")
        self._gl, self._surface = gl, surface
        self.ctx = moderngl.create_context(require=required_gl())

    def prepare(self):
        """The display program and its sampler on the context (a shader error is a ShaderError)."""
        ctx = self.ctx
        self._program = display_program(ctx)
        self._vao = ctx.vertex_array(self._program, [])
        self._sampler = ctx.sampler(filter=(moderngl.LINEAR, moderngl.LINEAR), repeat_x=False, repeat_y=False)
        self._lut = self._lut_name = None

    def make_current(self):
        """The context current (the gl solver draws with it too)."""
        if self._gl is not None:
            self._gl.makeCurrent(self._surface)

    def renderer(self) -> str:
        return self.ctx.info.get("GL_RENDERER", "?") if self.ctx else "no GL"

    def upload(self, rgba: np.ndarray):
        """numpy path: copy (ny, nx, 4) float32 (rho, ux, uy, vorticity) into our field texture."""
        ny, nx = rgba.shape[:2]
        tex = self.field_texture
        if tex is None or tex.size != (nx, ny) or not self._own_texture:
            self._own_texture = True
            self.field_texture = tex = self.ctx.texture((nx, ny), 4, dtype="f4")
            tex.repeat_x = tex.repeat_y = False
        tex.write(np.ascontiguousarray(rgba, np.float32).tobytes(), alignment=4)

    def use_texture(self, texture):
        """gl path: draw the solver's own field texture."""
        self._own_texture = False
        self.field_texture = texture

    def _ensure_lut(self, name):
        if self._lut_name == name:
            return
        table = pg.colormap.get(name).getLookupTable(0.0, 1.0, 256, alpha=True).astype("u1")
        if self._lut is None:
            self._lut = self.ctx.texture((256, 1), 4, dtype="f1")
            self._lut.repeat_x = self._lut.repeat_y = False
        self._lut.write(np.ascontiguousarray(table).tobytes(), alignment=4)
        self._lut_name = name

    def image(self, size: tuple[int, int], mode, scale: float, rho_ref: float) -> QImage:
        """The field texture coloured at `size` (pixels) in display `mode` (display_modes.py:
        its colormap, shader mode and range; `scale` turns lattice values into the colour bar's
        unit, `rho_ref` is the pressure view's free-stream density), read back into a QImage
        whose first row is the lattice's top."""
        ctx = self.ctx
        self.make_current()
        ctx.enable_only(moderngl.NOTHING)
        if self._image_fbo is None or self._image_fbo.size != size:
            if self._image_fbo is not None:
                self._image_fbo.color_attachments[0].release()
                self._image_fbo.release()
            self._image_fbo = ctx.framebuffer(color_attachments=[ctx.texture(size, 4, dtype="f1")])
            self._pixels = bytearray(size[0] * size[1] * 4)
        self._image_fbo.use()
        ctx.viewport = (0, 0, *size)
        self._ensure_lut(mode.colormap)
        self.field_texture.use(0)
        self._sampler.use(0)          # smooth, without changing the solver's own texture
        self._lut.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self._lut.use(1)
        program = self._program
        program["field"] = 0
        program["lut"] = 1
        program["mode"] = mode.shader_mode
        program["scale"] = scale
        program["range"] = mode.range
        program["rho_ref"] = rho_ref
        program["flip_y"] = 1.0  # the image's first row is the lattice's top
        program["bgra"] = int(LITTLE_ENDIAN)   # B, G, R, A bytes are QImage.Format_RGB32 there
        self._vao.render(moderngl.TRIANGLE_STRIP, vertices=4)
        self._image_fbo.read_into(self._pixels, components=4, alignment=1)
        fmt = QImage.Format_RGB32 if LITTLE_ENDIAN else QImage.Format_RGBA8888   # RGB32: QPainter's fastest
        return QImage(self._pixels, size[0], size[1], 4 * size[0], fmt)
