"""The band area: slots for the body window right of the lattice in every state texture.

The forces of step t come from the post-collision populations f*(t) around the body (the
momentum exchange of Ladd 1994 and Wen et al. 2014, or any model's own code on the window).
To read a whole block of steps at once, the step's own pass also copies the body window of its
source state into a slot of its destination's band area: BAND_WIDTH node columns right of the
lattice in each state texture, so a tunnel's textures are nx + BAND_WIDTH wide. One pass a step
keeps llvmpipe at one scene a step; step b of a block writes slot b // 2 of the side it draws
into (the two ping-pong sides alternate). Where every force model is a momentum exchange, the
link-sum pass (solver/gl_link_sums.py) fills the slots with link sums instead of the window.

An x-periodic grid has no band area (its texture must be exactly nx wide for the REPEAT wrap),
and a window wider than the area does not fit: those take the check atlas (solver/gl_checks.py).
"""
from __future__ import annotations

import moderngl

from feelflow.solver.gl_layout import G_NAMES, UNIT_G
from feelflow.solver.gl_programs import create_program, set_uniforms, triangles

#: width in nodes of the band area right of the lattice in each state texture
BAND_WIDTH = 128


class BandArea:
    """The slots of the band area (texel columns [kx, kx + width) of every state texture) and
    the window copy's draw into them."""

    def __init__(self, ctx, kx: int, width: int, ny: int, tex_size):
        self.ctx, self.kx, self.width, self.ny, self.tex_size = ctx, kx, width, ny, tex_size
        self.layout = None  # (cols, ww, wh): slots across, window width and height in texels
        self._vao = self._vbo = self._prog = None

    def slots(self, window_texels) -> int:
        """Slots for a body window of texel box `window_texels` (0: no band area, or the window
        does not fit); lays the copy pass's rectangles out for that window size."""
        if not self.width:
            return 0
        k0, y0, k1, y1 = window_texels
        ww, wh = k1 - k0, y1 - y0
        cols, rows = self.width // ww, self.ny // wh
        if cols * rows == 0:
            return 0
        layout = (cols, ww, wh)
        if layout != self.layout:
            if self._prog is None:
                self._prog = create_program(self.ctx, "rect_vertex.glsl", "copy_window.glsl")
                set_uniforms(self._prog, **dict(zip(G_NAMES, UNIT_G)),
                             grid_size=(float(self.tex_size[0]), float(self.ny)))
                self._vbo = self.ctx.buffer(reserve=1)
            else:
                self._vao.release()
            rects = [(self.kx + c * ww, r * wh, self.kx + (c + 1) * ww, (r + 1) * wh)
                     for r in range(rows) for c in range(cols)]
            data = triangles(rects).tobytes()
            self._vbo.orphan(len(data))
            self._vbo.write(data)
            self._vao = self.ctx.vertex_array(self._prog, [(self._vbo, "2f", "in_pos")])
            self.layout = layout
        return cols * rows

    def slot_origin(self, slot: int) -> tuple[int, int]:
        """The lower-left texel of slot `slot` in a state texture."""
        cols, ww, wh = self.layout
        return self.kx + (slot % cols) * ww, (slot // cols) * wh

    def draw_copy(self, slot: int, window_texels) -> None:
        """Copy the body window (texel box) of the bound source state into slot `slot` of the
        bound target (inside the step's pass)."""
        k0, y0 = window_texels[:2]
        sx, sy = self.slot_origin(slot)
        self._vao.program["shift"].value = (k0 - sx, y0 - sy)
        self._vao.render(moderngl.TRIANGLES, vertices=6, first=6 * slot)

    def windows(self, read_texels, sides, bands: int, window) -> list:
        """The stored g (9, h, w) of each step's body window (x0, y0, x1, y1): step b's is slot
        b // 2 of side sides[b % 2]; each side's used rows are read once through
        `read_texels(kbox, side)`."""
        cols, ww, wh = self.layout
        x0, _, x1, _ = window
        lo = x0 - 2 * (x0 // 2)  # the window's first node within its first texel
        out = []
        areas = {}
        for b in range(bands):
            side, slot = sides[b % 2], b // 2
            if side not in areas:
                used = (bands - 1 - b % 2) // 2 + 1  # slots this side holds
                h = -(-used // cols) * wh
                areas[side] = read_texels((self.kx, 0, self.kx + cols * ww, h), side)
            c, r = slot % cols, slot // cols
            nodes = areas[side][:, r * wh:(r + 1) * wh, 2 * c * ww:2 * (c + 1) * ww]
            out.append(nodes[:, :, lo:lo + x1 - x0])
        return out

    def release(self) -> None:
        for obj in (self._vao, self._vbo, self._prog):
            if obj is not None:
                obj.release()
        self._vao = self._vbo = self._prog = None
        self.layout = None
