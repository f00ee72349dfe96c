"""The divergence check of the gl backend, and the check atlas that carries it to the CPU.

Steps run in blocks of up to CHECK_EVERY with nothing read back inside a block (every read
drains llvmpipe's queue). At the end of a block a pass sums texture G0 of the final state over
tiles of BLOCK_X x BLOCK_Y texels (shaders/finite_check.glsl) into a band of the check atlas; a
non-finite sum means a non-finite population somewhere. One texture suffices: streaming and the
collision's moments carry a NaN or Inf into every population of a node's neighbours within one
step, so a non-finite value never vanishes from the fluid.

Where the body's force window has no slot in the state textures' band area (solver/gl_band.py:
an x-periodic grid, whose texture must be exactly nx wide for the REPEAT wrap, or a window wider
than the band area), a second pass per step copies the window of the step's source state into a
band of the same atlas (shaders/copy_window.glsl), and the block reads all bands at once.
"""
from __future__ import annotations

import moderngl
import numpy as np

from feelflow.solver.gl_layout import G_NAMES, TEXTURES, UNIT_G, unpack
from feelflow.solver.gl_programs import begin_pass, create_program, set_uniforms, triangles

#: steps whose divergence checks and force windows are read back together (one GPU sync)
CHECK_EVERY = 32


def tile_block(kx: int) -> tuple[int, int]:
    """(BLOCK_X, BLOCK_Y) of the finite check: 256 texels a tile, at least 128 tiles across
    (two of llvmpipe's 64-pixel bins, so both threads reduce) where the grid allows."""
    bx = 1
    while bx < 16 and -(-kx // (2 * bx)) >= 128:
        bx *= 2
    return bx, 256 // bx


class CheckAtlas:
    """Per step one band of tile sums (columns [0, TW)) and, where asked, one band of the body
    window (columns [TW, TW + w), in texels); five RGBA32F attachments, as the state."""

    def __init__(self, ctx, kx: int, nx: int, ny: int):
        self.ctx, self.kx, self.nx, self.ny = ctx, kx, nx, ny
        self.block = tile_block(kx)
        self.grid = (-(-kx // self.block[0]), -(-ny // self.block[1]))  # tiles (TW, TH)
        self.size = None
        self.fbo = None
        self.window = (0, 0)  # (w, h) in texels of the body window's bands
        self._layout = None
        self._targets = []  # the atlas textures and framebuffer (remade when it grows)
        self._passes = None  # ((vao, vbo) of the tile sums, (vao, vbo) of the window copy)
        self._objects = []

    def ensure(self, window_texels=None) -> int:
        """Size the atlas for the tile sums and, with `window_texels` (k0, y0, k1, y1), the
        body window; returns how many bands (steps) fit: CHECK_EVERY, fewer for a window too
        tall for the texture."""
        tw, th = self.grid
        ww, wh = (0, 0)
        if window_texels is not None:
            k0, y0, k1, y1 = window_texels
            ww, wh = k1 - k0, y1 - y0
        limit = int(self.ctx.info.get("GL_MAX_TEXTURE_SIZE", 16384))
        bands = max(1, min(CHECK_EVERY, limit // max(th, wh)))
        need = (tw + ww, max(th, wh) * bands)
        if self.size is None or any(a < b for a, b in zip(self.size, need)):
            old = self.size or (0, 0)
            for obj in self._targets:
                obj.release()
            size = (min(limit, max(need[0], old[0])), min(limit, max(need[1], old[1])))
            texs = [self.ctx.texture(size, 4, dtype="f4") for _ in range(TEXTURES)]
            self.fbo = self.ctx.framebuffer(color_attachments=texs)
            self.size, self._targets, self._layout = size, [self.fbo, *texs], None
        if self._passes is None:
            tiles = self._program("finite_check.glsl", {"BLOCK_X": self.block[0], "BLOCK_Y": self.block[1]})
            set_uniforms(tiles[0].program, N=(self.kx, self.ny))
            self._passes = (tiles, self._program("copy_window.glsl"))
        size = self.size
        for vao, _ in self._passes:
            set_uniforms(vao.program, grid_size=(float(size[0]), float(size[1])))
        if (size, ww, wh) != self._layout:
            self._layout = (size, ww, wh)
            band_h = max(th, wh)
            rects = [(0, b * band_h, tw, b * band_h + th) for b in range(CHECK_EVERY)]
            rects += [(tw, b * band_h, tw + ww, b * band_h + wh) for b in range(CHECK_EVERY)]
            for _, vbo in self._passes:
                vbo.orphan(len(rects) * 6 * 8)
                vbo.write(triangles(rects).tobytes())
        self.window = (ww, wh)
        return bands

    def _program(self, fragment, defines=None):
        """(vao, vbo) of a pass into the atlas; the vbo holds one rectangle per band."""
        prog = create_program(self.ctx, "rect_vertex.glsl", fragment, defines)
        vbo = self.ctx.buffer(reserve=2 * CHECK_EVERY * 6 * 8)
        vao = self.ctx.vertex_array(prog, [(vbo, "2f", "in_pos")])
        self._objects += [vao, vbo, prog]
        set_uniforms(prog, **dict(zip(G_NAMES, UNIT_G)), N=(self.nx, self.ny))
        return vao, vbo

    def _band_height(self) -> int:
        return max(self.grid[1], self.window[1])

    def queue(self, band: int, state=None, window_state=None, window_origin=None) -> None:
        """Into band `band`: the tile sums of `state` (its five textures) and the body window,
        lower-left texel `window_origin`, of `window_state` (one pass: both draws share
        llvmpipe's scene)."""
        tw = self.grid[0]
        band_h = self._band_height()
        (tile_vao, _), (window_vao, _) = self._passes
        begin_pass(self.ctx, self.fbo, self.size)
        if state is not None:
            state[0].use(location=UNIT_G[0])
            tile_vao.program["band"].value = (0, band * band_h)
            tile_vao.render(moderngl.TRIANGLES, vertices=6, first=6 * band)
        if window_state is not None:
            for unit, texture in zip(UNIT_G, window_state):
                texture.use(location=unit)
            k0, y0 = window_origin
            window_vao.program["shift"].value = (k0 - tw, y0 - band * band_h)
            window_vao.render(moderngl.TRIANGLES, vertices=6, first=6 * (CHECK_EVERY + band))

    def tiles_finite(self, band: int = 0) -> bool:
        """Whether every tile sum of band `band` is finite (a read: waits for the GPU)."""
        tw, th = self.grid
        data = self.fbo.read(viewport=(0, band * self._band_height(), tw, th), components=4,
                             attachment=0, dtype="f4")
        return bool(np.all(np.isfinite(np.frombuffer(data, dtype="f4"))))

    def windows(self, window, bands: int) -> list[np.ndarray]:
        """The stored g (9, h, w) of the body window (x0, y0, x1, y1) of each of the first
        `bands` steps, read from the atlas at once."""
        tw = self.grid[0]
        ww, wh = self.window
        band_h = self._band_height()
        height = (bands - 1) * band_h + wh
        g = unpack([np.frombuffer(self.fbo.read(viewport=(tw, 0, ww, height), components=4, attachment=k,
                                                dtype="f4"), dtype="f4").reshape(height, ww, 4)
                    for k in range(TEXTURES)])
        x0, _, x1, _ = window
        lo = x0 - 2 * (x0 // 2)
        return [g[:, b * band_h:b * band_h + wh, lo:lo + x1 - x0] for b in range(bands)]

    def release(self) -> None:
        for obj in [*self._targets, *self._objects]:
            obj.release()
        self._targets, self._objects, self._passes, self.size, self.fbo = [], [], None, None, None
